//! The one progress bar on stderr (indicatif): a run's simulated time, or a
//! count of jobs (Monte Carlo trials). Hidden unless enabled (a terminal,
//! no `--quiet`).

use indicatif::{ProgressBar, ProgressState, ProgressStyle};

/// A bar of `len` units drawn with `style` (hidden unless `enabled`).
fn bar(enabled: bool, len: u64, style: impl FnOnce() -> ProgressStyle) -> ProgressBar {
    if enabled {
        ProgressBar::new(len).with_style(style())
    } else {
        ProgressBar::hidden()
    }
}

/// `steps` steps of `dt` seconds: simulated time, real-time factor, eta.
#[must_use]
pub fn of_steps(enabled: bool, steps: u64, dt: f64) -> ProgressBar {
    bar(enabled, steps, || {
        let total = steps as f64 * dt;
        let template =
            format!("{{bar:40}} t = {{simt}} / {total} s  {{rtf}}× real time  eta {{eta}}");
        ProgressStyle::with_template(&template)
            .expect("valid template")
            .with_key(
                "simt",
                move |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = write!(w, "{:.2}", s.pos() as f64 * dt);
                },
            )
            .with_key(
                "rtf",
                move |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = write!(w, "{:.1}", s.per_sec() * dt);
                },
            )
    })
}

/// `n` jobs called `unit` (e.g. `trials`): count, rate, eta.
#[must_use]
pub fn of_jobs(enabled: bool, n: u64, unit: &str) -> ProgressBar {
    bar(enabled, n, || {
        let template = format!("{{bar:40}} {{pos}}/{{len}} {unit}  {{per_sec}}  eta {{eta}}");
        ProgressStyle::with_template(&template).expect("valid template")
    })
}
