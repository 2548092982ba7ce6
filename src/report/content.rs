//! The report's text: what was compared, the error table (Table 5 form), the cost table
//! (Table 6 form), the plots and where every number comes from.

use super::costs::{CostTable, DemPeriodSource, TABLE_PERIODS};
use super::document::{bold, code, link, para, text, Block, Document};
use crate::compare::Comparison;
use recorder::format::{ExtrapolationInfo, RecordingInfo, RecordingSummary};

/// Columns of the error table before it continues in a second table.
const COLUMNS_PER_TABLE: usize = 10;

/// The plot files (written before the report that links them).
pub const MEANS_SVG: &str = "means.svg";
pub const ERRORS_SVG: &str = "eps_rel.svg";
pub const SPEEDUP_SVG: &str = "error_vs_speedup.svg";
pub const DURATIONS_SVG: &str = "duration_cdf.svg";
pub const FIELD_SVG: &str = "field.svg";

/// Everything the text is made from.
pub struct Inputs<'a> {
    pub recording_path: String,
    pub extrapolation_path: String,
    pub info: &'a RecordingInfo,
    pub extrapolation: &'a ExtrapolationInfo,
    pub summary: Option<&'a RecordingSummary>,
    pub comparison: &'a Comparison,
    /// `Err(why)` when the cost table cannot be made.
    pub costs: Result<CostTable, String>,
    /// `Ok(k)`: the field plot shows `t_k`; `Err(why)` when it could not be drawn.
    pub field: Result<u32, String>,
    /// The plots written, in order.
    pub plots: Vec<&'static str>,
}

/// `x` with `digits` significant digits (fixed notation in a readable range).
pub fn sig(x: f64, digits: usize) -> String {
    if !x.is_finite() {
        return "-".into();
    }
    if x == 0.0 {
        return "0".into();
    }
    let digits = digits.max(1);
    let magnitude = x.abs().log10().floor() as i64;
    if !(-3..9).contains(&magnitude) {
        return format!("{:.*e}", digits - 1, x);
    }
    let decimals = (digits as i64 - 1 - magnitude).max(0) as usize;
    format!("{x:.decimals$}")
}

/// `x` to 6 significant digits without trailing zeros: `1e-4`, `0.001`, `12.5`.
pub fn short(x: f64) -> String {
    let s = sig(x, 6);
    match s.split_once('e') {
        Some((mantissa, exp)) if mantissa.contains('.') => {
            let m = mantissa.trim_end_matches('0').trim_end_matches('.');
            format!("{m}e{exp}")
        }
        None if s.contains('.') => s.trim_end_matches('0').trim_end_matches('.').into(),
        _ => s,
    }
}

/// Seconds: whole seconds from 1000 s, else 3 significant digits.
fn secs(x: f64) -> String {
    if x.abs() >= 1000.0 {
        format!("{x:.0}")
    } else {
        sig(x, 3)
    }
}

fn opt(x: Option<f64>, f: impl Fn(f64) -> String) -> String {
    x.map_or("-".into(), f)
}

fn speedup(x: Option<f64>) -> String {
    x.map_or("-".into(), |s| format!("{}×", sig(s, 3)))
}

fn case_name(info: &RecordingInfo) -> String {
    let from_case = info
        .case_resolved
        .get("name")
        .and_then(|v| v.as_str())
        .filter(|s| !s.is_empty());
    match from_case {
        Some(name) => name.to_string(),
        None => std::path::Path::new(&info.case_path)
            .file_stem()
            .map_or_else(
                || "unnamed case".into(),
                |s| s.to_string_lossy().into_owned(),
            ),
    }
}

fn row(label: &str, value: String) -> Vec<String> {
    vec![label.to_string(), value]
}

