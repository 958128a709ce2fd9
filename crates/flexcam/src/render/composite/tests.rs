use glam::{DVec3, Vec3};

use super::*;
use crate::projection::ProjectionSpec;
use crate::render::compare::{compare, Comparison};
use crate::render::Method;
use crate::scene::reflector_fixtures::{
    lens_plane, sphere_and_cube, ReflectorFixture, BALL, BALL_CENTER,
};
use crate::scene::TrilinearReflector;

const SIZE: (u32, u32) = (160, 120);

/// The shared sphere-and-cube fixture with the 32-segment sphere as a trilinear reflector.
fn scene() -> Scene {
    sphere_and_cube_reflector(32)
}

fn sphere_and_cube_reflector(segments: u32) -> Scene {
    let mut scene = sphere_and_cube(segments);
    scene.trilinear_reflectors = vec![TrilinearReflector::new(BALL)];
    scene
}

fn raycast(
    scene: &PreparedScene,
    projection: &dyn Projection,
    options: &RenderOptions,
) -> Result<(Frame, Stats)> {
    Method::Raycast.render(scene, projection, options)
}

fn flat() -> RenderOptions<'static> {
    flat_by(Method::Raycast)
}

/// Flat shading by `method` (which renders every view of the composite).
fn flat_by(method: Method) -> RenderOptions<'static> {
    RenderOptions {
        method,
        shading: Shading::Flat,
        ..RenderOptions::default()
    }
}

/// `scene` through `main` by the entry point, the reflectors composited as `options` say.
fn try_composite(
    scene: &Scene,
    main: &dyn Projection,
    options: &RenderOptions,
) -> Result<Rendered> {
    crate::render::render(&PreparedScene::new(scene), main, options)
}

/// [`try_composite`], which must succeed.
fn composited(scene: &Scene, main: &dyn Projection, options: &RenderOptions) -> Rendered {
    try_composite(scene, main, options).unwrap()
}

/// The pixels of `frame` where `reference` sees object `id`, as a one-row frame.
fn masked(frame: &Frame, reference: &Frame, id: u32) -> Frame {
    let keep: Vec<usize> = (0..reference.ids.len())
        .filter(|&k| reference.ids[k] == id)
        .collect();
    Frame {
        width: keep.len() as u32,
        height: 1,
        color: keep.iter().map(|&k| frame.color[k]).collect(),
        depth: keep.iter().map(|&k| frame.depth[k]).collect(),
        ids: keep.iter().map(|&k| frame.ids[k]).collect(),
        surface: Vec::new(),
    }
}

/// Agreement on the reflector's pixels: the comparison (relative RGB error of Vallance 2005) and
/// the fraction of pixels with exactly the reference colour (flat colours are discrete).
fn agreement(frame: &Frame, reference: &Frame, id: u32) -> (Comparison, f64) {
    let (a, b) = (
        masked(frame, reference, id),
        masked(reference, reference, id),
    );
    let same = a
        .color
        .iter()
        .zip(&b.color)
        .filter(|(x, y)| (**x - **y).abs().max_element() < 1e-6)
        .count();
    (compare(&a, &b).unwrap(), same as f64 / a.color.len() as f64)
}

/// The plain ray-cast image with the reflector as a true mirror (or glass).
fn reference(scene: &Scene, main: &dyn Projection) -> Frame {
    reference_with(scene, main, &flat())
}

/// [`reference`] with other render options.
fn reference_with(scene: &Scene, main: &dyn Projection, options: &RenderOptions) -> Frame {
    let mut plain = scene.clone();
    plain.trilinear_reflectors.clear();
    raycast(&PreparedScene::new(&plain), main, options)
        .unwrap()
        .0
}

