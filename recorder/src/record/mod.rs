//! The sampled collision table (Haydar §2.1.1): a sampler fed every `n` DEM steps and the
//! splitter that cuts collisions longer than `Δt_c^max` into rows (Algorithm 2).

pub mod checkpoint;
pub mod journal;
pub mod recording;
pub mod sampler;
pub mod splitter;

pub use checkpoint::{Checkpoint, CheckpointError, Stage};
pub use journal::JournalError;
pub use recording::{
    checkpoint_path, journal_path, record, record_from_t0, record_many_from_t0, record_run, resume,
    run_to_t0, twin_of, Phase, RecordError, RecordJob, RecordOptions, RecordRun,
};
pub use sampler::ContactSampler;

/// One row of the collision table, times in DEM steps from the recording's origin.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
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
