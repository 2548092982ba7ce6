//! What a recording is asked for: its options, the run that writes it (case, destination,
//! checkpoint interval) and the phases its progress reports name.

use crate::case::Case;
use std::path::Path;
use tdex_format::AreaEncoding;

/// What to record, validated by the caller (the CLI plan).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RecordOptions {
    /// Sampling factor `n` (steps).
    pub sample_every: u32,
    /// `Δt_c^max` in steps, a positive multiple of `n`.
    pub dtc_max_steps: u32,
    /// `τ` in steps, a positive multiple of `n`.
    pub period_steps: u64,
    /// Reference periods after `t1`.
    pub reference_periods: u32,
    /// DEM twins: further runs continued from the state at `t1` over the reference periods,
    /// twin `m` with the drum's angular velocity changed by `m` units in the last place.
    pub twins: u32,
    /// Consecutive periods recorded from `t0` (`P`, 1 to [`tdex_format::MAX_RECORDED_PERIODS`]):
    /// `P` collision tables, one after the other, and the snapshots `t0 … tP`.
    pub recorded_periods: u32,
    /// The recorded snapshot `t_s` the twins part from the run at (1 to `P`, and at most the
    /// reference periods): until there a twin is the run. 1 in checkpoints written before the
    /// field existed.
    #[serde(default = "one")]
    pub twins_from: u32,
    pub area_encoding: AreaEncoding,
}

fn one() -> u32 {
    1
}

impl RecordOptions {
    /// Index of the run's last own snapshot ([`tdex_format::last_snapshot`]).
    pub fn last_snapshot(&self) -> u32 {
        tdex_format::last_snapshot(self.recorded_periods, self.reference_periods)
    }
}

/// The stage a progress report belongs to. A report `(phase, done, total)` counts the steps
/// of the phase; each phase (or its part after a resume) is reported once where it starts,
/// before its first step, then every [`REPORT_EVERY`] steps and at its end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    Settle,
    SpinUp,
    Period,
    Reference,
    /// The reference periods of DEM twin `m` (1-based), continued from `t1`.
    Twin(u32),
}

/// Steps between progress reports, stability checks and checkpoint opportunities outside
/// the recorded period.
pub const REPORT_EVERY: u64 = 500;

/// A `tdex record` run: what to record, where, and how often to checkpoint it.
#[derive(Debug, Clone, Copy)]
pub struct RecordRun<'a> {
    pub case: &'a Case,
    /// The case path as the recording's metadata states it.
    pub case_path: &'a Path,
    /// The case file as given (the recording stores it).
    pub case_toml: &'a str,
    pub options: &'a RecordOptions,
    pub dest: &'a Path,
    /// Wall-clock seconds between checkpoints to [`super::checkpoint_path`]; `None`: no
    /// checkpoints.
    pub checkpoint_every: Option<f64>,
    /// Write the `tdex.costs` record (wall times, threads); without it the file depends only
    /// on the case, its seed and the options, resumed or not.
    pub write_costs: bool,
}

/// One recording of [`super::record_many_from_t0`]: its settings and its file.
#[derive(Debug, Clone)]
pub struct RecordJob<'a> {
    pub options: RecordOptions,
    pub dest: &'a Path,
}
