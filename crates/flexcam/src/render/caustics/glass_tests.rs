//! Refraction caustics (caustics of glass objects): the flat sheet's closed form, energy,
//! camera triangles against the exact map, total internal reflection and grazing light.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::{DVec2, DVec3, Vec3};

use super::photon_map::{solid_angle, triangle_area, CausticTriangle, PhotonMap};
use super::tests::{caustic_power, eye_irradiance, map_of, point_light, SOURCES};
use crate::geometry::optics::refract;
use crate::projection::Projection;
use crate::scene::{self, Finish, Mesh, Scene};

fn glass_scene() -> Scene {
    scene::load(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenes/camtri-caustic-glass.toml"
    ))
    .unwrap()
}

/// A 1 x 1 glass sheet of index 1.5 and tint `[0.9, 0.8, 0.7]` at height 2, 8 x 8 cells,
/// facing up (`rotate` 180 about x: facing down), over a floor of side `floor` at height 0,
/// lit by a point light at `light` (intensity 2), photon map of `map` texels.
fn sheet(light: DVec3, facing_down: bool, map: u32, floor: f64) -> Scene {
    let rotate = if facing_down {
        "rotate = [180.0, 0.0, 0.0]"
    } else {
        ""
    };
    let text = format!(
        r#"
        [projection]
        type = "perspective"
        position = [0.0, 1.0, 6.0]
        look_at = [0.0, 0.0, 0.0]
        fov = 60.0
        [[object]]
        name = "sheet"
        shape = "plane"
        size = [1.0, 1.0]
        tessellation = 8
        material = "glass"
        ior = 1.5
        color = [0.9, 0.8, 0.7]
        {rotate}
        translate = [0.0, 2.0, 0.0]
        caustics = true
        caustic_map = {map}
        [[object]]
        name = "floor"
        shape = "plane"
        size = [{floor}, {floor}]
        [[light]]
        type = "point"
        position = [{}, {}, {}]
        intensity = 2.0
        "#,
        light.x, light.y, light.z
    );
    scene::file::parse(&text, Path::new("sheet.toml")).unwrap()
}

