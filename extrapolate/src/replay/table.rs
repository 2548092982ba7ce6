//! The table in the replay's compact form: each row as its two bodies, its start and the
//! heat it can carry per kelvin, `H·m` (J/K); 24 bytes a row.

use tdex_format::{CollisionRow, TableBatch};
use tdex_format::{FormatError, RecordingInfo, RecordingReader, Snapshot};

/// One row ready to apply.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exchange {
    /// Particle (role) id.
    pub i: u32,
    /// Other particle id, or `particles + wall` for a wall row.
    pub j: u32,
    pub start_step: u32,
    /// `H · m`: conductance times the row's duration (J/K).
    pub conductance_time: f64,
}

/// Heat capacities of the particles and temperatures of the conducting walls.
#[derive(Debug, Clone, PartialEq)]
pub struct Bodies {
    /// `C = ρ c (4/3)π r³` of each particle (J/K).
    pub capacity: Vec<f64>,
    pub inverse_capacity: Vec<f64>,
    /// Fixed temperature of wall `w` (body `particles + w`), `None` if adiabatic.
    pub wall_temperature: Vec<Option<f64>>,
}

impl Bodies {
    /// The bodies of a recording, with the particle radii of its `t0` snapshot.
    pub fn of(info: &RecordingInfo, t0: &Snapshot) -> Self {
        let capacity: Vec<f64> = t0
            .radius
            .iter()
            .map(|r| {
                info.density * info.heat_capacity * (4.0 / 3.0) * std::f64::consts::PI * r * r * r
            })
            .collect();
        Self {
            inverse_capacity: capacity.iter().map(|c| 1.0 / c).collect(),
            capacity,
            wall_temperature: info.walls.iter().map(|w| w.temperature).collect(),
        }
    }

    pub fn particles(&self) -> usize {
        self.capacity.len()
    }

    /// The row's CFL number `c = H m (1/C_k + 1/C_l)` (a wall's capacity is infinite).
    pub fn cfl(&self, e: &Exchange) -> f64 {
        let inverse_l = self
            .inverse_capacity
            .get(e.j as usize)
            .copied()
            .unwrap_or(0.0);
        e.conductance_time * (self.inverse_capacity[e.i as usize] + inverse_l)
    }
}

impl Exchange {
    /// A decoded row, with the recording's conduction constants.
    pub fn of(row: &CollisionRow, info: &RecordingInfo) -> Self {
        Self::in_period(row, info, 0)
    }

    /// [`Exchange::of`] of a row of a recorded period that starts `offset` steps after
    /// `t0`: its start counted from the period's start.
    pub fn in_period(row: &CollisionRow, info: &RecordingInfo, offset: u64) -> Self {
        let conductivity = if row.j >= info.particles {
            info.wall_conductivity
        } else {
            info.pair_conductivity
        };
        Self {
            i: row.i,
            j: row.j,
            start_step: row.start_step.wrapping_sub(offset) as u32,
            conductance_time: conductivity * row.sqrt_area * row.duration_steps as f64 * info.dt,
        }
    }
}

/// The row with the largest CFL number `c = H m (1/C_k + 1/C_l)`, as a user needs it to
/// change the recording (its ids, duration and area).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct CflRow {
    pub row: u64,
    pub i: u32,
    pub j: u32,
    pub start_step: u64,
    pub duration_steps: u32,
    pub sqrt_area: f64,
    pub cfl: f64,
}

/// What one pass over a table found.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TableScan {
    pub rows: u64,
    pub batches: u64,
    /// The row with the largest CFL number.
    pub worst: Option<CflRow>,
}

/// One pass over the table in the file: hands every row, decoded and as an [`Exchange`],
/// to `each`, and finds the worst CFL row. Memory: one chunk and one batch.
pub fn scan(
    reader: &RecordingReader,
    bodies: &Bodies,
    each: impl FnMut(&CollisionRow, Exchange),
) -> Result<TableScan, FormatError> {
    scan_batches(reader.table(), reader.info(), 0, bodies, each)
}

