//! The file contract of tdex: what a recording, an extrapolation and a pairing sidecar hold
//! and how they are written and read (MCAP and JSON, docs/method.md §4; layout in
//! docs/file-format.md), the collision row they carry, and the atomic outputs every file
//! goes through.
//!
//! This crate is the bottom layer: the engine and recorder (`recorder`), the pairing and
//! replay (`extrapolate`) and the CLI read and write through it, and it depends on none of
//! them (docs/architecture.md).

pub mod extrapolation;
pub mod fuzzing;
mod mcap_file;
pub mod output;
pub mod proto;
pub mod reader;
pub mod sidecar;
pub mod snapshot;
pub mod table;
pub mod writer;

pub use extrapolation::{
    ExtrapolationCosts, ExtrapolationInfo, ExtrapolationReader, ExtrapolationWriter,
};
pub use reader::RecordingReader;
pub use sidecar::{PairingSummary, StoredPairing};
pub use snapshot::{size_classes, Snapshot};
pub use table::TableBatch;
pub use writer::RecordingWriter;

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// MCAP header profile of a tdex recording.
pub const PROFILE: &str = "tdex";
/// Version of the layout below; readers refuse other versions.
pub const FORMAT_VERSION: u32 = 1;
/// Channel of the particle snapshots (`foxglove.PointCloud`).
pub const SNAPSHOT_TOPIC: &str = "/tdex/snapshots";
/// Channel of DEM twin `m`'s snapshots (`foxglove.PointCloud`): `/tdex/twins/<m>`, m ≥ 1.
pub fn twin_topic(twin: u32) -> String {
    format!("/tdex/twins/{twin}")
}
/// Most DEM twins a recording may hold (each costs the reference periods again).
pub const MAX_TWINS: u32 = 16;
/// Most consecutive periods one recording may hold (`--recorded-periods P`).
pub const MAX_RECORDED_PERIODS: u32 = 64;
/// The latest recorded snapshot `t_s` that DEM twins may part from the run at
/// (`--twins-from s`): a twin parts at a recorded snapshot and runs over at least one
/// reference period after it, so s ≤ min(recorded periods, reference periods); without twins
/// nothing parts, and s is 1. Shared by the CLI, the recorder and the reader so that their
/// ranges agree.
pub fn latest_twins_parting(recorded_periods: u32, reference_periods: u32, twins: u32) -> u32 {
    if twins == 0 {
        1
    } else {
        recorded_periods.min(reference_periods).max(1)
    }
}
/// Channel of the collision table (`tdex.CollisionBatch`).
pub const COLLISION_TOPIC: &str = "/tdex/collisions";
/// Metadata record written first: [`RecordingInfo`] as JSON under the key `json`.
pub const INFO_METADATA: &str = "tdex.recording";
/// Metadata record written after the table: [`RecordingSummary`] as JSON under the key `json`.
pub const SUMMARY_METADATA: &str = "tdex.summary";
/// Metadata record written last: [`RecordingCosts`] as JSON under the key `json`. The only
/// part of a recording that depends on the machine and thread count: the file is identical
/// byte for byte up to this record.
pub const COSTS_METADATA: &str = "tdex.costs";
/// Quantisation of `sqrt(a)`: the code range `0..=65535` spans `sqrt(π)·R_max`, the largest
/// value a lens or wall disc can take, so a code fits 16 bits (stored as a varint).
pub const SQRT_AREA_CODES: f64 = 65535.0;

/// How the per-row `sqrt(a)` is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AreaEncoding {
    /// Integer codes of `sqrt(π)·R_max / 65535` m (median relative error 6e-5 on the small
    /// drum, see docs/benchmarks.md).
    Quantized,
    /// `f64` metres, bit-exact (for self-consistency checks; 9.7 instead of 4.0 bytes per row
    /// on the small drum, see docs/benchmarks.md).
    Exact,
}

