//! The one timing rule of `flexcam bench`: one untimed warm-up run (caches, page faults of
//! first allocations, lazily built state), then the median wall-clock time of `repeat` timed
//! runs and their mean CPU time over all threads.
//!
//! The median rather than the fastest run: on a machine shared with other work a single
//! lucky run is not reproducible, while the median of a few runs is. The CPU time (user and
//! system, every thread) grows far less with other processes' load than the wall time does.

use std::time::Instant;

use flexcam::Result;

/// What [`measure`] found, in seconds: the median wall-clock time of one run, and the mean
/// CPU time of one run over all threads (`None` where the system does not report it).
#[derive(Debug, Clone, Copy, Default)]
pub struct Timing {
    pub median: f64,
    pub cpu: Option<f64>,
}

impl Timing {
    /// The CPU time times `scale` with `decimals` decimals, or "-" when unknown.
    pub fn cpu_text(&self, scale: f64, decimals: usize) -> String {
        self.cpu.map_or_else(
            || "-".to_string(),
            |c| format!("{:.*}", decimals, c * scale),
        )
    }

    /// The mean CPU milliseconds of one run, NaN when unknown (NaN carries through ratios
    /// and prints as "NaN").
    pub fn cpu_ms(&self) -> f64 {
        self.cpu.map_or(f64::NAN, |c| 1e3 * c)
    }

    /// The median wall-clock milliseconds of one run.
    pub fn median_ms(&self) -> f64 {
        1e3 * self.median
    }
}

/// Runs `run` once untimed, then `repeat` (at least 1) timed times: the [`Timing`] of the
/// timed runs and the output of the median one (of the two middle runs of an even count,
/// the slower).
pub fn measure<T>(repeat: u32, mut run: impl FnMut() -> Result<T>) -> Result<(Timing, T)> {
    run()?;
    let repeat = repeat.max(1);
    let mut runs = Vec::with_capacity(repeat as usize);
    let cpu_start = process_cpu_seconds();
    for _ in 0..repeat {
        let start = Instant::now();
        let out = run()?;
        runs.push((start.elapsed().as_secs_f64(), out));
    }
    let cpu = match (cpu_start, process_cpu_seconds()) {
        (Some(start), Some(end)) => Some((end - start) / f64::from(repeat)),
        _ => None,
    };
    runs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (median, out) = runs.swap_remove(runs.len() / 2);
    Ok((Timing { median, cpu }, out))
}

/// The user and system CPU time of this process so far, all threads, from `/proc/self/stat`
/// (fields 14 and 15, in clock ticks of 1/100 s: Linux's fixed USER_HZ); `None` where that
/// file is missing or unreadable.
fn process_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The command name (field 2) is parenthesised and may hold spaces: count from after it.
    let rest = &stat[stat.rfind(')')? + 1..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i)?.parse::<u64>().ok();
    Some((ticks(11)? + ticks(12)?) as f64 / 100.0)
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::*;

    /// One warm-up call, then `repeat` timed ones; the reported time and output are those of
    /// the median timed call, not the fastest or the warm-up.
    #[test]
    fn measure_reports_the_median_run_after_one_warm_up() {
        // Sleep lengths (ms) by call: the warm-up, then five timed calls, 100 ms apart so
        // that a loaded machine's late wake-ups do not reorder them.
        let sleeps = [600, 1, 400, 200, 300, 100];
        let mut call = 0;
        let (timing, out) = measure(5, || {
            let ms = sleeps[call];
            call += 1;
            std::thread::sleep(Duration::from_millis(ms));
            Ok(ms)
        })
        .unwrap();
        assert_eq!(call, 6);
        assert_eq!(out, 200);
        assert!(
            timing.median >= 0.200 && timing.median < 0.300,
            "{timing:?}"
        );
        assert!(timing.median_ms() >= 200.0);
        // Sleeping uses next to no CPU time: less than a run's wall time even with the other
        // tests of this binary counted (the process's CPU time holds every thread).
        if let Some(cpu) = timing.cpu {
            assert!(cpu < timing.median, "{timing:?}");
        }
        assert_eq!(Timing::default().cpu_text(1.0, 2), "-");
        assert!(Timing::default().cpu_ms().is_nan());
    }

    /// An error of any run, the warm-up included, is returned.
    #[test]
    fn measure_returns_the_first_error() {
        let mut calls = 0;
        let result = measure(3, || {
            calls += 1;
            if calls == 2 {
                Err(flexcam::Error::new("run failed"))
            } else {
                Ok(())
            }
        });
        assert!(result.is_err());
        assert_eq!(calls, 2);
    }
}