/// The irradiance on a plane at depth `b` below a flat interface of index `ior` (single
/// refraction: the plane inside the material) of a point light of unit intensity at height
/// `a` above it, at horizontal distance `rho` from the light's foot, and the Fresnel
/// transmittance there (docs/camera-triangles.md, "Refraction caustics"): with `θt` from
/// `sin θi = ior sin θt` and `rho = a tan θi + b tan θt` (solved for `θi` by bisection),
/// `E = T sin θi / (rho (a / cos² θi + b cos θi / (ior cos³ θt)))`.
fn flat_interface(a: f64, b: f64, ior: f64, rho: f64) -> (f64, f64) {
    let theta_t = |theta_i: f64| (theta_i.sin() / ior).asin();
    let landing = |theta_i: f64| a * theta_i.tan() + b * theta_t(theta_i).tan();
    let (mut lo, mut hi) = (0.0, std::f64::consts::FRAC_PI_2);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if landing(mid) < rho {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let (ti, tt) = (0.5 * (lo + hi), theta_t(0.5 * (lo + hi)));
    let spread = a / ti.cos().powi(2) + b * ti.cos() / (ior * tt.cos().powi(3));
    let incident = DVec3::new(ti.sin(), -ti.cos(), 0.0);
    let transmittance = 1.0 - refract(incident, DVec3::Y, 1.0 / ior).unwrap().reflectance;
    (transmittance * ti.sin() / (rho * spread), transmittance)
}

/// Worst relative difference between each caustic triangle's irradiance and the closed
/// form at its centroid, and the largest and smallest transmittance seen there.
fn against_closed_form(
    triangles: &[CausticTriangle],
    light: DVec3,
    tinted: Vec3,
) -> (f64, f64, f64) {
    let (mut worst, mut t_max, mut t_min) = (0.0f64, 0.0f64, 1.0f64);
    for t in triangles {
        let c = (t.points[0] + t.points[1] + t.points[2]) / 3.0;
        assert!(c.y.abs() < 1e-5, "lands off the floor at {c}");
        let rho = DVec3::new(c.x - light.x, 0.0, c.z - light.z).length();
        let (e, transmittance) = flat_interface(light.y - 2.0, 2.0, 1.5, rho);
        t_max = t_max.max(transmittance);
        t_min = t_min.min(transmittance);
        for channel in 0..3 {
            let want = f64::from(tinted[channel]) * e;
            let got = f64::from(t.irradiance[channel]);
            worst = worst.max((got - want).abs() / want);
        }
    }
    (worst, t_max, t_min)
}

/// A flat glass sheet spreads the refracted beam (it does not keep the light's distance
/// law): every caustic triangle's irradiance is the flat interface's closed form at its
/// centroid, Fresnel transmittance included, for a light above the sheet's middle and for
/// one at grazing incidence (78 to 84 degrees: transmittance well below 1). The exact map to
/// the second-order difference between a triangle's mean and its centroid's value; the map
/// through the sheet's camera triangles to the error of its interpolated rays (refraction is
/// not linear across a cell, unlike a flat mirror's reflection).
#[test]
fn flat_glass_sheet_gives_the_closed_form() {
    let tinted = Vec3::new(0.9, 0.8, 0.7) * 2.0;
    for (light, map, exact_bound, surface_bound) in [
        // Measured: exact 6.9e-4 (1.3e-3 at map 96), camera triangles 1.4e-2.
        (DVec3::new(0.2, 3.0, 0.1), 192, 1e-3, 0.02),
        // Measured: exact 6.5e-3, camera triangles 4.9e-2 (a thin sliver of the map).
        (DVec3::new(1.5, 2.2, 0.0), 256, 1e-2, 0.06),
    ] {
        let scene = sheet(light, false, map, 40.0);
        for source in SOURCES {
            let triangles = map_of(&scene, source).caustic_triangles(tinted);
            assert!(triangles.len() > 1000, "{source:?}: {}", triangles.len());
            let (worst, t_max, t_min) = against_closed_form(&triangles, light, tinted);
            eprintln!(
                "light {light}, {source:?}: {} triangles, transmittance {t_min:.3} to \
                 {t_max:.3}, relative error {worst:.2e}",
                triangles.len()
            );
            let bound = if source == SOURCES[1] {
                exact_bound
            } else {
                surface_bound
            };
            assert!(worst < bound, "{source:?}: relative error {worst}");
            if light.y < 2.5 {
                assert!(t_max < 0.75, "grazing: transmittance up to {t_max}");
            }
        }
    }
}

/// Energy: the light the caustic triangles carry, `Σ E A`, is the light that enters the
/// glass, `I tint ∫ T dΩ` over the cap as seen from the light, `T` the Fresnel transmittance
/// about the interpolated shading normal; the integral is computed independently of the
/// maps, over the cap's own triangles (each cut into 64 pieces, each piece's solid angle from
/// the light times `T` at its centroid). Up to the map triangles lost at the cap's rim.
#[test]
fn refraction_caustics_carry_the_light_the_glass_lets_through() {
    let scene = glass_scene();
    let (light, intensity) = point_light(&scene);
    let glass = &scene.objects[0];
    let Finish::Glass { ior } = glass.material.finish else {
        panic!("not glass")
    };
    let mesh = &glass.mesh;
    let m = 8;
    let mut through = 0.0;
    for t in &mesh.triangles {
        let p = t.map(|i| mesh.positions[i as usize].as_dvec3());
        let n = t.map(|i| mesh.normals[i as usize].as_dvec3());
        let at = |u: f64, v: f64| {
            (
                p[0] + u * (p[1] - p[0]) + v * (p[2] - p[0]),
                n[0] + u * (n[1] - n[0]) + v * (n[2] - n[0]),
            )
        };
        let step = 1.0 / f64::from(m);
        for i in 0..m {
            for j in 0..m - i {
                let (u, v) = (f64::from(i) * step, f64::from(j) * step);
                let mut pieces = vec![[(u, v), (u + step, v), (u, v + step)]];
                if i + j + 1 < m {
                    pieces.push([(u + step, v), (u + step, v + step), (u, v + step)]);
                }
                for piece in pieces {
                    let corners = piece.map(|(u, v)| (at(u, v).0 - light).normalize());
                    let (cu, cv) = (
                        piece.iter().map(|q| q.0).sum::<f64>() / 3.0,
                        piece.iter().map(|q| q.1).sum::<f64>() / 3.0,
                    );
                    let (point, normal) = at(cu, cv);
                    let incident = (point - light).normalize();
                    let normal = normal.normalize();
                    assert!(incident.dot(normal) < 0.0, "the light sees the cap's front");
                    let r = refract(incident, normal, 1.0 / f64::from(ior)).unwrap();
                    through += (1.0 - r.reflectance) * solid_angle(corners);
                }
            }
        }
    }
    let tinted = intensity * glass.material.color;
    for source in SOURCES {
        let power = caustic_power(&scene, source, tinted);
        let want = f64::from(tinted.x) * through;
        let lost = 1.0 - power / want;
        eprintln!("{source:?}: power {power:.5}, I tint ∫T dΩ {want:.5}, lost {lost:.5}");
        // Measured: 0.93 % lost, by both maps.
        assert!((0.0..0.02).contains(&lost), "{source:?}: lost {lost}");
    }
}

/// The refraction caustic through camera triangles against the exact one, in the eye's
/// view (160 x 120, photon maps of 128 texels; the exact main view's ids and depth for
/// both): `Σ |E - E_exact| / Σ E_exact` over the pixels either lights.
#[test]
fn camera_triangle_refraction_caustic_matches_the_exact_one() {
    let mut scene = glass_scene();
    scene.caustics[0].map_size = 128;
    let [ours, exact] = eye_irradiance(&scene, 160, 120);
    let (mut difference, mut total, mut lit) = (0.0, 0.0, 0);
    let (mut inner_difference, mut inner_total) = (0.0, 0.0);
    for (a, b) in ours.iter().zip(&exact) {
        if *a != Vec3::ZERO && *b != Vec3::ZERO {
            inner_difference += f64::from((*a - *b).abs().element_sum());
            inner_total += f64::from(b.element_sum());
        }
        if *a != Vec3::ZERO || *b != Vec3::ZERO {
            difference += f64::from((*a - *b).abs().element_sum());
            total += f64::from(b.element_sum());
            lit += 1;
        }
    }
    let error = difference / total;
    eprintln!(
        "refraction caustic: relative error {error:.4} over {lit} pixels, {:.4} where both \
         light",
        inner_difference / inner_total
    );
    // Measured: 17.1 % over 425 pixels, 7.7 % where both light (the rest is the spot's
    // rim, moved by the interpolated rays' direction error, which the focusing magnifies).
    assert!(lit > 200, "{lit} pixels lit");
    assert!(error < 0.2, "relative error {error}");
}

/// Total internal reflection everywhere: a light above a sheet facing down, far to the side
/// (incidence 78 degrees and more), meets the sheet's back, where the light would leave the
/// glass (relative index 1.5, critical angle 41.8 degrees): no texel holds a photon, by
/// either map. The light straight above the same sheet (incidence below the critical angle
/// over most of it) does pass it in the exact map; the refraction surface refracts through
/// the front (the normals' side) only and drops the back, as camera-triangle refraction of
/// the main view does, so its map stays empty there too.
#[test]
fn total_internal_reflection_holds_no_photon() {
    let sideways = sheet(DVec3::new(3.0, 2.5, 0.0), true, 64, 40.0);
    for source in SOURCES {
        let map = map_of(&sideways, source);
        assert_eq!(map.photon_count(), 0, "{source:?}");
        assert!(map.caustic_triangles(Vec3::ONE).is_empty(), "{source:?}");
    }
    let above = sheet(DVec3::new(0.1, 3.0, 0.0), true, 64, 40.0);
    let [surface, exact] = SOURCES.map(|source| map_of(&above, source).photon_count());
    assert!(exact > 500, "{exact} photons");
    assert_eq!(surface, 0);
}

/// `mesh` with every triangle split into four at its edge midpoints, each midpoint on the
/// flat triangle with the average of its ends' raw normals: the ray caster's surface (flat
/// triangles, linearly interpolated normals) is unchanged, while a surface built on the
/// mesh gets twice as many camera triangles along each side.
fn split_in_four(mesh: &Mesh) -> Mesh {
    let mut out = Mesh {
        positions: mesh.positions.clone(),
        normals: mesh.normals.clone(),
        ..Mesh::default()
    };
    let mut midpoints = HashMap::new();
    let mut midpoint = |a: u32, b: u32| {
        *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
            let (a, b) = (a as usize, b as usize);
            out.positions
                .push((out.positions[a] + out.positions[b]) * 0.5);
            out.normals.push((out.normals[a] + out.normals[b]) * 0.5);
            (out.positions.len() - 1) as u32
        })
    };
    let mut triangles = Vec::new();
    for &[a, b, c] in &mesh.triangles {
        let (ab, bc, ca) = (midpoint(a, b), midpoint(b, c), midpoint(c, a));
        triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    out.triangles = triangles;
    out
}

