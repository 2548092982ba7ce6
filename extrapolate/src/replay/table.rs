//! The table in the replay's compact form: each row as its two bodies and the heat it can
//! carry per kelvin, `H·m` (J/K), 16 bytes a row; the rows' start steps only as the runs of
//! equal starts the synchronous scheme applies together.

use tdex_format::{CollisionRow, TableBatch};
use tdex_format::{FormatError, RecordingInfo, RecordingReader, Snapshot};

/// One row ready to apply. The replay streams every row each period, so its speed is the
/// memory bandwidth over this size: no padding, no start step (kept in [`Exchanges`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exchange {
    /// Particle (role) id.
    pub i: u32,
    /// Other particle id, or `particles + wall` for a wall row.
    pub j: u32,
    /// `H · m`: conductance times the row's duration (J/K).
    pub conductance_time: f64,
}

/// A run of consecutive rows that start at the same step (a synchronous group, or part of
/// one when it straddles two batches or exceeds `u32::MAX` rows).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StartRun {
    /// Steps from the period's start.
    pub start_step: u32,
    pub rows: u32,
}

/// Rows in apparition order and the runs of equal start steps they form: a run costs 8
/// bytes, and a period has at most one per time step, against one row per contact and step.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Exchanges {
    rows: Vec<Exchange>,
    runs: Vec<StartRun>,
}

impl Exchanges {
    /// Room for `rows` rows reserved exactly (the memory estimate counts rows × 16 B, not
    /// the up to twice as much of a growing Vec); unreserved if that much cannot be had.
    pub fn with_room_for(rows: u64) -> Self {
        let mut exchanges = Self::default();
        let _ = exchanges
            .rows
            .try_reserve_exact(usize::try_from(rows).unwrap_or(0));
        exchanges
    }

    /// Appends a row that starts `start_step` steps after its period's start.
    pub fn push(&mut self, exchange: Exchange, start_step: u32) {
        self.rows.push(exchange);
        match self.runs.last_mut() {
            Some(run) if run.start_step == start_step && run.rows < u32::MAX => run.rows += 1,
            _ => self.runs.push(StartRun {
                start_step,
                rows: 1,
            }),
        }
    }

    /// Appends a decoded row of a recorded period that starts `offset` steps after `t0`.
    pub fn push_row(&mut self, row: &CollisionRow, info: &RecordingInfo, offset: u64) {
        self.push(Exchange::of(row, info), start_in_period(row, offset));
    }

    pub fn clear(&mut self) {
        self.rows.clear();
        self.runs.clear();
    }

    pub fn len(&self) -> usize {
        self.rows.len()
    }

    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The rows in apparition order.
    pub fn rows(&self) -> &[Exchange] {
        &self.rows
    }

    /// The runs of equal start steps, in order; their rows add up to [`Self::len`].
    pub fn runs(&self) -> &[StartRun] {
        &self.runs
    }
}

/// The row's start counted from the start of its recorded period, `offset` steps after `t0`.
fn start_in_period(row: &CollisionRow, offset: u64) -> u32 {
    row.start_step.wrapping_sub(offset) as u32
}

/// Heat capacities of the particles and temperatures of the conducting walls.
#[derive(Debug, Clone, PartialEq)]
pub struct Bodies {
    /// `C = ρ c (4/3)π r³` of each particle (J/K).
    capacity: Vec<f64>,
    /// `1/C` when it is the same value bit for bit for every particle (a monodisperse bed,
    /// the usual DEM case): the replay's loops then use this constant instead of reading
    /// each role's own.
    uniform_inverse_capacity: Option<f64>,
    /// Fixed temperature of wall `w` (body `particles + w`), `None` if adiabatic.
    wall_temperature: Vec<Option<f64>>,
}

impl Bodies {
    /// Particles of heat capacities `capacity` (J/K) and walls at `wall_temperature` (`None`
    /// if adiabatic).
    pub fn new(capacity: Vec<f64>, wall_temperature: Vec<Option<f64>>) -> Self {
        let first = capacity.first().map(|&c| inverse(c));
        let uniform_inverse_capacity = first.filter(|first| {
            capacity
                .iter()
                .all(|&c| inverse(c).to_bits() == first.to_bits())
        });
        Self {
            capacity,
            uniform_inverse_capacity,
            wall_temperature,
        }
    }

    /// The bodies of a recording, with the particle radii of its `t0` snapshot.
    pub fn of(info: &RecordingInfo, t0: &Snapshot) -> Self {
        let capacity: Vec<f64> = t0
            .radius
            .iter()
            .map(|r| {
                info.density * info.heat_capacity * (4.0 / 3.0) * std::f64::consts::PI * r * r * r
            })
            .collect();
        Self::new(capacity, info.walls.iter().map(|w| w.temperature).collect())
    }

