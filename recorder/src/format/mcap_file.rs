//! The layer both tdex readers share: a memory-mapped MCAP file whose summary section has
//! been checked, its JSON metadata records, its channels and its messages chunk by chunk.

use super::FormatError;
use memmap2::Mmap;
use std::fs::File;
use std::path::{Path, PathBuf};

const MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// The bytes of an MCAP file: memory-mapped from disk, or handed over in memory.
pub(crate) enum Bytes {
    Mapped(Mmap),
    Owned(Vec<u8>),
}

impl std::ops::Deref for Bytes {
    type Target = [u8];

    fn deref(&self) -> &[u8] {
        match self {
            Bytes::Mapped(m) => m,
            Bytes::Owned(v) => v,
        }
    }
}

/// An MCAP file opened for reading; `what` names the kind of tdex file for error messages.
pub(crate) struct McapFile {
    pub(crate) path: PathBuf,
    pub(crate) bytes: Bytes,
    pub(crate) summary: mcap::Summary,
    what: &'static str,
}

impl McapFile {
    /// Maps `path`, checks magic bytes, footer, summary section and chunk indexes.
    pub(crate) fn open(path: &Path, what: &'static str) -> Result<Self, FormatError> {
        let path_buf = path.to_path_buf();
        let file = File::open(path).map_err(|error| FormatError::Open {
            path: path_buf.clone(),
            error,
        })?;
        // SAFETY: the map is read-only; tdex never writes its files in place (it renames a
        // finished file over them), so the mapped bytes do not change under us.
        let bytes = unsafe { Mmap::map(&file) }.map_err(|error| FormatError::Open {
            path: path_buf.clone(),
            error,
        })?;
        Self::from_bytes(path, Bytes::Mapped(bytes), what)
    }

    /// Checks the bytes of the file `path` (named in messages) as [`McapFile::open`] does.
    pub(crate) fn from_bytes(
        path: &Path,
        bytes: Bytes,
        what: &'static str,
    ) -> Result<Self, FormatError> {
        let path_buf = path.to_path_buf();
        if !bytes.starts_with(MAGIC) {
            return Err(FormatError::NotMcap { path: path_buf });
        }
        if bytes.len() < 2 * MAGIC.len() + 29 || !bytes.ends_with(MAGIC) {
            return Err(FormatError::Truncated { path: path_buf });
        }
        let summary = match mcap::read::Summary::read(&bytes) {
            Ok(Some(s)) => s,
            Ok(None) => return Err(FormatError::Truncated { path: path_buf }),
            Err(e) => {
                return Err(FormatError::Corrupt {
                    path: path_buf,
                    detail: format!("summary section: {e}"),
                })
            }
        };
        let file = Self {
            path: path_buf,
            bytes,
            summary,
            what,
        };
        for ci in &file.summary.chunk_indexes {
            let end = ci.chunk_start_offset.checked_add(ci.chunk_length);
            if ci.chunk_length < 9 || end.is_none_or(|e| e > file.bytes.len() as u64) {
                return Err(file.corrupt(format!(
                    "chunk index at offset {} (length {}) points outside the file of {} bytes",
                    ci.chunk_start_offset,
                    ci.chunk_length,
                    file.bytes.len()
                )));
            }
        }
        Ok(file)
    }

    pub(crate) fn corrupt(&self, detail: String) -> FormatError {
        FormatError::Corrupt {
            path: self.path.clone(),
            detail,
        }
    }

    /// The file is MCAP but not the kind of tdex file expected.
    pub(crate) fn not_ours(&self, detail: String) -> FormatError {
        FormatError::NotRecording {
            path: self.path.clone(),
            expected: self.what,
            detail,
        }
    }

    /// The `json` entry of the metadata record `name`, if the file has one.
    pub(crate) fn metadata_json(&self, name: &str) -> Result<Option<String>, FormatError> {
        let Some(index) = self
            .summary
            .metadata_indexes
            .iter()
            .find(|m| m.name == name)
        else {
            return Ok(None);
        };
        let end = index.offset.checked_add(index.length);
        if end.is_none_or(|e| e > self.bytes.len() as u64) || index.length < 9 {
            return Err(self.corrupt(format!("metadata index '{name}' points outside the file")));
        }
        let record = mcap::read::metadata(&self.bytes, index)
            .map_err(|e| self.corrupt(format!("metadata '{name}': {e}")))?;
        record
            .metadata
            .get("json")
            .cloned()
            .map(Some)
            .ok_or_else(|| self.corrupt(format!("metadata '{name}' has no 'json' entry")))
    }

    /// The metadata record `name` decoded from JSON, if present.
    pub(crate) fn metadata<T: serde::de::DeserializeOwned>(
        &self,
        name: &str,
    ) -> Result<Option<T>, FormatError> {
        match self.metadata_json(name)? {
            Some(json) => serde_json::from_str(&json)
                .map(Some)
                .map_err(|e| self.corrupt(format!("metadata '{name}': {e}"))),
            None => Ok(None),
        }
    }

    /// The id of the channel `topic` with schema `schema`.
    pub(crate) fn channel(&self, topic: &str, schema: &str) -> Result<u16, FormatError> {
        self.summary
            .channels
            .values()
            .find(|c| c.topic == topic)
            .filter(|c| c.schema.as_ref().is_some_and(|s| s.name == schema))
            .map(|c| c.id)
            .ok_or_else(|| self.not_ours(format!("no channel '{topic}' with schema '{schema}'")))
    }

    /// Chunks holding messages of `channel` (logged at `time`, ns, if given), in file order.
    pub(crate) fn chunks_of_at(
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

    /// Messages of `channel` (in the chunks that hold messages logged at `time`, ns, if
    /// given), decompressing one chunk at a time: `(sequence, data)`. A chunk's messages are
    /// handed out only after its CRC has been checked (at the chunk's end), so damaged data
    /// is never decoded.
    pub(crate) fn messages_at(
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
}
