//! `[[object]]`: checks an object table against its shape and converts it into world-space
//! [`Object`]s (one per part of a model file, all sharing the object's id).

use std::path::Path;
use std::sync::Arc;

use glam::{Affine3A, Mat3, Vec3};
use toml::Spanned;

use super::displacement;
use super::raw::{Numbers, RawObject};
use super::shape::{analytic_mesh, Shape, MAX_TESSELLATION};
use super::source::Source;
use crate::error::Result;
use crate::projection::trilinear_builders::{SurfaceRays, SurfaceScreenMap};
use crate::projection::ProjectionSpec;
use crate::scene::loaders::{load_model, load_texture};
use crate::scene::{
    CausticReflector, Finish, Material, Mesh, Object, Pattern, ReflectionImage, TrilinearReflector,
};

/// Surface names as written in scene files.
const MATERIALS: [&str; 4] = ["diffuse", "mirror", "glass", "emissive"];

/// Index of refraction of `glass` when `ior` is not given.
const DEFAULT_IOR: f64 = 1.5;

/// Converts one object table; `id` is its 1-based position in the file. Relative paths
/// (`file`, `texture`) are resolved against `base_dir`.
pub(super) fn convert(
    src: &Source,
    table: &Spanned<RawObject>,
    id: u32,
    base_dir: &Path,
) -> Result<Vec<Object>> {
    let raw = table.get_ref();
    let shape = Shape::parse(raw.shape.get_ref()).ok_or_else(|| {
        let name = raw.shape.get_ref();
        src.unknown(&raw.shape.span(), "shape", name, &Shape::all_names())
    })?;
    check_keys_fit_shape(src, table, shape)?;
    let overrides = MaterialOverrides::read(src, raw, base_dir)?;
    let object_to_world = transform(src, raw)?;
    let parts: Vec<(Mesh, Material)> = match (&raw.file, analytic(src, raw, shape)?) {
        (_, Some((mesh, base))) => vec![(mesh, overrides.apply(base))],
        (Some(file), None) => {
            let path = src.existing_file(file, base_dir, "model file")?;
            let model = match src.take_model(&path) {
                Some(model) => model,
                None => {
                    src.check_model_size(&path, &file.span())?;
                    load_model(&path).map_err(|e| e.or_in_file(&path))?
                }
            };
            let triangles = model.parts.iter().map(|p| p.mesh.triangle_count() as u64);
            src.reserve_triangles(triangles.sum(), &file.span())?;
            src.read_files(model.files);
            model
                .parts
                .into_iter()
                .map(|part| {
                    (
                        part.mesh,
                        overrides.apply(part.material.unwrap_or_default()),
                    )
                })
                .collect()
        }
        (None, None) => return Err(src.error(&table.span(), "shape \"mesh\" needs `file`")),
    };
    let name = raw
        .name
        .as_ref()
        .map_or_else(|| shape.name().to_string(), |n| n.get_ref().clone());
    let world_to_object = object_to_world.inverse();
    let displacement = match &raw.displacement {
        Some(table) => {
            let meshes: Vec<&Mesh> = parts.iter().map(|(mesh, _)| mesh).collect();
            Some(displacement::convert(src, table, base_dir, &name, &meshes)?)
        }
        None => None,
    };
    Ok(parts
        .into_iter()
        .map(|(mut mesh, material)| {
            mesh.transform(&object_to_world);
            Object {
                id,
                name: name.clone(),
                mesh: mesh.into(),
                material,
                world_to_object,
                displacement: displacement.clone(),
            }
        })
        .collect())
}