/// One row of the collision table, times in DEM steps from the recording's origin.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CollisionRow {
    /// Smaller particle id of the pair (fixed ids).
    pub i: u32,
    /// Larger particle id.
    pub j: u32,
    /// First step of the row.
    pub start_step: u64,
    /// Duration `m` in steps: samples × `n`, at most `Δt_c^max`.
    pub duration_steps: u32,
    /// Mean of `sqrt(contact area)` over the row's samples (m).
    pub sqrt_area: f64,
}

/// Which surface of the drum a wall body is (`mantle`, `cap_low`, `cap_high` in the files).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WallKind {
    /// The cylinder, the only wall that can be heated.
    Mantle,
    /// The end cap at the low end of the axis (y < 0).
    CapLow,
    /// The end cap at the high end of the axis.
    CapHigh,
}

impl WallKind {
    /// A drum's walls in their body order: body `particles + w` is `DRUM[w]`.
    pub const DRUM: [WallKind; 3] = [WallKind::Mantle, WallKind::CapLow, WallKind::CapHigh];
}

/// How the extrapolation updates the temperatures of a row's pair (docs/method.md §6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Scheme {
    /// The paper's: rows one after the other, `Q = H (T_k − T_l)` held for `m`.
    Explicit,
    /// Rows one after the other, each relaxing its pair exactly:
    /// `ΔT ← ΔT · exp(−H m (1/C_k + 1/C_l))`; unconditionally stable.
    Exact,
    /// Rows with the same start applied at once from the temperatures before them, as the
    /// DEM updates all contacts of a step together.
    Synchronous,
}

impl Scheme {
    pub const ALL: [Scheme; 3] = [Scheme::Explicit, Scheme::Exact, Scheme::Synchronous];

    /// The scheme's name on the command line and in the files.
    pub fn name(self) -> &'static str {
        match self {
            Scheme::Explicit => "explicit",
            Scheme::Exact => "exact",
            Scheme::Synchronous => "synchronous",
        }
    }
}

/// A wall that can appear in the table as body `particles + index`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WallInfo {
    /// Body id in the table: `particles + wall index`.
    pub id: u32,
    pub kind: WallKind,
    /// Fixed temperature (K) when the wall conducts; `None` for an adiabatic wall.
    pub temperature: Option<f64>,
}

/// Everything about how a recording was made; the first metadata record of the file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordingInfo {
    pub format_version: u32,
    pub tool_version: String,
    /// The case file as given (TOML text) and its path when recorded.
    pub case_toml: String,
    pub case_path: String,
    /// The case as resolved (all defaults filled in).
    pub case_resolved: serde_json::Value,
    pub particles: u32,
    pub walls: Vec<WallInfo>,
    /// DEM time step (s).
    pub dt: f64,
    /// Sampling factor `n` (steps per sample).
    pub sample_every: u32,
    /// `Δt_c^max` in steps.
    pub dtc_max_steps: u32,
    /// `τ` in steps and seconds.
    pub period_steps: u64,
    pub tau: f64,
    /// `t0`: simulated time and step count at the start of the recorded period.
    pub t0: f64,
    pub step_t0: u64,
    /// Reference periods stored after `t1` (`--reference K`).
    pub reference_periods: u32,
    /// DEM twins (`--twins M`): further DEM runs continued from the state at `t1`, each with
    /// the drum's angular velocity changed in its last bits, stored at the same reference
    /// `t_k` on channels [`twin_topic`]. Absent from the JSON when 0, so that a recording
    /// without twins is the same bytes as before twins existed.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub twins: u32,
    /// Consecutive periods recorded (`--recorded-periods P`): `P` collision tables one
    /// after the other in the table (period `p`, 0-based, holds the rows that start in
    /// `[p τ, (p+1) τ)` steps from `t0`, cut at the period boundaries; no batch spans two
    /// periods) and the snapshots `t0 … tP`. Absent from the JSON when 1 (the paper's
    /// method), so that such a recording is the same bytes as before the field existed.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub recorded_periods: u32,
    /// The recorded snapshot `t_s` the DEM twins part from the run at (`--twins-from s`,
    /// 1 ≤ s ≤ P and s ≤ K). Until `t_s` a twin *is* the run, so its snapshots `t2 … t_s`
    /// are the run's, stored again so that every run holds `t2 … t(K+1)`. `s = P` puts the
    /// twins' parting where an extrapolation of all `P` periods starts. Absent from the JSON
    /// when 1 (the twins part at `t1`), so that such a recording is the same bytes as before
    /// the field existed.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub twins_from: u32,
    pub area_encoding: AreaEncoding,
    /// Metres per `sqrt(a)` code (quantised encoding), else 0.
    pub sqrt_area_unit: f64,
    /// `H = pair_conductivity · sqrt(a)` for a particle row (W/K per m).
    pub pair_conductivity: f64,
    /// `H = wall_conductivity · sqrt(a)` for a wall row.
    pub wall_conductivity: f64,
    /// Particle material: `C = density · heat_capacity · (4/3)π r³`.
    pub density: f64,
    pub heat_capacity: f64,
    pub conductivity: f64,
}

