//! The last few grid fits of this process, kept by their inputs. A scene with
//! correspondences is built when it is read (building is what checks its parameters) and
//! again when it is rendered, fitted, exported or edited in the viewer; the fit, the costly
//! part (seconds for a 9 x 9 grid with a thousand points), is a pure function of the prior
//! grid, the correspondences and the starts model, so each later build takes the kept
//! result instead of fitting again.
//!
//! Inputs are compared exactly (floating-point equality, so a NaN never matches and is
//! refitted); failed fits are not kept (their error is found again). At most [`CAPACITY`]
//! fits are kept, the least recently used dropped first.

use std::sync::{Mutex, PoisonError};

use super::grid::FitReport;
use crate::error::Result;
use crate::projection::flexible::{Correspondence, ProjectorGrid, Starts};

/// Fits kept at most (a scene and its animation keys, or the viewer's last few edits).
const CAPACITY: usize = 8;

/// A fit's inputs and its result.
struct Entry {
    prior: ProjectorGrid,
    correspondences: Vec<Correspondence>,
    starts: Starts,
    result: (ProjectorGrid, FitReport),
}

/// Kept fits, the most recently used last.
#[derive(Default)]
struct FitMemo {
    entries: Vec<Entry>,
}

impl FitMemo {
    /// The kept result of fitting `prior` to `correspondences` with `starts`, now the most
    /// recently used.
    fn get(
        &mut self,
        prior: &ProjectorGrid,
        correspondences: &[Correspondence],
        starts: Starts,
    ) -> Option<(ProjectorGrid, FitReport)> {
        let i = self.entries.iter().position(|e| {
            e.starts == starts && e.correspondences == correspondences && e.prior == *prior
        })?;
        let entry = self.entries.remove(i);
        let result = entry.result.clone();
        self.entries.push(entry);
        Some(result)
    }

    /// Keeps `result` as the fit of `prior` to `correspondences` with `starts`, dropping the
    /// least recently used fit when full.
    fn insert(
        &mut self,
        prior: &ProjectorGrid,
        correspondences: &[Correspondence],
        starts: Starts,
        result: (ProjectorGrid, FitReport),
    ) {
        if self.entries.len() == CAPACITY {
            self.entries.remove(0);
        }
        self.entries.push(Entry {
            prior: prior.clone(),
            correspondences: correspondences.to_vec(),
            starts,
            result,
        });
    }
}

/// This process's kept fits.
static MEMO: Mutex<FitMemo> = Mutex::new(FitMemo {
    entries: Vec::new(),
});

/// This process's kept fit of `prior` to `correspondences` with `starts`, or `fit()`'s, kept
/// when it succeeds.
pub(super) fn fitted(
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    starts: Starts,
    fit: impl FnOnce() -> Result<(ProjectorGrid, FitReport)>,
) -> Result<(ProjectorGrid, FitReport)> {
    fitted_in(&MEMO, prior, correspondences, starts, fit)
}

/// `memo`'s kept fit of `prior` to `correspondences` with `starts`, or `fit()`'s, kept when
/// it succeeds. The lock is not held while fitting, so fits on several threads run together
/// (two threads fitting the same inputs both fit, and keep one copy each).
fn fitted_in(
    memo: &Mutex<FitMemo>,
    prior: &ProjectorGrid,
    correspondences: &[Correspondence],
    starts: Starts,
    fit: impl FnOnce() -> Result<(ProjectorGrid, FitReport)>,
) -> Result<(ProjectorGrid, FitReport)> {
    // A poisoned lock only means another thread panicked while holding it; the entries are
    // whole (each is pushed complete).
    let memo = || memo.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(result) = memo().get(prior, correspondences, starts) {
        return Ok(result);
    }
    let result = fit()?;
    memo().insert(prior, correspondences, starts, result.clone());
    Ok(result)
}

#[cfg(test)]
mod tests {
    use std::cell::Cell;

    use glam::{DVec2, DVec3};

    use super::*;
    use crate::projection::flexible::projector_grid::GridInterpolation;

    fn grid(x: f64) -> ProjectorGrid {
        let starts = vec![DVec3::new(x, 0.0, 0.0); 4];
        let ends = vec![DVec3::new(x, 0.0, -1.0); 4];
        ProjectorGrid::new((2, 2), starts, ends, GridInterpolation::Bilinear).unwrap()
    }

    fn point(z: f64) -> Correspondence {
        Correspondence {
            uv: DVec2::new(0.5, 0.5),
            point: DVec3::new(0.0, 0.0, z),
        }
    }

    #[test]
    fn a_fit_is_kept_until_its_inputs_change() {
        let memo = Mutex::new(FitMemo::default());
        let calls = Cell::new(0);
        let fit = |x: f64| {
            calls.set(calls.get() + 1);
            Ok((grid(x), FitReport::default()))
        };
        let (prior, data) = (grid(0.0), [point(-2.0)]);
        let first = fitted_in(&memo, &prior, &data, Starts::Auto, || fit(1.0)).unwrap();
        let again = fitted_in(&memo, &prior, &data, Starts::Auto, || fit(2.0)).unwrap();
        assert_eq!(
            (calls.get(), &first.0, &again.0),
            (1, &grid(1.0), &grid(1.0))
        );
        // Another starts model, another point, another prior: each fitted anew.
        fitted_in(&memo, &prior, &data, Starts::Eye, || fit(3.0)).unwrap();
        fitted_in(&memo, &prior, &[point(-3.0)], Starts::Auto, || fit(4.0)).unwrap();
        fitted_in(&memo, &grid(0.5), &data, Starts::Auto, || fit(5.0)).unwrap();
        assert_eq!(calls.get(), 4);
        // A NaN input never matches itself.
        let nan = [point(f64::NAN)];
        fitted_in(&memo, &prior, &nan, Starts::Auto, || fit(6.0)).unwrap();
        fitted_in(&memo, &prior, &nan, Starts::Auto, || fit(6.0)).unwrap();
        assert_eq!(calls.get(), 6);
    }

    #[test]
    fn failures_are_not_kept_and_the_least_recently_used_fit_goes_first() {
        let memo = Mutex::new(FitMemo::default());
        let prior = grid(0.0);
        let failed = fitted_in(&memo, &prior, &[point(-2.0)], Starts::Auto, || {
            Err(crate::error::Error::new("no"))
        });
        assert!(failed.is_err());
        let calls = Cell::new(0);
        let fit = || {
            calls.set(calls.get() + 1);
            Ok((grid(1.0), FitReport::default()))
        };
        fitted_in(&memo, &prior, &[point(-2.0)], Starts::Auto, fit).unwrap();
        fitted_in(&memo, &prior, &[point(-3.0)], Starts::Auto, fit).unwrap();
        assert_eq!(calls.get(), 2);
        // Using the first again makes the second the least recently used.
        fitted_in(&memo, &prior, &[point(-2.0)], Starts::Auto, fit).unwrap();
        for k in 0..CAPACITY - 1 {
            let data = [point(-4.0 - k as f64)];
            fitted_in(&memo, &prior, &data, Starts::Auto, fit).unwrap();
        }
        assert_eq!(calls.get(), 1 + CAPACITY);
        fitted_in(&memo, &prior, &[point(-2.0)], Starts::Auto, fit).unwrap();
        assert_eq!(calls.get(), 1 + CAPACITY);
        fitted_in(&memo, &prior, &[point(-3.0)], Starts::Auto, fit).unwrap();
        assert_eq!(calls.get(), 2 + CAPACITY);
    }
}