/// Per map triangle whose three texels hold photons in both maps (of one object): the
/// relative difference of `surface`'s irradiance from `exact`'s, and `exact`'s irradiance
/// (light and tint left out: the ratio `Ω_a T / A`).
fn triangle_differences(surface: &PhotonMap, exact: &PhotonMap) -> Vec<(f64, f64)> {
    let n = exact.size as usize;
    let mut out = Vec::new();
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            for texels in [
                [(x, y), (x + 1, y), (x, y + 1)],
                [(x + 1, y), (x + 1, y + 1), (x, y + 1)],
            ] {
                let of = |map: &PhotonMap| {
                    let photons = texels.map(|(x, y)| map.photons[y * n + x]);
                    let [Some(a), Some(b), Some(c)] = photons else {
                        return None;
                    };
                    let area = triangle_area([a.point, b.point, c.point]);
                    let carried = (a.transmittance + b.transmittance + c.transmittance) / 3.0;
                    (a.id == b.id && a.id == c.id && area > 0.0).then_some(carried / area)
                };
                if let (Some(s), Some(e)) = (of(surface), of(exact)) {
                    out.push(((s - e).abs() / e, e));
                }
            }
        }
    }
    out
}

/// Why the refraction caustic through camera triangles is further from the exact one than
/// the mirror's, and that it converges. The example cap's outer zone refracts more strongly
/// than its middle (spherical aberration), so its rays cross before the floor: the exact
/// irradiance has a fold (the bright rim of the spot) where the landing map's Jacobian
/// vanishes and `Ω_a T / A` grows without bound. The camera triangles' rays are the vertex
/// rays interpolated: their directions are off by the second order of a camera triangle's
/// size `h`, their derivative (which sets the caustic triangles' areas) by the first, so a
/// caustic triangle's relative error is `O(h)` divided by the Jacobian, which is near 0 at
/// the fold. Hence (1) most of the error lies at the fold (map triangles of more than twice
/// the median exact irradiance), and (2) both parts at least halve when every camera
/// triangle is split in four (`h` halved: first order at worst, 0.6 allowing for the terms of
/// higher order); the exact map does not change (the split leaves the ray caster's surface
/// as it was: to 1e-5 of rounding). A defect in the refracted rays or the transmittance
/// (anything but the interpolation) would not fall with `h`.
#[test]
fn camera_triangle_refraction_caustic_error_sits_at_the_fold_and_converges() {
    let mut scene = glass_scene();
    scene.caustics[0].map_size = 128;
    let mut parts = Vec::new();
    let mut exact_maps: Vec<PhotonMap> = Vec::new();
    for level in 0..2 {
        if level > 0 {
            scene.objects[0].mesh = Arc::new(split_in_four(&scene.objects[0].mesh));
        }
        let [surface, exact] = SOURCES.map(|source| map_of(&scene, source));
        let differences = triangle_differences(&surface, &exact);
        let mut irradiance: Vec<f64> = differences.iter().map(|d| d.1).collect();
        irradiance.sort_by(f64::total_cmp);
        let fold = 2.0 * irradiance[irradiance.len() / 2];
        let mean = |near: bool| {
            let part: Vec<f64> = differences
                .iter()
                .filter(|d| (d.1 > fold) == near)
                .map(|d| d.0)
                .collect();
            (part.iter().sum::<f64>() / part.len() as f64, part.len())
        };
        let ((near, near_count), (away, away_count)) = (mean(true), mean(false));
        let [ours, exact_eye] = eye_irradiance(&scene, 160, 120);
        let (mut difference, mut total) = (0.0, 0.0);
        for (a, b) in ours.iter().zip(&exact_eye) {
            difference += f64::from((*a - *b).abs().element_sum());
            total += f64::from(b.element_sum());
        }
        eprintln!(
            "{} camera triangles: mean relative error per map triangle {near:.4} at the fold \
             ({near_count} triangles), {away:.4} away from it ({away_count}); in the eye's \
             view {:.4}",
            scene.objects[0].mesh.triangles.len(),
            difference / total
        );
        assert!(near > 5.0 * away, "the error does not sit at the fold");
        parts.push((near, away));
        if let Some(before) = exact_maps.last() {
            let mut moved = 0;
            for pair in before.photons.iter().zip(&exact.photons) {
                match pair {
                    (Some(a), Some(b)) => assert!((a.point - b.point).length() < 1e-5),
                    (None, None) => {}
                    // A texel centre on the cap's rim, decided the other way by rounding.
                    _ => moved += 1,
                }
            }
            assert!(
                moved * 1000 < before.photon_count(),
                "{moved} texels changed"
            );
        }
        exact_maps.push(exact);
    }
    let [(near0, away0), (near1, away1)] = [parts[0], parts[1]];
    assert!(near1 < 0.6 * near0, "at the fold: {near0} then {near1}");
    assert!(
        away1 < 0.6 * away0,
        "away from the fold: {away0} then {away1}"
    );
}