impl RecordingInfo {
    /// Simulated time of the snapshot with this index (0: `t0`, 1: `t1`, k: `t0 + kτ`).
    pub fn snapshot_time(&self, index: u32) -> f64 {
        // in f64 (exact below 2^53 steps): a damaged file's step counts cannot overflow
        (self.step_t0 as f64 + index as f64 * self.period_steps as f64) * self.dt
    }

    /// Index of the last snapshot of the run: `tP` or the last reference `t_{K+1}`, whichever
    /// is later (the reference snapshots inside the recorded stretch are its own snapshots).
    pub fn last_snapshot(&self) -> u32 {
        last_snapshot(self.recorded_periods, self.reference_periods)
    }

    /// The recorded period (0-based) a row starting `start_step` steps after `t0` belongs to.
    pub fn period_of_step(&self, start_step: u64) -> u64 {
        start_step / self.period_steps.max(1)
    }

    /// Checks the values the readers and the replay rely on; the error names the field, its
    /// value and what is allowed.
    pub fn check(&self) -> Result<(), String> {
        let bad = |field: &str, value: &dyn std::fmt::Display, allowed: &str| {
            Err(format!("{field} = {value} is not allowed: {allowed}"))
        };
        let bodies = self.particles as u64 + self.walls.len() as u64;
        if self.particles == 0 || bodies > u32::MAX as u64 {
            return bad(
                "particles",
                &self.particles,
                &format!(
                    "must be at least 1, and with the {} walls at most {}",
                    self.walls.len(),
                    u32::MAX
                ),
            );
        }
        for (k, w) in self.walls.iter().enumerate() {
            if w.id as u64 != self.particles as u64 + k as u64 {
                return bad(
                    &format!("walls[{k}].id"),
                    &w.id,
                    "must be particles + the wall's index",
                );
            }
            if w.temperature.is_some_and(|t| !t.is_finite()) {
                return bad(
                    &format!("walls[{k}].temperature"),
                    &w.temperature.unwrap_or_default(),
                    "must be a finite number or absent",
                );
            }
        }
        if self.twins > MAX_TWINS || (self.twins > 0 && self.reference_periods == 0) {
            return bad(
                "twins",
                &self.twins,
                &format!(
                    "must be at most {MAX_TWINS}, and 0 without reference periods (here {})",
                    self.reference_periods
                ),
            );
        }
        let latest_parting =
            latest_twins_parting(self.recorded_periods, self.reference_periods, self.twins);
        if !(1..=latest_parting).contains(&self.twins_from) {
            return bad(
                "twins_from",
                &self.twins_from,
                &format!(
                    "must be between 1 and the recorded periods and the reference periods, \
                     whichever is fewer (here {latest_parting}), and 1 without twins"
                ),
            );
        }
        if !(1..=MAX_RECORDED_PERIODS).contains(&self.recorded_periods) {
            return bad(
                "recorded_periods",
                &self.recorded_periods,
                &format!("must be between 1 and {MAX_RECORDED_PERIODS}"),
            );
        }
        for (field, value) in [
            ("sample_every", self.sample_every as u64),
            ("dtc_max_steps", self.dtc_max_steps as u64),
            ("period_steps", self.period_steps),
        ] {
            if value == 0 {
                return bad(field, &value, "must be at least 1");
            }
        }
        let last_step = (self.last_snapshot() as u64)
            .checked_mul(self.period_steps)
            .and_then(|s| s.checked_add(self.step_t0));
        if last_step.is_none() {
            return bad(
                "step_t0",
                &self.step_t0,
                &format!(
                    "with {} snapshots after t0, {} steps apart, must end before step 2^64",
                    self.last_snapshot(),
                    self.period_steps
                ),
            );
        }
        for (field, value) in [
            ("dt", self.dt),
            ("density", self.density),
            ("heat_capacity", self.heat_capacity),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return bad(field, &value, "must be a finite number > 0");
            }
        }
        for (field, value) in [
            ("pair_conductivity", self.pair_conductivity),
            ("wall_conductivity", self.wall_conductivity),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return bad(field, &value, "must be a finite number >= 0");
            }
        }
        let unit = self.sqrt_area_unit;
        if self.area_encoding == AreaEncoding::Quantized && !(unit.is_finite() && unit > 0.0) {
            return bad(
                "sqrt_area_unit",
                &unit,
                "must be a finite number > 0 with quantized areas",
            );
        }
        Ok(())
    }
}

