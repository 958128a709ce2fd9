//! Caustics of curved mirrors (Hou, Wei, Shum and Guo 2006, section 3.3, after Wyman 2006):
//! two passes per mirror (scene key `caustics = true`) and point light.
//!
//! 1. **Photon-location map** ([`photon_map`]): a square image from the light's point of view,
//!    framing the mirror; each texel whose light ray reaches the mirror first holds the
//!    receiver point its reflected ray lands on, with the receiver's id. With
//!    `--method camera-triangles` (or `trilinear`) the map is the mirror's reflection surface
//!    seen from the light (the trilinear surface of the mirror's vertex rays reflected from
//!    the light, `reflector_surface`), rendered by that method: its projection triangles are
//!    the camera triangles the photons come through. With `--method raycast` each texel's
//!    light ray is traced exactly: intersected with the mirror, reflected about its
//!    interpolated normal, intersected with the rest of the scene. That is the reference
//!    `flexcam compare` measures the camera-triangle caustic against.
//! 2. **Splatting** ([`splat`]): two neighbouring texels and a third make a map triangle;
//!    its photons make a *caustic triangle* on the receiver, which takes the light the map
//!    triangle's beam carries. Each caustic triangle is drawn into the eye's image, adding
//!    its irradiance at the receiver pixels it covers, and each such pixel's colour gains
//!    its albedo (the base colour the main view shows there) times the irradiance.
//!
//! **Irradiance of a caustic triangle.** Let `a, b, c` be the unit directions from the light
//! through the map triangle's texel centres. The map triangle subtends the solid angle
//! `Ω_a = 2 atan2(|a · (b × c)|, 1 + a·b + b·c + c·a)` (Van Oosterom and Strackee), so a light
//! of radiant intensity `I` (its `color * intensity`, per channel) sends the power
//! `Φ = I Ω_a` into it, of which the mirror reflects `R Φ` (`R` the mirror's colour: the ray
//! caster's mirror tints its reflection by it). That power lands on the caustic triangle
//! `P0 P1 P2`, of area `A = |(P1 - P0) × (P2 - P0)| / 2`, so its irradiance is
//!
//! ```text
//! E = R I Ω_a / A.
//! ```
//!
//! In the paper's terms, a ratio of solid angles: seen from distance `d` along the light's
//! reflected path (light to mirror to receiver), arriving at angle `θ` to the receiver's
//! normal, the caustic triangle subtends `Ω_A = A cos θ / d²`, and
//! `E = R I (Ω_a / Ω_A) cos θ / d²`. For a flat mirror `Ω_A`, seen from the mirrored light,
//! is `Ω_a`, so `E = R I cos θ / d²`, the closed form of a point light's mirror image. The
//! area form is what is computed: it needs no `θ` or `d` (a grazing beam spreads over a
//! larger `A`). The caustic falls off with distance as a photon tracer's does, unlike
//! flexcam's direct point-light term, which by convention does not (module
//! [`crate::scene::Light`]). Overlapping caustic triangles (folds of the reflected wavefront)
//! add, as the light they carry does.
//!
//! Degenerate cases, each dropping the map triangle's light (tests name each):
//! - a caustic triangle of zero area (its photons on a line: a focal line on the receiver)
//!   would have infinite irradiance;
//! - photons of one map triangle on different objects (the beam splits at an edge), or on
//!   an object that is not diffuse (no albedo to scatter with);
//! - texels whose light ray does not reach the mirror first (outside it, or shadowed).
//!
//! A caustic triangle whose photons straddle an occlusion edge of one receiver spreads its
//! light over the hidden gap, as Wyman's splats do. Light is reflected once: the mirror
//! receives none of its own. Directional lights cast no caustics (they have no position to
//! map from); a light inside the mirror's bounding sphere has no map that frames it and is
//! refused.

#[cfg(test)]
mod glass_tests;
mod photon_map;
mod splat;
#[cfg(test)]
mod tests;

use std::time::Instant;

use glam::Vec3;

use self::photon_map::{PhotonMap, PhotonSource};
use self::splat::splat;
use super::composite::{
    add_camera_triangle_counts, main_camera, perspective_as_trilinear, Reflector,
};
use crate::error::Result;
use crate::projection::Projection;
use crate::render::prepared::PreparedScene;
use crate::render::{
    frame_name, Counter, Method, Outputs, RenderOptions, Rendered, Shading, Stats,
};
use crate::scene::{Finish, Light, Scene};
use crate::try_alloc;

/// Whether [`add`] has caustics to add: the scene names caustic mirrors and the shading is
/// `lit` (flat shading shows base colours, without light).
pub(super) fn wanted(scene: &Scene, options: &RenderOptions) -> bool {
    !scene.caustics.is_empty() && options.shading == Shading::Lit
}

