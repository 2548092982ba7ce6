//! Reads a recording without loading it whole: the file is memory-mapped, the summary section
//! gives the metadata and chunk indexes, and the table is decoded one chunk at a time.

use super::mcap_file::{Bytes, McapFile};
use super::table::{self, TableBatch};
use super::writer::log_time;
use super::*;
use std::path::Path;

/// An open recording.
pub struct RecordingReader {
    file: McapFile,
    info: RecordingInfo,
    run_summary: Option<RecordingSummary>,
    costs: Option<RecordingCosts>,
    snapshot_channel: u16,
    /// Channel of twin `m` at `m - 1`.
    twin_channels: Vec<u16>,
    collision_channel: u16,
}

impl std::fmt::Debug for RecordingReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordingReader")
            .field("path", &self.file.path)
            .finish_non_exhaustive()
    }
}

impl RecordingReader {
    /// Opens `path` and checks that it is a complete tdex recording of a known version.
    pub fn open(path: &Path) -> Result<Self, FormatError> {
        Self::checked(McapFile::open(path, "recording")?)
    }

    /// [`RecordingReader::open`] on the file's bytes already in memory; `path` names the
    /// file in messages.
    pub fn from_bytes(path: &Path, bytes: Vec<u8>) -> Result<Self, FormatError> {
        Self::checked(McapFile::from_bytes(
            path,
            Bytes::Owned(bytes),
            "recording",
        )?)
    }

