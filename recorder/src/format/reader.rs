//! Reads a recording without loading it whole: the file is memory-mapped, the summary section
//! gives the metadata and chunk indexes, and the table is decoded one chunk at a time.

use super::table::{self, TableBatch};
use super::writer::log_time;
use super::*;
use memmap2::Mmap;
use std::fs::File;
use std::path::Path;

const MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// An open recording.
pub struct RecordingReader {
    path: PathBuf,
    bytes: Mmap,
    summary: mcap::Summary,
    info: RecordingInfo,
    run_summary: Option<RecordingSummary>,
    costs: Option<RecordingCosts>,
    snapshot_channel: u16,
    collision_channel: u16,
}

impl std::fmt::Debug for RecordingReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RecordingReader")
            .field("path", &self.path)
            .finish_non_exhaustive()
    }
}

impl RecordingReader {
    /// Opens `path` and checks that it is a complete tdex recording of a known version.
    pub fn open(path: &Path) -> Result<Self, FormatError> {
        let path_buf = path.to_path_buf();
        let file = File::open(path).map_err(|error| FormatError::Open {
            path: path_buf.clone(),
            error,
        })?;
        // SAFETY: the map is read-only; tdex never writes a recording in place (it renames a
        // finished file over it), so the mapped bytes do not change under us.
        let bytes = unsafe { Mmap::map(&file) }.map_err(|error| FormatError::Open {
            path: path_buf.clone(),
            error,
        })?;
        let corrupt = |detail: String| FormatError::Corrupt {
            path: path_buf.clone(),
            detail,
        };
        if !bytes.starts_with(MAGIC) {
            return Err(FormatError::NotMcap { path: path_buf });
        }
        if bytes.len() < 2 * MAGIC.len() + 29 || !bytes.ends_with(MAGIC) {
            return Err(FormatError::Truncated { path: path_buf });
        }
        let summary = match mcap::read::Summary::read(&bytes) {
            Ok(Some(s)) => s,
            Ok(None) => return Err(FormatError::Truncated { path: path_buf }),
            Err(e) => return Err(corrupt(format!("summary section: {e}"))),
        };
        let not_recording = |detail: String| FormatError::NotRecording {
            path: path_buf.clone(),
            detail,
        };
        let metadata_json = |name: &str| -> Result<Option<String>, FormatError> {
            let Some(index) = summary.metadata_indexes.iter().find(|m| m.name == name) else {
                return Ok(None);
            };
            let end = index.offset.checked_add(index.length);
            if end.is_none_or(|e| e > bytes.len() as u64) || index.length < 9 {
                return Err(corrupt(format!(
                    "metadata index '{name}' points outside the file"
                )));
            }
            let record = mcap::read::metadata(&bytes, index)
                .map_err(|e| corrupt(format!("metadata '{name}': {e}")))?;
            record
                .metadata
                .get("json")
                .cloned()
                .map(Some)
                .ok_or_else(|| corrupt(format!("metadata '{name}' has no 'json' entry")))
        };
        let info_json = metadata_json(INFO_METADATA)?
            .ok_or_else(|| not_recording(format!("it has no '{INFO_METADATA}' metadata record")))?;
        let info: RecordingInfo = serde_json::from_str(&info_json)
            .map_err(|e| corrupt(format!("metadata '{INFO_METADATA}': {e}")))?;
        if info.format_version != FORMAT_VERSION {
            return Err(not_recording(format!(
                "format version {} (this tdex reads version {FORMAT_VERSION})",
                info.format_version
            )));
        }
        let run_summary = match metadata_json(SUMMARY_METADATA)? {
            Some(json) => Some(
                serde_json::from_str(&json)
                    .map_err(|e| corrupt(format!("metadata '{SUMMARY_METADATA}': {e}")))?,
            ),
            None => None,
        };
        let costs = match metadata_json(COSTS_METADATA)? {
            Some(json) => Some(
                serde_json::from_str(&json)
                    .map_err(|e| corrupt(format!("metadata '{COSTS_METADATA}': {e}")))?,
            ),
            None => None,
        };
        let channel = |topic: &str, schema: &str| {
            summary
                .channels
                .values()
                .find(|c| c.topic == topic)
                .filter(|c| c.schema.as_ref().is_some_and(|s| s.name == schema))
                .map(|c| c.id)
                .ok_or_else(|| {
                    not_recording(format!("no channel '{topic}' with schema '{schema}'"))
                })
        };
        let snapshot_channel = channel(SNAPSHOT_TOPIC, "foxglove.PointCloud")?;
        let collision_channel = channel(COLLISION_TOPIC, "tdex.CollisionBatch")?;
        for ci in &summary.chunk_indexes {
            let end = ci.chunk_start_offset.checked_add(ci.chunk_length);
            if ci.chunk_length < 9 || end.is_none_or(|e| e > bytes.len() as u64) {
                return Err(corrupt(format!(
                    "chunk index at offset {} (length {}) points outside the file of {} bytes",
                    ci.chunk_start_offset,
                    ci.chunk_length,
                    bytes.len()
                )));
            }
        }
        Ok(Self {
            path: path_buf,
            bytes,
            summary,
            info,
            run_summary,
            costs,
            snapshot_channel,
            collision_channel,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
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
        self.bytes.len() as u64
    }

    /// Bytes of the chunks holding the table (compressed, with their message indexes).
    pub fn table_bytes(&self) -> u64 {
        self.chunks_of(self.collision_channel)
            .map(|ci| ci.chunk_length + ci.message_index_length)
            .sum()
    }

    fn corrupt(&self, detail: String) -> FormatError {
        FormatError::Corrupt {
            path: self.path.clone(),
            detail,
        }
    }

    /// Chunks holding messages of `channel`, in file order.
    fn chunks_of(&self, channel: u16) -> impl Iterator<Item = &mcap::records::ChunkIndex> {
        self.chunks_of_at(channel, None)
    }

    /// Chunks holding messages of `channel` (logged at `time`, ns, if given), in file order.
    fn chunks_of_at(
        &self,
        channel: u16,
        time: Option<u64>,
    ) -> impl Iterator<Item = &mcap::records::ChunkIndex> {
        let mut chunks: Vec<_> = self
            .summary
            .chunk_indexes
            .iter()
            .filter(|ci| ci.message_index_offsets.contains_key(&channel))
            .filter(|ci| {
                time.is_none_or(|t| (ci.message_start_time..=ci.message_end_time).contains(&t))
            })
            .collect();
        chunks.sort_by_key(|ci| ci.chunk_start_offset);
        chunks.into_iter()
    }

    /// Messages of `channel`, decompressing one chunk at a time: `(sequence, data)`. A chunk's
    /// messages are handed out only after its CRC has been checked (at the chunk's end), so
    /// damaged data is never decoded.
    fn messages(
        &self,
        channel: u16,
    ) -> impl Iterator<Item = Result<(u32, Vec<u8>), FormatError>> + '_ {
        self.messages_at(channel, None)
    }

    /// [`Self::messages`] of the chunks that hold messages logged at `time` (ns), if given.
    fn messages_at(
        &self,
        channel: u16,
        time: Option<u64>,
    ) -> impl Iterator<Item = Result<(u32, Vec<u8>), FormatError>> + '_ {
        self.chunks_of_at(channel, time).flat_map(move |ci| {
            let chunk_error = |e: mcap::McapError| {
                self.corrupt(format!(
                    "chunk at byte offset {}: {e}",
                    ci.chunk_start_offset
                ))
            };
            let messages: Result<Vec<(u32, Vec<u8>)>, FormatError> = self
                .summary
                .stream_chunk(&self.bytes, ci)
                .map_err(chunk_error)
                .and_then(|stream| {
                    stream
                        .filter_map(|m| match m {
                            Ok(m) if m.channel.id == channel => {
                                Some(Ok((m.sequence, m.data.into_owned())))
                            }
                            Ok(_) => None,
                            Err(e) => Some(Err(chunk_error(e))),
                        })
                        .collect()
                });
            let batch: Vec<Result<(u32, Vec<u8>), FormatError>> = match messages {
                Ok(messages) => messages.into_iter().map(Ok).collect(),
                Err(e) => vec![Err(e)],
            };
            batch
        })
    }

    /// All snapshots, by index (0: `t0`, 1: `t1`, then the reference periods).
    pub fn snapshots(&self) -> Result<Vec<Snapshot>, FormatError> {
        let mut snaps = Vec::new();
        for m in self.messages(self.snapshot_channel) {
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
        for m in self.messages_at(self.snapshot_channel, Some(time)) {
            let (sequence, data) = m?;
            if sequence == index {
                return self.decode_snapshot(index, &data).map(Some);
            }
        }
        Ok(None)
    }

    /// The table, batch by batch in apparition order; memory holds one chunk and one batch.
    pub fn table(&self) -> impl Iterator<Item = Result<TableBatch, FormatError>> + '_ {
        let mut next_row = 0u64;
        let mut last_start = 0u64;
        self.messages(self.collision_channel).map(move |m| {
            let (_, data) = m?;
            let batch = table::decode(&data, &self.info).map_err(|e| self.corrupt(e))?;
            if batch.first_row != next_row {
                return Err(self.corrupt(format!(
                    "batch starts at row {} where row {next_row} was expected",
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
            next_row += batch.rows.len() as u64;
            last_start = batch.rows.last().map_or(last_start, |r| r.start_step);
            Ok(batch)
        })
    }
}