/// The composite made from `surface` (possibly broken on purpose).
fn composite_from(scene: &Scene, main: &dyn Projection, surface: &ReflectorSurface) -> Frame {
    let camera = main_camera(scene, main).unwrap();
    let mut plain = scene.clone();
    plain.trilinear_reflectors.clear();
    plain.objects[0].material.finish = Finish::Diffuse;
    let mut frame = raycast(&PreparedScene::new(&plain), main, &flat())
        .unwrap()
        .0;
    let image = render_through(
        &PreparedScene::new(&without(scene, BALL)),
        surface,
        SurfaceScreenMap::Projective,
        &camera,
        &flat(),
        &raycast,
    )
    .unwrap()
    .unwrap();
    paste(&mut frame, BALL, &image, Vec3::ONE).unwrap();
    frame
}

/// Thresholds for the sphere (32 segments) at 160 x 120 (see docs/trilinear-surfaces.md for
/// the measured values): the composite must reach both, each broken surface must miss both.
const MIN_SAME_COLOUR: f64 = 0.9;
const MAX_RGB_ERROR: f64 = 0.1;

#[test]
fn sphere_composite_matches_the_true_mirror() {
    let scene = scene();
    let main = scene.projection.build(SIZE.0, SIZE.1).unwrap();
    let reference = reference(&scene, main.as_ref());
    let Rendered {
        frame,
        counters: stats,
        ..
    } = composited(&scene, main.as_ref(), &flat());
    assert_eq!(frame.ids, reference.ids, "ids are the main view's");
    // Depth is the reflector's own (to f32 rounding: the diffuse path reports the f32 hit).
    let depth_ok = frame
        .depth
        .iter()
        .zip(&reference.depth)
        .all(|(a, b)| a == b || (a - b).abs() <= 1e-5 * b);
    assert!(depth_ok, "depth is the reflector's own");
    let (c, same) = agreement(&frame, &reference, BALL);
    println!(
        "sphere composite: {} reflector pixels, same colour {same:.4}, relative RGB error {:.4}",
        c.pixels, c.relative_rgb_error
    );
    assert!(
        c.pixels > 2000,
        "the sphere fills part of the image: {}",
        c.pixels
    );
    assert!(same >= MIN_SAME_COLOUR, "{same}");
    assert!(
        c.relative_rgb_error <= MAX_RGB_ERROR,
        "{}",
        c.relative_rgb_error
    );
    // Outside the reflector the composite is the plain render.
    let (rest, _) = agreement(&frame, &reference, 0);
    assert_eq!(rest.relative_rgb_error, 0.0);
    assert_eq!(
        stats.get("reflector_pixels"),
        Some(&Counter::Count(c.pixels))
    );
    assert_eq!(stats.get("reflectors"), Some(&Counter::Count(1)));
}

#[test]
fn broken_surfaces_fail_the_agreement() {
    let scene = scene();
    let main = scene.projection.build(SIZE.0, SIZE.1).unwrap();
    let reference = reference(&scene, main.as_ref());
    let camera = main_camera(&scene, main.as_ref()).unwrap();
    let reflector = Reflector::of(&scene, BALL).unwrap();
    let good = reflector_surface(&reflector.mesh, &camera, Optic::Reflect).unwrap();
    let (_, good_same) = agreement(
        &composite_from(&scene, main.as_ref(), &good),
        &reference,
        BALL,
    );
    assert!(good_same >= MIN_SAME_COLOUR);

    let eye = camera.basis().origin;
    let center = BALL_CENTER;
    let mut wrong_sign = good.clone();
    // The thesis's Eq. 7.6 as printed: r = 2 (n.i) n - i.
    wrong_sign.mesh.normals.iter_mut().for_each(|r| *r = -*r);
    let mut swapped_axis = good.clone();
    swapped_axis
        .mesh
        .screen
        .iter_mut()
        .for_each(|s| s.y = 1.0 - s.y);
    let mut unnormalised = good.clone();
    for (p, r) in unnormalised
        .mesh
        .points
        .iter()
        .zip(unnormalised.mesh.normals.iter_mut())
    {
        // Normals of length 2 (a scaled mesh) used without normalising.
        let (i, n) = ((*p - eye).normalize(), 2.0 * (*p - center).normalize());
        *r = i - 2.0 * n.dot(i) * n;
    }
    for (name, broken) in [
        ("wrong sign", wrong_sign),
        ("swapped screen axis", swapped_axis),
        ("missing normalisation", unnormalised),
    ] {
        let (c, same) = agreement(
            &composite_from(&scene, main.as_ref(), &broken),
            &reference,
            BALL,
        );
        println!(
            "{name}: same colour {same:.4}, relative RGB error {:.4}",
            c.relative_rgb_error
        );
        assert!(
            same < MIN_SAME_COLOUR && c.relative_rgb_error > MAX_RGB_ERROR,
            "{name} passes: {same} {}",
            c.relative_rgb_error
        );
    }
}