    fn checked(file: McapFile) -> Result<Self, FormatError> {
        let info: RecordingInfo = file
            .metadata(INFO_METADATA)?
            .ok_or_else(|| file.not_ours(format!("it has no '{INFO_METADATA}' metadata record")))?;
        if info.format_version != FORMAT_VERSION {
            return Err(file.not_ours(format!(
                "format version {} (this tdex reads version {FORMAT_VERSION})",
                info.format_version
            )));
        }
        info.check()
            .map_err(|e| file.corrupt(format!("metadata '{INFO_METADATA}': {e}")))?;
        let run_summary = file.metadata(SUMMARY_METADATA)?;
        let costs = file.metadata(COSTS_METADATA)?;
        let snapshot_channel = file.channel(SNAPSHOT_TOPIC, "foxglove.PointCloud")?;
        let collision_channel = file.channel(COLLISION_TOPIC, "tdex.CollisionBatch")?;
        let twin_channels = (1..=info.twins)
            .map(|m| file.channel(&twin_topic(m), "foxglove.PointCloud"))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            twin_channels,
            file,
            info,
            run_summary,
            costs,
            snapshot_channel,
            collision_channel,
        })
    }

    pub fn path(&self) -> &Path {
        &self.file.path
    }

    pub fn info(&self) -> &RecordingInfo {
        &self.info
    }

    /// The run's measurements (absent only if the writer was interrupted after the table).
    pub fn summary(&self) -> Option<&RecordingSummary> {
        self.run_summary.as_ref()
    }

    /// What the recording run cost (timings and threads).
    pub fn costs(&self) -> Option<&RecordingCosts> {
        self.costs.as_ref()
    }

    /// File size in bytes.
    pub fn file_bytes(&self) -> u64 {
        self.file.bytes.len() as u64
    }

    /// Bytes of the chunks holding the table (compressed, with their message indexes).
    pub fn table_bytes(&self) -> u64 {
        self.file
            .chunks_of_at(self.collision_channel, None)
            .map(|ci| ci.chunk_length.saturating_add(ci.message_index_length))
            .fold(0, u64::saturating_add)
    }

    /// The largest uncompressed chunk holding table batches (bytes): what reading the
    /// table holds in memory at once, besides one decoded batch.
    pub fn largest_table_chunk(&self) -> u64 {
        self.file
            .chunks_of_at(self.collision_channel, None)
            .map(|ci| ci.uncompressed_size)
            .max()
            .unwrap_or(0)
    }

    /// Rows of the table: the summary's count, never more than its batches can hold (the
    /// bound alone for a recording whose writer was interrupted before its summary).
    pub fn table_rows(&self) -> u64 {
        let batches = self.file.summary.stats.as_ref().map(|st| {
            st.channel_message_counts
                .get(&self.collision_channel)
                .copied()
                .unwrap_or(0)
        });
        let most = batches.map_or(u64::MAX, |b| b.saturating_mul(table::BATCH_ROWS as u64));
        self.run_summary.as_ref().map_or(most, |s| s.rows.min(most))
    }

    fn corrupt(&self, detail: String) -> FormatError {
        self.file.corrupt(detail)
    }

    /// All snapshots, by index (0: `t0`, 1: `t1`, then the reference periods).
    pub fn snapshots(&self) -> Result<Vec<Snapshot>, FormatError> {
        self.snapshots_on(self.snapshot_channel)
    }

    /// The DEM twins' reference snapshots: entry `m - 1` holds twin `m`'s, by index
    /// (`t2` on: a twin parts from the DEM at `t1`, or at `t_s` with `twins_from` = s, when its
    /// snapshots up to `t_s` are the DEM's). Empty without twins.
    pub fn twin_snapshots(&self) -> Result<Vec<Vec<Snapshot>>, FormatError> {
        let twins: Vec<Vec<Snapshot>> = self
            .twin_channels
            .iter()
            .map(|&c| self.snapshots_on(c))
            .collect::<Result<_, _>>()?;
        for (m, snaps) in twins.iter().enumerate() {
            let expected = self.info.reference_periods as usize;
            if snaps.len() != expected || snaps.iter().zip(2..).any(|(s, k)| s.index != k) {
                return Err(self.corrupt(format!(
                    "twin {}: {} snapshots numbered {:?}; a twin holds one at each of t2..t{}",
                    m + 1,
                    snaps.len(),
                    snaps.iter().map(|s| s.index).collect::<Vec<_>>(),
                    expected + 1
                )));
            }
        }
        Ok(twins)
    }

    fn snapshots_on(&self, channel: u16) -> Result<Vec<Snapshot>, FormatError> {
        let mut snaps = Vec::new();
        for m in self.file.messages_at(channel, None) {
            let (index, data) = m?;
            snaps.push(self.decode_snapshot(index, &data)?);
        }
        snaps.sort_by_key(|s| s.index);
        Ok(snaps)
    }

    /// Decodes a stored snapshot and checks it holds every particle in id order.
    fn decode_snapshot(&self, index: u32, data: &[u8]) -> Result<Snapshot, FormatError> {
        {
            let snap = Snapshot::decode(index, data).map_err(|e| self.corrupt(e))?;
            if snap.len() != self.info.particles as usize {
                return Err(self.corrupt(format!(
                    "snapshot {index}: {} points for {} particles",
                    snap.len(),
                    self.info.particles
                )));
            }
            if let Some(k) = snap
                .id
                .iter()
                .enumerate()
                .position(|(k, &id)| id as usize != k)
            {
                return Err(self.corrupt(format!(
                    "snapshot {index}: point {k} has id {} (points must be in id order)",
                    snap.id[k]
                )));
            }
            Ok(snap)
        }
    }

    /// The snapshot with this index, if stored; only its own chunk is read and decoded.
    pub fn snapshot(&self, index: u32) -> Result<Option<Snapshot>, FormatError> {
        let time = log_time(self.info.snapshot_time(index));
        for m in self
            .file
            .messages_at(self.snapshot_channel, Some(time..=time))
        {
            let (sequence, data) = m?;
            if sequence == index {
                return self.decode_snapshot(index, &data).map(Some);
            }
        }
        Ok(None)
    }

    /// The rows of recorded period `period` (0-based), batch by batch in apparition order,
    /// start steps still counted from `t0`. Only the chunks logged within the period are
    /// read (a batch is logged at its first row's start); a chunk that also holds batches of
    /// a neighbouring period has those decoded and skipped (a batch never spans two periods).
    pub fn period_table(
        &self,
        period: u32,
    ) -> impl Iterator<Item = Result<TableBatch, FormatError>> + '_ {
        let info = &self.info;
        let start = |p: u64| log_time((info.step_t0 + p * info.period_steps) as f64 * info.dt);
        // one nanosecond of margin on each side: the window only chooses chunks to read, the
        // rows' start steps decide
        let window = start(period as u64).saturating_sub(1)..=start(period as u64 + 1) + 1;
        let period = period as u64;
        self.batches(self.file.messages_at(self.collision_channel, Some(window)), None)
            .filter_map(move |batch| {
                let batch = match batch {
                    Ok(batch) => batch,
                    Err(e) => return Some(Err(e)),
                };
                let of = |r: &CollisionRow| self.info.period_of_step(r.start_step);
                let (first, last) = (batch.rows.first()?, batch.rows.last()?);
                if of(first) != of(last) {
                    return Some(Err(self.corrupt(format!(
                        "batch at row {} spans recorded periods {} to {} (a batch holds one period's rows)",
                        batch.first_row,
                        of(first),
                        of(last)
                    ))));
                }
                if of(first) >= self.info.recorded_periods as u64 {
                    return Some(Err(self.corrupt(format!(
                        "row {}: start step {} is past the {} recorded period(s) of {} steps",
                        batch.first_row, first.start_step, self.info.recorded_periods, self.info.period_steps
                    ))));
                }
                (of(first) == period).then_some(Ok(batch))
            })
    }

    /// The table, batch by batch in apparition order; memory holds one chunk and one batch.
    pub fn table(&self) -> impl Iterator<Item = Result<TableBatch, FormatError>> + '_ {
        self.batches(self.file.messages_at(self.collision_channel, None), Some(0))
    }

    /// The table batches of `messages`, decoded and checked: consecutive rows (the first at
    /// row `first_row`, or wherever the first batch says when the messages start inside the
    /// table) and start steps in apparition order.
    fn batches<'a>(
        &'a self,
        messages: impl Iterator<Item = Result<(u32, Vec<u8>), FormatError>> + 'a,
        first_row: Option<u64>,
    ) -> impl Iterator<Item = Result<TableBatch, FormatError>> + 'a {
        let mut next_row = first_row;
        let mut last_start = 0u64;
        messages.map(move |m| {
            let (_, data) = m?;
            let batch = table::decode(&data, &self.info).map_err(|e| self.corrupt(e))?;
            let expected = *next_row.get_or_insert(batch.first_row);
            if batch.first_row != expected {
                return Err(self.corrupt(format!(
                    "batch starts at row {} where row {expected} was expected",
                    batch.first_row
                )));
            }
            if let Some(first) = batch.rows.first() {
                if first.start_step < last_start {
                    return Err(self.corrupt(format!(
                        "row {}: start step {} before the previous row's {last_start}",
                        batch.first_row, first.start_step
                    )));
                }
            }
            next_row = Some(expected + batch.rows.len() as u64);
            last_start = batch.rows.last().map_or(last_start, |r| r.start_step);
            Ok(batch)
        })
    }
}
