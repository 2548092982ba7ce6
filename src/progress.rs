//! Progress bars on stderr for the long stages (hidden with `--json`), shared by every
//! command that runs the DEM.

use indicatif::{ProgressBar, ProgressStyle};
use recorder::record::Phase;

/// A bar for the DEM phases, prefixed with `label` (may be empty).
pub fn dem_bar(hidden: bool, label: &str) -> ProgressBar {
    if hidden {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{label}{}{{msg:>9}} [{{bar:40}}] {{pos}}/{{len}} steps ({{eta}} left)",
            if label.is_empty() { "" } else { " " }
        ))
        .expect("static template")
        .progress_chars("=> "),
    );
    bar
}

/// The recorder's progress callback, drawing on `bar` (one length per phase).
pub fn on_phase(bar: &ProgressBar) -> impl FnMut(Phase, u64, u64) + '_ {
    move |phase, done, total| {
        let name = match phase {
            Phase::Settle => "settle",
            Phase::SpinUp => "spin-up",
            Phase::Period => "record",
            Phase::Reference => "reference",
        };
        if bar.message() != name {
            bar.set_message(name);
            bar.set_length(total);
            bar.reset_eta();
        }
        bar.set_position(done);
    }
}

/// A bar counting `total` runs of `what`.
pub fn runs_bar(hidden: bool, total: usize, what: &str) -> ProgressBar {
    if hidden {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(total as u64);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{what} [{{bar:40}}] {{pos}}/{{len}} runs ({{elapsed}}) {{msg}}"
        ))
        .expect("static template")
        .progress_chars("=> "),
    );
    bar
}

/// A spinner for a stage of unknown length (an external program), with its elapsed time.
pub fn spinner(hidden: bool, what: &str) -> ProgressBar {
    if hidden {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template(&format!("{{spinner}} {what} ({{elapsed}})"))
            .expect("static template"),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}
