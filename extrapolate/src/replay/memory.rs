//! What an extrapolation needs in memory (by layout), and whether its table is held in memory or streamed from the recording period after period.
//!
//! The figures are upper bounds from the sizes of the arrays the replay holds, not
//! measurements; docs/reliability.md compares them with measured peaks. The recording itself
//! is memory-mapped: its pages are the page cache's, dropped under memory pressure, and are
//! not counted.

use super::table::{Exchange, StartRun};
use super::ReplayError;
use tdex_format::table::BATCH_ROWS;
use tdex_format::CollisionRow;

/// One row of the table held in memory (an [`Exchange`]: two ids and `H·m`). The runs of
/// equal start steps the synchronous scheme needs (8 B each, at most one per time step of a
/// period: under 0.4 MB for the 50 000-step period of `long_kiln`, against 1.5 GB of rows)
/// are not counted apart: the buffers' margins cover them.
pub const ROW_BYTES: u64 = std::mem::size_of::<Exchange>() as u64;

/// One snapshot point decoded: id (4), position (24), radius (8), temperature (8), velocity
/// (24); also the size of an encoded point (`POINT_STRIDE`).
const POINT_BYTES: u64 = 68;

/// Per particle, whatever the table: the `t0` and `t1` snapshots (2 points), the role
/// temperatures beside their `1/C` and the temperatures' next copy (16 + 8), the output's
/// ids and their next copy (8), the capacities (8), the pairing and its stored JSON text
/// (16), the synchronous scheme's deltas (8), and one snapshot in transit: encoded, then in
/// the writer's chunk (or, when read, a decompressed chunk and its message copy): 3 points.
pub const PARTICLE_BYTES: u64 = 2 * POINT_BYTES + 24 + 8 + 8 + 16 + 8 + 3 * POINT_BYTES;

/// Per particle and per recorded period of a recurrence path (`P' > 1`): the `P' − 1` end
/// snapshots beyond `t1`, whose positions, radii and velocities the output carries, and the
/// output's own copy of one (the paper's method writes `t1` itself).
pub const PERIOD_BYTES: u64 = POINT_BYTES;

/// Per particle and per pairing beyond the first (a recurrence path jumping to several
/// starts): its `g`, held for the whole replay.
pub const EXTRA_PAIRING_BYTES: u64 = 4;

/// Candidates per particle the pairing may hold: 24 at first, doubled once when they admit
/// no perfect matching (`PairingOptions::k_initial`).
const PAIRING_K: u64 = 48;

/// Per particle, while the pairing is computed (nothing when a stored one is reused): both
/// position sets in Morton order (48) and their orders (16), the candidate lists and the
/// solver's graph (`2 · k · (4 + 8)`), and the search trees, duals and certificate (200).
pub const PAIRING_BYTES: u64 = 48 + 16 + 2 * PAIRING_K * 12 + 200;

/// The process and the output writer: code, thread stacks and allocator (4 MiB peak for
/// `tdex --version`, 8 MiB with margin), the writer's chunk of up to 8 MiB and its zstd
/// state (4 MiB).
pub const BASE_BYTES: u64 = 20 << 20;

/// Decoding one batch: its protobuf columns (at most 32 bytes a row), the decoded rows and
/// their [`Exchange`]s (and at most one run of equal starts per row).
const BATCH_BYTES: u64 = BATCH_ROWS as u64
    * (32
        + std::mem::size_of::<CollisionRow>() as u64
        + ROW_BYTES
        + std::mem::size_of::<StartRun>() as u64);

/// The parts of an extrapolation's memory, in bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct MemoryNeeds {
    pub particles: u64,
    pub rows: u64,
    /// Per-particle state ([`PARTICLE_BYTES`] each, and [`PERIOD_BYTES`] and
    /// [`EXTRA_PAIRING_BYTES`] for each further recorded period and pairing of a path).
    pub particle_bytes: u64,
    /// Computing the pairing; 0 when a stored pairing is reused.
    pub pairing_bytes: u64,
    /// The whole table in memory: `rows × 16 B`.
    pub table_bytes: u64,
    /// Reading the table: the largest decompressed chunk twice (the chunk and its
    /// messages) and one decoded batch; the process and the writer ([`BASE_BYTES`]).
    pub buffer_bytes: u64,
}