/// The exact flat-sheet error is first order in the texel size per caustic triangle (it
/// halves when the map's side doubles), and second order per texel square (it quarters): a
/// caustic triangle has straight edges between its photons, while the light of its spherical
/// triangle lands inside the images of great-circle arcs, which the refraction bends (unlike
/// a flat mirror's central projection, which keeps them straight). A bent edge of length `h`
/// with sagitta `O(h²)` moves `O(h³)` of area, relative `O(h)`; the neighbour across the
/// edge gains what the triangle loses, so the power is conserved and the error alternates.
/// Over a texel square the diagonal's share cancels and opposite sides bend alike
/// (`O(h⁴)`), leaving the second-order difference between the square's mean and its
/// centroid's value. Maps of 48 then 96 texels (a double-precision model of the same maps
/// gives 2.4e-3 then 1.3e-3 per triangle, 1.4e-4 then 3.6e-5 per square): the triangle's
/// worst error must fall by at least 1.5 (2 in the limit), the square's by at least 3 (4 in
/// the limit), and the square's must be the smaller. The floor is small (side 4): the
/// receiver's `f32` coordinates round a photon by about `1e-7` of their size, which moves a
/// square's area by a part that grows as `1 / h` (on the 40-wide floor about 1.5e-4 at map
/// 192, above the square's own error there; printed for map 192).
#[test]
fn exact_flat_sheet_error_is_first_order_per_triangle_second_per_square() {
    let light = DVec3::new(0.2, 3.0, 0.1);
    let tinted = Vec3::ONE;
    let mut errors = Vec::new();
    for map in [48, 96, 192] {
        let scene = sheet(light, false, map, 4.0);
        let photons = map_of(&scene, SOURCES[1]);
        let (triangle, _, _) =
            against_closed_form(&photons.caustic_triangles(tinted), light, tinted);
        let square = worst_square_error(&photons, light);
        eprintln!(
            "map {map}: worst relative error per triangle {triangle:.2e}, per square {square:.2e}"
        );
        errors.push((triangle, square));
    }
    let [(triangle0, square0), (triangle1, square1)] = [errors[0], errors[1]];
    assert!(
        square1 < triangle1,
        "square {square1}, triangle {triangle1}"
    );
    assert!(
        triangle1 < triangle0 / 1.5,
        "per triangle: {triangle0} then {triangle1}"
    );
    assert!(
        square1 < square0 / 3.0,
        "per square: {square0} then {square1}"
    );
}

