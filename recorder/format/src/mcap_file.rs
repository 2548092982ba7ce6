//! The layer both tdex readers share: a memory-mapped MCAP file whose summary section has
//! been checked, its JSON metadata records, its channels and its messages chunk by chunk.

use super::FormatError;
use memmap2::Mmap;
use std::fs::File;
use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};

const MAGIC: &[u8] = b"\x89MCAP0\r\n";
/// Largest accepted ratio of a chunk's uncompressed to compressed size. tdex's chunks
/// compress a few times (about 4 bytes a row from some 20, docs/benchmarks.md); zstd can
/// reach 30 000 on degenerate data, which is how a small damaged file would claim gigabytes.
const MAX_COMPRESSION_RATIO: u64 = 1000;
/// A chunk may always hold this much, whatever its compressed size.
const MIN_CHUNK_LIMIT: u64 = 1 << 20;

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
        if let Err(detail) = check_summary_section(&bytes) {
            return Err(FormatError::Corrupt {
                path: path_buf,
                detail: format!("summary section: {detail}"),
            });
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
            let index_end = end.and_then(|e| e.checked_add(ci.message_index_length));
            if ci.chunk_length < 9 || index_end.is_none_or(|e| e > file.bytes.len() as u64) {
                return Err(file.corrupt(format!(
                    "chunk index at offset {} (length {}, message indexes {} bytes) points \
                     outside the file of {} bytes",
                    ci.chunk_start_offset,
                    ci.chunk_length,
                    ci.message_index_length,
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
        // parsed here: the mcap crate's `read::metadata` runs its linear reader over the
        // indexed bytes, which enters a chunk record found there (see
        // `check_summary_section`)
        let record = &self.bytes[index.offset as usize..(index.offset + index.length) as usize];
        let body_length = u64::from_le_bytes(record[1..9].try_into().expect("8 bytes"));
        if record[0] != mcap::records::op::METADATA || body_length != index.length - 9 {
            return Err(self.corrupt(format!(
                "metadata index '{name}' points at a record of opcode {:#04x} and length {body_length}, \
                 not a metadata record of {} bytes",
                record[0],
                index.length - 9
            )));
        }
        let metadata = match mcap::parse_record(mcap::records::op::METADATA, &record[9..]) {
            Ok(mcap::records::Record::Metadata(m)) => m,
            Ok(_) => return Err(self.corrupt(format!("metadata '{name}': not a metadata record"))),
            Err(e) => return Err(self.corrupt(format!("metadata '{name}': {e}"))),
        };
        metadata
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

    /// Chunks holding messages of `channel` (some logged within `times`, ns, if given), in
    /// file order.
    pub(crate) fn chunks_of_at(
        &self,
        channel: u16,
        times: Option<RangeInclusive<u64>>,
    ) -> impl Iterator<Item = &mcap::records::ChunkIndex> {
        let mut chunks: Vec<_> = self
            .summary
            .chunk_indexes
            .iter()
            .filter(|ci| ci.message_index_offsets.contains_key(&channel))
            .filter(|ci| {
                times.as_ref().is_none_or(|t| {
                    ci.message_start_time <= *t.end() && ci.message_end_time >= *t.start()
                })
            })
            .collect();
        chunks.sort_by_key(|ci| ci.chunk_start_offset);
        chunks.into_iter()
    }

    /// Messages of `channel` (in the chunks that hold messages logged within `times`, ns, if
    /// given), decompressing one chunk at a time: `(sequence, data)`. A chunk's messages are
    /// handed out only after its CRC has been checked, so damaged data is never decoded.
    pub(crate) fn messages_at(
        &self,
        channel: u16,
        times: Option<RangeInclusive<u64>>,
    ) -> impl Iterator<Item = Result<(u32, Vec<u8>), FormatError>> + '_ {
        self.chunks_of_at(channel, times).flat_map(move |ci| {
            let batch: Vec<Result<(u32, Vec<u8>), FormatError>> =
                match self.chunk_messages(ci, channel) {
                    Ok(messages) => messages.into_iter().map(Ok).collect(),
                    Err(detail) => vec![Err(self.corrupt(format!(
                        "chunk at byte offset {}: {detail}",
                        ci.chunk_start_offset
                    )))],
                };
            batch
        })
    }

    /// The messages of `channel` in the chunk `ci`. The chunk is decompressed here rather than
    /// by the mcap crate, whose chunk reader allocates whatever size a record header inside
    /// the chunk claims: the declared uncompressed size is refused above
    /// [`Self::chunk_limit`], the output grows only as data is decompressed, and every record
    /// length is checked against the bytes left.
    fn chunk_messages(
        &self,
        ci: &mcap::records::ChunkIndex,
        channel: u16,
    ) -> Result<Vec<(u32, Vec<u8>)>, String> {
        use mcap::records::{op, Record};
        // the index was checked against the file's length when it was opened
        let start = ci.chunk_start_offset as usize;
        let record = &self.bytes[start..start + ci.chunk_length as usize];
        if record[0] != op::CHUNK {
            return Err(format!(
                "opcode {:#04x} where a chunk was indexed",
                record[0]
            ));
        }
        let (header, data) = match mcap::parse_record(op::CHUNK, &record[9..]) {
            Ok(Record::Chunk { header, data }) => (header, data),
            Ok(_) => return Err("not a chunk record".into()),
            Err(e) => return Err(e.to_string()),
        };
        let size = header.uncompressed_size;
        let limit = Self::chunk_limit(data.len());
        if size > limit {
            return Err(format!(
                "uncompressed size {size} bytes is over the {limit} bytes a chunk of {} \
                 compressed bytes can hold",
                data.len()
            ));
        }
        let records: Vec<u8> = match header.compression.as_str() {
            "" => data.into_owned(),
            "zstd" => {
                use std::io::Read;
                let mut out = Vec::new();
                zstd::stream::read::Decoder::new(&data[..])
                    .and_then(|d| d.take(size + 1).read_to_end(&mut out))
                    .map_err(|e| format!("zstd: {e}"))?;
                out
            }
            other => return Err(format!("compression '{other}' (tdex reads zstd or none)")),
        };
        if records.len() as u64 != size {
            return Err(format!(
                "{} bytes after decompression where the chunk header says {size}",
                records.len()
            ));
        }
        if header.uncompressed_crc != 0 && crc32fast::hash(&records) != header.uncompressed_crc {
            return Err("CRC mismatch: the chunk's data is damaged".into());
        }
        let mut messages = Vec::new();
        let mut rest = &records[..];
        while !rest.is_empty() {
            let Some((&opcode, tail)) = rest.split_first().filter(|_| rest.len() >= 9) else {
                return Err(format!("{} bytes at the end are not a record", rest.len()));
            };
            let length = u64::from_le_bytes(tail[..8].try_into().expect("8 bytes"));
            let body_end = usize::try_from(length)
                .ok()
                .and_then(|l| l.checked_add(9))
                .filter(|&e| e <= rest.len())
                .ok_or_else(|| {
                    format!(
                        "a record of {length} bytes where {} bytes are left",
                        rest.len() - 9
                    )
                })?;
            let body = &rest[9..body_end];
            rest = &rest[body_end..];
            if opcode != op::MESSAGE {
                continue;
            }
            match mcap::parse_record(opcode, body) {
                Ok(Record::Message { header, data }) => {
                    if !self.summary.channels.contains_key(&header.channel_id) {
                        return Err(format!(
                            "message {} on channel {}, which the summary does not list",
                            header.sequence, header.channel_id
                        ));
                    }
                    if header.channel_id == channel {
                        messages.push((header.sequence, data.into_owned()));
                    }
                }
                Ok(_) => return Err("not a message record".into()),
                Err(e) => return Err(e.to_string()),
            }
        }
        Ok(messages)
    }

    /// The largest uncompressed size accepted for a chunk of `compressed` bytes:
    /// [`MAX_COMPRESSION_RATIO`] times that, or [`MIN_CHUNK_LIMIT`] for a small chunk.
    fn chunk_limit(compressed: usize) -> u64 {
        (compressed as u64)
            .saturating_mul(MAX_COMPRESSION_RATIO)
            .max(MIN_CHUNK_LIMIT)
    }
}

/// Checks that the summary section the footer points to is a run of whole records of the
/// kinds a summary holds, before the mcap crate reads it: its summary reader would also
/// enter a chunk record there and, on a chunk shorter than the records it claims, subtract
/// past zero. The file is at least two magics and a footer long.
fn check_summary_section(bytes: &[u8]) -> Result<(), String> {
    use mcap::records::op;
    const FOOTER_LENGTH: usize = 1 + 8 + 20;
    let footer = bytes.len() - MAGIC.len() - FOOTER_LENGTH;
    let u64_at = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"));
    if bytes[footer] != op::FOOTER {
        return Ok(()); // no footer: the mcap crate says so
    }
    if u64_at(footer + 1) != 20 {
        return Err(format!(
            "the footer's record length is {} (it must be 20)",
            u64_at(footer + 1)
        ));
    }
    let start = u64_at(footer + 9);
    if start == 0 {
        return Ok(()); // no summary section: reported as an unfinished file
    }
    if start < MAGIC.len() as u64 || start > footer as u64 {
        return Err(format!(
            "the footer puts it at byte {start}, outside the file's {} bytes of records",
            footer
        ));
    }
    let mut at = start as usize;
    while at < footer {
        if footer - at < 9 {
            return Err(format!(
                "{} bytes at offset {at} are not a record",
                footer - at
            ));
        }
        let opcode = bytes[at];
        let length = u64_at(at + 1);
        if length > (footer - at - 9) as u64 {
            return Err(format!(
                "the record at offset {at} claims {length} bytes where {} are left",
                footer - at - 9
            ));
        }
        if ![
            op::SCHEMA,
            op::CHANNEL,
            op::STATISTICS,
            op::CHUNK_INDEX,
            op::ATTACHMENT_INDEX,
            op::METADATA_INDEX,
            op::SUMMARY_OFFSET,
        ]
        .contains(&opcode)
        {
            return Err(format!(
                "the record at offset {at} has opcode {opcode:#04x}, not one a summary holds"
            ));
        }
        at += 9 + length as usize;
    }
    Ok(())
}
