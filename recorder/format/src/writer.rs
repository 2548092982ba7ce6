//! Writes a recording: to a temporary file beside the destination ([`crate::output`]), renamed only by [`RecordingWriter::finish`], so an interrupted run never leaves a file that looks complete.

use super::proto::{COLLISION_BATCH_DESCRIPTOR, POINT_CLOUD_DESCRIPTOR};
use super::table::{self, BATCH_ROWS};
use super::*;
use crate::output::AtomicFile;
use crate::CollisionRow;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Uncompressed chunk size: several batches per chunk, so that zstd finds the rows of a long
/// contact again in the next batch.
const CHUNK_BYTES: u64 = 8 << 20;

pub struct RecordingWriter {
    mcap: Option<McapWriter>,
    info: RecordingInfo,
    dest: PathBuf,
    snapshot_channel: u16,
    /// Channel of twin `m` at `m - 1`.
    twin_channels: Vec<u16>,
    collision_channel: u16,
    pending: Vec<CollisionRow>,
    rows_written: u64,
    batches: u64,
    wall_rows: u64,
    snapshots: u32,
    /// Rows of each recorded period so far (period of the last row pushed last).
    period_rows: Vec<u64>,
}

impl RecordingWriter {
    /// Starts a recording at `dest` (written to a hidden partial file until `finish`).
    pub fn create(dest: &Path, info: RecordingInfo) -> Result<Self, FormatError> {
        let mut mcap = open_partial(dest)?;
        let mcap_err = |e| FormatError::writing(dest, e);
        write_json_metadata(&mut mcap, INFO_METADATA, &info).map_err(mcap_err)?;
        let snapshot_schema = mcap
            .add_schema("foxglove.PointCloud", "protobuf", POINT_CLOUD_DESCRIPTOR)
            .map_err(mcap_err)?;
        let collision_schema = mcap
            .add_schema(
                "tdex.CollisionBatch",
                "protobuf",
                COLLISION_BATCH_DESCRIPTOR,
            )
            .map_err(mcap_err)?;
        let snapshot_channel = mcap
            .add_channel(
                snapshot_schema,
                SNAPSHOT_TOPIC,
                "protobuf",
                &BTreeMap::new(),
            )
            .map_err(mcap_err)?;
        let collision_channel = mcap
            .add_channel(
                collision_schema,
                COLLISION_TOPIC,
                "protobuf",
                &BTreeMap::new(),
            )
            .map_err(mcap_err)?;
        let twin_channels = (1..=info.twins)
            .map(|m| {
                mcap.add_channel(
                    snapshot_schema,
                    &twin_topic(m),
                    "protobuf",
                    &BTreeMap::new(),
                )
                .map_err(mcap_err)
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            mcap: Some(mcap),
            info,
            dest: dest.to_path_buf(),
            snapshot_channel,
            twin_channels,
            collision_channel,
            pending: Vec::with_capacity(BATCH_ROWS),
            rows_written: 0,
            batches: 0,
            wall_rows: 0,
            snapshots: 0,
            period_rows: Vec::new(),
        })
    }

    fn mcap_err(&self, error: mcap::McapError) -> FormatError {
        FormatError::writing(&self.dest, error)
    }

    fn nanos(&self, step: u64) -> u64 {
        log_time(step as f64 * self.info.dt)
    }

    /// Stores a snapshot in its own chunk (the table chunks then hold only table rows).
    pub fn write_snapshot(&mut self, snapshot: &Snapshot) -> Result<(), FormatError> {
        self.snapshots += 1;
        self.write_snapshot_on(self.snapshot_channel, snapshot)
    }

    /// Stores a snapshot of DEM twin `twin` (1-based, at most the info's `twins`).
    pub fn write_twin_snapshot(
        &mut self,
        twin: u32,
        snapshot: &Snapshot,
    ) -> Result<(), FormatError> {
        let channel = *twin
            .checked_sub(1)
            .and_then(|m| self.twin_channels.get(m as usize))
            .expect("twin numbers run from 1 to the recording's twins");
        self.write_snapshot_on(channel, snapshot)
    }

    fn write_snapshot_on(&mut self, channel: u16, snapshot: &Snapshot) -> Result<(), FormatError> {
        let step = self.info.step_t0 + snapshot.index as u64 * self.info.period_steps;
        let time = self.nanos(step);
        let data = snapshot.encode();
        let mcap = self.mcap.as_mut().expect("not finished");
        let result = mcap
            .flush()
            .and_then(|_| write_message(mcap, channel, snapshot.index, time, &data))
            .and_then(|_| mcap.flush());
        result.map_err(|e| self.mcap_err(e))
    }

    /// Appends rows (in apparition order); full batches are encoded and written at once. A
    /// row of a later recorded period than the pending ones first writes them as a batch of
    /// their own: no batch spans two periods, so a reader takes a period's rows batch by batch.
    pub fn push_rows(
        &mut self,
        rows: impl IntoIterator<Item = CollisionRow>,
    ) -> Result<(), FormatError> {
        for row in rows {
            let period = self.info.period_of_step(row.start_step) as usize;
            if period + 1 != self.period_rows.len() {
                self.write_batch()?;
                if self.period_rows.len() <= period {
                    self.period_rows.resize(period + 1, 0);
                }
            }
            self.period_rows[period] += 1;
            self.wall_rows += (row.j >= self.info.particles) as u64;
            self.pending.push(row);
            if self.pending.len() == BATCH_ROWS {
                self.write_batch()?;
            }
        }
        Ok(())
    }

