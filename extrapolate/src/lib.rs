//! Pairing of the t0/t1 snapshots and replay of a recorded collision table (docs/method.md §5–6;
//! issue 4): [`pairing`] finds the roles, [`replay`] applies the table period after period,
//! [`sidecar`] stores the pairing beside the recording.

pub mod pairing;
pub mod replay;

pub use tdex_format::sidecar;