impl MemoryNeeds {
    /// The needs of replaying `rows` rows over `particles` particles from a recording whose
    /// largest table chunk is `largest_chunk` bytes uncompressed, through `pairings`
    /// pairings (all stored: `pairing_reused`) and the end snapshots of `recorded_periods`
    /// periods (1 and 1 for the paper's method).
    pub fn estimate(
        particles: u64,
        rows: u64,
        largest_chunk: u64,
        pairing_reused: bool,
        recorded_periods: u32,
        pairings: usize,
    ) -> Self {
        let per_particle = PARTICLE_BYTES
            + if recorded_periods > 1 {
                u64::from(recorded_periods) * PERIOD_BYTES
            } else {
                0
            }
            + (pairings.saturating_sub(1) as u64) * EXTRA_PAIRING_BYTES;
        Self {
            particles,
            rows,
            particle_bytes: particles.saturating_mul(per_particle),
            pairing_bytes: if pairing_reused {
                0
            } else {
                particles.saturating_mul(PAIRING_BYTES)
            },
            table_bytes: rows.saturating_mul(ROW_BYTES),
            buffer_bytes: BASE_BYTES + 2 * largest_chunk + BATCH_BYTES,
        }
    }

    /// Peak with the table in memory. The pairing's arrays are freed before the table is
    /// read, so the peak is the larger of the two phases.
    pub fn in_memory(&self) -> u64 {
        self.particle_bytes.saturating_add(
            self.pairing_bytes
                .max(self.table_bytes.saturating_add(self.buffer_bytes)),
        )
    }

    /// Peak with the table streamed from the file every period.
    pub fn streamed(&self) -> u64 {
        self.particle_bytes
            .saturating_add(self.pairing_bytes.max(self.buffer_bytes))
    }
}

/// Where the replay reads the table from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableMode {
    /// Decoded once, kept in memory.
    InMemory,
    /// Decoded from the recording batch by batch, every period.
    Streamed,
}

/// Why the table is where it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModeReason {
    /// The whole replay fits the limit with the table in memory.
    Fits,
    /// The table would not fit the limit.
    TooLarge,
    /// Asked for (`--stream`).
    Requested,
}

/// The decision and the figures behind it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MemoryPlan {
    pub needs: MemoryNeeds,
    pub limit: u64,
    pub mode: TableMode,
    pub reason: ModeReason,
}

impl MemoryPlan {
    /// The table in memory if the whole replay fits `limit` bytes (and streaming was not
    /// asked for), else streamed; refused when even the streamed replay does not fit.
    /// `limit_source` says where the limit came from, for the refusal.
    pub fn choose(
        needs: MemoryNeeds,
        limit: u64,
        limit_source: &str,
        force_stream: bool,
    ) -> Result<Self, ReplayError> {
        if needs.streamed() > limit {
            return Err(ReplayError::Memory {
                particles: needs.particles,
                needed: needs.streamed(),
                particle_bytes: needs.particle_bytes,
                pairing_bytes: needs.pairing_bytes,
                buffer_bytes: needs.buffer_bytes,
                limit,
                limit_source: limit_source.to_string(),
            });
        }
        let (mode, reason) = if force_stream {
            (TableMode::Streamed, ModeReason::Requested)
        } else if needs.in_memory() <= limit {
            (TableMode::InMemory, ModeReason::Fits)
        } else {
            (TableMode::Streamed, ModeReason::TooLarge)
        };
        Ok(Self {
            needs,
            limit,
            mode,
            reason,
        })
    }

    /// The peak of the chosen mode.
    pub fn needed(&self) -> u64 {
        match self.mode {
            TableMode::InMemory => self.needs.in_memory(),
            TableMode::Streamed => self.needs.streamed(),
        }
    }
}

