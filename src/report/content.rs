//! The report's text: a summary of what was predicted, the prediction over all extrapolated
//! periods, the error table against the DEM where the recording has a reference (Table 5
//! form), the cost table (Table 6 form), the plots and where every number comes from.

use super::costs::{CostTable, DemPeriodSource, TABLE_PERIODS};
use super::document::{bold, code, link, para, text, Block, Document};
use super::prediction::{Point, Prediction};
use crate::compare::classes::{self, ClassComparison};
use crate::compare::{Comparison, ContrastKind, PeriodComparison};
use crate::fmt::trim_zeros;
use tdex_format::extrapolation::{Roles, Symmetry};
use tdex_format::{ExtrapolationInfo, RecordingInfo, RecordingSummary};

/// Columns of the error table before it continues in a second table.
const COLUMNS_PER_TABLE: usize = 10;

/// The plot files (written before the report that links them).
pub const MEANS_SVG: &str = "means.svg";
pub const ERRORS_SVG: &str = "eps_rel.svg";
pub const SPEEDUP_SVG: &str = "error_vs_speedup.svg";
pub const DURATIONS_SVG: &str = "duration_cdf.svg";
pub const FIELD_SVG: &str = "field.svg";
pub const BED_MEAN_SVG: &str = "bed_mean.svg";
pub const WALL_HEAT_SVG: &str = "wall_heat.svg";
pub const SPREAD_SVG: &str = "spread.svg";
pub const LACEY_SVG: &str = "lacey.svg";
pub const FIELDS_SVG: &str = "fields.svg";
pub const CLASS_MEANS_SVG: &str = "class_means.svg";
pub const SEGREGATION_SVG: &str = "segregation.svg";

/// Everything the text is made from.
pub struct Inputs<'a> {
    pub recording_path: String,
    pub extrapolation_path: String,
    pub info: &'a RecordingInfo,
    pub extrapolation: &'a ExtrapolationInfo,
    pub summary: Option<&'a RecordingSummary>,
    /// What the extrapolation predicts, from its file alone.
    pub prediction: &'a Prediction,
    /// The comparison with the DEM reference (None when the recording has none).
    pub comparison: Option<&'a Comparison>,
    /// `Err(why)` when the cost table cannot be made.
    pub costs: Result<CostTable, String>,
    /// With a comparison: `Ok(k)`: the DEM-against-extrapolated field plot shows `t_k`;
    /// `Err(why)` when it could not be drawn.
    pub field: Option<Result<u32, String>>,
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
        Some((mantissa, exp)) => format!("{}e{exp}", trim_zeros(mantissa.into())),
        None => trim_zeros(s),
    }
}

