//! `tdex pair`: the pairing of a recording's `t1` snapshot to `t0` (or, for several recorded
//! periods, of `tP` to the start of each period), stored beside it for reuse by
//! `tdex extrapolate` (`RECORDING.pairing.json`, `RECORDING.pairing.t<end>-t<start>.json`,
//! [`extrapolate::cache`]), told on the terminal; with `--mirror`, also the pairing to each
//! start's mirror image (`RECORDING.pairing.t<end>-mirror-t<start>.json`) and the mirror check.

use crate::cli::PairPlan;
use anyhow::Result;
use extrapolate::cache::{compute, snapshot, start_image, store_image};
use extrapolate::pairing;
use extrapolate::{ExtrapolateError, MirrorCheck};
use std::path::PathBuf;
use tdex_format::extrapolation::Symmetry;
use tdex_format::sidecar::{PairingSummary, StoredPairing};
use tdex_format::{RecordingReader, Snapshot};

/// One pairing computed and stored: its summary as measured (with the time, whatever
/// `--reproducible` kept in the file), its permutation and where it was stored.
struct Paired {
    measured: PairingSummary,
    stored: StoredPairing,
    path: PathBuf,
}

pub fn run(plan: &PairPlan) -> Result<()> {
    let reader = RecordingReader::open(&plan.file)?;
    if plan.mirror && !extrapolate::has_mirror_image(reader.info()) {
        return Err(ExtrapolateError::NoMirrorImage {
            recording: plan.file.clone(),
        }
        .into());
    }
    let last = reader.info().recorded_periods;
    // the starts a recurrence path can jump to: t0 … t_{P−1}, each paired from the end tP
    // (P = 1: t1 to t0, the paper's pairing)
    let end = snapshot(&reader, last)?;
    let mut json = Vec::new();
    let mut checks = Vec::new();
    for start in 0..last {
        let start = snapshot(&reader, start)?;
        let plain = pair(plan, &reader, &start, &end, Symmetry::None)?;
        // the mirror pairing and its check travel together: the check is of this start
        let mirror = if plan.mirror {
            let mirrored = pair(plan, &reader, &start, &end, Symmetry::AxialMirror)?;
            let check =
                MirrorCheck::of(end.index, start.index, &plain.measured, &mirrored.measured);
            checks.push(check);
            Some((mirrored, check))
        } else {
            None
        };
        if plan.json {
            let mut one = as_json(&plain)?;
            if last > 1 {
                one["end"] = end.index.into();
                one["start"] = start.index.into();
            }
            if let Some((mirrored, check)) = &mirror {
                one["mirror"] = as_json(mirrored)?;
                one["mirror_check"] = serde_json::to_value(check)?;
            }
            json.push(one);
            continue;
        }
        if last > 1 {
            println!("t{} to t{}", end.index, start.index);
        }
        tell(&plain, "pairing");
        if let Some((mirrored, _)) = &mirror {
            tell(mirrored, "mirror image");
        }
    }
    // the verdict is on the path, which jumps to every start alike: after all of them
    if !plan.json {
        for line in crate::extrapolation::mirror_check_lines(&checks) {
            println!("mirror check  {line}");
        }
    }
    match &json[..] {
        [] => {}
        // one recorded period: the one object, as before several existed
        [one] => println!("{}", serde_json::to_string_pretty(one)?),
        all => println!("{}", serde_json::to_string_pretty(all)?),
    }
    Ok(())
}

/// The pairing of `end` to the image of `start` under `symmetry`, computed and stored.
fn pair(
    plan: &PairPlan,
    reader: &RecordingReader,
    start: &Snapshot,
    end: &Snapshot,
    symmetry: Symmetry,
) -> Result<Paired> {
    let image = start_image(start, symmetry);
    let period = extrapolate::axial_period(reader.info());
    let mut stored = crate::with_workers(plan.threads, || Ok(compute(&image, end, period)?))?;
    let measured = stored.summary.clone();
    if plan.reproducible {
        stored.summary = stored.summary.reproducible();
    }
    let path = store_image(reader, end.index, start.index, symmetry, &stored)?;
    Ok(Paired {
        measured,
        stored,
        path,
    })
}

/// The summary, the pairing's file and its cycles, as one JSON object.
fn as_json(p: &Paired) -> Result<serde_json::Value> {
    // replaying one period applies g again and again: each particle only ever plays the
    // roles of its own cycle
    let cycles = pairing::cycle_structure(&p.stored.g);
    let mut one = serde_json::to_value(&p.measured)?;
    one["pairing_file"] = p.path.display().to_string().into();
    one["cycles"] = serde_json::to_value(&cycles)?;
    one["cycles"]["short_cycle_periods"] = pairing::SHORT_CYCLE.into();
    one["cycles"]["short_share"] = cycles.short_share(p.stored.g.len()).into();
    Ok(one)
}

/// The pairing, its cycles and its time in plain words; `what` names it on the first line.
fn tell(p: &Paired, what: &str) {
    let s = &p.measured;
    let cycles = pairing::cycle_structure(&p.stored.g);
    // a bed of several sizes is paired one size class at a time
    let classes = match s.size_classes {
        Some(k) if k > 1 => format!(" within {k} size classes"),
        _ => String::new(),
    };
    println!(
        "{what:<13} {} particles{classes}, total distance {} diameters (mean {}), k = {}, {} solve round(s), {}",
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
        crate::fmt::sig(100.0 * cycles.short_share(p.stored.g.len()), 3),
        pairing::SHORT_CYCLE,
        cycles.longest
    );
    println!(
        "time          {:.3} s on {} threads; stored in {}",
        s.seconds.unwrap_or_default(),
        s.threads.unwrap_or_default(),
        p.path.display()
    );
}