/// [`scan`] of the rows of recorded period `period` (1-based) alone, their [`Exchange`]
/// starts counted from the period's own start (a synchronous group never spans two
/// periods). The table of a recording of one period is its whole table, read as [`scan`]
/// reads it.
pub fn scan_period(
    reader: &RecordingReader,
    bodies: &Bodies,
    period: u32,
    each: impl FnMut(&CollisionRow, Exchange),
) -> Result<TableScan, FormatError> {
    let (batches, offset) = period_batches(reader, period);
    scan_batches(batches, reader.info(), offset, bodies, each)
}

/// The batches of recorded period `period` (1-based) and the steps from `t0` to its start:
/// the whole table of a recording of one period (as [`scan`] reads it), else
/// [`RecordingReader::period_table`].
pub fn period_batches(
    reader: &RecordingReader,
    period: u32,
) -> (
    Box<dyn Iterator<Item = Result<TableBatch, FormatError>> + '_>,
    u64,
) {
    let info = reader.info();
    if info.recorded_periods == 1 {
        return (Box::new(reader.table()), 0);
    }
    let index = period.saturating_sub(1);
    (
        Box::new(reader.period_table(index)),
        u64::from(index) * info.period_steps,
    )
}

/// The rows of `batches` handed to `each`, their starts moved back by `offset` steps, and
/// the worst CFL row among them.
fn scan_batches(
    batches: impl Iterator<Item = Result<TableBatch, FormatError>>,
    info: &RecordingInfo,
    offset: u64,
    bodies: &Bodies,
    mut each: impl FnMut(&CollisionRow, Exchange),
) -> Result<TableScan, FormatError> {
    let mut found = TableScan::default();
    for batch in batches {
        let batch = batch?;
        for (k, r) in batch.rows.iter().enumerate() {
            let e = Exchange::in_period(r, info, offset);
            let cfl = bodies.cfl(&e);
            if found.worst.is_none_or(|w| cfl > w.cfl) {
                found.worst = Some(CflRow {
                    row: batch.first_row + k as u64,
                    i: r.i,
                    j: r.j,
                    start_step: r.start_step,
                    duration_steps: r.duration_steps,
                    sqrt_area: r.sqrt_area,
                    cfl,
                });
            }
            each(r, e);
        }
        found.rows += batch.rows.len() as u64;
        found.batches += 1;
    }
    Ok(found)
}

/// The whole table decoded once and kept in memory (the replay reads it every period).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    pub exchanges: Vec<Exchange>,
}

impl Table {
    /// Decodes the table of a recording (streamed batch by batch from the file), with its
    /// worst CFL row.
    pub fn read(
        reader: &RecordingReader,
        bodies: &Bodies,
    ) -> Result<(Self, Option<CflRow>), FormatError> {
        // sized once from the recording (the memory estimate counts rows × 24 B, not the
        // up to twice as much of a growing Vec); unreserved if that much cannot be had
        let mut exchanges = Vec::new();
        let _ = exchanges.try_reserve_exact(usize::try_from(reader.table_rows()).unwrap_or(0));
        let found = scan(reader, bodies, |_, e| exchanges.push(e))?;
        Ok((Self { exchanges }, found.worst))
    }

    /// Decodes the rows of recorded period `period` (1-based), `rows` of them
    /// ([`scan_period`]), with their worst CFL row.
    pub fn read_period(
        reader: &RecordingReader,
        bodies: &Bodies,
        period: u32,
        rows: u64,
    ) -> Result<(Self, Option<CflRow>), FormatError> {
        let mut exchanges = Vec::new();
        let _ = exchanges.try_reserve_exact(usize::try_from(rows).unwrap_or(0));
        let found = scan_period(reader, bodies, period, |_, e| exchanges.push(e))?;
        Ok((Self { exchanges }, found.worst))
    }
}
