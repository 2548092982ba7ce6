//! `tdex compare`: opens the two files the way round the user gave them, runs the library's
//! comparison ([`tdex::compare`]) and prints it as a table, JSON or CSV.

use crate::cli::{ComparePlan, UsageError};
use anyhow::Result;
use tdex::compare::{self, CompareError, Second};
use tdex_format::{ExtrapolationReader, FormatError, RecordingReader};

pub fn run(plan: &ComparePlan) -> Result<()> {
    let recording = match RecordingReader::open(&plan.recording) {
        Ok(r) => r,
        // an extrapolation given first: the arguments are the wrong way round
        Err(FormatError::NotRecording { .. })
            if ExtrapolationReader::open(&plan.recording).is_ok() =>
        {
            return Err(UsageError(format!(
                "{} is not a tdex recording but an extrapolation: the arguments are the \
                 wrong way round, the recording comes first (tdex compare RUN.mcap EXTRA.mcap)",
                plan.recording.display()
            ))
            .into());
        }
        Err(e) => return Err(e.into()),
    };
    // A file without recording metadata is read as an extrapolation, whose reader then
    // names what is missing; any other fault of a recording is reported as it is.
    let dem_runs = compare::open_dem_runs(&plan.dem_runs)?;
    let dem_runs: Vec<&RecordingReader> = dem_runs.iter().collect();
    let c = match RecordingReader::open(&plan.extrapolation) {
        Ok(dem) => compare::compare_runs(
            &recording,
            Second::Dem(&dem),
            &dem_runs,
            plan.cells,
            plan.seed,
        ),
        Err(FormatError::NotRecording { .. }) => {
            let extrapolation = ExtrapolationReader::open(&plan.extrapolation)?;
            compare::compare_runs(
                &recording,
                Second::Extrapolation(&extrapolation),
                &dem_runs,
                plan.cells,
                plan.seed,
            )
        }
        Err(e) => return Err(e.into()),
    }
    .map_err(advice)?;
    if plan.json {
        println!("{}", serde_json::to_string_pretty(&c)?);
    } else if plan.csv {
        print!("{}", compare::csv(&c));
    } else {
        print!("{}", compare::table(&c));
    }
    Ok(())
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