pub fn document(inp: &Inputs) -> Document {
    let info = inp.info;
    let c = inp.comparison;
    let case = case_name(info);
    let mut d = Document {
        title: format!("tdex report: {case}"),
        ..Default::default()
    };
    d.push(para(vec![
        text("The extrapolation "),
        code(&inp.extrapolation_path),
        text(" of the recording "),
        code(&inp.recording_path),
        text(
            ", compared with the complete DEM that the recording continued as its reference, \
             in the form of Haydar et al. (2023) §3.1–3.2: the errors of Table 5, the costs of \
             Table 6, the group means of Figure 7 and the collision durations of Figure 9.",
        ),
    ]));

    // What was compared.
    d.push(Block::Heading(2, "What was compared".into()));
    let n_steps = info.sample_every;
    let periods = inp.extrapolation.periods;
    let span = |last: u32| {
        if last >= 2 {
            format!("t_2 … t_{last}")
        } else {
            "none".into()
        }
    };
    let pairing = &inp.extrapolation.pairing;
    let pairing_text = {
        let mean = pairing
            .get("mean_distance_diameters")
            .and_then(|v| v.as_f64());
        let certified = pairing.get("certified").and_then(|v| v.as_bool());
        let seconds = pairing.get("seconds").and_then(|v| v.as_f64());
        format!(
            "mean distance {} diameters; certified optimal: {}; computed in {} s",
            opt(mean, |m| sig(m, 4)),
            certified.map_or("unknown", |b| if b { "yes" } else { "no" }),
            opt(seconds, secs),
        )
    };
    let groups = if c.hot_particles + c.cold_particles > 0 {
        format!(
            "{} ({} initially hot, {} initially cold)",
            info.particles, c.hot_particles, c.cold_particles
        )
    } else {
        format!("{} (uniform initial temperature)", info.particles)
    };
    d.push(Block::Table {
        header: vec!["Quantity".into(), "Value".into()],
        rows: vec![
            row("Recording", inp.recording_path.clone()),
            row("Extrapolation", inp.extrapolation_path.clone()),
            row(
                "Case",
                if info.case_path.is_empty() {
                    case.clone()
                } else {
                    format!("{case} ({})", info.case_path)
                },
            ),
            row("Particles", groups),
            row("DEM time step Δt", format!("{} s", short(info.dt))),
            row(
                "Sampling n",
                format!("{n_steps} steps ({} s)", short(n_steps as f64 * info.dt)),
            ),
            row(
                "Δt_c^max",
                format!(
                    "{} steps ({} s)",
                    info.dtc_max_steps,
                    short(info.dtc_max_steps as f64 * info.dt)
                ),
            ),
            row(
                "Period τ",
                format!("{} s ({} steps)", short(info.tau), info.period_steps),
            ),
            row(
                "t0, t1",
                format!(
                    "{} s, {} s",
                    short(info.snapshot_time(0)),
                    short(info.snapshot_time(1))
                ),
            ),
            row(
                "DEM reference",
                format!(
                    "{} periods after t1 ({})",
                    info.reference_periods,
                    span(info.reference_periods + 1)
                ),
            ),
            row("Extrapolation scheme", inp.extrapolation.scheme.clone()),
            row(
                "Extrapolated periods",
                format!("{periods} ({})", span(periods + 1)),
            ),
            row("Pairing of t0 and t1", pairing_text),
            row("Voronoi cells", format!("{} (seed {})", c.cells, c.seed)),
            row("tdex version", info.tool_version.clone()),
        ],
        numeric: false,
    });

    errors_section(&mut d, c);
    costs_section(&mut d, inp);
    durations_section(&mut d, inp);
    field_section(&mut d, inp);

    d.push(Block::Heading(2, "Files".into()));
    d.push(Block::List(
        inp.plots.iter().map(|p| vec![link(*p, *p)]).collect(),
    ));
    d
}

fn errors_section(d: &mut Document, c: &Comparison) {
    d.push(Block::Heading(2, "Errors (Table 5 form)".into()));
    d.push(para(vec![
        text(format!(
            "At each extrapolated t_k with a DEM reference, the bed is divided into {} Voronoi \
             cells (seeds drawn inside the bed at t1); ",
            c.cells
        )),
        bold("ε_abs"),
        text(
            " is the mean over the cells of |T̄_DEM − T̄_extra|, the cells' mean temperatures \
             of the DEM particles (at their DEM positions) and of the extrapolated ones (at \
             their extrapolated positions); ",
        ),
        bold("ε_rel"),
        text(" = ε_abs / |T̄_hot − T̄_cold| with the DEM means of the initially hot and cold particles (Eq. 9); the "),
        bold("Eq. 10 error"),
        text(
            " compares the energy moved from t_(k−1) to t_k: (Σ|ΔT_DEM| − Σ|ΔT_extra|) / Σ|ΔT_DEM| \
             over the particles. The paper reports ε_rel of 1.3–3.1 % over t_2 … t_7 and Eq. 10 \
             errors of 0.1–4.5 %.",
        ),
    ]));
    for chunk in c.periods.chunks(COLUMNS_PER_TABLE) {
        let mut header = vec!["Extrapolation step".to_string()];
        header.extend(chunk.iter().map(|p| format!("t_{}", p.k)));
        let line = |label: &str, f: &dyn Fn(&crate::compare::PeriodComparison) -> String| {
            let mut r = vec![label.to_string()];
            r.extend(chunk.iter().map(f));
            r
        };
        let temp = |x: Option<f64>| opt(x, |v| format!("{v:.4}"));
        let rows = vec![
            line("t (s)", &|p| short(p.t)),
            line("ε_abs (K)", &|p| sig(p.eps_abs, 4)),
            line("ε_rel (%)", &|p| opt(p.eps_rel, |v| sig(100.0 * v, 4))),
            line("Eq. 10 energy error (%)", &|p| {
                opt(p.energy_error, |v| sig(100.0 * v, 4))
            }),
            line("T̄_hot DEM (K)", &|p| temp(p.hot_mean_dem)),
            line("T̄_hot extrapolated (K)", &|p| temp(p.hot_mean_extra)),
            line("T̄_cold DEM (K)", &|p| temp(p.cold_mean_dem)),
            line("T̄_cold extrapolated (K)", &|p| temp(p.cold_mean_extra)),
            line("Voronoi cells used", &|p| p.cells_used.to_string()),
        ];
        d.push(Block::Table {
            header,
            rows,
            numeric: true,
        });
    }
    if !c.unreferenced.is_empty() {
        let ks: Vec<String> = c.unreferenced.iter().map(|k| format!("t_{k}")).collect();
        d.push(para(vec![text(format!(
            "No DEM reference for {} (the recording was made with a smaller --reference): \
             not compared.",
            ks.join(", ")
        ))]));
    }
    figure(d, "Mean temperature of the initially hot and cold particles, DEM against extrapolated (the paper's Figure 7; the extrapolation starts from the DEM state at t1): ", MEANS_SVG, "Hot and cold group means over time, DEM and extrapolated");
    figure(
        d,
        "ε_rel, the Eq. 10 error and ε_abs per extrapolation step: ",
        ERRORS_SVG,
        "Relative, energy-transfer and absolute errors per extrapolation step",
    );
}

