//! Progress bars on stderr for the long stages (hidden with `--json`), shared by every
//! command that runs the DEM.

use indicatif::{ProgressBar, ProgressState, ProgressStyle};
use recorder::record::Phase;

/// Every bar fits in this many columns (a standard terminal).
pub const COLUMNS: usize = 80;

/// A bar for the DEM phases, prefixed with `label` (may be empty):
/// `study    record [=====>    ] 1.235M/2.5M steps (3m 05s left)`, at most [`COLUMNS`] wide.
pub fn dem_bar(hidden: bool, label: &str) -> ProgressBar {
    if hidden {
        return ProgressBar::hidden();
    }
    // phase 9 + " [" + "] " + steps 19 ("123.4k/1.235M steps") + " (" + eta 8 + " left)"
    const FIXED: usize = 9 + 2 + 2 + 19 + 2 + 8 + 6;
    let label = fit(label, 20);
    let prefix = if label.is_empty() {
        String::new()
    } else {
        format!("{label} ")
    };
    let bar_width = bar_width(FIXED + prefix.chars().count());
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{prefix}{{msg:>9!}} [{{bar:{bar_width}}}] {{steps}} ({{eta_short}} left)"
        ))
        .expect("static template")
        .with_key("steps", |s: &ProgressState, w: &mut dyn std::fmt::Write| {
            let _ = write!(
                w,
                "{}/{} steps",
                compact(s.pos()),
                compact(s.len().unwrap_or(0))
            );
        })
        .with_key(
            "eta_short",
            |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = w.write_str(&duration(s.eta()));
            },
        )
        .progress_chars("=> "),
    );
    bar
}

/// The recorder's progress callback, drawing on `bar` (one length per phase).
pub fn on_phase(bar: &ProgressBar) -> impl FnMut(Phase, u64, u64) + '_ {
    move |phase, done, total| {
        let name = match phase {
            Phase::Settle => "settle".to_string(),
            Phase::SpinUp => "spin-up".to_string(),
            Phase::Period => "record".to_string(),
            Phase::Reference => "reference".to_string(),
            Phase::Twin(m) => format!("twin {m}"),
        };
        if bar.message() != name {
            bar.set_message(name);
            bar.set_length(total);
            bar.reset_eta();
        }
        bar.set_position(done);
    }
}

/// A bar counting `total` runs of `what`, with the current run's name as its message:
/// `extrapolate+compare [====>     ] 3/16 runs (1m 05s) n10_dtc100`, at most [`COLUMNS`]
/// wide (a longer message is cut).
pub fn runs_bar(hidden: bool, total: usize, what: &str) -> ProgressBar {
    if hidden {
        return ProgressBar::hidden();
    }
    // " [" + "] " + "100/100 runs" + " (" + elapsed 8 + ") ", then the message
    const FIXED: usize = 2 + 2 + 12 + 2 + 8 + 2;
    /// Room kept for the message (a study's run name such as `n1000_dtc10000`).
    const MESSAGE: usize = 14;
    let what = fit(what, 24);
    let used = FIXED + what.chars().count();
    let bar_width = bar_width(used + MESSAGE);
    let message = COLUMNS.saturating_sub(used + bar_width).max(1);
    let bar = ProgressBar::new(total as u64);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{what} [{{bar:{bar_width}}}] {{pos}}/{{len}} runs ({{elapsed_short}}) {{msg:{message}!}}"
        ))
        .expect("static template")
        .with_key(
            "elapsed_short",
            |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = w.write_str(&duration(s.elapsed()));
            },
        )
        .progress_chars("=> "),
    );
    bar
}

/// A spinner for a stage of unknown length (an external program), with its elapsed time;
/// a `what` too long for [`COLUMNS`] loses its middle.
pub fn spinner(hidden: bool, what: &str) -> ProgressBar {
    if hidden {
        return ProgressBar::hidden();
    }
    // spinner + " " + " (" + elapsed 8 + ")"
    let what = fit(what, COLUMNS - (1 + 1 + 2 + 8 + 1));
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template(&format!("{{spinner}} {what} ({{elapsed_short}})"))
            .expect("static template")
            .with_key(
                "elapsed_short",
                |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = w.write_str(&duration(s.elapsed()));
                },
            ),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

/// The bar's width when `used` columns go to the rest of the line: what is left of
/// [`COLUMNS`], between 10 and 30.
fn bar_width(used: usize) -> usize {
    COLUMNS.saturating_sub(used).clamp(10, 30)
}

