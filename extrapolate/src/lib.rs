//! Pairing of the t0/t1 snapshots and replay of a recorded collision table (docs/method.md
//! §5–6): [`pairing`] finds the roles, [`replay`] applies the table period after period,
//! [`path`] chooses the recorded period each period replays (several recorded periods),
//! [`sidecar`] stores the pairing beside the recording and [`cache`] reuses it;
//! [`extrapolate_recording`] extrapolates a recording with them.

pub mod boundary;
pub mod cache;
mod driver;
mod error;
pub mod pairing;
pub mod path;
pub mod replay;

pub use driver::{
    axial_period, extrapolate_recording, has_mirror_image, ExtrapolationOutcome,
    ExtrapolationRequest, JumpStarts, Leave, MemoryLimit, MirrorCheck, Notice, TableChoice,
};
pub use error::{fault_of, ExtrapolateError};
/// The pairing sidecar's format lives with the other files in `tdex-format`.
pub use tdex_format::sidecar;