/// A paragraph `caption` linking `file`, then the image itself.
fn figure(d: &mut Document, caption: &str, file: &str, alt: &str) {
    d.push(para(vec![text(caption), link(file, file), text(".")]));
    d.push(Block::Image(alt.into(), file.into()));
}

fn costs_section(d: &mut Document, inp: &Inputs) {
    d.push(Block::Heading(
        2,
        format!("Costs (Table 6 form, {TABLE_PERIODS} τ)"),
    ));
    let t = match &inp.costs {
        Ok(t) => t,
        Err(why) => {
            d.push(para(vec![text(format!(
                "The cost table is unavailable: {why}."
            ))]));
            return;
        }
    };
    let m = TABLE_PERIODS as f64;
    d.push(Block::Table {
        header: vec![
            format!("{} particles", inp.info.particles),
            "Complete DEM".into(),
            "Extrapolated DEM".into(),
        ],
        rows: vec![
            vec!["Until t1 (s)".into(), secs(t.until_t1), secs(t.until_t1)],
            vec!["Pairing (s)".into(), "0".into(), secs(t.pairing)],
            vec![
                "Collision file (s)".into(),
                "0".into(),
                secs(t.collision_file),
            ],
            vec!["For one τ (s)".into(), secs(t.tau_dem), secs(t.tau_extra)],
            vec![
                format!("Total for {TABLE_PERIODS} τ (s)"),
                secs(t.total_dem(m)),
                secs(t.total_extrapolated(m)),
            ],
        ],
        numeric: true,
    });
    let mut summary = vec![
        text("Speedup: "),
        bold(speedup(t.speedup(m))),
        text(format!(" for {TABLE_PERIODS} τ, ")),
        bold(speedup(t.speedup_per_period())),
        text(" per τ"),
    ];
    match t.break_even_periods() {
        Some(p) => summary.push(text(format!(
            "; the extrapolation is faster than the complete DEM from {} periods after t1.",
            sig(p, 3)
        ))),
        None => summary.push(text(
            "; an extrapolated period is not cheaper than a DEM period here, so the extrapolation never pays off.",
        )),
    }
    d.push(para(summary));
    let dem_period = match t.tau_dem_source {
        DemPeriodSource::Reference { periods } => format!(
            "seconds_reference / {periods}: the DEM continued {periods} reference periods after \
             t1 without the recorder"
        ),
        DemPeriodSource::RecordedPeriod => "seconds_period − seconds_recorder: the recorded \
             period without the recorder's share (the recording has no reference run)"
            .into(),
    };
    d.push(para(vec![text(format!(
        "Wall-clock seconds measured on this machine with {} thread(s) (the recording's costs \
         record); the paper's are CPU seconds on one 2.66 GHz thread for 80 000 particles: \
         8580 | 8580, 0 | 551, 0 | 7619, 3900 | 6, totals 398 580 | 17 350 (speedup 23× for \
         100 τ, 650× per τ). Where each row comes from:",
        t.threads
    ))]));
    let pairing_note = if t.pairing_reused {
        "the pairing summary's seconds (the pairing was computed once and reused by this \
         extrapolation, which spent no time on it)"
    } else {
        "the pairing summary's seconds (computed by this extrapolation)"
    };
    d.push(Block::List(vec![
        vec![
            bold("Until t1"),
            text(": the recording's seconds_to_t0 + (seconds_period − seconds_recorder), the DEM to t0 and through the recorded period."),
        ],
        vec![bold("Pairing"), text(format!(": {pairing_note}."))],
        vec![
            bold("Collision file"),
            text(": the recording's seconds_recorder, the time spent sampling, splitting, encoding and writing the collision table during the recorded period."),
        ],
        vec![
            bold("For one τ"),
            text(format!(
                ": complete DEM: {dem_period}; extrapolated DEM: the extrapolation's seconds_per_period (replay only)."
            )),
        ],
        vec![
            bold(format!("Total for {TABLE_PERIODS} τ")),
            text(format!(
                ": Until t1 + {TABLE_PERIODS} × For one τ (complete); Until t1 + Pairing + Collision file + {TABLE_PERIODS} × For one τ (extrapolated)."
            )),
        ],
    ]));
    if inp.plots.contains(&SPEEDUP_SVG) {
        figure(d, "ε_rel at each compared t_k against the speedup of reaching t_k with k − 1 extrapolated periods: ", SPEEDUP_SVG, "Relative error against the speedup of reaching each t_k");
    }
}

