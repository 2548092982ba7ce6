//! The collision table on the wire: rows grouped into `tdex.CollisionBatch` messages of packed
//! varint columns (about 4 bytes a row after zstd, see docs/benchmarks.md).

use super::proto::tdex::CollisionBatch;
use super::{AreaEncoding, RecordingInfo};
use crate::CollisionRow;
use prost::Message;

/// Rows per batch: large enough that a batch spans more than `Δt_c^max` on the small drums,
/// so zstd sees the rows of a long contact repeat (most of the compression).
pub const BATCH_ROWS: usize = 65_536;

/// Consecutive rows of the table.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TableBatch {
    /// Index of `rows[0]` in the whole table.
    pub first_row: u64,
    pub rows: Vec<CollisionRow>,
}

/// Encodes `rows` (the table from row `first_row` on) as one `tdex.CollisionBatch`.
pub fn encode(first_row: u64, rows: &[CollisionRow], encoding: AreaEncoding, unit: f64) -> Vec<u8> {
    let mut batch = CollisionBatch {
        first_row,
        i: rows.iter().map(|r| r.i).collect(),
        j: rows.iter().map(|r| r.j).collect(),
        start_step: rows.iter().map(|r| r.start_step).collect(),
        duration_steps: rows.iter().map(|r| r.duration_steps).collect(),
        ..Default::default()
    };
    match encoding {
        AreaEncoding::Quantized => {
            batch.sqrt_area_unit = unit;
            batch.sqrt_area_code = rows
                .iter()
                .map(|r| (r.sqrt_area / unit).round() as u32)
                .collect();
        }
        AreaEncoding::Exact => batch.sqrt_area = rows.iter().map(|r| r.sqrt_area).collect(),
    }
    batch.encode_to_vec()
}

/// Decodes one batch and checks it against the recording: equal column lengths, ids in range,
/// durations within `Δt_c^max`, starts inside the period and in apparition order.
pub fn decode(bytes: &[u8], info: &RecordingInfo) -> Result<TableBatch, String> {
    let b = CollisionBatch::decode(bytes).map_err(|e| format!("collision batch: {e}"))?;
    let n = b.i.len();
    let at = b.first_row;
    let (areas, unit) = match info.area_encoding {
        AreaEncoding::Quantized => (b.sqrt_area_code.len(), b.sqrt_area_unit),
        AreaEncoding::Exact => (b.sqrt_area.len(), 0.0),
    };
    if [b.j.len(), b.start_step.len(), b.duration_steps.len(), areas] != [n; 4] {
        return Err(format!(
            "batch at row {at}: columns of unequal length (i {n}, j {}, start_step {}, duration_steps {}, sqrt(a) {areas})",
            b.j.len(),
            b.start_step.len(),
            b.duration_steps.len()
        ));
    }
    if info.area_encoding == AreaEncoding::Quantized && unit != info.sqrt_area_unit {
        return Err(format!(
            "batch at row {at}: sqrt_area_unit {unit} differs from the recording's {}",
            info.sqrt_area_unit
        ));
    }
    let bodies = info.particles.saturating_add(info.walls.len() as u32);
    let mut rows = Vec::with_capacity(n);
    let mut previous_start = 0;
    for r in 0..n {
        let row = CollisionRow {
            i: b.i[r],
            j: b.j[r],
            start_step: b.start_step[r],
            duration_steps: b.duration_steps[r],
            sqrt_area: match info.area_encoding {
                AreaEncoding::Quantized => b.sqrt_area_code[r] as f64 * unit,
                AreaEncoding::Exact => b.sqrt_area[r],
            },
        };
        let bad = |what: String| Err(format!("row {}: {what}", at + r as u64));
        if row.i >= info.particles || row.j >= bodies || row.i >= row.j {
            return bad(format!(
                "bodies ({}, {}) outside 0 ≤ i < j < {bodies} (particles {}, walls {})",
                row.i,
                row.j,
                info.particles,
                info.walls.len()
            ));
        }
        if row.duration_steps == 0 || row.duration_steps > info.dtc_max_steps {
            return bad(format!(
                "duration {} steps outside 1..={} (Δt_c^max)",
                row.duration_steps, info.dtc_max_steps
            ));
        }
        // a row ends inside the recorded period it starts in (rows are cut at the period
        // boundaries), and that period is one of the recording's
        let period = info.period_of_step(row.start_step);
        let period_end = (period + 1).checked_mul(info.period_steps);
        let end = row.start_step.checked_add(row.duration_steps as u64);
        if period >= info.recorded_periods as u64
            || end.zip(period_end).is_none_or(|(end, limit)| end > limit)
            || row.start_step < previous_start
        {
            return bad(format!(
                "start step {} (duration {}) out of apparition order or beyond its recorded period ({} of {} steps)",
                row.start_step, row.duration_steps, info.recorded_periods, info.period_steps
            ));
        }
        if !(row.sqrt_area.is_finite() && row.sqrt_area >= 0.0) {
            return bad(format!(
                "sqrt(a) = {} is not a finite non-negative length",
                row.sqrt_area
            ));
        }
        previous_start = row.start_step;
        rows.push(row);
    }
    Ok(TableBatch {
        first_row: at,
        rows,
    })
}