/// The worst relative difference, over the texel squares of the exact map of the sheet of
/// [`sheet`] (index 1.5, unit tint) lit from `light`, between the square's irradiance (the
/// power of its two caustic triangles over their area) and the closed form at its centroid.
fn worst_square_error(photons: &PhotonMap, light: DVec3) -> f64 {
    let n = photons.size as usize;
    let direction = |(x, y): (usize, usize)| {
        let centre = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
        photons.camera.ray(centre).unwrap().direction
    };
    let mut worst = 0.0f64;
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let corners = [(x, y), (x + 1, y), (x + 1, y + 1), (x, y + 1)];
            let found = corners.map(|(x, y)| photons.photons[y * n + x]);
            let [Some(p0), Some(p1), Some(p2), Some(p3)] = found else {
                continue;
            };
            let points = [p0, p1, p2, p3];
            let (mut power, mut area, mut centroid) = (0.0, 0.0, DVec3::ZERO);
            for half in [[0, 1, 3], [1, 2, 3]] {
                let a = triangle_area(half.map(|k| points[k].point));
                let carried = half.iter().map(|&k| points[k].transmittance).sum::<f64>() / 3.0;
                power += solid_angle(half.map(|k| direction(corners[k]))) * carried;
                area += a;
                centroid += a * half.iter().map(|&k| points[k].point).sum::<DVec3>() / 3.0;
            }
            let c = centroid / area;
            let rho = DVec3::new(c.x - light.x, 0.0, c.z - light.z).length();
            let (want, _) = flat_interface(light.y - 2.0, 2.0, 1.5, rho);
            worst = worst.max((power / area - want).abs() / want);
        }
    }
    worst
}
