//! `tdex study regimes`: the flow-regime study of Haydar §3.3 (Figures 11–12). Per drum
//! speed: the Froude number and Mellmann's regime, the bed's flow measured on the t1
//! snapshot, and the extrapolation against the DEM reference where the particles move
//! relative to the drum; where they do not (Fr ≥ 1, or measured), it is refused.

use super::flow::{self, Regime};
use super::{evaluate, num, pct, plots, run_paths, write_file, Outcome};
use crate::cli::{RegimeRun, StudyPlan};
use anyhow::{Context, Result};
use indicatif::ProgressBar;
use recorder::record;
use serde::Serialize;
use std::time::Instant;
use tdex_format::RecordingReader;

#[derive(Debug, Serialize)]
struct Entry {
    rotation_period: f64,
    omega: f64,
    froude: f64,
    regime: Regime,
    /// Every regime whose Mellmann range holds the Froude number.
    mellmann_candidates: Vec<Regime>,
    tau: f64,
    angle_degrees: Option<f64>,
    active_layer_m: Option<f64>,
    active_layer_diameters: Option<f64>,
    /// The velocity stayed above the threshold down to the deepest particles measured.
    active_layer_whole_depth: Option<bool>,
    /// Mean speed relative to solid-body rotation / (ωR), at t1.
    relative_speed: f64,
    extrapolated: bool,
    refusal: Option<String>,
    outcome: Option<Outcome>,
}

#[derive(Debug, Serialize)]
struct RegimesStudy {
    study: &'static str,
    case: String,
    particles: usize,
    drum_radius: f64,
    tau_rev: f64,
    min_relative: f64,
    runs: Vec<Entry>,
}

/// Why the extrapolation is refused at this speed, if it is.
fn refusal(
    rotation_period: f64,
    omega: f64,
    fr: f64,
    relative: f64,
    min_relative: f64,
) -> Option<String> {
    let head = format!(
        "{rotation_period} s per revolution (ω = {omega:.3} rad/s, Froude {fr:.3}): extrapolation refused"
    );
    let tail = "so the pairing of t0 and t1 would be the identity and the table a fixed contact \
                network: the method has nothing to extrapolate";
    if fr >= 1.0 {
        Some(format!(
            "{head}: the drum centrifuges (Fr = ω²R/g ≥ 1: the wall's centripetal acceleration \
             exceeds gravity and the bed turns with the drum), {tail}"
        ))
    } else if relative < min_relative {
        Some(format!(
            "{head}: the particles have no motion relative to the drum (mean speed relative to \
             solid-body rotation {:.3} % of ωR at t1, below --min-relative {} %), {tail}",
            100.0 * relative,
            100.0 * min_relative
        ))
    } else {
        None
    }
}

/// Records one speed of the study, measures its flow at t1 and, unless the method is refused
/// there (a centrifuging drum, or particles moving relative to the drum at less than
/// `min_relative` of ωR), extrapolates and compares it.
fn run_speed(
    plan: &StudyPlan,
    r: &RegimeRun,
    min_relative: f64,
    bar: &ProgressBar,
) -> Result<Entry> {
    let dir = &plan.output;
    let stem = format!("rev{}s", r.rotation_period);
    let (rec, extra) = run_paths(dir, &stem);
    let case_path = dir.join(format!("{stem}.toml"));
    write_file(dir, &format!("{stem}.toml"), &r.case_toml)?;
    let omega = r.case.angular_velocity();
    let fr = flow::froude(&r.case);
    if !plan.json {
        bar.suspend(|| {
            println!(
                "speed         {} s per revolution: ω = {omega:.4} rad/s, Froude {fr:.4e} ({})",
                r.rotation_period,
                flow::regime(fr).name()
            )
        });
    }
    let started = Instant::now();
    crate::with_workers(plan.threads, || {
        let mut progress = super::on_phase_logged(bar);
        let mut sim = record::run_to_t0(&r.case, &mut progress)?;
        let seconds_to_t0 = started.elapsed().as_secs_f64();
        Ok(record::record_from_t0(
            &mut sim,
            &case_path,
            &r.case_toml,
            &r.options,
            &rec,
            seconds_to_t0,
            &mut progress,
        )?)
    })
    .with_context(|| format!("recording {} s per revolution", r.rotation_period))?;
    bar.set_message("");
    let reader = RecordingReader::open(&rec)?;
    let t1 = reader
        .snapshot(1)?
        .with_context(|| format!("{}: no snapshot at t1", rec.display()))?;
    let measured = flow::measure(&t1, omega, r.case.drum.radius);
    let diameter = t1.mean_diameter();
    let refused = refusal(
        r.rotation_period,
        omega,
        fr,
        measured.relative_speed,
        min_relative,
    );
    let outcome = match &refused {
        Some(_) => None,
        None => Some(evaluate(
            &rec,
            &extra,
            r.options.reference_periods,
            plan.threads,
            plan.cells,
        )?),
    };
    if let Some(msg) = &refused {
        if !plan.json {
            bar.suspend(|| println!("refused       {msg}"));
        }
    }
    let layer = measured.active_layer.as_ref();
    Ok(Entry {
        rotation_period: r.rotation_period,
        omega,
        froude: fr,
        regime: flow::regime(fr),
        mellmann_candidates: flow::candidate_regimes(fr),
        tau: r.options.period_steps as f64 * r.case.time.dt,
        angle_degrees: measured.angle_degrees,
        active_layer_m: layer.map(|l| l.thickness),
        active_layer_diameters: layer.map(|l| l.thickness / diameter),
        active_layer_whole_depth: layer.map(|l| l.whole_depth),
        relative_speed: measured.relative_speed,
        extrapolated: outcome.as_ref().is_some_and(|o| o.error.is_none()),
        refusal: refused,
        outcome,
    })
}