/// `x` rounded to `digits` significant digits first (see [`sig`]), then written by
/// [`short`]: `40.8`, `1e-4`.
fn rounded(x: f64, digits: usize) -> String {
    short(sig(x, digits).parse().unwrap_or(x))
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

/// Kelvin with `decimals` decimals.
fn kelvin(x: f64, decimals: usize) -> String {
    format!("{x:.decimals$} K")
}

/// Decimals for temperatures whose differences of interest are about `scale` K: three
/// significant digits of the difference, 1 to 4 decimals.
fn temp_decimals(scale: f64) -> usize {
    if !(scale.is_finite() && scale > 0.0) {
        return 1;
    }
    (2 - scale.log10().floor() as i64).clamp(1, 4) as usize
}

/// A temperature difference: three significant digits, no trailing zeros (`1.3 K`, `20 K`).
fn delta(x: f64) -> String {
    let s = sig(x, 3);
    let s = if s.contains('e') { s } else { trim_zeros(s) };
    format!("{s} K")
}

/// A fraction as a percentage: whole percent from 10 %, else two significant digits.
fn percent(f: f64) -> String {
    let p = 100.0 * f;
    if p.abs() >= 10.0 {
        format!("{p:.0} %")
    } else {
        format!("{} %", sig(p, 2))
    }
}

/// An amount in the unit `unit` with a k/M prefix from 1000, three significant digits.
fn si(x: f64, unit: &str) -> String {
    let (v, prefix) = match x.abs() {
        a if a >= 1e9 => (x / 1e9, "G"),
        a if a >= 1e6 => (x / 1e6, "M"),
        a if a >= 1e3 => (x / 1e3, "k"),
        _ => (x, ""),
    };
    format!("{} {prefix}{unit}", rounded(v, 3))
}

/// The three-line summary of what was predicted, computed from the numbers: the bed mean
/// (and the walls' heat), the groups' contrast and mixing or the bed's spread, and how far
/// to trust it.
pub fn summary_lines(p: &Prediction, c: Option<&Comparison>) -> [String; 3] {
    let (first, last) = (p.first(), p.last());
    let periods = p.periods();
    let elapsed = rounded(last.t - first.t, 6);
    let change = (last.bed - first.bed).abs();
    let d = temp_decimals(change.max(first.p95 - first.p05).max(last.p95 - last.p05));
    let after = format!(
        "After {periods} period{} ({elapsed} s)",
        if periods == 1 { "" } else { "s" }
    );
    let bed = match (p.wall_temperature, p.wall_heat()) {
        (Some(wall), Some(heat)) => {
            let total: f64 = heat.iter().map(|h| h.2).sum();
            let power = if last.t > first.t {
                format!(", {} on average", si(total / (last.t - first.t), "W"))
            } else {
                String::new()
            };
            let way = if (wall - first.bed).abs() > 0.0 {
                format!(
                    "{} of the way from its start ({} at t1) to the wall temperature ({} K)",
                    percent((last.bed - first.bed) / (wall - first.bed)),
                    kelvin(first.bed, d),
                    short(wall)
                )
            } else {
                format!(
                    "where it started, at the wall temperature ({} K)",
                    short(wall)
                )
            };
            format!(
                "{after} the bed mean is {}, {way}; the walls gave {}{power}.",
                kelvin(last.bed, d),
                si(total, "J")
            )
        }
        _ => format!(
            "{after} the bed mean is {}, as at t1 ({}): no wall conducts, so the bed's heat is \
             conserved and only redistributed.",
            kelvin(last.bed, d),
            kelvin(first.bed, d)
        ),
    };
    let inner = match (first.hot.zip(first.cold), last.hot.zip(last.cold)) {
        (Some((h1, c1)), Some((h, c))) => {
            let mixing = match (last.lacey, first.lacey) {
                (Some(m), Some(m1)) => format!(
                    "; Lacey index of the hot and cold particles {:.2} ({:.2} at t1, 1 = randomly \
                     mixed)",
                    m, m1
                ),
                (Some(m), None) => format!("; Lacey index {m:.2}"),
                _ => String::new(),
            };
            format!(
                "The initially hot and cold particles are {} apart ({} at t1){mixing}.",
                delta(h - c),
                delta(h1 - c1)
            )
        }
        _ => format!(
            "The bed's temperatures span {} over 5–95 % of its volume (standard deviation {}; \
             {} and {} at t1).",
            delta(last.p95 - last.p05),
            delta(last.std),
            delta(first.p95 - first.p05),
            delta(first.std)
        ),
    };
    let trust = match c {
        Some(c) => format!("Trust: {}.", c.verdict.text.trim_end_matches('.')),
        None => "No DEM reference was recorded, so nothing is judged: this is the \
                 extrapolation's prediction alone (record with --reference K --twins 2 to \
                 measure it against the DEM and the DEM's own run-to-run spread)."
            .to_string(),
    };
    [bed, inner, trust]
}

pub fn document(inp: &Inputs) -> Document {
    let info = inp.info;
    let c = inp.comparison;
    let p = inp.prediction;
    let case = case_name(info);
    let mut d = Document {
        title: format!("tdex report: {case}"),
        ..Default::default()
    };
    d.push(Block::List(
        summary_lines(p, c)
            .into_iter()
            .map(|l| vec![text(l)])
            .collect(),
    ));
    let what = match c {
        Some(_) => {
            ": what it predicts over all its periods, then compared with the complete \
                   DEM that the recording continued as its reference, in the form of Haydar et \
                   al. (2023) §3.1–3.2: the errors of Table 5, the costs of Table 6, the group \
                   means of Figure 7 and the collision durations of Figure 9."
        }
        None => {
            ": what it predicts over all its periods. The recording has no DEM reference \
                (recorded without --reference), so the prediction is shown alone; the costs \
                of Table 6 and the collision durations of Figure 9 of Haydar et al. (2023) \
                follow."
        }
    };
    d.push(para(vec![
        text("The extrapolation "),
        code(&inp.extrapolation_path),
        text(" of the recording "),
        code(&inp.recording_path),
        text(what),
    ]));

    extrapolated_section(&mut d, inp);
    prediction_section(&mut d, inp);
    match c {
        Some(c) => {
            errors_section(&mut d, c);
            if let Some(size_classes) = &c.size_classes {
                size_classes_section(&mut d, size_classes);
            }
        }
        None => {
            d.push(Block::Heading(2, "Errors".into()));
            d.push(para(vec![text(
                "No DEM reference was recorded, so nothing is judged here: the errors of Table 5 \
                 need the complete DEM at the extrapolated t_k. Record the case with \
                 --reference K (and --twins 2 to measure the DEM's own run-to-run spread, the \
                 floor no extrapolation can beat) to compare.",
            )]));
        }
    }
    costs_section(&mut d, inp);
    durations_section(&mut d, inp);
    field_section(&mut d, inp);

    d.push(Block::Heading(2, "Files".into()));
    d.push(Block::List(
        inp.plots.iter().map(|p| vec![link(*p, *p)]).collect(),
    ));
    d
}

/// What was extrapolated: the files, the case, the recording's settings and the
/// extrapolation's.
fn extrapolated_section(d: &mut Document, inp: &Inputs) {
    d.push(Block::Heading(2, "What was extrapolated".into()));
    let mut rows = recording_rows(inp);
    rows.extend(extrapolation_rows(inp));
    rows.push(row("tdex version", inp.info.tool_version.clone()));
    d.push(Block::Table {
        header: vec!["Quantity".into(), "Value".into()],
        rows,
        numeric: false,
    });
}

/// `t_2 … t_last`, or none.
fn span_to(last: u32) -> String {
    if last >= 2 {
        format!("t_2 … t_{last}")
    } else {
        "none".into()
    }
}

/// The rows of the recording: its files, case, particles, sampling, period, reference and
/// walls.
fn recording_rows(inp: &Inputs) -> Vec<Vec<String>> {
    let info = inp.info;
    let p = inp.prediction;
    let case = case_name(info);
    let n_steps = info.sample_every;
    let groups = if p.hot_particles + p.cold_particles > 0 {
        format!(
            "{} ({} initially hot, {} initially cold)",
            info.particles, p.hot_particles, p.cold_particles
        )
    } else {
        format!("{} (uniform initial temperature)", info.particles)
    };
    vec![
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
            if info.reference_periods == 0 {
                "none (recorded without --reference)".into()
            } else {
                format!(
                    "{} periods after t1 ({}){}",
                    info.reference_periods,
                    span_to(info.reference_periods + 1),
                    match info.twins {
                        0 => String::new(),
                        1 => ", and 1 DEM twin".into(),
                        m => format!(", and {m} DEM twins"),
                    }
                )
            },
        ),
        row(
            "Walls",
            match p.wall_temperature {
                Some(w) => format!("conducting, held at {} K", short(w)),
                None => "adiabatic".into(),
            },
        ),
    ]
}