/// The object's trilinear reflector entry (object id `id`) if it asks for
/// `trilinear_reflector = true`: its reflection (mirror) or refraction (glass) is then
/// rendered through a trilinear surface built from its mesh and composited into the main
/// image, with screen map `trilinear_screen_map` (default affine) and refinement tolerance
/// `trilinear_refine_px` (main-image pixels, default
/// [`TrilinearReflector::DEFAULT_REFINE_PX`], 0 for none) and camera-mesh size
/// `camera_triangles` (default automatic), `reflection` (`"surface"`, the default, or
/// `"env-map"`: the environment-map baseline, or `"atlas"`: the camera triangles' joint texture
/// atlas) and `camera_rays` (`"interpolated"`, the
/// default, or `"per-fragment"`: mirrors only). Errors, at the key: an object
/// whose material is neither mirror nor glass, a scene whose projection is not perspective
/// (the surface's screen positions are the main camera's image of the reflector), a
/// `trilinear_screen_map` other than "projective" or "affine", a `reflection` other than
/// "surface", "env-map" or "atlas", a `camera_rays` other than "interpolated" or "per-fragment" or
/// "per-fragment" on glass, a `trilinear_refine_px` that
/// is negative or not finite, a bad `camera_triangles` ([`camera_triangles`]), or any of
/// these keys without `trilinear_reflector = true`.
pub(super) fn trilinear_reflector(
    src: &Source,
    table: &Spanned<RawObject>,
    id: u32,
    parts: &[Object],
    projection: &ProjectionSpec,
) -> Result<Option<TrilinearReflector>> {
    let raw = table.get_ref();
    let screen_map = match &raw.trilinear_screen_map {
        None => SurfaceScreenMap::default(),
        Some(name) => match name.get_ref().as_str() {
            "projective" => SurfaceScreenMap::Projective,
            "affine" => SurfaceScreenMap::Affine,
            other => {
                let expected = ["affine", "projective"];
                return Err(src.unknown(&name.span(), "trilinear_screen_map", other, &expected));
            }
        },
    };
    let refine_px = match &raw.trilinear_refine_px {
        None => TrilinearReflector::DEFAULT_REFINE_PX,
        Some(value) => {
            let px = src.number(value, "trilinear_refine_px")?;
            if px < 0.0 {
                return Err(src.error(
                    &value.span(),
                    format!(
                        "`trilinear_refine_px` must be at least 0 (0: no refinement), not {px}"
                    ),
                ));
            }
            px
        }
    };
    let camera_triangles = camera_triangles(src, table, parts)?;
    let reflection = match &raw.reflection {
        None => ReflectionImage::Surface,
        Some(name) => match name.get_ref().as_str() {
            "surface" => ReflectionImage::Surface,
            "env-map" => ReflectionImage::EnvMap,
            "atlas" => ReflectionImage::Atlas,
            other => {
                let expected = ["atlas", "env-map", "surface"];
                return Err(src.unknown(&name.span(), "reflection", other, &expected));
            }
        },
    };
    let camera_rays = match &raw.camera_rays {
        None => SurfaceRays::Interpolated,
        Some(name) => match name.get_ref().as_str() {
            "interpolated" => SurfaceRays::Interpolated,
            "per-fragment" => SurfaceRays::PerFragment,
            other => {
                let expected = ["interpolated", "per-fragment"];
                return Err(src.unknown(&name.span(), "camera_rays", other, &expected));
            }
        },
    };
    let enabled = raw
        .trilinear_reflector
        .as_ref()
        .filter(|flag| *flag.get_ref());
    let Some(flag) = enabled else {
        if let Some(name) = &raw.trilinear_screen_map {
            return Err(src.error(
                &name.span(),
                "`trilinear_screen_map` needs `trilinear_reflector = true`",
            ));
        }
        if let Some(value) = &raw.trilinear_refine_px {
            return Err(src.error(
                &value.span(),
                "`trilinear_refine_px` needs `trilinear_reflector = true`",
            ));
        }
        if let Some(name) = &raw.reflection {
            return Err(src.error(
                &name.span(),
                "`reflection` needs `trilinear_reflector = true`",
            ));
        }
        if let Some(value) = &raw.camera_triangles {
            return Err(src.error(
                &value.span(),
                "`camera_triangles` needs `trilinear_reflector = true`",
            ));
        }
        if let Some(name) = &raw.camera_rays {
            return Err(src.error(
                &name.span(),
                "`camera_rays` needs `trilinear_reflector = true`",
            ));
        }
        return Ok(None);
    };
    if let Some(part) = parts
        .iter()
        .find(|p| !matches!(p.material.finish, Finish::Mirror | Finish::Glass { .. }))
    {
        return Err(src.error(
            &flag.span(),
            format!(
                "`trilinear_reflector` needs material \"mirror\" or \"glass\", but \"{}\" is {}",
                part.name,
                surface_name(part.material.finish)
            ),
        ));
    }
    if let (Some(name), SurfaceRays::PerFragment) = (&raw.camera_rays, camera_rays) {
        if let Some(part) = parts.iter().find(|p| p.material.finish != Finish::Mirror) {
            return Err(src.error(
                &name.span(),
                format!(
                    "`camera_rays = \"per-fragment\"` needs material \"mirror\" (per-fragment \
                     refraction has no bound yet), but \"{}\" is {}",
                    part.name,
                    surface_name(part.material.finish)
                ),
            ));
        }
    }
    if !matches!(projection, ProjectionSpec::Perspective { .. }) {
        return Err(src.error(
            &flag.span(),
            format!(
                "`trilinear_reflector` needs a perspective [projection] (the main camera), not {}",
                projection.kind()
            ),
        ));
    }
    Ok(Some(TrilinearReflector {
        id,
        screen_map,
        refine_px,
        camera_triangles,
        reflection,
        camera_rays,
    }))
}

