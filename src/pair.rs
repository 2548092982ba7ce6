//! `tdex pair`: the pairing of a recording's `t0` and `t1` snapshots, stored beside it for
//! reuse by `tdex extrapolate` (`RECORDING.pairing.json`, [`extrapolate::cache`]), told on
//! the terminal.

use crate::cli::PairPlan;
use anyhow::Result;
use extrapolate::cache::{compute, period_snapshots, store};
use extrapolate::pairing;
use tdex_format::RecordingReader;

pub fn run(plan: &PairPlan) -> Result<()> {
    let reader = RecordingReader::open(&plan.file)?;
    let (t0, t1) = period_snapshots(&reader)?;
    let mut stored = crate::with_workers(plan.threads, || Ok(compute(&t0, &t1)?))?;
    let measured = stored.summary.clone();
    if plan.reproducible {
        stored.summary = stored.summary.reproducible();
    }
    let path = store(&reader, &stored)?;
    let s = &measured;
    // replaying one period applies g again and again: each particle only ever plays the
    // roles of its own cycle
    let cycles = pairing::cycle_structure(&stored.g);
    let short_share = cycles.short_share(stored.g.len());
    if plan.json {
        let mut json = serde_json::to_value(s)?;
        json["pairing_file"] = path.display().to_string().into();
        json["cycles"] = serde_json::to_value(&cycles)?;
        json["cycles"]["short_cycle_periods"] = pairing::SHORT_CYCLE.into();
        json["cycles"]["short_share"] = short_share.into();
        println!("{}", serde_json::to_string_pretty(&json)?);
    } else {
        println!(
            "pairing       {} particles, total distance {} diameters (mean {}), k = {}, {} solve round(s), {}",
            s.particles,
            crate::fmt::sig(s.total_distance_diameters, 4),
            crate::fmt::sig(s.mean_distance_diameters, 4),
            s.k_used,
            s.rounds,
            if s.certified { "certified optimal" } else { "NOT certified" }
        );
        println!(
            "cycles of g   {} cycles, {} fixed points (particles that keep their role), {} % of \
             the particles on cycles of at most {} periods, longest {} periods",
            cycles.cycles,
            cycles.fixed_points,
            crate::fmt::sig(100.0 * short_share, 3),
            pairing::SHORT_CYCLE,
            cycles.longest
        );
        println!(
            "time          {:.3} s on {} threads; stored in {}",
            s.seconds.unwrap_or_default(),
            s.threads.unwrap_or_default(),
            path.display()
        );
    }
    Ok(())
}
