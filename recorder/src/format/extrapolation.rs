//! The extrapolation file: the extrapolated snapshots at every `t_k`, in the recording's
//! conventions (`foxglove.PointCloud` on `/tdex/snapshots`, sequence = snapshot index).

use super::proto::POINT_CLOUD_DESCRIPTOR;
use super::writer::{
    close_into_place, log_time, open_partial, write_json_metadata, write_message, McapWriter,
};
use super::*;
use std::collections::BTreeMap;
use std::path::Path;

/// Metadata record written first: [`ExtrapolationInfo`] as JSON under `json`.
pub const EXTRAPOLATION_METADATA: &str = "tdex.extrapolation";
/// Metadata record written last: [`ExtrapolationCosts`] as JSON under `json`.
pub const EXTRAPOLATION_COSTS_METADATA: &str = "tdex.extrapolation_costs";

/// How an extrapolation was made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExtrapolationInfo {
    pub format_version: u32,
    pub tool_version: String,
    /// The recording replayed (path as given) and its own info.
    pub recording: String,
    pub recording_info: RecordingInfo,
    pub scheme: String,
    pub periods: u32,
    /// The pairing's summary (see `tdex pair --json`).
    pub pairing: serde_json::Value,
}

/// What the extrapolation cost.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExtrapolationCosts {
    pub seconds_pairing: f64,
    pub pairing_reused: bool,
    pub seconds_read_table: f64,
    pub seconds_replay: f64,
    pub seconds_per_period: f64,
    pub rows_per_second: f64,
    pub rows: u64,
}

pub struct ExtrapolationWriter {
    mcap: Option<McapWriter>,
    partial: PathBuf,
    dest: PathBuf,
    channel: u16,
}

impl ExtrapolationWriter {
    pub fn create(dest: &Path, info: &ExtrapolationInfo) -> Result<Self, FormatError> {
        let (mut mcap, partial) = open_partial(dest)?;
        let mcap_err = |error| FormatError::Mcap {
            path: dest.to_path_buf(),
            error,
        };
        write_json_metadata(&mut mcap, EXTRAPOLATION_METADATA, info).map_err(mcap_err)?;
        let schema = mcap
            .add_schema("foxglove.PointCloud", "protobuf", POINT_CLOUD_DESCRIPTOR)
            .map_err(mcap_err)?;
        let channel = mcap
            .add_channel(schema, SNAPSHOT_TOPIC, "protobuf", &BTreeMap::new())
            .map_err(mcap_err)?;
        Ok(Self {
            mcap: Some(mcap),
            partial,
            dest: dest.to_path_buf(),
            channel,
        })
    }

    pub fn write_snapshot(&mut self, snapshot: &Snapshot) -> Result<(), FormatError> {
        let mcap = self.mcap.as_mut().expect("not finished");
        let result = write_message(
            mcap,
            self.channel,
            snapshot.index,
            log_time(snapshot.time),
            &snapshot.encode(),
        );
        result.map_err(|error| FormatError::Mcap {
            path: self.dest.clone(),
            error,
        })
    }

    pub fn finish(mut self, costs: &ExtrapolationCosts) -> Result<(), FormatError> {
        let mut mcap = self.mcap.take().expect("finished once");
        write_json_metadata(&mut mcap, EXTRAPOLATION_COSTS_METADATA, costs).map_err(|error| {
            FormatError::Mcap {
                path: self.dest.clone(),
                error,
            }
        })?;
        close_into_place(mcap, &self.partial, &self.dest)
    }
}

impl Drop for ExtrapolationWriter {
    /// An unfinished file is removed, never left looking complete.
    fn drop(&mut self) {
        if let Some(mcap) = self.mcap.take() {
            drop(mcap);
            let _ = std::fs::remove_file(&self.partial);
        }
    }
}