/// The rows of the extrapolation: its scheme, periods, roles, mirror check, boundary maps
/// and the comparison's cells.
fn extrapolation_rows(inp: &Inputs) -> Vec<Vec<String>> {
    let (info, p, periods) = (inp.info, inp.prediction, inp.extrapolation.periods);
    let mut rows = vec![
        row(
            "Extrapolation scheme",
            inp.extrapolation.scheme.name().into(),
        ),
        row(
            "Extrapolated periods",
            format!("{periods} ({})", span_to(periods + 1)),
        ),
        roles_row(inp),
    ];
    // with the mirror, whether the bed was its own mirror image: how far to trust it
    if !inp.extrapolation.mirror_check.is_empty() {
        rows.push(row(
            "Mirror check",
            crate::extrapolation::mirror_check_lines(&inp.extrapolation.mirror_check).join("; "),
        ));
    }
    // with fresh boundary maps, what each jump drew from
    if !inp.extrapolation.boundary.is_exact() {
        rows.push(row(
            "Boundary maps",
            crate::extrapolation::boundary_lines(
                inp.extrapolation.boundary,
                &inp.extrapolation.fresh_pools,
            )
            .join("; "),
        ));
    }
    if let Some(c) = inp.comparison {
        rows.push(row(
            "Voronoi cells",
            format!("{} (seed {})", c.cells, c.seed),
        ));
    }
    if let Some(n) = p.lacey_cells {
        rows.push(row(
            "Voronoi cells of the Lacey index",
            format!(
                "{n} (about {} particles each)",
                short(
                    sig(info.particles as f64 / n as f64, 3)
                        .parse()
                        .unwrap_or(0.0)
                )
            ),
        ));
    }
    rows
}

