//! The test that decides between two nested least-squares models of the same
//! correspondences (one with `extra` more unknowns): shared by the model choice (`select`)
//! and the pinhole camera's optional principal point (`pinhole_camera`).

/// Whether a model with `unknowns` and the sum of squared misses `ss` should replace
/// one with fewer (`unknowns - extra`) and `simpler_ss`: it must lower the sum by more than 4
/// noise variances per extra unknown, the variance estimated from its own residual and its
/// degrees of freedom (2 equations a correspondence less `unknowns`); never where it has no
/// spare equations.
pub(super) fn clearly_better(
    count: usize,
    unknowns: usize,
    extra: usize,
    ss: f64,
    simpler_ss: f64,
) -> bool {
    let freedom = 2 * count;
    if freedom <= unknowns {
        return false;
    }
    simpler_ss > ss * (1.0 + 4.0 * extra as f64 / (freedom - unknowns) as f64)
}