    fn write_batch(&mut self) -> Result<(), FormatError> {
        if self.pending.is_empty() {
            return Ok(());
        }
        let data = table::encode(
            self.rows_written,
            &self.pending,
            self.info.area_encoding,
            self.info.sqrt_area_unit,
        );
        let time = self.nanos(self.info.step_t0 + self.pending[0].start_step);
        let mcap = self.mcap.as_mut().expect("not finished");
        let result = write_message(
            mcap,
            self.collision_channel,
            self.batches as u32,
            time,
            &data,
        );
        result.map_err(|e| self.mcap_err(e))?;
        self.rows_written += self.pending.len() as u64;
        self.batches += 1;
        self.pending.clear();
        Ok(())
    }

    /// Rows and batches written so far (pending rows included in `rows`).
    pub fn rows(&self) -> u64 {
        self.rows_written + self.pending.len() as u64
    }

    /// Writes the last batch, the summary (with the collision-duration histogram) and the
    /// costs (if given: without them the file depends only on the run's inputs), ends the
    /// MCAP file and renames it into place.
    pub fn finish(
        mut self,
        duration_histogram: Vec<u64>,
        costs: Option<&RecordingCosts>,
    ) -> Result<RecordingSummary, FormatError> {
        self.write_batch()?;
        let summary = RecordingSummary {
            rows: self.rows_written,
            wall_rows: self.wall_rows,
            batches: self.batches,
            duration_histogram,
            snapshots: self.snapshots,
            period_rows: if self.info.recorded_periods > 1 {
                let mut rows = std::mem::take(&mut self.period_rows);
                rows.resize(self.info.recorded_periods as usize, 0);
                rows
            } else {
                Vec::new()
            },
        };
        let mut mcap = self.mcap.take().expect("finished once");
        let written =
            write_json_metadata(&mut mcap, SUMMARY_METADATA, &summary).and_then(|()| match costs {
                Some(costs) => write_json_metadata(&mut mcap, COSTS_METADATA, costs),
                None => Ok(()),
            });
        if let Err(e) = written {
            abandon(mcap);
            return Err(FormatError::writing(&self.dest, e));
        }
        close_into_place(mcap, &self.dest)?;
        Ok(summary)
    }
}

/// A zstd-chunked MCAP writer on the hidden temporary file of `dest` ([`crate::output`]).
pub(crate) fn open_partial(dest: &Path) -> Result<McapWriter, FormatError> {
    let file = AtomicFile::create(dest)?;
    mcap::WriteOptions::new()
        .profile(PROFILE)
        .library(format!("tdex {}", env!("CARGO_PKG_VERSION")))
        .compression(Some(mcap::Compression::Zstd))
        .chunk_size(Some(CHUNK_BYTES))
        .create(file)
        .map_err(|e| FormatError::writing(dest, e))
}

pub(crate) type McapWriter = mcap::Writer<AtomicFile>;

/// MCAP log (and publish) time of a simulated instant: nanoseconds of simulated time.
pub(crate) fn log_time(seconds: f64) -> u64 {
    (seconds * 1e9).round() as u64
}

/// One message on a known channel, logged at `time` (ns).
pub(crate) fn write_message(
    mcap: &mut McapWriter,
    channel: u16,
    sequence: u32,
    time: u64,
    data: &[u8],
) -> Result<(), mcap::McapError> {
    let header = mcap::records::MessageHeader {
        channel_id: channel,
        sequence,
        log_time: time,
        publish_time: time,
    };
    mcap.write_to_known_channel(&header, data)
}

/// A metadata record holding `value` as JSON under the key `json`.
pub(crate) fn write_json_metadata(
    mcap: &mut McapWriter,
    name: &str,
    value: &impl serde::Serialize,
) -> Result<(), mcap::McapError> {
    let json = serde_json::to_string(value).expect("tdex metadata serialises");
    mcap.write_metadata(&mcap::records::Metadata {
        name: name.into(),
        metadata: BTreeMap::from([("json".to_string(), json)]),
    })
}

/// Ends the MCAP file, fsyncs it, renames it to `dest` and fsyncs the directory.
pub(crate) fn close_into_place(mut mcap: McapWriter, dest: &Path) -> Result<(), FormatError> {
    if let Err(e) = mcap.finish() {
        abandon(mcap);
        return Err(FormatError::writing(dest, e));
    }
    mcap.into_inner().commit()?;
    Ok(())
}

/// Drops an unfinished writer without finishing the MCAP file: its temporary file is removed.
pub(crate) fn abandon(mcap: McapWriter) {
    // into_inner() marks the writer finished, so its own Drop writes nothing more
    drop(mcap.into_inner());
}

impl Drop for RecordingWriter {
    /// An unfinished recording is removed, never left looking complete.
    fn drop(&mut self) {
        if let Some(mcap) = self.mcap.take() {
            abandon(mcap);
        }
    }
}