/// Bytes for people: `512 B`, `3.1 KiB`, `24.0 MiB`, `3.10 GiB` (powers of 1024, as
/// `--max-memory` reads them).
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["KiB", "MiB", "GiB", "TiB", "PiB"];
    if bytes < 1024 {
        return format!("{bytes} B");
    }
    let mut value = bytes as f64 / 1024.0;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    let digits = if value < 10.0 { 2 } else { 1 };
    format!("{value:.digits$} {}", UNITS[unit])
}

#[cfg(test)]
mod tests {
    use super::*;

    const MIB: u64 = 1 << 20;

    #[test]
    fn a_table_that_fits_stays_in_memory_and_one_that_does_not_is_streamed() {
        // 10 000 particles, 10 million rows (153 MiB of table), 8 MiB chunks
        let needs = MemoryNeeds::estimate(10_000, 10_000_000, 8 * MIB, false, 1, 1);
        assert_eq!(needs.table_bytes, 160_000_000);
        assert!(needs.in_memory() > needs.table_bytes);
        assert!(needs.streamed() < 100 * MIB, "{}", needs.streamed());

        let roomy = MemoryPlan::choose(needs, 4096 * MIB, "test", false).unwrap();
        assert_eq!(
            (roomy.mode, roomy.reason),
            (TableMode::InMemory, ModeReason::Fits)
        );
        assert_eq!(roomy.needed(), needs.in_memory());

        let tight = MemoryPlan::choose(needs, 150 * MIB, "test", false).unwrap();
        assert_eq!(
            (tight.mode, tight.reason),
            (TableMode::Streamed, ModeReason::TooLarge)
        );
        assert!(tight.needed() <= 150 * MIB);

        // exactly at the limit still fits
        let edge = MemoryPlan::choose(needs, needs.in_memory(), "test", false).unwrap();
        assert_eq!(edge.mode, TableMode::InMemory);
        let edge = MemoryPlan::choose(needs, needs.in_memory() - 1, "test", false).unwrap();
        assert_eq!(edge.mode, TableMode::Streamed);

        let asked = MemoryPlan::choose(needs, 4096 * MIB, "test", true).unwrap();
        assert_eq!(
            (asked.mode, asked.reason),
            (TableMode::Streamed, ModeReason::Requested)
        );
    }

    #[test]
    fn a_limit_below_the_streamed_needs_is_refused_with_the_numbers() {
        let needs = MemoryNeeds::estimate(1_000_000, 5_000_000, 8 * MIB, false, 1, 1);
        let err = MemoryPlan::choose(needs, needs.streamed() - 1, "--max-memory", false)
            .unwrap_err()
            .to_string();
        for part in [
            "1000000 particles",
            &human_bytes(needs.streamed()),
            &human_bytes(needs.streamed() - 1),
            "--max-memory",
        ] {
            assert!(err.contains(part), "missing '{part}': {err}");
        }
        // a stored pairing lowers the need below the pairing's peak
        let reused = MemoryNeeds::estimate(1_000_000, 5_000_000, 8 * MIB, true, 1, 1);
        assert!(reused.streamed() < needs.streamed());
        assert!(MemoryPlan::choose(reused, needs.streamed() - 1, "x", false).is_ok());
    }

    #[test]
    fn the_figures_add_up_by_layout() {
        assert_eq!(ROW_BYTES, 16);
        let needs = MemoryNeeds::estimate(1000, 0, 0, true, 1, 1);
        assert_eq!(needs.particle_bytes, 1000 * PARTICLE_BYTES);
        // a path through 4 recorded periods holding 3 pairings: t2, t3, t4 and the output's
        // copy, 2 more g
        let path = MemoryNeeds::estimate(1000, 0, 0, true, 4, 3);
        assert_eq!(
            path.particle_bytes,
            1000 * (PARTICLE_BYTES + 4 * PERIOD_BYTES + 2 * EXTRA_PAIRING_BYTES)
        );
        assert_eq!(needs.in_memory(), needs.streamed());
        assert_eq!(human_bytes(512), "512 B");
        assert_eq!(human_bytes(3 << 30), "3.00 GiB");
        assert_eq!(human_bytes(24 * MIB + MIB / 2), "24.5 MiB");
    }
}
