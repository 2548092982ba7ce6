//! `tdex compare`: opens the two files the way round the user gave them, runs the library's
//! comparison ([`tdex::compare`]) and prints it as a table, JSON or CSV. With `--draw`, each
//! further (recording, extrapolation) pair of the case is compared the same way, and the
//! pooled verdict over all the draws ([`tdex::compare::draws`]) follows.

use crate::cli::{ComparePlan, UsageError};
use anyhow::Result;
use serde::Serialize;
use std::path::{Path, PathBuf};
use tdex::compare::draws::{self, Draw, Draws};
use tdex::compare::{self, CompareError, Comparison, Second};
use tdex_format::{ExtrapolationReader, FormatError, RecordingReader};

pub fn run(plan: &ComparePlan) -> Result<()> {
    if !plan.draws.is_empty() {
        return run_draws(plan);
    }
    let recording = open_recording(&plan.recording)?;
    let c = judge(&recording, &plan.extrapolation, &plan.dem_runs, plan)?;
    if plan.json {
        println!("{}", serde_json::to_string_pretty(&c)?);
    } else if plan.csv {
        print!("{}", compare::csv(&c));
    } else {
        print!("{}", compare::table(&c));
    }
    Ok(())
}

/// The recording of a pair, refused with advice when it is an extrapolation (the arguments
/// the wrong way round).
fn open_recording(path: &Path) -> Result<RecordingReader> {
    match RecordingReader::open(path) {
        Ok(r) => Ok(r),
        // an extrapolation given first: the arguments are the wrong way round
        Err(FormatError::NotRecording { .. }) if ExtrapolationReader::open(path).is_ok() => {
            Err(UsageError(format!(
                "{} is not a tdex recording but an extrapolation: the arguments are the \
                 wrong way round, the recording comes first (tdex compare RUN.mcap EXTRA.mcap)",
                path.display()
            ))
            .into())
        }
        Err(e) => Err(e.into()),
    }
}

/// Compares `second` (an extrapolation, or a second DEM run's recording) with `recording`'s
/// DEM reference, its twins and the further `dem_runs`.
fn judge(
    recording: &RecordingReader,
    second: &Path,
    dem_runs: &[PathBuf],
    plan: &ComparePlan,
) -> Result<Comparison> {
    // A file without recording metadata is read as an extrapolation, whose reader then
    // names what is missing; any other fault of a recording is reported as it is.
    let dem_runs = compare::open_dem_runs(dem_runs)?;
    let dem_runs: Vec<&RecordingReader> = dem_runs.iter().collect();
    let c = match RecordingReader::open(second) {
        Ok(dem) => compare::compare_runs(
            recording,
            Second::Dem(&dem),
            &dem_runs,
            plan.cells,
            plan.seed,
        ),
        Err(FormatError::NotRecording { .. }) => {
            let extrapolation = ExtrapolationReader::open(second)?;
            compare::compare_runs(
                recording,
                Second::Extrapolation(&extrapolation),
                &dem_runs,
                plan.cells,
                plan.seed,
            )
        }
        Err(e) => return Err(e.into()),
    }
    .map_err(advice)?;
    Ok(c)
}

/// `tdex compare --json` with draws: each pair's comparison as without them, and the pooled
/// verdict.
#[derive(Serialize)]
struct Pooled<'a> {
    comparisons: &'a [Comparison],
    draws: &'a Draws,
}

/// The first pair and every `--draw`, each compared as alone, then the pooled verdict. The
/// recordings are checked first (one case, at least 3 DEM runs each), before any comparison.
fn run_draws(plan: &ComparePlan) -> Result<()> {
    let pairs: Vec<(&PathBuf, &PathBuf)> = std::iter::once((&plan.recording, &plan.extrapolation))
        .chain(plan.draws.iter().map(|(r, x)| (r, x)))
        .collect();
    let recordings = pairs
        .iter()
        .map(|(r, _)| open_recording(r))
        .collect::<Result<Vec<_>>>()?;
    let first = &recordings[0];
    for (rec, (path, _)) in recordings.iter().zip(&pairs) {
        draws::check_same_case(
            (&plan.recording.display().to_string(), first.info()),
            (&path.display().to_string(), rec.info()),
        )?;
        let dem_runs = 1 + rec.info().twins as usize;
        if dem_runs < draws::MIN_DEM_RUNS {
            return Err(CompareError::DrawTooFewRuns {
                recording: path.display().to_string(),
                dem_runs,
            }
            .into());
        }
    }
    let mut comparisons: Vec<Comparison> = Vec::with_capacity(pairs.len());
    for (rec, (_, second)) in recordings.iter().zip(&pairs) {
        let c = judge(rec, second, &[], plan)?;
        if let Some(c0) = comparisons.first() {
            if c.second != c0.second {
                return Err(UsageError(format!(
                    "--draw {} {}: its second file is {} and {}'s is {}; the draws of a pooled \
                     verdict are of one kind",
                    c.recording,
                    c.extrapolation,
                    kind(&c),
                    c0.extrapolation,
                    kind(c0)
                ))
                .into());
            }
        }
        comparisons.push(c);
    }
    let each = comparisons
        .iter()
        .map(Draw::of)
        .collect::<Result<Vec<_>, _>>()?;
    let pooled = Draws::pool(each)?;
    if plan.json {
        let out = Pooled {
            comparisons: &comparisons,
            draws: &pooled,
        };
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    let n = comparisons.len();
    for (i, c) in comparisons.iter().enumerate() {
        println!("draw {} of {n}: {}", i + 1, c.recording);
        print!("{}", compare::table(c));
        println!();
    }
    print!("{}", pooled.table());
    println!("verdict over the draws: {}", pooled.text);
    Ok(())
}

/// What the second file of a comparison is, in words.
fn kind(c: &Comparison) -> &'static str {
    match c.second {
        compare::SecondKind::Extrapolation => "an extrapolation",
        compare::SecondKind::Dem => "a second DEM run",
    }
}

/// The comparison's refusal, with what to do about it where a flag helps.
pub fn advice(e: CompareError) -> anyhow::Error {
    match e {
        CompareError::NoReference { .. } => UsageError(format!(
            "{e}: record it with `--reference K` (K ≥ the periods to compare) to compare an \
             extrapolation"
        ))
        .into(),
        e => e.into(),
    }
}
