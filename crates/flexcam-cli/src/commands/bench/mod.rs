//! `flexcam bench`: the source documents' timing tables, rerun with flexcam's renderers.

pub mod camera_triangles;
pub mod displaced;
mod displaced_methods;
pub mod flexible;
pub mod simplify;
mod timing;
pub mod trilinear;
pub mod view;

use clap::Subcommand;
use flexcam::Result;

/// Which table to measure.
#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// Table 1 of Hou et al. 2006 (reflection rows) and the 5,000-triangle mirror-sphere
    /// target: camera triangles against the paper and against the ray caster.
    CameraTriangles(camera_triangles::CameraTrianglesArgs),
    /// Figure 8.1 of Ramsey 2005: the displaced three-holed torus at subdivision levels 0 to
    /// 6, ray traced without tessellation, beside the same micro-triangles as a
    /// pre-tessellated mesh (time and peak memory); and Table 8.1: the transition system
    /// against full displacement, and every rendering method at the three camera positions.
    Displaced(displaced::DisplacedArgs),
    /// Table 7.1 of Brosz 2011: quadratic vs 2 to 6 segment projectors at 800 x 800, and the
    /// throughput of --method raster on a 1280 x 720 panorama of a 123,554-triangle scene.
    Flexible(flexible::FlexibleArgs),
    /// Chapter 8 and appendix D of Vallance 2005: ray casting vs trilinear rasterisation of random
    /// scenes and of the cube-floor scene through 2 to 50 projection triangles; with --study,
    /// Table 8.1's examples, the appendix C configurations or the tessellation factors.
    Trilinear(trilinear::TrilinearArgs),
    /// Table 6.2 of Ramsey 2005: simplification of polygon meshes (teapot
    /// tessellations, closed tori, the repository's OBJ models) with tau = 0.99 and 1 % of
    /// the edges searched per collapse.
    Simplify(simplify::SimplifyBenchArgs),
    /// The viewer's frame rate at 1280 x 720 while a projection parameter changes every
    /// frame: cube-floor through a perspective and a fisheye, and the 123,554-triangle
    /// teapot-dense scene as an equirectangular panorama.
    View(view::ViewBenchArgs),
}

/// Runs `flexcam bench`.
pub fn run(command: &BenchCommand) -> Result<()> {
    match command {
        BenchCommand::CameraTriangles(args) => camera_triangles::run(args),
        BenchCommand::Displaced(args) => displaced::run(args),
        BenchCommand::Flexible(args) => flexible::run(args),
        BenchCommand::Trilinear(args) => trilinear::run(args),
        BenchCommand::Simplify(args) => simplify::run(args),
        BenchCommand::View(args) => view::run(args),
    }
}