    pub fn particles(&self) -> usize {
        self.capacity.len()
    }

    /// `C` of each particle (J/K).
    pub fn capacity(&self) -> &[f64] {
        &self.capacity
    }

    /// `1/C` of particle `k` (K/J): not stored (the replay keeps it beside each role's
    /// temperature), computed, or the uniform one of a monodisperse bed.
    ///
    /// # Panics
    /// If `k` is not a particle.
    pub fn inverse_capacity(&self, k: usize) -> f64 {
        let capacity = self.capacity[k];
        self.uniform_inverse_capacity
            .unwrap_or_else(|| inverse(capacity))
    }

    /// The one `1/C` of every particle, if they all have the same bits.
    pub fn uniform_inverse_capacity(&self) -> Option<f64> {
        self.uniform_inverse_capacity
    }

    /// Fixed temperature of wall `w` (body `particles + w`), `None` if adiabatic.
    pub fn wall_temperature(&self, w: usize) -> Option<f64> {
        self.wall_temperature[w]
    }

    /// The row's CFL number `c = H m (1/C_k + 1/C_l)` (a wall's capacity is infinite).
    pub fn cfl(&self, e: &Exchange) -> f64 {
        let inverse_l = if (e.j as usize) < self.particles() {
            self.inverse_capacity(e.j as usize)
        } else {
            0.0
        };
        e.conductance_time * (self.inverse_capacity(e.i as usize) + inverse_l)
    }
}

/// `1/C`, computed one way wherever it is needed (the same bits each time).
fn inverse(capacity: f64) -> f64 {
    1.0 / capacity
}

impl Exchange {
    /// A decoded row, with the recording's conduction constants.
    pub fn of(row: &CollisionRow, info: &RecordingInfo) -> Self {
        let conductivity = if row.j >= info.particles {
            info.wall_conductivity
        } else {
            info.pair_conductivity
        };
        Self {
            i: row.i,
            j: row.j,
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
    mut each: impl FnMut(&CollisionRow, Exchange),
) -> Result<TableScan, FormatError> {
    scan_batches(reader.table(), reader.info(), 0, bodies, |r, e, _| {
        each(r, e)
    })
}

/// [`scan`] of the rows of recorded period `period` (1-based) alone. The table of a recording of one period is its whole table, read as [`scan`]
/// reads it.
pub fn scan_period(
    reader: &RecordingReader,
    bodies: &Bodies,
    period: u32,
    mut each: impl FnMut(&CollisionRow, Exchange),
) -> Result<TableScan, FormatError> {
    let (batches, offset) = period_batches(reader, period);
    scan_batches(batches, reader.info(), offset, bodies, |r, e, _| each(r, e))
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

/// The rows of `batches` handed to `each` with their starts counted from the period's own
/// start, `offset` steps after `t0` (a synchronous group never spans two periods), and the
/// worst CFL row among them.
fn scan_batches(
    batches: impl Iterator<Item = Result<TableBatch, FormatError>>,
    info: &RecordingInfo,
    offset: u64,
    bodies: &Bodies,
    mut each: impl FnMut(&CollisionRow, Exchange, u32),
) -> Result<TableScan, FormatError> {
    let mut found = TableScan::default();
    for batch in batches {
        let batch = batch?;
        for (k, r) in batch.rows.iter().enumerate() {
            let e = Exchange::of(r, info);
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
            each(r, e, start_in_period(r, offset));
        }
        found.rows += batch.rows.len() as u64;
        found.batches += 1;
    }
    Ok(found)
}

/// The whole table decoded once and kept in memory (the replay reads it every period).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    pub exchanges: Exchanges,
}

impl Table {
    /// Decodes the table of a recording (streamed batch by batch from the file), with its
    /// worst CFL row.
    pub fn read(
        reader: &RecordingReader,
        bodies: &Bodies,
    ) -> Result<(Self, Option<CflRow>), FormatError> {
        let mut exchanges = Exchanges::with_room_for(reader.table_rows());
        let found = scan_batches(reader.table(), reader.info(), 0, bodies, |_, e, start| {
            exchanges.push(e, start)
        })?;
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
        let mut exchanges = Exchanges::with_room_for(rows);
        let (batches, offset) = period_batches(reader, period);
        let found = scan_batches(batches, reader.info(), offset, bodies, |_, e, start| {
            exchanges.push(e, start)
        })?;
        Ok((Self { exchanges }, found.worst))
    }
}