/// The table's row of the roles: the pairing, or the path through several recorded periods.
fn roles_row(inp: &Inputs) -> Vec<String> {
    match &inp.extrapolation.roles {
        Roles::Pairing(pairing) => {
            let mean = Some(pairing.mean_distance_diameters);
            let certified = Some(pairing.certified);
            let seconds = pairing.seconds;
            let symmetry = inp.extrapolation.symmetry;
            row(
                match symmetry {
                    Symmetry::None => "Pairing of t0 and t1",
                    Symmetry::AxialMirror => "Pairing of t1 and the mirror image of t0",
                },
                format!(
                    "{}mean distance {} diameters; certified optimal: {}; computed in {} s",
                    crate::extrapolation::symmetry_words(symmetry)
                        .map_or(String::new(), |w| format!("{w}; ")),
                    opt(mean, |m| sig(m, 4)),
                    certified.map_or("unknown", |b| if b { "yes" } else { "no" }),
                    opt(seconds, secs),
                ),
            )
        }
        Roles::Path(path) => row(
            "Recurrence path",
            std::iter::once(crate::extrapolation::path_words(path))
                .chain(
                    crate::extrapolation::symmetry_words(inp.extrapolation.symmetry)
                        .map(String::from),
                )
                .chain(path.pairings.iter().map(|p| {
                    format!(
                        "pairing {}",
                        crate::extrapolation::path_pairing_words(p, inp.extrapolation.symmetry)
                    )
                }))
                .collect::<Vec<_>>()
                .join("; "),
        ),
    }
}

/// The prediction over all extrapolated periods: its plots and a table at the first, a
/// middle and the last `t_k`.
fn prediction_section(d: &mut Document, inp: &Inputs) {
    let p = inp.prediction;
    let with_dem = if inp.comparison.is_some() {
        " The DEM reference (dots) and its twins or further DEM runs (hollow dots) are drawn \
         where the recording has them."
    } else {
        ""
    };
    d.push(Block::Heading(
        2,
        format!("Prediction over {} periods", p.periods()),
    ));
    d.push(para(vec![text(format!(
        "Computed from the extrapolation file alone, at t1 (the DEM state the extrapolation \
         starts from) and at each of the {} extrapolated t_k. The bed mean is weighted by \
         particle volume (the mean of the heat content, as the comparison's); the spread is \
         over the bed's volume.{with_dem}",
        p.periods()
    ))]));
    d.push(prediction_table(p));
    prediction_figures(d, inp);
}

/// The prediction at t1, a middle and the last t_k: the means, the spread, the mixing and
/// the walls' heat.
fn prediction_table(p: &Prediction) -> Block {
    let shown: Vec<&Point> = {
        let mut v: Vec<&Point> = Vec::new();
        for q in [p.first(), &p.points[p.points.len() / 2], p.last()] {
            if !v.iter().any(|w| w.k == q.k) {
                v.push(q);
            }
        }
        v
    };
    let decimals = temp_decimals(
        shown
            .iter()
            .map(|q| q.p95 - q.p05)
            .chain([(p.last().bed - p.first().bed).abs()])
            .fold(0.0, f64::max),
    );
    let temp = |x: f64| format!("{x:.decimals$}");
    let mut header = vec!["Quantity".to_string()];
    header.extend(shown.iter().map(|q| format!("t_{}", q.k)));
    let line = |label: &str, f: &dyn Fn(&Point) -> String| {
        let mut r = vec![label.to_string()];
        r.extend(shown.iter().map(|q| f(q)));
        r
    };
    let mut rows = vec![
        line("t (s)", &|q| short(q.t)),
        line("Bed mean (K)", &|q| temp(q.bed)),
    ];
    if p.has_groups() {
        rows.push(line("Hot group mean (K)", &|q| {
            q.hot.map_or_else(String::new, temp)
        }));
        rows.push(line("Cold group mean (K)", &|q| {
            q.cold.map_or_else(String::new, temp)
        }));
    }
    rows.push(line("5 % of the volume below (K)", &|q| temp(q.p05)));
    rows.push(line("95 % of the volume below (K)", &|q| temp(q.p95)));
    rows.push(line("Standard deviation (K)", &|q| sig(q.std, 3)));
    if p.points.iter().any(|q| q.lacey.is_some()) {
        rows.push(line("Lacey index", &|q| {
            q.lacey
                .map_or_else(|| "undefined".into(), |m| format!("{m:.3}"))
        }));
    }
    if p.wall_temperature.is_some() {
        let t1_heat = p.first().heat;
        rows.push(line("Heat the walls gave since t1 (J)", &|q| {
            sig(q.heat - t1_heat, 4)
        }));
    }
    Block::Table {
        header,
        rows,
        numeric: true,
    }
}

