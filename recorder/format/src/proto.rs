//! Rust types of the recording's protobuf schemas (`recorder/proto/`), generated at build time.

#![allow(clippy::all, missing_docs)]

/// Foxglove's well-known schemas used by tdex (snapshots as `foxglove.PointCloud`).
pub mod foxglove {
    include!(concat!(env!("OUT_DIR"), "/foxglove.rs"));
}

/// tdex's own schemas.
pub mod tdex {
    include!(concat!(env!("OUT_DIR"), "/tdex.rs"));
}

/// Binary FileDescriptorSet of `foxglove.PointCloud` and its imports (MCAP schema data).
pub const POINT_CLOUD_DESCRIPTOR: &[u8] =
    include_bytes!(concat!(env!("OUT_DIR"), "/point_cloud.fds"));
/// Binary FileDescriptorSet of `tdex.CollisionBatch`.
pub const COLLISION_BATCH_DESCRIPTOR: &[u8] =
    include_bytes!(concat!(env!("OUT_DIR"), "/collision_batch.fds"));
