//! Progress bars on stderr for the long stages (hidden with `--json`), shared by every
//! command that runs the DEM.

use indicatif::{ProgressBar, ProgressState, ProgressStyle};
use recorder::record::Phase;
use std::time::{Duration, Instant};

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

/// A DEM phase's name, as the bar and the log show it.
fn phase_name(phase: Phase) -> String {
    match phase {
        Phase::Settle => "settle".to_string(),
        Phase::SpinUp => "spin-up".to_string(),
        Phase::Period => "record".to_string(),
        Phase::Reference => "reference".to_string(),
        Phase::Twin(m) => format!("twin {m}"),
    }
}

/// The recorder's progress callback, drawing on `bar` (one length per phase).
pub fn on_phase(bar: &ProgressBar) -> impl FnMut(Phase, u64, u64) + '_ {
    move |phase, done, total| {
        let name = phase_name(phase);
        if bar.message() != name {
            bar.set_message(name);
            bar.set_length(total);
            bar.reset_eta();
        }
        bar.set_position(done);
    }
}

/// Plain progress lines for a run whose stderr is not a terminal (a long recording or run in
/// the background, `nohup tdex record … 2> run.log &`), where no bar is drawn: one line when a
/// DEM phase starts, one at each tenth of its steps and one when it ends, each stamped with
/// the wall time since this process started (a resumed run counts from its resumption), so
/// that `tail -f run.log` shows how far it is, as LIGGGHTS's thermo output does.
pub struct PhaseLog<W: std::io::Write> {
    out: W,
    started: Instant,
    /// The phase being logged: when and at which step it started (a resumed run starts
    /// mid-phase), and the last tenth logged.
    current: Option<LoggedPhase>,
}

struct LoggedPhase {
    name: String,
    at: Instant,
    from: u64,
    tenth: u64,
}

impl PhaseLog<std::io::Stderr> {
    /// A log on stderr when it is not a terminal (a terminal has the bar), else `None`.
    pub fn on_stderr() -> Option<Self> {
        use std::io::IsTerminal;
        let err = std::io::stderr();
        (!err.is_terminal()).then(|| PhaseLog::new(err))
    }
}

impl<W: std::io::Write> PhaseLog<W> {
    pub fn new(out: W) -> Self {
        // one clock for the process: a study makes a log per DEM run, stamped alike
        static STARTED: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
        let started = *STARTED.get_or_init(Instant::now);
        PhaseLog {
            out,
            started,
            current: None,
        }
    }

    /// A progress report: `done` of `total` steps of the phase `name`. The caller reports a
    /// phase once where it starts, before its first step (0, or mid-way: a resumed run,
    /// twins that part after t1), as the recorder does ([`Phase`]); that first report starts
    /// the phase's clock.
    pub fn report(&mut self, name: &str, done: u64, total: u64) {
        let now = Instant::now();
        let stamp = duration(now - self.started);
        let total = total.max(1);
        let tenth = (done.min(total) * 10 / total).min(9);
        let line = match &mut self.current {
            Some(p) if p.name == name => {
                if done >= total {
                    let took = duration(now - p.at);
                    self.current = None;
                    format!("[{stamp}] {name}: done, {} steps in {took}", compact(total))
                } else if tenth > p.tenth {
                    p.tenth = tenth;
                    let rate = (done - p.from) as f64 / (now - p.at).as_secs_f64();
                    let left = if rate > 0.0 {
                        let secs = ((total - done) as f64 / rate).min(1e9);
                        format!(", about {} left", duration(Duration::from_secs_f64(secs)))
                    } else {
                        String::new()
                    };
                    format!(
                        "[{stamp}] {name}: {} % ({} of {} steps){left}",
                        tenth * 10,
                        compact(done),
                        compact(total)
                    )
                } else {
                    return;
                }
            }
            // a phase with no steps left
            _ if done >= total => format!("[{stamp}] {name}: done, {} steps", compact(total)),
            _ => {
                self.current = Some(LoggedPhase {
                    name: name.to_string(),
                    at: now,
                    from: done,
                    tenth,
                });
                // a resumed run, or twins that part after t1 (`--twins-from`), start mid-phase
                let from = if done > 0 {
                    format!(", from {} %", done * 100 / total)
                } else {
                    String::new()
                };
                format!("[{stamp}] {name}: {} steps{from}", compact(total))
            }
        };
        // a log that cannot be written is no reason to stop a DEM run: the line is dropped
        let _ = writeln!(self.out, "{line}");
        let _ = self.out.flush();
    }
}

/// The recorder's progress callback for `tdex record`: the bar, and a [`PhaseLog`] on stderr
/// when it is not a terminal.
pub fn on_phase_logged(bar: &ProgressBar) -> impl FnMut(Phase, u64, u64) + '_ {
    let mut draw = on_phase(bar);
    let mut log = PhaseLog::on_stderr();
    move |phase, done, total| {
        draw(phase, done, total);
        if let Some(log) = &mut log {
            log.report(&phase_name(phase), done, total);
        }
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
pub fn duration(d: Duration) -> String {
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

    /// One line when a phase starts (or is resumed), one per tenth, one when it ends; a
    /// new phase starts its own count.
    #[test]
    fn the_log_has_a_line_per_tenth_of_each_phase() {
        let mut out = Vec::new();
        {
            let mut log = PhaseLog::new(&mut out);
            for done in (0..=10_000).step_by(500) {
                log.report("spin-up", done, 10_000);
            }
            log.report("settle", 0, 300);
            log.report("settle", 300, 300);
            // a twin resumed at 30 %
            for done in (300_000..=1_000_000).step_by(500) {
                log.report("twin 2", done, 1_000_000);
            }
        }
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let body = |l: &str| l.split_once("] ").unwrap().1.to_string();
        assert!(lines.iter().all(|l| l.starts_with('[')), "{text}");
        assert_eq!(body(lines[0]), "spin-up: 10000 steps");
        assert!(
            body(lines[1]).starts_with("spin-up: 10 % (1000 of 10000 steps)"),
            "{text}"
        );
        assert!(
            body(lines[9]).starts_with("spin-up: 90 % (9000 of 10000 steps)"),
            "{text}"
        );
        assert!(
            body(lines[10]).starts_with("spin-up: done, 10000 steps in "),
            "{text}"
        );
        // a phase shorter than a report's block: its start and its end
        assert_eq!(body(lines[11]), "settle: 300 steps");
        assert!(
            body(lines[12]).starts_with("settle: done, 300 steps in "),
            "{text}"
        );
        assert_eq!(body(lines[13]), "twin 2: 1M steps, from 30 %");
        assert!(
            body(lines[14]).starts_with("twin 2: 40 % (400k of 1M steps)"),
            "{text}"
        );
        assert!(
            body(lines[20]).starts_with("twin 2: done, 1M steps in "),
            "{text}"
        );
        assert_eq!(lines.len(), 21, "{text}");
        // a phase with nothing left to run (resumed at its end) is one line
        let mut out = Vec::new();
        PhaseLog::new(&mut out).report("reference", 250_000, 250_000);
        let text = String::from_utf8(out).unwrap();
        assert_eq!(body(text.trim_end()), "reference: done, 250k steps");
    }

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