/// The object's caustic entry (object id `id`) if it asks for `caustics = true`, with the
/// span of that key (the scene's lights are checked against it once they are read): the
/// mirror's reflection (the glass's refraction) of each point light is then added as a
/// caustic in `lit` shading, through a photon-location map of `caustic_map` texels a side
/// (default [`CausticReflector::DEFAULT_MAP_SIZE`]). Errors, at the key: a part that is
/// neither mirror nor glass, parts of different materials (or glass of different indices),
/// a scene whose projection is not perspective (the caustics are splatted into the main
/// camera's image), a `caustic_map` outside [`CausticReflector::MAP_SIZES`], or
/// `caustic_map` without `caustics = true`.
pub(super) fn caustic_reflector(
    src: &Source,
    table: &Spanned<RawObject>,
    id: u32,
    parts: &[Object],
    projection: &ProjectionSpec,
) -> Result<Option<(CausticReflector, std::ops::Range<usize>)>> {
    let raw = table.get_ref();
    let Some(flag) = raw.caustics.as_ref().filter(|flag| *flag.get_ref()) else {
        if let Some(value) = &raw.caustic_map {
            return Err(src.error(&value.span(), "`caustic_map` needs `caustics = true`"));
        }
        return Ok(None);
    };
    let map_size = match &raw.caustic_map {
        None => CausticReflector::DEFAULT_MAP_SIZE,
        Some(value) => {
            let sizes = CausticReflector::MAP_SIZES;
            match u32::try_from(*value.get_ref()) {
                Ok(n) if sizes.contains(&n) => n,
                _ => {
                    return Err(src.error(
                        &value.span(),
                        format!(
                            "`caustic_map` must be between {} and {} texels, not {}",
                            sizes.start(),
                            sizes.end(),
                            value.get_ref()
                        ),
                    ))
                }
            }
        }
    };
    let focuses = |finish| matches!(finish, Finish::Mirror | Finish::Glass { .. });
    if let Some(part) = parts.iter().find(|p| !focuses(p.material.finish)) {
        return Err(src.error(
            &flag.span(),
            format!(
                "`caustics` needs material \"mirror\" or \"glass\", but \"{}\" is {}",
                part.name,
                surface_name(part.material.finish)
            ),
        ));
    }
    let named = |finish| match finish {
        Finish::Glass { ior } => format!("glass of index {ior}"),
        finish => surface_name(finish).to_string(),
    };
    if let [first, rest @ ..] = parts {
        if let Some(part) = rest
            .iter()
            .find(|p| p.material.finish != first.material.finish)
        {
            return Err(src.error(
                &flag.span(),
                format!(
                    "`caustics` needs one material for the whole object, but \"{}\" is {} \
                     and \"{}\" is {}",
                    first.name,
                    named(first.material.finish),
                    part.name,
                    named(part.material.finish)
                ),
            ));
        }
    }
    if !matches!(projection, ProjectionSpec::Perspective { .. }) {
        return Err(src.error(
            &flag.span(),
            format!(
                "`caustics` needs a perspective [projection] (the eye the caustics are splatted \
                 into), not {}",
                projection.kind()
            ),
        ));
    }
    Ok(Some((CausticReflector { id, map_size }, flag.span())))
}

/// The object's `camera_triangles` (the size of its camera mesh), if given. Errors, at the
/// key: not a whole number, below 1, more than the object's own triangles, or given
/// together with `trilinear_refine_px` (which refines the automatically chosen mesh only).
fn camera_triangles(
    src: &Source,
    table: &Spanned<RawObject>,
    parts: &[Object],
) -> Result<Option<usize>> {
    let raw = table.get_ref();
    let Some(value) = &raw.camera_triangles else {
        return Ok(None);
    };
    let n = *value.get_ref() as usize;
    let own: usize = parts.iter().map(|p| p.mesh.triangles.len()).sum();
    if n == 0 || n > own {
        return Err(src.error(
            &value.span(),
            format!(
                "`camera_triangles` must be between 1 and the object's {own} triangles, not {n}"
            ),
        ));
    }
    if raw.trilinear_refine_px.is_some() {
        return Err(src.error(
            &value.span(),
            "`camera_triangles` fixes the camera mesh, which is not refined: leave out \
             `trilinear_refine_px` (it refines the automatically sized mesh)",
        ));
    }
    Ok(Some(n))
}