fn durations_section(d: &mut Document, inp: &Inputs) {
    d.push(Block::Heading(2, "Collision durations (Figure 9)".into()));
    let Some(summary) = inp.summary.filter(|_| inp.plots.contains(&DURATIONS_SVG)) else {
        d.push(para(vec![text(
            "The recording has no summary record (its writer was interrupted), so the \
             collision-duration distribution is unavailable.",
        )]));
        return;
    };
    let h = &summary.duration_histogram;
    let total: u64 = h.iter().sum();
    let n = inp.info.sample_every;
    let mut p = vec![text(format!(
        "{total} collisions over the recorded period, by the number s of consecutive samples \
         they were seen at (a collision seen at s samples lasted about s·n steps, n = {n})."
    ))];
    if total > 0 {
        let one = h.get(1).copied().unwrap_or(0);
        let split_at = (inp.info.dtc_max_steps / n.max(1)) as usize;
        let longer: u64 = h.iter().skip(split_at + 1).sum();
        p.push(text(format!(
            " Seen at one sample only (shorter than {} steps): {} %; longer than Δt_c^max = {} \
             steps (split into several rows): {} %. The paper chose n from this curve: 97 % of \
             its collisions lasted more than 10 steps.",
            2 * n,
            sig(100.0 * one as f64 / total as f64, 3),
            inp.info.dtc_max_steps,
            sig(100.0 * longer as f64 / total as f64, 3),
        )));
    }
    p.push(text(" "));
    p.push(link(DURATIONS_SVG, DURATIONS_SVG));
    d.push(para(p));
    d.push(Block::Image(
        "Cumulative distribution of collision durations".into(),
        DURATIONS_SVG.into(),
    ));
}

fn field_section(d: &mut Document, inp: &Inputs) {
    match &inp.field {
        Ok(k) => {
            d.push(Block::Heading(2, format!("Temperature field at t_{k}")));
            d.push(para(vec![
                text(format!(
                    "The particles at t_{k} seen along the drum axis (y), x across and z up, \
                     DEM (left) and extrapolated (right) on one colour scale; only the \
                     particles visible from the end of the drum are drawn. "
                )),
                link(FIELD_SVG, FIELD_SVG),
            ]));
            d.push(Block::Image(
                format!("Temperature field at t_{k}, DEM and extrapolated"),
                FIELD_SVG.into(),
            ));
        }
        Err(why) => {
            d.push(Block::Heading(2, "Temperature field".into()));
            d.push(para(vec![text(format!(
                "The temperature field is not drawn: {why}."
            ))]));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_formatted_to_significant_digits() {
        assert_eq!(sig(0.0123456, 3), "0.0123");
        assert_eq!(sig(29.87654, 4), "29.88");
        assert_eq!(sig(398580.0, 3), "398580");
        assert_eq!(sig(1.5e-7, 2), "1.5e-7");
        assert_eq!(sig(f64::NAN, 2), "-");
        assert_eq!(secs(17350.4), "17350");
        assert_eq!(secs(0.5), "0.500");
        assert_eq!(short(1e-4), "1e-4");
        assert_eq!(short(0.001), "0.001");
        assert_eq!(short(12.5), "12.5");
        assert_eq!(short(50000.0), "50000");
    }
}