/// The thesis's lens (7.4, Figure 7.6): the fixtures' 5 x 5-cell plane whose vertex normals
/// radiate from a point below it, as glass (one refracting surface), over the checker floor;
/// object id 1 is the lens, composited as a trilinear reflector.
fn lens_scene() -> Scene {
    let mut scene = ReflectorFixture {
        eye: [0.0, 3.0, 1.5],
        look_at: [0.0, 0.0, 0.0],
        reflector: r#"name = "lens"
        shape = "sphere"
        material = "glass"
        ior = 1.5"#,
        cube: r#"size = [0.8, 0.8, 0.8]
        translate = [0.0, 0.4, 0.0]"#,
        cell: 0.25,
    }
    .scene("lens.toml");
    // Replace the placeholder sphere by the lens plane at y = 1.2.
    scene.objects[0].mesh = lens_plane(1.2, 2.2).into();
    scene.trilinear_reflectors = vec![TrilinearReflector::new(1)];
    scene
}

#[test]
fn lens_composite_matches_ray_cast_glass() {
    let scene = lens_scene();
    let main = scene.projection.build(SIZE.0, SIZE.1).unwrap();
    let reference = reference(&scene, main.as_ref());
    let Rendered { frame, .. } = composited(&scene, main.as_ref(), &flat());
    let (c, same) = agreement(&frame, &reference, 1);
    println!(
        "lens composite: {} pixels, same colour {same:.4}, relative RGB error {:.4}",
        c.pixels, c.relative_rgb_error
    );
    assert!(c.pixels > 2000);
    assert!(same >= MIN_SAME_COLOUR, "{same}");
    assert!(
        c.relative_rgb_error <= MAX_RGB_ERROR,
        "{}",
        c.relative_rgb_error
    );
}

/// Lit glass mixes reflection and refraction by the exact Fresnel reflectance, as the ray
/// caster's glass does: on the lens's pixels the composite agrees with the ray-cast glass
/// within the flat tests' RGB threshold, and clearly better than the tinted refraction alone
/// (what the composite did before Fresnel mixing).
#[test]
fn lit_glass_mixes_reflection_and_refraction_by_fresnel() {
    let scene = lens_scene();
    let lit = RenderOptions::default();
    let main = scene.projection.build(SIZE.0, SIZE.1).unwrap();
    let reference = reference_with(&scene, main.as_ref(), &lit);
    let Rendered {
        frame,
        counters: stats,
        ..
    } = composited(&scene, main.as_ref(), &lit);
    let (fresnel, _) = agreement(&frame, &reference, 1);

    // Refraction alone, tinted: the main view with the lens diffuse, the refraction pasted.
    let camera = main_camera(&scene, main.as_ref()).unwrap();
    let lens = Reflector::of(&scene, 1).unwrap();
    let refraction = reflector_surface(&lens.mesh, &camera, lens.optic).unwrap();
    let mut plain = scene.clone();
    plain.trilinear_reflectors.clear();
    plain.objects[0].material.finish = Finish::Diffuse;
    let mut alone = raycast(&PreparedScene::new(&plain), main.as_ref(), &lit)
        .unwrap()
        .0;
    let image = render_through(
        &PreparedScene::new(&without(&scene, 1)),
        &refraction,
        SurfaceScreenMap::Projective,
        &camera,
        &lit,
        &raycast,
    )
    .unwrap()
    .unwrap();
    paste(&mut alone, 1, &image, lens.tint).unwrap();
    let (refraction_only, _) = agreement(&alone, &reference, 1);
    println!(
        "lit lens: {} pixels, relative RGB error {:.4} with Fresnel, {:.4} refraction only",
        fresnel.pixels, fresnel.relative_rgb_error, refraction_only.relative_rgb_error
    );
    assert!(
        fresnel.relative_rgb_error <= MAX_RGB_ERROR,
        "{}",
        fresnel.relative_rgb_error
    );
    assert!(
        fresnel.relative_rgb_error < 0.5 * refraction_only.relative_rgb_error,
        "{} vs {}",
        fresnel.relative_rgb_error,
        refraction_only.relative_rgb_error
    );
    assert_eq!(
        stats.get("reflector_fresnel_rays"),
        Some(&Counter::Count(fresnel.pixels))
    );
}