/// The scene-file name (key `surface`) of a finish.
fn surface_name(finish: Finish) -> &'static str {
    match finish {
        Finish::Diffuse => "diffuse",
        Finish::Mirror => "mirror",
        Finish::Glass { .. } => "glass",
        Finish::Emissive => "emissive",
    }
}

/// Rejects keys that the shape does not take: `file` belongs to meshes only, `size` and
/// `tessellation` to analytic shapes only, `face_colors` to boxes only.
fn check_keys_fit_shape(src: &Source, table: &Spanned<RawObject>, shape: Shape) -> Result<()> {
    let raw = table.get_ref();
    let is_mesh = shape == Shape::Mesh;
    let misplaced = [
        ("file", raw.file.as_ref().map(Spanned::span), !is_mesh),
        ("size", raw.size.as_ref().map(Spanned::span), is_mesh),
        (
            "tessellation",
            raw.tessellation.as_ref().map(Spanned::span),
            is_mesh,
        ),
        (
            "face_colors",
            raw.face_colors.as_ref().map(Spanned::span),
            shape != Shape::Box,
        ),
    ];
    match misplaced
        .into_iter()
        .find(|(_, span, wrong)| span.is_some() && *wrong)
    {
        Some((key, Some(span), _)) => Err(src.error(
            &span,
            format!("`{key}` does not apply to shape \"{}\"", shape.name()),
        )),
        _ => Ok(()),
    }
}

/// The object-space mesh and base material of an analytic shape; `None` for model files.
fn analytic(src: &Source, raw: &RawObject, shape: Shape) -> Result<Option<(Mesh, Material)>> {
    let (Some(form), Some((default_tessellation, min_tessellation))) =
        (shape.size_form(), shape.tessellation_default_and_min())
    else {
        return Ok(None);
    };
    let mut size = [0.0; 3];
    match &raw.size {
        None => size[..form.default.len()].copy_from_slice(form.default),
        Some(value) => {
            let numbers = value.get_ref().as_slice();
            if numbers.len() != form.default.len() {
                return Err(src.error(
                    &value.span(),
                    format!("`size` of a {} is {}", shape.name(), form.written),
                ));
            }
            src.all_finite(numbers, value, "size")?;
            if let Some(bad) = numbers.iter().find(|&&x| x <= 0.0) {
                return Err(src.error(&value.span(), format!("`size` must be positive, not {bad}")));
            }
            for (s, &x) in size.iter_mut().zip(numbers) {
                *s = x as f32;
            }
        }
    }
    let tessellation = match &raw.tessellation {
        None => default_tessellation,
        Some(t) => {
            let t_value = *t.get_ref();
            if !(min_tessellation..=MAX_TESSELLATION).contains(&t_value) {
                return Err(src.error(
                    &t.span(),
                    format!(
                        "`tessellation` of a {} must be in {min_tessellation}..={MAX_TESSELLATION}, not {t_value}",
                        shape.name()
                    ),
                ));
            }
            t_value
        }
    };
    let face_colors = match &raw.face_colors {
        None => None,
        Some(value) => {
            let mut colors = [Vec3::ZERO; 6];
            for (c, rgb) in colors.iter_mut().zip(value.get_ref()) {
                *c = src.color(&Spanned::new(value.span(), *rgb), "face_colors")?;
            }
            Some(colors)
        }
    };
    // Face colours are vertex colours, which multiply the base colour: default it to white.
    let base = Material {
        color: if face_colors.is_some() {
            Vec3::ONE
        } else {
            Material::default().color
        },
        ..Material::default()
    };
    let at = raw
        .tessellation
        .as_ref()
        .map_or(raw.shape.span(), Spanned::span);
    src.reserve_triangles(shape.triangle_bound(tessellation), &at)?;
    Ok(analytic_mesh(shape, size, tessellation, face_colors).map(|mesh| (mesh, base)))
}

