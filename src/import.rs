//! `tdex import liggghts`: a recording from LIGGGHTS dumps, and a summary of what was read.

use crate::cli::ImportPlan;
use crate::inspect::Sampling;
use anyhow::Result;
use recorder::import::ImportError;
use serde::Serialize;
use tdex_format::RecordingReader;

/// `tdex import liggghts --json` (keys documented in docs/user-guide.md).
#[derive(Debug, Serialize)]
struct ImportSummary {
    output: String,
    case: String,
    #[serde(flatten)]
    sampling: Sampling,
    step_t0: u64,
    step_t1: u64,
    contact_frames: u64,
    contact_frames_skipped: u64,
    atom_frames_skipped: u64,
    /// Wall contact frames sampled (`null` for adiabatic walls).
    wall_frames: Option<u64>,
    /// Particle samples that touched the mantle through several of its facets, merged.
    wall_contacts_merged: u64,
    rows: u64,
    file_bytes: u64,
    table_bytes: u64,
    bytes_per_row: f64,
}

pub fn run(plan: &ImportPlan) -> Result<()> {
    let report = recorder::import::liggghts::import(
        &plan.case,
        &plan.case_path,
        &plan.case_toml,
        &plan.dumps,
        &plan.options,
        &plan.output,
    )
    .map_err(|e| {
        let advice = match e {
            ImportError::NoAtomDumpAtT1 { .. } => " (give --tau / --tau-rev for the period dumped)",
            ImportError::HeatedMantleWithoutWallDumps { .. } => {
                " (give --wall-contacts with the dumps of `compute wall/gran/local id contactArea`, \
                 or import with a case without drum.wall_temperature)"
            }
            ImportError::WallDumpsWithoutHeatedMantle { .. } => {
                " (set drum.wall_temperature to the mantle's `temperature` in the deck, or leave \
                 out --wall-contacts)"
            }
            _ => "",
        };
        let (atoms, contacts) = (&plan.dumps.atoms, &plan.dumps.contacts);
        let dumps = match &plan.dumps.walls {
            Some(walls) => format!("{atoms}, {contacts} and {}", walls.pattern),
            None => format!("{atoms} and {contacts}"),
        };
        anyhow::Error::new(e).context(format!("importing the LIGGGHTS dumps {dumps}{advice}"))
    })?;
    let reader = RecordingReader::open(&plan.output)?;
    let summary = ImportSummary {
        output: plan.output.display().to_string(),
        case: plan.case.name.clone(),
        sampling: Sampling::of(reader.info()),
        step_t0: report.step_t0,
        step_t1: report.step_t1,
        contact_frames: report.contact_frames,
        contact_frames_skipped: report.contact_frames_skipped,
        atom_frames_skipped: report.atom_frames_skipped,
        wall_frames: report.wall_frames,
        wall_contacts_merged: report.wall_contacts_merged,
        rows: report.summary.rows,
        file_bytes: reader.file_bytes(),
        table_bytes: reader.table_bytes(),
        bytes_per_row: reader.table_bytes() as f64 / report.summary.rows.max(1) as f64,
    };
    if plan.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
        return Ok(());
    }
    let s = &summary.sampling;
    println!(
        "recording     {} ({} particles, case {})",
        summary.output, s.particles, summary.case
    );
    println!(
        "period        LIGGGHTS timesteps {} → {} (τ = {} s, {} steps of {:e} s); n = {}, Δt_c^max = {} steps",
        summary.step_t0, summary.step_t1, s.tau, s.period_steps, s.dt, s.n, s.dtc_max_steps
    );
    println!(
        "read          {} contact frames sampled ({} passed over), {} reference snapshots ({} atom frames passed over)",
        summary.contact_frames,
        summary.contact_frames_skipped,
        s.reference_periods,
        summary.atom_frames_skipped
    );
    if let Some(frames) = summary.wall_frames {
        println!(
            "mantle        {frames} wall contact frames sampled; {}",
            match summary.wall_contacts_merged {
                0 => "one contact per particle and sample".to_string(),
                m => format!(
                    "{m} particle samples touched the mantle through several facets at once (a \
                     contact a facet, as LIGGGHTS counts them where facets meet at more than \
                     `curvature`): each is one wall row with the facets' summed conductance, as \
                     LIGGGHTS conducted"
                ),
            }
        );
    }
    println!(
        "table         {} rows, {:.2} bytes per row, file {:.1} MB",
        summary.rows,
        summary.bytes_per_row,
        summary.file_bytes as f64 / 1e6
    );
    Ok(())
}