/// Adds the caustics of every caustic mirror of `prepared` and point light to `rendered`,
/// the main view through `projection` (which must hold ids and depth), as the module doc
/// says: the photon maps come from `options.method` ([`PhotonSource::of`]). Reports
/// `caustic_photons` (map texels holding a photon), `caustic_triangles` (caustic triangles
/// splatted), `caustic_pixels` (eye pixels lit by a caustic) and `caustic_ms`, and with
/// camera triangles the maps' renders through the mirrors' surfaces summed as
/// `caustic_camera_triangles`, `caustic_bounding_fragments`, `caustic_rendered_fragments`
/// and `caustic_overdraw` (bounding over rendered: Table 1's caustics row). Errors: a
/// method without a photon map, a main projection that is not perspective, a light inside
/// a mirror's bounding sphere, memory that cannot be had (module `try_alloc`).
pub(super) fn add(
    prepared: &PreparedScene,
    projection: &dyn Projection,
    options: &RenderOptions,
    rendered: &mut Rendered,
) -> Result<()> {
    let start = Instant::now();
    let scene = prepared.scene();
    let source = PhotonSource::of(options.method)?;
    let eye = main_camera(scene, projection)?;
    let frame = &mut rendered.frame;
    let mut irradiance = try_alloc::zeroed(frame.color.len(), || {
        format!("the caustics of {}", frame_name(frame.width, frame.height))
    })?;
    let (mut photons, mut triangles) = (0u64, 0u64);
    let mut maps = Stats::new();
    for caustic in &scene.caustics {
        let tint = Reflector::of(scene, caustic.id)?.tint;
        for light in &scene.lights {
            let Light::Point {
                position,
                color,
                intensity,
            } = *light
            else {
                continue;
            };
            let map = PhotonMap::render(prepared, caustic, position.as_dvec3(), source, options)?;
            photons += map.photon_count();
            add_camera_triangle_counts(&mut maps, &map.counters);
            let caustic_triangles = map.caustic_triangles(color * intensity * tint);
            triangles += caustic_triangles.len() as u64;
            splat(
                &eye,
                &frame.ids,
                &frame.depth,
                &caustic_triangles,
                &mut irradiance,
            )?;
        }
    }
    let albedo = albedo(prepared, projection, options)?;
    let mut pixels = 0;
    for (k, e) in irradiance.iter().enumerate() {
        if *e != Vec3::ZERO {
            frame.color[k] += albedo[k] * *e;
            pixels += 1;
        }
    }
    let stats = &mut rendered.counters;
    stats.insert("caustic_photons", Counter::Count(photons));
    stats.insert("caustic_triangles", Counter::Count(triangles));
    stats.insert("caustic_pixels", Counter::Count(pixels));
    for (name, as_name) in [
        ("camera_triangles", "caustic_camera_triangles"),
        ("bounding_fragments", "caustic_bounding_fragments"),
        ("rendered_fragments", "caustic_rendered_fragments"),
        ("overdraw", "caustic_overdraw"),
    ] {
        if let Some(counter) = maps.get(name) {
            stats.insert(as_name, *counter);
        }
    }
    stats.insert(
        "caustic_ms",
        Counter::Value(start.elapsed().as_secs_f64() * 1e3),
    );
    Ok(())
}

/// The base colour each pixel of the main view shows (its flat shading): the albedo the
/// caustics scatter with, at the diffuse receivers. Rendered by the method that renders the
/// main view: the ray caster, or for the trilinear methods the trilinear method through the
/// pinhole as two projection triangles (as reflector compositing renders the main view).
fn albedo(
    prepared: &PreparedScene,
    projection: &dyn Projection,
    options: &RenderOptions,
) -> Result<Vec<Vec3>> {
    let flat = RenderOptions {
        composite_reflectors: false,
        shading: Shading::Flat,
        outputs: Outputs::COLOR,
        progress: None,
        crop: None,
        ..*options
    };
    let frame = match options.method {
        Method::Trilinear | Method::CameraTriangles => {
            let pinhole = perspective_as_trilinear(&main_camera(prepared.scene(), projection)?)?;
            Method::Trilinear.render(prepared, &pinhole, &flat)?.0
        }
        method => method.render(prepared, projection, &flat)?.0,
    };
    Ok(frame.color)
}

/// Whether the object with id `id` scatters caustics: every part of it is diffuse.
fn receives(scene: &Scene, id: u32) -> bool {
    let mut parts = scene.objects.iter().filter(|o| o.id == id).peekable();
    parts.peek().is_some() && parts.all(|o| o.material.finish == Finish::Diffuse)
}