fn is_zero(x: &u32) -> bool {
    *x == 0
}

/// Index of the last snapshot of a run's own: `tP` (`recorded_periods` = P) or the last
/// reference snapshot `t_{K+1}` (`reference_periods` = K), whichever is later; the run stores
/// `t0` to it, the recorded snapshots counting as references.
pub fn last_snapshot(recorded_periods: u32, reference_periods: u32) -> u32 {
    recorded_periods.max(reference_periods.saturating_add(1))
}

/// Reference periods the run simulates after its recorded ones (from `tP` to `t_{K+1}`;
/// none when the recorded stretch already reaches the last reference snapshot).
pub fn periods_after_recorded(recorded_periods: u32, reference_periods: u32) -> u32 {
    last_snapshot(recorded_periods, reference_periods) - recorded_periods
}

fn one() -> u32 {
    1
}

fn is_one(x: &u32) -> bool {
    *x == 1
}

fn is_zero_f64(x: &f64) -> bool {
    *x == 0.0
}

/// What the recorded period holds; written after the table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordingSummary {
    /// Rows of the table, of which wall rows.
    pub rows: u64,
    pub wall_rows: u64,
    pub batches: u64,
    /// Collisions (before splitting) by sampled length: entry `s` counts the collisions seen
    /// at `s` consecutive samples, i.e. lasting between `(s−1)n+1` and `(s+1)n−1` steps.
    /// Collisions open at `t0` or `t1` count with their length inside the period.
    pub duration_histogram: Vec<u64>,
    /// Snapshots stored (`t0`, `t1`, then one per further recorded or reference period).
    pub snapshots: u32,
    /// Rows of each recorded period, when there are several (absent for one: the paper's
    /// method, whose summary is the same bytes as before).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub period_rows: Vec<u64>,
}

/// What the run cost, for the speedup report; the last metadata record.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct RecordingCosts {
    /// Wall-clock seconds: DEM to `t0`, the recorded period (DEM + recorder), the reference.
    pub seconds_to_t0: f64,
    pub seconds_period: f64,
    pub seconds_reference: f64,
    /// Of `seconds_period`, the time spent sampling, splitting, encoding and writing.
    pub seconds_recorder: f64,
    /// The DEM twins' reference periods, all twins (absent without twins).
    #[serde(default, skip_serializing_if = "is_zero_f64")]
    pub seconds_twins: f64,
    /// Wall-clock seconds of each recorded period, DEM and recorder, when there are several
    /// (their sum is `seconds_period`): what recording `p < P` periods would have cost.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub seconds_each_period: Vec<f64>,
    /// Per-stage DEM seconds over the whole run.
    pub stage_seconds: BTreeMap<String, f64>,
    pub threads: usize,
    /// The vector instructions of the engine's hot loops (`avx512`, `avx2` or `scalar`),
    /// which the times depend on as much as on `threads`; absent in recordings made before
    /// 2026-11-29 and in imported ones.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub vector_instructions: String,
}