/// The material keys an object gives; each replaces that part of the base material (the
/// shape's default, or the material a model file assigns).
struct MaterialOverrides {
    color: Option<Vec3>,
    pattern: Option<Pattern>,
    finish: Option<Finish>,
}

impl MaterialOverrides {
    fn read(src: &Source, raw: &RawObject, base_dir: &Path) -> Result<Self> {
        let color = raw
            .color
            .as_ref()
            .map(|c| src.color(c, "color"))
            .transpose()?;
        if let (Some(_), Some(texture)) = (&raw.checker, &raw.texture) {
            return Err(src.error(
                &texture.span(),
                "`texture` and `checker` cannot be combined",
            ));
        }
        let pattern = if let Some(checker) = &raw.checker {
            let checker = checker.get_ref();
            Some(Pattern::Checker {
                other: src.color(&checker.color, "checker.color")?,
                size: checker
                    .size
                    .as_ref()
                    .map_or(Ok(1.0), |s| src.positive(s, "checker.size"))?
                    as f32,
            })
        } else if let Some(texture) = &raw.texture {
            let path = src.existing_file(texture, base_dir, "texture")?;
            let texture = load_texture(&path).map_err(|e| e.or_in_file(&path))?;
            Some(Pattern::Texture(Arc::new(texture)))
        } else {
            None
        };
        Ok(MaterialOverrides {
            color,
            pattern,
            finish: finish(src, raw)?,
        })
    }

    fn apply(&self, base: Material) -> Material {
        Material {
            color: self.color.unwrap_or(base.color),
            pattern: self.pattern.clone().unwrap_or(base.pattern),
            finish: self.finish.unwrap_or(base.finish),
        }
    }
}

/// `material` and `ior`; `ior` belongs to glass only.
fn finish(src: &Source, raw: &RawObject) -> Result<Option<Finish>> {
    let is_glass = raw
        .material
        .as_ref()
        .is_some_and(|m| m.get_ref() == "glass");
    if let (Some(ior), false) = (&raw.ior, is_glass) {
        return Err(src.error(&ior.span(), "`ior` applies only to material = \"glass\""));
    }
    let Some(material) = &raw.material else {
        return Ok(None);
    };
    Ok(Some(match material.get_ref().as_str() {
        "diffuse" => Finish::Diffuse,
        "mirror" => Finish::Mirror,
        "emissive" => Finish::Emissive,
        "glass" => Finish::Glass {
            ior: raw
                .ior
                .as_ref()
                .map_or(Ok(DEFAULT_IOR), |ior| src.positive(ior, "ior"))? as f32,
        },
        other => return Err(src.unknown(&material.span(), "material", other, &MATERIALS)),
    }))
}

/// The object-to-world transform T * R * S: scale, then rotate about x, then y, then z
/// (R = Rz * Ry * Rx, degrees), then translate.
fn transform(src: &Source, raw: &RawObject) -> Result<Affine3A> {
    let translate = raw
        .translate
        .as_ref()
        .map_or(Ok(Vec3::ZERO), |t| src.vec3(t, "translate"))?;
    let rotate = raw
        .rotate
        .as_ref()
        .map_or(Ok(Vec3::ZERO), |r| src.vec3(r, "rotate"))?;
    let scale = match &raw.scale {
        None => Vec3::ONE,
        Some(value) => {
            let numbers = value.get_ref();
            src.all_finite(numbers.as_slice(), value, "scale")?;
            let scale = match numbers {
                Numbers::One(s) => Vec3::splat(*s as f32),
                Numbers::List(xs) if xs.len() == 3 => {
                    Vec3::new(xs[0] as f32, xs[1] as f32, xs[2] as f32)
                }
                Numbers::List(_) => {
                    return Err(src.error(&value.span(), "`scale` is a number or [x, y, z]"));
                }
            };
            // A zero (or vanishingly small) factor flattens the object and has no inverse.
            if !(scale.x * scale.y * scale.z).is_normal() {
                return Err(src.error(&value.span(), "`scale` must not be zero"));
            }
            scale
        }
    };
    let r = rotate * (std::f32::consts::PI / 180.0);
    let rotation =
        Mat3::from_rotation_z(r.z) * Mat3::from_rotation_y(r.y) * Mat3::from_rotation_x(r.x);
    Ok(Affine3A::from_mat3_translation(
        rotation * Mat3::from_diagonal(scale),
        translate,
    ))
}