/// The prediction's figures over time, those the report drew.
fn prediction_figures(d: &mut Document, inp: &Inputs) {
    let p = inp.prediction;
    figure(
        d,
        "The bed mean over time: ",
        BED_MEAN_SVG,
        "Bed mean temperature over time",
    );
    if inp.plots.contains(&MEANS_SVG) {
        figure(
            d,
            "The means of the initially hot and cold particles (the paper's Figure 7): ",
            MEANS_SVG,
            "Hot and cold group means over time",
        );
    }
    if inp.plots.contains(&WALL_HEAT_SVG) {
        figure(
            d,
            "The heat the walls gave, the change of Σ C_i T_i (C_i = ρ c_p (4/3)π r_i³) between \
             consecutive t_k (particle-particle conduction conserves it), per period and since \
             t1: ",
            WALL_HEAT_SVG,
            "Heat the walls gave per period and in total",
        );
    }
    if inp.plots.contains(&SPREAD_SVG) {
        figure(
            d,
            "The spread of the bed's temperatures, 5–95 % of its volume and the standard \
             deviation: ",
            SPREAD_SVG,
            "Spread of the bed's temperatures over time",
        );
    }
    if inp.plots.contains(&LACEY_SVG) {
        figure(
            d,
            "The mixing of the initially hot and cold particles: the Lacey index \
             M = (σ0² − σ²)/(σ0² − σr²) of the hot fraction of the Voronoi cells (σ² its \
             variance over the cells, σ0² = p(1 − p) segregated, σr² = p(1 − p)/n̄ randomly \
             mixed; 0 segregated, 1 mixed). In the extrapolation the particles keep their roles' \
             positions and the hot and cold labels move with the heat: ",
            LACEY_SVG,
            "Lacey mixing index over time",
        );
    }
    if inp.plots.contains(&FIELDS_SVG) {
        let ks: Vec<String> = p.fields.iter().map(|s| format!("t_{}", s.index)).collect();
        figure(
            d,
            &format!(
                "The temperature field at {} seen along the drum axis (y), x across and z up, \
                 inside the drum's cross-section, on one colour scale; only the particles \
                 visible from the end of the drum are drawn: ",
                ks.join(", ")
            ),
            FIELDS_SVG,
            "Temperature field at the first, a middle and the last t_k",
        );
    }
}

fn errors_section(d: &mut Document, c: &Comparison) {
    d.push(Block::Heading(2, "Errors (Table 5 form)".into()));
    errors_definitions(d, c);
    d.push(para(vec![
        bold("Trust"),
        text(format!(": {}.", c.verdict.text.trim_end_matches('.'))),
    ]));
    // rows that have no value at any t_k are left out, never shown as dashes
    let quantities: Vec<(&str, Box<Cell>)> = error_rows(c)
        .into_iter()
        .filter(|(_, f)| c.periods.iter().any(|p| f(p).is_some()))
        .collect();
    for chunk in c.periods.chunks(COLUMNS_PER_TABLE) {
        let mut header = vec!["Extrapolation step".to_string()];
        header.extend(chunk.iter().map(|p| format!("t_{}", p.k)));
        let rows = quantities
            .iter()
            .map(|(label, f)| {
                let mut r = vec![label.to_string()];
                r.extend(chunk.iter().map(|p| f(p).unwrap_or_else(|| "-".into())));
                r
            })
            .collect();
        d.push(Block::Table {
            header,
            rows,
            numeric: true,
        });
    }
    if !c.unreferenced.is_empty() {
        d.push(para(vec![text(format!(
            "No DEM reference for {} (the recording was made with a smaller --reference): \
             not compared.",
            crate::compare::span_of(&c.unreferenced)
        ))]));
    }
    figure(
        d,
        "ε_abs with the DEM runs' own spread (the floor, where twins were recorded), ε_rel and \
         the Eq. 10 error, and the contrast ε_rel divides by, per extrapolation step (a decaying \
         contrast makes ε_rel grow for the same ε_abs): ",
        ERRORS_SVG,
        "Absolute, relative and energy-transfer errors per extrapolation step, and the contrast",
    );
}

/// A row of the errors' table: its value at a `t_k`, if it has one there.
type Cell = dyn Fn(&PeriodComparison) -> Option<String>;