/// A count in at most 6 columns: `99999`, then `123.5k`, `1.235M`, `12.35G`.
fn compact(x: u64) -> String {
    if x < 100_000 {
        return x.to_string();
    }
    let (value, unit) = [(1e3, "k"), (1e6, "M"), (1e9, "G"), (1e12, "T")]
        .into_iter()
        .map(|(scale, unit)| (x as f64 / scale, unit))
        .find(|(v, _)| *v < 999.95)
        .unwrap_or((x as f64 / 1e15, "P"));
    format!("{}{unit}", crate::fmt::sig(value, 4))
}

/// A duration in at most 8 columns: `45s`, `12m 05s`, `3h 07m`, `2d 05h`.
fn duration(d: std::time::Duration) -> String {
    let s = d.as_secs();
    match s {
        0..=59 => format!("{s}s"),
        60..=3599 => format!("{}m {:02}s", s / 60, s % 60),
        3600..=86399 => format!("{}h {:02}m", s / 3600, s % 3600 / 60),
        _ => format!("{}d {:02}h", (s / 86400).min(999), s % 86400 / 3600),
    }
}

/// `text` in at most `columns` characters: the middle of a longer one replaced by `…`.
fn fit(text: &str, columns: usize) -> String {
    let chars: Vec<char> = text.chars().collect();
    if chars.len() <= columns {
        return text.to_string();
    }
    let head = (columns - 1) / 2;
    let tail = columns - 1 - head;
    let mut out: String = chars[..head].iter().collect();
    out.push('…');
    out.extend(&chars[chars.len() - tail..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counters_and_durations_are_compact() {
        assert_eq!(compact(0), "0");
        assert_eq!(compact(99_999), "99999");
        assert_eq!(compact(123_456), "123.5k");
        assert_eq!(compact(999_999), "1M");
        assert_eq!(compact(1_234_567), "1.235M");
        assert_eq!(compact(u64::MAX), "18447P");
        for x in [
            0,
            99_999,
            100_000,
            999_949,
            999_950,
            12_345_678,
            999_999_999,
            u64::MAX / 1000,
        ] {
            assert!(compact(x).chars().count() <= 6, "{x}: {}", compact(x));
        }
        use std::time::Duration;
        assert_eq!(duration(Duration::from_secs(45)), "45s");
        assert_eq!(duration(Duration::from_secs(725)), "12m 05s");
        assert_eq!(duration(Duration::from_secs(3 * 3600 + 420)), "3h 07m");
        assert_eq!(
            duration(Duration::from_secs(2 * 86400 + 5 * 3600)),
            "2d 05h"
        );
        assert!(duration(Duration::from_secs(u64::MAX)).chars().count() <= 8);
        assert_eq!(fit("abcdefghij", 5), "ab…ij");
        assert_eq!(fit("abc", 5), "abc");
    }

    /// The widest line each bar can draw (longest phase name, 6-column counters, 8-column
    /// times, the labels and messages tdex uses) fits in [`COLUMNS`].
    #[test]
    fn every_bar_fits_in_80_columns() {
        for label in ["", "tdex", "study"] {
            let prefix = if label.is_empty() {
                String::new()
            } else {
                format!("{label} ")
            };
            let width = bar_width(9 + 2 + 2 + 19 + 2 + 8 + 6 + prefix.chars().count());
            let line = format!(
                "{prefix}{:>9} [{}] {}/{} steps ({} left)",
                "reference",
                "=".repeat(width),
                compact(123_456),
                compact(1_234_567),
                duration(std::time::Duration::from_secs(36_000 * 24 - 1))
            );
            assert!(
                line.chars().count() <= COLUMNS,
                "{} columns: {line}",
                line.chars().count()
            );
        }
        let what = "extrapolate+compare";
        let used = 2 + 2 + 12 + 2 + 8 + 2 + what.len();
        let width = bar_width(used + 14);
        let message = COLUMNS - used - width;
        assert!(message >= 14, "{message}");
        let line = format!(
            "{what} [{}] 100/100 runs ({}) {}",
            "=".repeat(width),
            duration(std::time::Duration::from_secs(3599)),
            "n1000_dtc10000"
        );
        assert!(
            line.chars().count() <= COLUMNS,
            "{} columns: {line}",
            line.chars().count()
        );
    }
}