/// The split is the ray caster's: at the pixel looking straight down the lens's central
/// normal the reflectance is ((1.5 - 1) / (1.5 + 1))^2 = 0.04, larger at oblique pixels,
/// and a pixel beside the lens misses it.
#[test]
fn fresnel_split_is_the_exact_reflectance_at_the_hit() {
    let mut scene = lens_scene();
    // Look straight down the lens's central normal (flat shading normal there: +y).
    scene.projection = ProjectionSpec::Perspective {
        frame: crate::projection::CameraFrame {
            position: DVec3::new(0.0, 4.0, 0.0),
            look_at: DVec3::ZERO,
            up: DVec3::NEG_Z,
        },
        fov: 60.0,
    };
    let main = scene.projection.build(101, 101).unwrap();
    let camera = main_camera(&scene, main.as_ref()).unwrap();
    let split = FresnelSplit::new(&PreparedScene::new(&scene), 1, camera);
    let GlassSplit::Fresnel(centre) = split.at(50, 50) else {
        panic!("the centre pixel sees the lens");
    };
    assert!((centre - 0.04).abs() < 1e-4, "{centre}");
    let GlassSplit::Fresnel(oblique) = split.at(50, 70) else {
        panic!("an oblique pixel sees the lens");
    };
    assert!(oblique > centre, "{oblique} vs {centre}");
    assert_eq!(split.at(0, 0), GlassSplit::Missed);
}

#[test]
fn without_reflectors_the_renderer_runs_once_and_unchanged() {
    let mut scene = scene();
    scene.trilinear_reflectors.clear();
    let main = scene.projection.build(40, 30).unwrap();
    let Rendered {
        frame,
        counters: stats,
        ..
    } = composited(&scene, main.as_ref(), &flat());
    assert_eq!(
        frame,
        raycast(&PreparedScene::new(&scene), main.as_ref(), &flat())
            .unwrap()
            .0
    );
    assert!(!stats.contains_key("reflectors"));
}

#[test]
fn paste_replaces_only_the_reflector_and_checks_sizes() {
    let mut main = Frame::new(2, 1, Vec3::ZERO);
    main.ids = vec![BALL, 3];
    let mut reflection = Frame::new(2, 1, Vec3::ONE);
    reflection.color[1] = Vec3::splat(0.5);
    let replaced = paste(&mut main, BALL, &reflection, Vec3::new(1.0, 0.5, 0.25)).unwrap();
    assert_eq!(replaced, 1);
    assert_eq!(main.color, vec![Vec3::new(1.0, 0.5, 0.25), Vec3::ZERO]);
    let e = paste(&mut main, BALL, &Frame::new(1, 1, Vec3::ONE), Vec3::ONE).unwrap_err();
    assert!(e.message.contains("1x1 reflection into a 2x1"), "{e}");
}

