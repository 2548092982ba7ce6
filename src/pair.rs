//! `tdex pair`: the pairing of a recording's `t1` snapshot to `t0` (or, for several recorded
//! periods, of `tP` to the start of each period), stored beside it for reuse by
//! `tdex extrapolate` (`RECORDING.pairing.json`, `RECORDING.pairing.t<end>-t<start>.json`,
//! [`extrapolate::cache`]), told on the terminal.

use crate::cli::PairPlan;
use anyhow::Result;
use extrapolate::cache::{compute, snapshot, store};
use extrapolate::pairing;
use tdex_format::RecordingReader;

pub fn run(plan: &PairPlan) -> Result<()> {
    let reader = RecordingReader::open(&plan.file)?;
    let last = reader.info().recorded_periods;
    // the starts a recurrence path can jump to: t0 … t_{P−1}, each paired from the end tP
    // (P = 1: t1 to t0, the paper's pairing)
    let end = snapshot(&reader, last)?;
    let mut json = Vec::new();
    for start in 0..last {
        let start = snapshot(&reader, start)?;
        let mut stored = crate::with_workers(plan.threads, || Ok(compute(&start, &end)?))?;
        let measured = stored.summary.clone();
        if plan.reproducible {
            stored.summary = stored.summary.reproducible();
        }
        let path = store(&reader, end.index, start.index, &stored)?;
        let s = &measured;
        // replaying one period applies g again and again: each particle only ever plays the
        // roles of its own cycle
        let cycles = pairing::cycle_structure(&stored.g);
        let short_share = cycles.short_share(stored.g.len());
        if plan.json {
            let mut one = serde_json::to_value(s)?;
            one["pairing_file"] = path.display().to_string().into();
            one["cycles"] = serde_json::to_value(&cycles)?;
            one["cycles"]["short_cycle_periods"] = pairing::SHORT_CYCLE.into();
            one["cycles"]["short_share"] = short_share.into();
            if last > 1 {
                one["end"] = end.index.into();
                one["start"] = start.index.into();
            }
            json.push(one);
            continue;
        }
        if last > 1 {
            println!("t{} to t{}", end.index, start.index);
        }
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
    match &json[..] {
        [] => {}
        // one recorded period: the one object, as before several existed
        [one] => println!("{}", serde_json::to_string_pretty(one)?),
        all => println!("{}", serde_json::to_string_pretty(all)?),
    }
    Ok(())
}