/// What ε_abs, ε_rel, the Eq. 10 error and (with twins) the floor are, for this comparison.
fn errors_definitions(d: &mut Document, c: &Comparison) {
    let divisor = match c.contrast {
        ContrastKind::HotCold => {
            "|T̄_hot − T̄_cold| with the DEM means of the initially hot and cold particles (Eq. 9)"
        }
        ContrastKind::WallBed => {
            "|T_wall − T̄_bed|, the conducting wall's temperature less the DEM's bed mean (the \
             bed has no hot and cold groups, so it is compared on its bed mean)"
        }
        ContrastKind::None => "nothing here: the bed has neither groups nor a conducting wall",
    };
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
        text(format!(" = ε_abs / {divisor}; the ")),
        bold("Eq. 10 error"),
        text(
            " compares the energy moved from t_(k−1) to t_k: (Σ|ΔT_DEM| − Σ|ΔT_extra|) / Σ|ΔT_DEM| \
             over the particles. The paper reports ε_rel of 1.3–3.1 % over t_2 … t_7 and Eq. 10 \
             errors of 0.1–4.5 %.",
        ),
    ]));
    let floors = c.periods.iter().any(|p| p.floor_eps_abs.is_some());
    if floors {
        d.push(para(vec![
            bold("Floor"),
            text(format!(
                ": two DEM runs of a chaotic flow part at the particle scale, so ε_abs between \
                 the {} DEM runs (the reference and its twins) is the floor no extrapolation can \
                 beat; the extrapolation's mean ε_abs to {} over the floor is its ratio to the \
                 floor (1: as far from them as they are from each other).",
                c.dem_runs,
                c.departure
                    .runs_measured_to()
                    .unwrap_or_else(|| "those runs".to_string())
            )),
        ]));
    }
}

/// The errors' table rows, each a label and its value at a `t_k`: the errors, the floor,
/// the ratio, then the group (or bed) means and the cells used.
fn error_rows(c: &Comparison) -> Vec<(&'static str, Box<Cell>)> {
    let temp = |x: Option<f64>| x.map(|v| format!("{v:.4}"));
    let pct = |x: Option<f64>| x.map(|v| sig(100.0 * v, 4));
    let groups = c.contrast == ContrastKind::HotCold;
    let mut quantities: Vec<(&str, Box<Cell>)> = vec![
        ("t (s)", Box::new(|p| Some(short(p.t)))),
        ("ε_abs (K)", Box::new(|p| Some(sig(p.eps_abs, 4)))),
        ("ε_rel (%)", Box::new(move |p| pct(p.eps_rel))),
        (
            match c.contrast {
                ContrastKind::WallBed => "Contrast |T_wall − T̄_bed| (K)",
                _ => "Contrast |T̄_hot − T̄_cold| (K)",
            },
            Box::new(|p| p.contrast.map(|v| sig(v, 4))),
        ),
        (
            "Floor ε_abs, DEM runs (K)",
            Box::new(|p| p.floor_eps_abs.map(|v| sig(v, 4))),
        ),
        (
            "Floor ε_abs min–max (K)",
            Box::new(|p| {
                Some(format!(
                    "{}–{}",
                    sig(p.floor_eps_abs_min?, 3),
                    sig(p.floor_eps_abs_max?, 3)
                ))
            }),
        ),
        (
            "ε_abs to the DEM runs (K)",
            Box::new(|p| p.eps_abs_to_dem_runs.map(|v| sig(v, 4))),
        ),
        (
            "Ratio to floor",
            // in parentheses where the extrapolation is still the recorded run (left out of
            // the verdict)
            Box::new(|p| {
                p.ratio_to_floor.map(|v| {
                    if p.within_recording {
                        format!("({})", sig(v, 3))
                    } else {
                        sig(v, 3)
                    }
                })
            }),
        ),
        (
            "Eq. 10 energy error (%)",
            Box::new(move |p| pct(p.energy_error)),
        ),
    ];
    if groups {
        quantities.extend([
            (
                "T̄_hot DEM (K)",
                Box::new(move |p: &PeriodComparison| temp(p.hot_mean_dem)) as Box<Cell>,
            ),
            (
                "T̄_hot extrapolated (K)",
                Box::new(move |p| temp(p.hot_mean_extra)),
            ),
            ("T̄_cold DEM (K)", Box::new(move |p| temp(p.cold_mean_dem))),
            (
                "T̄_cold extrapolated (K)",
                Box::new(move |p| temp(p.cold_mean_extra)),
            ),
        ]);
    } else {
        quantities.extend([
            (
                "T̄_bed DEM (K)",
                Box::new(move |p: &PeriodComparison| temp(Some(p.bed_mean_dem))) as Box<Cell>,
            ),
            (
                "T̄_bed extrapolated (K)",
                Box::new(move |p| temp(Some(p.bed_mean_extra))),
            ),
        ]);
    }
    quantities.push((
        "Voronoi cells used",
        Box::new(|p| Some(p.cells_used.to_string())),
    ));
    quantities
}