#[test]
fn bad_reflectors_are_errors() {
    let mut scene = scene();
    scene.trilinear_reflectors = vec![TrilinearReflector::new(9)];
    let main = scene.projection.build(40, 30).unwrap();
    let e = try_composite(&scene, main.as_ref(), &flat()).unwrap_err();
    assert!(e.message.contains("no object has this id"), "{e}");
    scene.trilinear_reflectors = vec![TrilinearReflector::new(2)];
    let e = try_composite(&scene, main.as_ref(), &flat()).unwrap_err();
    assert!(e.message.contains("must be a mirror or glass"), "{e}");
    let mut scene = self::scene();
    scene.projection = ProjectionSpec::Orthographic {
        frame: crate::projection::CameraFrame {
            position: DVec3::new(0.0, 1.0, 5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
        },
        width: 4.0,
    };
    let main = scene.projection.build(40, 30).unwrap();
    let e = try_composite(&scene, main.as_ref(), &flat()).unwrap_err();
    assert!(e.message.contains("need a perspective projection"), "{e}");
}

/// Finer reflector meshes approximate the mirror better (Vallance 2005, Figure 7.4: the error
/// falls as the projection surface is refined): the relative RGB error on the sphere's
/// pixels decreases from 8 to 16 to 64 segments.
#[test]
fn finer_reflectors_agree_better() {
    let mut errors = Vec::new();
    for segments in [8, 16, 64] {
        let mut scene = sphere_and_cube_reflector(segments);
        // The thesis's sweep: the reflector's own triangles, not refined.
        scene.trilinear_reflectors[0].refine_px = 0.0;
        let main = scene.projection.build(SIZE.0, SIZE.1).unwrap();
        let reference = reference(&scene, main.as_ref());
        let Rendered { frame, .. } = composited(&scene, main.as_ref(), &flat());
        let (c, same) = agreement(&frame, &reference, BALL);
        println!(
            "{segments} segments: same colour {same:.4}, relative RGB error {:.4}",
            c.relative_rgb_error
        );
        errors.push(c.relative_rgb_error);
    }
    assert!(errors[0] > errors[1] && errors[1] > errors[2], "{errors:?}");
}

/// An open mirror (a plane, one-sided by its winding) seen from behind: every triangle of the
/// surface is left out, and the reflector's pixels, which kept the diffuse colour, are ray
/// cast exactly: the composite is the true (two-sided) mirror, pixel for pixel. Seen from
/// the front nothing is cast where the surface covers the mirror.
#[test]
fn uncovered_reflector_pixels_are_ray_cast_exactly() {
    let behind = ReflectorFixture {
        eye: [0.5, 1.2, -3.0],
        look_at: [0.0, 1.0, 0.0],
        reflector: "shape = \"plane\"\nsize = [2.0, 2.0]\nmaterial = \"mirror\"\n\
                    rotate = [90.0, 0.0, 0.0]\ntranslate = [0.0, 1.2, 0.0]",
        cube: "size = [0.6, 0.6, 0.6]\ntranslate = [0.8, 0.3, -1.5]",
        cell: 0.5,
    };
    let mut scene = behind.scene("behind.toml");
    scene.trilinear_reflectors = vec![TrilinearReflector::new(BALL)];
    let main = scene.projection.build(SIZE.0, SIZE.1).unwrap();
    let camera = main_camera(&scene, main.as_ref()).unwrap();
    let mirror = Reflector::of(&scene, BALL).unwrap();
    let surface = reflector_surface(&mirror.mesh, &camera, mirror.optic).unwrap();
    assert!(surface.mesh.triangles.is_empty(), "seen from behind");
    let reference = reference(&scene, main.as_ref());
    let Rendered {
        frame,
        counters: stats,
        ..
    } = composited(&scene, main.as_ref(), &flat());
    let (c, same) = agreement(&frame, &reference, BALL);
    assert!(
        c.pixels > 1000,
        "the mirror fills part of the image: {}",
        c.pixels
    );
    assert_eq!(same, 1.0, "{c:?}");
    assert_eq!(
        stats.get("reflector_exact_pixels"),
        Some(&Counter::Count(c.pixels))
    );
    assert_eq!(
        stats.get("reflector_uncovered_pixels"),
        Some(&Counter::Count(c.pixels))
    );
    // Without casting the gaps, the uncovered pixels are counted, none is cast, and (there
    // being no surface) they keep the main view's flat colour of the reflector, one colour
    // where the true mirror shows several.
    let gaps = RenderOptions {
        cast_reflector_gaps: false,
        ..flat()
    };
    let Rendered {
        frame: left,
        counters: stats,
        ..
    } = composited(&scene, main.as_ref(), &gaps);
    assert_eq!(
        stats.get("reflector_exact_pixels"),
        Some(&Counter::Count(0))
    );
    assert_eq!(
        stats.get("reflector_uncovered_pixels"),
        Some(&Counter::Count(c.pixels))
    );
    let mirror_pixels: Vec<usize> = (0..left.ids.len())
        .filter(|&k| reference.ids[k] == BALL)
        .collect();
    let first = mirror_pixels[0];
    assert!(mirror_pixels
        .iter()
        .all(|&k| left.color[k] == left.color[first]));
    assert!(mirror_pixels
        .iter()
        .any(|&k| reference.color[k] != reference.color[first]));
    // From the front, the surface covers the mirror: (almost) nothing is cast.
    let front = ReflectorFixture {
        eye: [0.5, 1.2, 3.0],
        cube: "size = [0.6, 0.6, 0.6]\ntranslate = [0.8, 0.3, 1.5]",
        ..behind
    };
    let mut scene = front.scene("front.toml");
    scene.trilinear_reflectors = vec![TrilinearReflector::new(BALL)];
    let main = scene.projection.build(SIZE.0, SIZE.1).unwrap();
    let Rendered {
        counters: stats, ..
    } = composited(&scene, main.as_ref(), &flat());
    let Some(Counter::Count(cast)) = stats.get("reflector_exact_pixels") else {
        panic!("no counter: {stats:?}");
    };
    assert!(*cast < 50, "{cast} pixels cast from the front");
}

/// The main camera as two projection triangles is the same pinhole: at pixel centres (the
/// corner pixels, one inside) its ray starts at the eye and runs along the camera's ray (unit
/// directions agree to 1e-12), at odd image sizes too.
#[test]
fn perspective_as_trilinear_is_the_same_pinhole() {
    let scene = scene();
    for (width, height) in [(160, 120), (7, 5), (1, 1), (1000, 300)] {
        let main = scene.projection.build(width, height).unwrap();
        let camera = main_camera(&scene, main.as_ref()).unwrap();
        let pinhole = perspective_as_trilinear(&camera).unwrap();
        let (w, h) = (f64::from(width), f64::from(height));
        for (x, y) in [
            (0.5, 0.5),
            (w - 0.5, h - 0.5),
            (w * 0.37, h * 0.81),
            (w - 0.5, 0.5),
        ] {
            let pixel = DVec2::new(x, y);
            let (a, b) = (camera.ray(pixel).unwrap(), pinhole.ray(pixel).unwrap());
            // The pinhole's ray starts on the plane 1e-6 (1 + |eye|) in front of the eye,
            // on the camera's ray.
            let offset = b.origin - a.origin;
            assert!(
                offset.length() > 0.0 && offset.length() < 1e-5,
                "{width}x{height} {pixel}"
            );
            let along = offset.normalize().dot(a.direction.normalize());
            assert!(
                (along - 1.0).abs() < 1e-6,
                "{width}x{height} {pixel}: {along}"
            );
            let (da, db) = (a.direction.normalize(), b.direction.normalize());
            assert!(
                (da - db).length() < 1e-12,
                "{width}x{height} {pixel}: {da} {db}"
            );
        }
    }
}

/// `--method trilinear` renders a scene with reflectors (before: refused, the main view
/// being perspective): the main view through the pinhole's two projection triangles, the
/// reflection through the reflector's surface, both by the trilinear rasteriser. It agrees
/// with the ray-cast composite (same ids everywhere, colours but for rounding along edges)
/// and, on the mirror, with the true mirror as the ray-cast composite does.
#[test]
fn trilinear_method_composites_reflectors() {
    let scene = scene();
    let main = scene.projection.build(SIZE.0, SIZE.1).unwrap();
    let Rendered {
        frame: trilinear,
        counters: stats,
        ..
    } = composited(&scene, main.as_ref(), &flat_by(Method::Trilinear));
    let Rendered { frame: raycast, .. } = composited(&scene, main.as_ref(), &flat());
    let c = compare(&trilinear, &raycast).unwrap();
    assert!(c.id_agreement >= 0.9999, "{c:?}");
    assert!(c.relative_rgb_error < 0.002, "{c:?}");
    assert!(matches!(stats.get("reflector_pixels"), Some(Counter::Count(n)) if *n > 1000));
    let reference = reference(&scene, main.as_ref());
    let (c, same) = agreement(&trilinear, &reference, BALL);
    assert!(
        same >= MIN_SAME_COLOUR && c.relative_rgb_error <= MAX_RGB_ERROR,
        "{c:?} {same}"
    );
    // Without reflectors the method is unchanged: a perspective scene is still refused.
    let mut plain = scene.clone();
    plain.trilinear_reflectors.clear();
    assert!(try_composite(&plain, main.as_ref(), &flat_by(Method::Trilinear)).is_err());
}

/// [`lens_scene`] with index of refraction `ior` and the lens's screen map `map`; with
/// `flat_normals` the plate's vertex normals are all +y (a flat plate, or with a mirror, a
/// flat mirror).
fn plate_scene(ior: f32, map: SurfaceScreenMap, flat_normals: bool) -> Scene {
    let mut scene = lens_scene();
    scene.objects[0].material.finish = Finish::Glass { ior };
    if flat_normals {
        Arc::make_mut(&mut scene.objects[0].mesh)
            .normals
            .fill(Vec3::Y);
    }
    scene.trilinear_reflectors[0].screen_map = map;
    scene
}

/// The composite of `scene` (the trilinear method or the ray caster) against the exact
/// ray-cast image, over the whole frame and on the reflector's pixels.
fn composite_error(scene: &Scene, method: Method) -> (Comparison, Comparison) {
    let main = scene.projection.build(SIZE.0, SIZE.1).unwrap();
    let reference = reference(scene, main.as_ref());
    let Rendered { frame, .. } = composited(scene, main.as_ref(), &flat_by(method));
    let whole = compare(&frame, &reference).unwrap();
    (whole, agreement(&frame, &reference, 1).0)
}

/// A flat mirror (a 4 x 4-quad plane facing +z) in front of the checker floor and the cube,
/// with screen map `map`.
fn flat_mirror_scene(map: SurfaceScreenMap) -> Scene {
    let mut scene = ReflectorFixture {
        eye: [0.5, 1.2, 3.0],
        look_at: [0.0, 1.0, 0.0],
        reflector: "shape = \"plane\"\nsize = [2.0, 2.0]\nmaterial = \"mirror\"\n\
                    tessellation = 4\nrotate = [90.0, 0.0, 0.0]\ntranslate = [0.0, 1.2, 0.0]",
        cube: "size = [0.6, 0.6, 0.6]\ntranslate = [0.8, 0.3, 1.5]",
        cell: 0.5,
    }
    .scene("flat-mirror.toml");
    scene.trilinear_reflectors = vec![TrilinearReflector {
        screen_map: map,
        ..TrilinearReflector::new(1)
    }];
    scene
}

/// Straight vertex rays (ior 1) and a flat mirror: with the projective screen map every
/// main-image pixel's surface ray is the exact ray (the eye ray from the point it meets the
/// plate on, or its mirror image), so the composite is the exact image up to rounding at
/// colour edges, for the ray-cast and the trilinear composite; the affine map of Vallance 2005
/// (7.2.2) misses by an order of magnitude more (docs/robustness.md, audit 3).
#[test]
fn projective_surfaces_are_exact_for_straight_rays_and_flat_mirrors() {
    type Make = fn(SurfaceScreenMap) -> Scene;
    let cases: [(&str, Make); 3] = [
        ("ior 1 plate", |map| plate_scene(1.0, map, true)),
        ("ior 1 lens", |map| plate_scene(1.0, map, false)),
        ("flat mirror", flat_mirror_scene),
    ];
    for (name, make) in cases {
        let projective = make(SurfaceScreenMap::Projective);
        let affine = make(SurfaceScreenMap::Affine);
        for method in [Method::Raycast, Method::Trilinear] {
            let (whole, on_plate) = composite_error(&projective, method);
            let (_, affine_on_plate) = composite_error(&affine, method);
            println!(
                "{name}, {method:?}: ids {:.5}, RGB {:.6} on {} reflector pixels (affine {:.6})",
                whole.id_agreement,
                on_plate.relative_rgb_error,
                on_plate.pixels,
                affine_on_plate.relative_rgb_error
            );
            assert!(on_plate.pixels > 2000, "{name}");
            assert!(whole.id_agreement >= 0.9999, "{name} {method:?}: {whole:?}");
            assert!(
                on_plate.relative_rgb_error < 1e-3,
                "{name} {method:?}: {on_plate:?}"
            );
            assert!(
                affine_on_plate.relative_rgb_error > 5.0 * on_plate.relative_rgb_error,
                "{name} {method:?}: affine {} vs {}",
                affine_on_plate.relative_rgb_error,
                on_plate.relative_rgb_error
            );
        }
    }
}

/// The error on the reflector's pixels, its surface triangle and exactly cast pixel counts,
/// of `scene` (reflector `id`) with refinement tolerance `refine_px`, composited with the
/// ray caster at [`SIZE`].
fn refined_error(scene: &Scene, id: u32, refine_px: f64) -> (Comparison, f64, Stats) {
    let mut scene = scene.clone();
    scene.trilinear_reflectors[0].refine_px = refine_px;
    let main = scene.projection.build(SIZE.0, SIZE.1).unwrap();
    let reference = reference(&scene, main.as_ref());
    let Rendered {
        frame,
        counters: stats,
        ..
    } = composited(&scene, main.as_ref(), &flat());
    let (c, same) = agreement(&frame, &reference, id);
    (c, same, stats)
}

/// Adaptive refinement (the default tolerance) makes curved reflectors converge to the
/// true mirror and glass: the 24- and 32-segment spheres and the lens at ior 1.5 agree
/// better than the unrefined surfaces and within a relative RGB error of 0.02, and the
/// refined surfaces leave no reflector pixel uncovered (no cracks: nothing is ray cast).
#[test]
fn refined_surfaces_converge_to_the_true_mirror() {
    let cases = [
        ("sphere, 24 segments", sphere_and_cube_reflector(24), BALL),
        ("sphere, 32 segments", sphere_and_cube_reflector(32), BALL),
        ("lens, ior 1.5", lens_scene(), 1),
    ];
    for (name, scene, id) in cases {
        assert_eq!(
            scene.trilinear_reflectors[0].refine_px,
            TrilinearReflector::DEFAULT_REFINE_PX
        );
        let (before, same_before, stats_before) = refined_error(&scene, id, 0.0);
        let (after, same_after, stats) =
            refined_error(&scene, id, TrilinearReflector::DEFAULT_REFINE_PX);
        let count = |stats: &Stats, key| match stats.get(key) {
            Some(Counter::Count(n)) => *n,
            other => panic!("{key}: {other:?}"),
        };
        println!(
            "{name}: unrefined {} triangles, same colour {same_before:.4}, RGB {:.4}; \
             refined {} triangles, same colour {same_after:.4}, RGB {:.4}",
            count(&stats_before, "reflector_triangles"),
            before.relative_rgb_error,
            count(&stats, "reflector_triangles"),
            after.relative_rgb_error
        );
        assert!(
            after.relative_rgb_error < before.relative_rgb_error,
            "{name}: {after:?} vs {before:?}"
        );
        assert!(after.relative_rgb_error < 0.02, "{name}: {after:?}");
        assert!(same_after > same_before, "{name}");
        assert_eq!(count(&stats, "reflector_exact_pixels"), 0, "{name}");
        assert_eq!(count(&stats, "reflector_unsplit_edges"), 0, "{name}");
    }
}
