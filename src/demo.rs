//! `tdex demo`: the whole method end to end on the built-in small drum — record one
//! revolution with a six-period DEM reference and one DEM twin (the DEM's own spread),
//! extrapolate six periods, compare, report, and say how far to trust the prediction.

use crate::cli::{DemoPlan, RecordPlan, RecordStart, SamplingFlags, Tau};
use crate::{compare, extrapolation, record, report};
use anyhow::Result;
use extrapolate::ExtrapolationRequest;
use tdex_format::{AreaEncoding, ExtrapolationReader, RecordingReader};

/// The built-in case (the same text as `cases/small_drum.toml`).
pub const CASE_TOML: &str = include_str!("../cases/small_drum.toml");
/// Periods extrapolated and simulated by the DEM for reference.
pub const PERIODS: u32 = 6;
/// DEM twins recorded: one second DEM run from t1 measures the DEM's own spread.
pub const TWINS: u32 = 1;

pub fn run(plan: &DemoPlan) -> Result<()> {
    let began = std::time::Instant::now();
    let dir = &plan.output;
    tdex_format::output::create_dir_all(dir)?;
    let case_path = dir.join("small_drum.toml");
    tdex_format::output::write_atomically(&case_path, CASE_TOML.as_bytes())?;
    let (case, case_toml) = recorder::case::load_with_text(&case_path)?;
    let recording = dir.join("run.mcap");
    let extra = dir.join("extra.mcap");
    let report_dir = dir.join("report");
    let sampling = SamplingFlags::default();

    println!(
        "1/4 record    {}: {} particles, one revolution (τ = {} s), n = {}, Δt_c^max = {} steps,\n\
         \x20             then {PERIODS} periods of DEM as the reference and {TWINS} DEM twin from t1",
        case_path.display(),
        case.particles.count,
        case.drum.rotation_period,
        sampling.n,
        sampling.dtc_max
    );
    let mut options = crate::cli::record_options(
        &case,
        Tau::ONE_REVOLUTION,
        sampling,
        PERIODS,
        AreaEncoding::Quantized,
    )?;
    options.twins = TWINS;
    record::run(RecordPlan {
        start: RecordStart::Fresh {
            case_path: case_path.clone(),
            case_toml,
            case: Box::new(case),
            output: recording.clone(),
            options,
            checkpoint_every: None,
            reproducible: false,
        },
        threads: plan.threads,
        json: false,
    })?;

    println!("2/4 extrapolate {PERIODS} periods (pairing, then the explicit replay)");
    let request = ExtrapolationRequest::new(
        recording.clone(),
        PERIODS,
        extra.clone(),
        extrapolation::memory_limit(None),
    );
    let outcome = extrapolation::extrapolate_on(plan.threads, &request, extrapolation::tell)?;
    extrapolation::print(&request, outcome, false)?;

    println!("3/4 compare   against the DEM reference and its twin");
    let rec = RecordingReader::open(&recording)?;
    let ext = ExtrapolationReader::open(&extra)?;
    let comparison = compare::compare(&rec, &ext, compare::DEFAULT_CELLS, compare::DEFAULT_SEED)?;
    print!("{}", compare::table(&comparison));

    println!("4/4 report");
    let files = report::write(&report_dir, &rec, &ext, Some(&comparison))?;
    for f in &files {
        println!("              {}", f.display());
    }
    println!(
        "done: open {} (or report.md beside it)",
        report_dir.join("report.html").display()
    );
    println!("verdict: the extrapolation {}", comparison.verdict.text);
    println!(
        "total time {:.0} s (record, extrapolate, compare and report)",
        began.elapsed().as_secs_f64()
    );
    Ok(())
}
