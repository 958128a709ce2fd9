//! [`BuildReport`]: what building a projection reports besides the projection.

/// What building a projection found worth reporting, typed: counters for a render's
/// statistics (a fitted projector grid's residual) and warnings for the user (a fit whose
/// residual may hide a wrong image). Empty for projections built from explicit parameters.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BuildReport {
    /// (name, value) pairs, names as in `--stats` (`fit_rms_angle_deg`, ...).
    pub counters: Vec<(&'static str, f64)>,
    /// One line each, without a trailing full stop.
    pub warnings: Vec<String>,
}

impl BuildReport {
    /// Appends `other`'s counters and warnings.
    pub fn extend(&mut self, other: BuildReport) {
        self.counters.extend(other.counters);
        self.warnings.extend(other.warnings);
    }
}