pub fn run(plan: &StudyPlan, runs: &[RegimeRun], tau_rev: f64, min_relative: f64) -> Result<()> {
    let bar = super::dem_bar(plan.json, "study");
    let entries = runs
        .iter()
        .map(|r| run_speed(plan, r, min_relative, &bar))
        .collect::<Result<Vec<_>>>()?;
    bar.finish_and_clear();
    let study = RegimesStudy {
        study: "regimes",
        case: plan.case_path.display().to_string(),
        particles: plan.case.particles.count,
        drum_radius: plan.case.drum.radius,
        tau_rev,
        min_relative,
        runs: entries,
    };
    let mut svgs: Vec<(&str, String)> = Vec::new();
    let points: Vec<(f64, f64, String)> = study
        .runs
        .iter()
        .filter_map(|e| {
            Some((
                e.froude.log10(),
                100.0 * e.outcome.as_ref()?.eps_rel_max?,
                format!("{} s/rev", e.rotation_period),
            ))
        })
        .collect();
    svgs.push((
        "error_vs_froude.svg",
        plots::scatter(
            "Maximum ε_rel against the Froude number",
            "log10 Froude number ω²R/g",
            "max ε_rel over the t_k (%)",
            &points,
        )?,
    ));
    let table = table(&study);
    super::finish(plan, &study, &table, &markdown(&study, &table), svgs)
}

fn table(s: &RegimesStudy) -> String {
    let mut t = format!(
        "{:>8} {:>8} {:>10} {:>12} {:>7} {:>9} {:>7} {:>12} {:>9}\n",
        "s/rev",
        "ω rad/s",
        "Froude",
        "regime",
        "angle°",
        "layer d",
        "rel %",
        "max eps_rel%",
        "speedup"
    );
    for e in &s.runs {
        let o = e.outcome.as_ref();
        t += &format!(
            "{:>8} {:>8.3} {:>10.3e} {:>12} {:>7} {:>9} {:>7.2} {:>12} {:>9}\n",
            e.rotation_period,
            e.omega,
            e.froude,
            e.regime.name(),
            num(e.angle_degrees, 1),
            num(e.active_layer_diameters, 1),
            100.0 * e.relative_speed,
            if e.refusal.is_some() {
                "refused".into()
            } else {
                pct(o.and_then(|o| o.eps_rel_max))
            },
            num(o.and_then(|o| o.speedup_100), 2),
        );
        if let Some(err) = o.and_then(|o| o.error.as_ref()) {
            t += &format!(
                "         {} s/rev: not extrapolated: {err}\n",
                e.rotation_period
            );
        }
    }
    t
}

fn markdown(s: &RegimesStudy, table: &str) -> String {
    let mut m = format!(
        "# Flow-regime study: {}\n\n{} particles, drum radius {} m, τ = {} of a revolution at \
         every speed. Froude number ω²R/g; regime by Mellmann's (2001) ranges; angle: dynamic \
         angle of repose fitted to the free surface at t1; layer d: active-layer thickness in \
         mean particle diameters; rel %: mean speed relative to solid-body rotation as a \
         percentage of ωR (docs/theory.md, \"Flow regimes of the drum\").\n\n```\n{table}```\n\n",
        s.case, s.particles, s.drum_radius, s.tau_rev
    );
    for e in &s.runs {
        if let Some(r) = &e.refusal {
            m += &format!("- {r}.\n");
        }
    }
    m += "\n![error against Froude number](error_vs_froude.svg)\n";
    m
}