/// A bed of several particle sizes: each class's mean temperature and the radial
/// segregation index at the last compared `t_k`, whether they stayed within the DEM runs'
/// spread, and their plots over time.
fn size_classes_section(d: &mut Document, c: &ClassComparison) {
    let Some(last) = c.extra_series.last() else {
        return;
    };
    let k = last.k;
    let dem = c.dem_at(k);
    d.push(Block::Heading(2, "Size classes".into()));
    d.push(para(vec![
        text(format!(
            "The bed holds {} particle sizes, each a size class of one radius. For each class: \
             the ",
            c.radii.len()
        )),
        bold("mean temperature"),
        text(" of the particles of that radius (one radius, so no weighting within a class), and its "),
        bold("distance"),
        text(
            ": the mean distance of its particles from the bed's centroid in the \
             cross-section (x, z) over that of all particles (1: where the bed is on average; \
             below 1 the class gathers in the core, above 1 it rides outside, nearer the \
             mantle). The ",
        ),
        bold("segregation index"),
        text(
            " is the largest class's distance minus the smallest's: 0 for a mixed bed, \
             positive when the large particles ride outside the small ones. The DEM runs' \
             spread is the smallest to the largest value of the reference and its twins.",
        ),
    ]));
    let of_dem = |f: &dyn Fn(&classes::ClassState) -> String| dem.map_or("-".into(), f);
    let rows = c
        .radii
        .iter()
        .enumerate()
        .map(|(class, &r)| {
            vec![
                (class + 1).to_string(),
                classes::millimetres(r),
                c.particles[class].to_string(),
                of_dem(&|s| classes::temperature(s.mean_temperature[class])),
                classes::range(c.mean_spread(class, k), classes::temperature),
                classes::temperature(last.mean_temperature[class]),
                of_dem(&|s| classes::dimensionless(s.segregation.relative_distance[class])),
                classes::dimensionless(last.segregation.relative_distance[class]),
            ]
        })
        .collect();
    d.push(para(vec![text(format!(
        "At t_{k}, the last compared t_k:"
    ))]));
    d.push(Block::Table {
        header: [
            "Class",
            "Radius (mm)",
            "Particles",
            "T̄ DEM (K)",
            "T̄ DEM runs min..max (K)",
            "T̄ extrapolated (K)",
            "Distance DEM",
            "Distance extrapolated",
        ]
        .map(String::from)
        .to_vec(),
        rows,
        numeric: true,
    });
    d.push(para(vec![text(format!(
        "Segregation index at t_{k}: DEM {}, DEM runs {}, extrapolated {}.",
        of_dem(&|s| classes::dimensionless(s.segregation.index)),
        classes::range(c.index_spread(k), classes::dimensionless),
        classes::dimensionless(last.segregation.index),
    ))]));
    d.push(Block::List(
        classes::verdict_lines(c)
            .into_iter()
            .map(|l| vec![text(l)])
            .collect(),
    ));
    figure(
        d,
        "The mean temperature of each size class over time, the DEM runs' and the \
         extrapolation's at the compared t_k: ",
        CLASS_MEANS_SVG,
        "Mean temperature of each particle size over time",
    );
    figure(
        d,
        "The segregation index over time: ",
        SEGREGATION_SVG,
        "Radial segregation index of the particle sizes over time",
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
    d.push(costs_table(inp.info.particles, t));
    d.push(speedup_words(t));
    costs_sources(d, t);
    if inp.plots.contains(&SPEEDUP_SVG) {
        figure(d, "ε_rel at each compared t_k against the speedup of reaching t_k with k − 1 extrapolated periods: ", SPEEDUP_SVG, "Relative error against the speedup of reaching each t_k");
    }
}

/// The Table 6 rows: the complete DEM beside the extrapolated one, for `particles`.
fn costs_table(particles: u32, t: &CostTable) -> Block {
    let m = TABLE_PERIODS as f64;
    Block::Table {
        header: vec![
            format!("{particles} particles"),
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
            vec![
                "Reading the table (s)".into(),
                "0".into(),
                secs(t.read_table),
            ],
            vec!["For one τ (s)".into(), secs(t.tau_dem), secs(t.tau_extra)],
            vec![
                format!("Total for {TABLE_PERIODS} τ (s)"),
                secs(t.total_dem(m)),
                secs(t.total_extrapolated(m)),
            ],
        ],
        numeric: true,
    }
}

/// The speedup for the table's periods and per period, and from how many periods the
/// extrapolation pays.
fn speedup_words(t: &CostTable) -> Block {
    let m = TABLE_PERIODS as f64;
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
    para(summary)
}

/// Where each row of the cost table comes from.
fn costs_sources(d: &mut Document, t: &CostTable) {
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
        "Wall-clock seconds measured on this machine with {} thread(s){} (the recording's costs \
         record); the paper's are CPU seconds on one 2.66 GHz thread for 80 000 particles: \
         8580 | 8580, 0 | 551, 0 | 7619, 3900 | 6, totals 398 580 | 17 350 (speedup 23× for \
         100 τ, 650× per τ). Where each row comes from:",
        t.threads,
        super::costs::vectors_clause(&t.vector_instructions)
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
            bold("Reading the table"),
            text(": the extrapolation's seconds_read_table, reading the collision table into memory once before the first period (not in the paper's table; 0 when the table is streamed, which reads it within every period)."),
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
                ": Until t1 + {TABLE_PERIODS} × For one τ (complete); Until t1 + Pairing + Collision file + Reading the table + {TABLE_PERIODS} × For one τ (extrapolated)."
            )),
        ],
    ]));
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
    let Some(field) = &inp.field else {
        return;
    };
    match field {
        Ok(k) => {
            d.push(Block::Heading(
                2,
                format!("Temperature field at t_{k}, DEM and extrapolated"),
            ));
            d.push(para(vec![
                text(format!(
                    "The particles at t_{k}, the last compared t_k, seen along the drum axis \
                     (y), x across and z up, DEM (left) and extrapolated (right) on one colour \
                     scale; only the particles visible from the end of the drum are drawn. "
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
    fn a_bed_of_three_sizes_has_its_size_classes_section() {
        // the twin 0.5 K warmer than the reference; the extrapolation within their spread
        // at t2, 1 K too cold at t3
        let c = classes::synthetic::three_class_comparison();
        let mut d = Document::default();
        size_classes_section(&mut d, &c);
        let md = d.markdown();
        assert!(md.contains("## Size classes"), "{md}");
        assert!(md.contains("The bed holds 3 particle sizes"), "{md}");
        assert!(md.contains("At t_3, the last compared t_k:"), "{md}");
        let row = |cells: &[&str]| format!("| {} |", cells.join(" | "));
        for cells in [
            [
                "1",
                "1",
                "2",
                "303.000",
                "303.000..303.500",
                "302.000",
                "0.500",
                "0.500",
            ],
            [
                "2",
                "1.5",
                "2",
                "313.000",
                "313.000..313.500",
                "312.000",
                "1.000",
                "1.000",
            ],
            [
                "3",
                "2",
                "2",
                "323.000",
                "323.000..323.500",
                "322.000",
                "1.500",
                "1.500",
            ],
        ] {
            assert!(md.contains(&row(&cells)), "{md}");
        }
        assert!(md.contains(
            "Segregation index at t_3: DEM 1.000, DEM runs 1.000..1.000, extrapolated 1.000."
        ));
        assert!(
            md.contains("class 1 (1 mm) mean within the DEM runs' spread at 1 of 2 compared t_k")
        );
        assert!(md.contains("segregation index within the DEM runs' spread at 2 of 2 compared t_k"));
        assert!(md.contains(CLASS_MEANS_SVG) && md.contains(SEGREGATION_SVG));
        // the plots draw every class and the DEM runs
        let means = super::super::plots::class_means(&c).expect("drawn");
        assert!(means.contains("r = 1.5 mm") && means.contains("DEM twin"));
        let index = super::super::plots::segregation(&c).expect("drawn");
        assert!(index.contains("extrapolated"));
    }

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
        assert_eq!(delta(20.0), "20 K");
        assert_eq!(delta(1.2999), "1.3 K");
        assert_eq!(percent(0.5712), "57 %");
        assert_eq!(percent(0.0123), "1.2 %");
        assert_eq!(si(40804.2, "J"), "40.8 kJ");
        assert_eq!(si(12.0, "W"), "12 W");
        assert_eq!(temp_decimals(148.0), 1);
        assert_eq!(temp_decimals(0.05), 4);
        assert_eq!(kelvin(169.6123, 1), "169.6 K");
    }
}
