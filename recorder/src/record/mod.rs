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

pub use tdex_format::CollisionRow;
