//! The render progress bar: drawn on stderr only when stderr is a terminal and the render has
//! already taken about a second, so short renders and scripts stay quiet.

use std::io::IsTerminal;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How long a render runs before the bar appears.
const SHOW_AFTER: Duration = Duration::from_secs(1);

/// A progress bar that stays hidden for the first second.
pub struct RenderProgress {
    bar: ProgressBar,
    started: Instant,
    enabled: bool,
    shown: OnceLock<()>,
}

impl RenderProgress {
    /// A hidden bar; it can only ever show if stderr is a terminal.
    pub fn new() -> Self {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template(
            "{spinner} rendering [{bar:40}] {percent:>3}% {elapsed}/{duration}",
        ) {
            bar.set_style(style.progress_chars("=> "));
        }
        RenderProgress {
            bar,
            started: Instant::now(),
            enabled: std::io::stderr().is_terminal(),
            shown: OnceLock::new(),
        }
    }

    /// Records `done` of `total` work units; called from worker threads.
    pub fn update(&self, done: u64, total: u64) {
        if self.enabled && self.started.elapsed() >= SHOW_AFTER {
            self.shown.get_or_init(|| {
                self.bar.set_draw_target(ProgressDrawTarget::stderr());
            });
        }
        self.bar.set_length(total);
        self.bar.set_position(done);
    }

    /// Removes the bar from the terminal.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
