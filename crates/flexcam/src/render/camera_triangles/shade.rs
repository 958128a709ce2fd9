//! Shading of each pixel's winning fragment, once per pixel after its band is drawn: the hit
//! (scene triangle, ray parameter, barycentrics) goes to the shared shading
//! ([`PreparedScene::shade_hit`]: flat base colour with mirrors and glass passing the ray on,
//! or lit), on the pixel's own camera-triangle ray, as the ray caster shades its first hit;
//! flat colours of surfaces that show their base colour come from the scene triangle's
//! [`TriangleColor`], prepared once per renderer.

use glam::{DVec2, Vec2, Vec3};

use super::camera::Camera;
use super::fragment::BandBuffer;
use crate::render::prepared::PreparedScene;
use crate::render::scan::{FrameRows, NO_PRIMITIVE};
use crate::render::shading::triangle_color::TriangleColor;
use crate::render::trilinear::SceneGeometry;
use crate::render::RenderOptions;

/// Everything the shading pass reads.
pub struct Shader<'a> {
    pub cameras: &'a [Camera],
    pub scene: &'a SceneGeometry,
    pub prepared: &'a PreparedScene,
    pub options: &'a RenderOptions<'a>,
    pub background: Vec3,
    /// With flat shading, per scene triangle, its base colour where flat shading shows it;
    /// `None` for lit shading.
    pub flat_colors: Option<&'a [Option<TriangleColor>]>,
}

impl Shader<'_> {
    /// Shades the drawn band into the same rows of the frame, every pixel written; returns
    /// the secondary and shadow rays cast.
    pub fn rows(&self, drawn: &BandBuffer, out: FrameRows<'_>) -> u64 {
        let (drawn, width) = (&drawn.hits, out.width as usize);
        let mut rays = 0;
        for (i, &key) in drawn.keys[..out.color.len()].iter().enumerate() {
            if key == NO_PRIMITIVE {
                (out.color[i], out.depth[i], out.ids[i]) = (self.background, f32::INFINITY, 0);
                continue;
            }
            let (x, y) = ((i % width) as u32, drawn.rows().0 + (i / width) as u32);
            let centre = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
            let camera = &self.cameras[(key >> 32) as usize];
            let k = (key & u64::from(u32::MAX)) as usize;
            let owner = self.scene.owners[k];
            let t = drawn.depth[i];
            let barycentric = Vec2::from(drawn.barycentrics[i]);
            let Some(ray) = camera.pixel_ray(centre) else {
                (out.color[i], out.depth[i], out.ids[i]) = (self.background, f32::INFINITY, 0);
                continue;
            };
            let flat = self.flat_colors.and_then(|colors| colors[k].as_ref());
            let color = match flat {
                Some(color) => color.at(barycentric),
                None => {
                    let hit = owner.hit(t, barycentric);
                    let (color, cast) = self.prepared.shade_hit(&ray, hit, self.options);
                    rays += cast;
                    color
                }
            };
            out.color[i] = color;
            out.depth[i] = (t * ray.direction.length()) as f32;
            out.ids[i] = owner.id;
        }
        rays
    }
}
