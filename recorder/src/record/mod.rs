//! The sampled collision table (Haydar §2.1.1): a sampler fed every `n` DEM steps and the
//! splitter that cuts collisions longer than `Δt_c^max` into rows (Algorithm 2), and the
//! driver that records a run of a case with them.
//!
//! The modules, from the bottom: `options` and `metadata` (what a recording is asked for
//! and what its metadata says), `checkpoint` and `journal` (a run's saved state), `period`
//! (a recorded period's DEM and recorder threads) and `saver` (the checkpoints of a run),
//! and `driver` on top, the only one that knows the order of the stages.

pub mod checkpoint;
mod driver;
mod error;
pub mod journal;
pub(crate) mod metadata;
mod options;
mod period;
pub mod sampler;
mod saver;
pub mod splitter;

pub use checkpoint::{
    checkpoint_path, is_checkpoint, Checkpoint, CheckpointError, Part, Stage, StepsDone,
};
pub use driver::{
    record, record_from_t0, record_many_from_t0, record_run, resume, run_to_t0, twin_of,
};
pub use error::RecordError;
pub use journal::{journal_path, JournalError};
pub use metadata::{Elapsed, RunAtT0};
pub use options::{Phase, RecordJob, RecordOptions, RecordRun, REPORT_EVERY};
pub use sampler::ContactSampler;

pub use tdex_format::CollisionRow;