/// Whose fault an error is: the input the user gave (a file, a case, a flag: exit code 2)
/// or the run itself (a full disk, a failed write: exit code 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    Input,
    Run,
}

/// The one marker every library error of tdex carries: whose fault it is. Each library
/// crate has a `fault_of` that finds it on any of its error types, which is how the
/// command line chooses its exit code without knowing the types.
pub trait Classify {
    fn fault(&self) -> Fault;

    /// Whether the input the user gave is at fault (exit code 2).
    fn is_bad_input(&self) -> bool {
        self.fault() == Fault::Input
    }
}

/// The fault of `error` if it is an `E`.
pub fn fault_as<E: Classify + std::error::Error + 'static>(
    error: &(dyn std::error::Error + 'static),
) -> Option<Fault> {
    error.downcast_ref::<E>().map(Classify::fault)
}

/// The fault of `error` if it is one of this crate's errors.
pub fn fault_of(error: &(dyn std::error::Error + 'static)) -> Option<Fault> {
    fault_as::<FormatError>(error)
        .or_else(|| fault_as::<output::OutputError>(error))
        .or_else(|| fault_as::<sidecar::SidecarError>(error))
}

/// Why a recording cannot be written or read.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    #[error("{path}: cannot open: {error}")]
    Open {
        path: PathBuf,
        error: std::io::Error,
    },
    /// An I/O error outside [`crate::output`] (outputs report [`FormatError::Output`]).
    #[error("{path}: cannot write: {error}")]
    Write {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{path}: not an MCAP file (it does not start with the MCAP magic bytes)")]
    NotMcap { path: PathBuf },
    #[error("{path}: the MCAP file is truncated or was not finished (no summary section / footer); record it again")]
    Truncated { path: PathBuf },
    #[error("{path}: an MCAP file, but not a tdex {expected}: {detail}")]
    NotRecording {
        path: PathBuf,
        /// `recording` or `extrapolation`.
        expected: &'static str,
        detail: String,
    },
    #[error("{path}: corrupted recording: {detail}")]
    Corrupt { path: PathBuf, detail: String },
    #[error("{path}: MCAP error: {error}")]
    Mcap {
        path: PathBuf,
        error: mcap::McapError,
    },
    /// Writing an output failed (disk full, permission, ...): the reason in plain words.
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
}

impl FormatError {
    /// An error of the MCAP writer on `dest`: an I/O error (disk full, ...) becomes an
    /// [`FormatError::Output`] that says why in plain words.
    pub fn writing(dest: &std::path::Path, error: mcap::McapError) -> Self {
        match error {
            mcap::McapError::Io(e) => {
                FormatError::Output(crate::output::OutputError::writing(dest, e))
            }
            error => FormatError::Mcap {
                path: dest.to_path_buf(),
                error,
            },
        }
    }
}

impl Classify for FormatError {
    /// The input is at fault when the error is in a file the user gave, not in writing one.
    fn fault(&self) -> Fault {
        match self {
            FormatError::Write { .. } | FormatError::Mcap { .. } | FormatError::Output(_) => {
                Fault::Run
            }
            _ => Fault::Input,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::latest_twins_parting;

    #[test]
    fn twins_part_at_most_where_both_the_recording_and_the_reference_reach() {
        assert_eq!(latest_twins_parting(2, 6, 1), 2);
        assert_eq!(latest_twins_parting(3, 2, 2), 2);
        assert_eq!(latest_twins_parting(1, 6, 1), 1);
        // without twins nothing parts, whatever the periods
        assert_eq!(latest_twins_parting(4, 6, 0), 1);
        // no reference periods: no twins either, but never a range that excludes t1
        assert_eq!(latest_twins_parting(2, 0, 1), 1);
    }
}
