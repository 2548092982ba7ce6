//! The row journal of a checkpointed recording: every table row handed to the writer, in
//! order, so that a resumed run can rebuild the MCAP output to the byte before going on.
//!
//! The MCAP writer keeps its chunk, indexes and statistics in memory, so a partial output
//! cannot be continued in place; it is a pure function of the rows and snapshots given to it,
//! though, and the journal keeps the rows (the checkpoint keeps the snapshots). A checkpoint
//! stores a [`JournalMark`]: the rows synced so far and their CRC.

use super::CollisionRow;
use std::fs::{File, OpenOptions};
use std::io::{BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// Bytes of one row: `i`, `j` (u32), `start_step` (u64), `duration_steps` (u32),
/// `sqrt_area` (f64 bits), little-endian.
pub const ROW_BYTES: usize = 28;

/// The row journal kept beside a checkpoint: `<checkpoint>.rows`.
pub fn journal_path(checkpoint: &Path) -> PathBuf {
    let mut name = checkpoint.as_os_str().to_owned();
    name.push(".rows");
    PathBuf::from(name)
}

/// How far the journal had been synced when a checkpoint was taken.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct JournalMark {
    pub rows: u64,
    /// CRC-32 of the first `rows` rows' bytes.
    pub crc: u32,
}

/// Why the journal cannot be written or read back.
#[derive(Debug, thiserror::Error)]
pub enum JournalError {
    #[error("{}: cannot write the row journal: {error}", path.display())]
    Write {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{}: cannot read the row journal: {error}", path.display())]
    Read {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{}: the row journal holds {found} rows, the checkpoint needs {needed}: it is not this run's journal or was cut short", path.display())]
    Short {
        path: PathBuf,
        found: u64,
        needed: u64,
    },
    #[error("{}: the first {rows} rows of the row journal do not match the checkpoint (CRC {found:08x}, expected {expected:08x}): it was damaged or belongs to another run", path.display())]
    Mismatch {
        path: PathBuf,
        rows: u64,
        found: u32,
        expected: u32,
    },
}

impl tdex_format::Classify for JournalError {
    /// A journal that is not this run's, or was cut short, is the input's fault; failing
    /// to read or write it is the run's.
    fn fault(&self) -> tdex_format::Fault {
        match self {
            JournalError::Short { .. } | JournalError::Mismatch { .. } => tdex_format::Fault::Input,
            _ => tdex_format::Fault::Run,
        }
    }
}

/// The journal open for appending.
pub struct RowJournal {
    path: PathBuf,
    out: BufWriter<File>,
    crc: crc32fast::Hasher,
    rows: u64,
}

fn encode(row: &CollisionRow) -> [u8; ROW_BYTES] {
    let mut b = [0u8; ROW_BYTES];
    b[0..4].copy_from_slice(&row.i.to_le_bytes());
    b[4..8].copy_from_slice(&row.j.to_le_bytes());
    b[8..16].copy_from_slice(&row.start_step.to_le_bytes());
    b[16..20].copy_from_slice(&row.duration_steps.to_le_bytes());
    b[20..28].copy_from_slice(&row.sqrt_area.to_bits().to_le_bytes());
    b
}

fn decode(b: &[u8]) -> CollisionRow {
    let u32_at = |k: usize| u32::from_le_bytes(b[k..k + 4].try_into().expect("4 bytes"));
    let u64_at = |k: usize| u64::from_le_bytes(b[k..k + 8].try_into().expect("8 bytes"));
    CollisionRow {
        i: u32_at(0),
        j: u32_at(4),
        start_step: u64_at(8),
        duration_steps: u32_at(16),
        sqrt_area: f64::from_bits(u64_at(20)),
    }
}

impl RowJournal {
    /// Starts an empty journal at `path` (replacing any old one).
    pub fn create(path: &Path) -> Result<Self, JournalError> {
        let file = File::create(path).map_err(|error| JournalError::Write {
            path: path.to_path_buf(),
            error,
        })?;
        Ok(Self {
            path: path.to_path_buf(),
            out: BufWriter::with_capacity(1 << 20, file),
            crc: crc32fast::Hasher::new(),
            rows: 0,
        })
    }

    /// Reopens the journal of a checkpoint: checks that its first `mark.rows` rows are the
    /// ones the checkpoint saw, hands them to `replay` in order (in blocks), drops whatever
    /// was written after the checkpoint and positions the journal to append. `replay`'s
    /// errors (the caller's writer's) pass through as they are.
    pub fn resume<E: From<JournalError>>(
        path: &Path,
        mark: JournalMark,
        replay: &mut dyn FnMut(&[CollisionRow]) -> Result<(), E>,
    ) -> Result<Self, E> {
        let read_err = |error| JournalError::Read {
            path: path.to_path_buf(),
            error,
        };
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(read_err)?;
        let found = file.metadata().map_err(read_err)?.len() / ROW_BYTES as u64;
        if found < mark.rows {
            return Err(JournalError::Short {
                path: path.to_path_buf(),
                found,
                needed: mark.rows,
            }
            .into());
        }
        // check the whole prefix before replaying any of it: a damaged journal must not
        // half-build an output
        let mut crc = crc32fast::Hasher::new();
        const BLOCK_ROWS: u64 = 1 << 16;
        let mut buf = vec![0u8; BLOCK_ROWS as usize * ROW_BYTES];
        for pass in 0..2 {
            let mut reader = BufReader::new(&file);
            let mut left = mark.rows;
            while left > 0 {
                let rows = left.min(BLOCK_ROWS) as usize;
                let bytes = &mut buf[..rows * ROW_BYTES];
                reader.read_exact(bytes).map_err(read_err)?;
                if pass == 0 {
                    crc.update(bytes);
                } else {
                    let block: Vec<CollisionRow> =
                        bytes.chunks_exact(ROW_BYTES).map(decode).collect();
                    replay(&block)?;
                }
                left -= rows as u64;
            }
            if pass == 0 {
                let found = crc.clone().finalize();
                if found != mark.crc {
                    return Err(JournalError::Mismatch {
                        path: path.to_path_buf(),
                        rows: mark.rows,
                        found,
                        expected: mark.crc,
                    }
                    .into());
                }
            }
            drop(reader);
            file.seek(SeekFrom::Start(0)).map_err(read_err)?;
        }
        let end = mark.rows * ROW_BYTES as u64;
        let write_err = |error| JournalError::Write {
            path: path.to_path_buf(),
            error,
        };
        file.set_len(end).map_err(write_err)?;
        file.seek(SeekFrom::Start(end)).map_err(write_err)?;
        Ok(Self {
            path: path.to_path_buf(),
            out: BufWriter::with_capacity(1 << 20, file),
            crc,
            rows: mark.rows,
        })
    }

    /// Appends rows (buffered; [`Self::sync`] makes them durable).
    pub fn append(&mut self, rows: &[CollisionRow]) -> Result<(), JournalError> {
        for row in rows {
            let bytes = encode(row);
            self.crc.update(&bytes);
            self.out
                .write_all(&bytes)
                .map_err(|error| JournalError::Write {
                    path: self.path.clone(),
                    error,
                })?;
        }
        self.rows += rows.len() as u64;
        Ok(())
    }

    /// Flushes and syncs the journal; the mark a checkpoint stores.
    pub fn sync(&mut self) -> Result<JournalMark, JournalError> {
        let write_err = |error| JournalError::Write {
            path: self.path.clone(),
            error,
        };
        self.out.flush().map_err(write_err)?;
        self.out.get_ref().sync_data().map_err(write_err)?;
        Ok(JournalMark {
            rows: self.rows,
            crc: self.crc.clone().finalize(),
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(k: u64) -> CollisionRow {
        CollisionRow {
            i: k as u32,
            j: k as u32 + 7,
            start_step: 10 * k,
            duration_steps: 20,
            sqrt_area: 1e-4 * (k as f64 + 0.5),
        }
    }

    #[test]
    fn a_resumed_journal_replays_the_marked_rows_and_drops_the_rest() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rows");
        let mut j = RowJournal::create(&path).unwrap();
        let first: Vec<_> = (0..100_000).map(row).collect();
        j.append(&first).unwrap();
        let mark = j.sync().unwrap();
        j.append(&[row(7), row(8)]).unwrap(); // written after the checkpoint: dropped
        j.sync().unwrap();
        drop(j);

        let mut replayed = Vec::new();
        let mut j = RowJournal::resume::<JournalError>(&path, mark, &mut |rows| {
            replayed.extend_from_slice(rows);
            Ok(())
        })
        .unwrap();
        assert_eq!(replayed, first);
        j.append(&[row(9)]).unwrap();
        let again = j.sync().unwrap();
        assert_eq!(again.rows, 100_001);
        assert_eq!(
            std::fs::metadata(&path).unwrap().len(),
            100_001 * ROW_BYTES as u64
        );
        // the CRC continues over the kept prefix: a fresh journal of the same rows agrees
        let other = dir.path().join("other");
        let mut k = RowJournal::create(&other).unwrap();
        k.append(&first).unwrap();
        k.append(&[row(9)]).unwrap();
        assert_eq!(k.sync().unwrap(), again);
    }

    #[test]
    fn a_damaged_or_short_journal_is_refused_before_any_replay() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rows");
        let mut j = RowJournal::create(&path).unwrap();
        j.append(&(0..1000).map(row).collect::<Vec<_>>()).unwrap();
        let mark = j.sync().unwrap();
        drop(j);
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[500] ^= 1;
        std::fs::write(&path, &bytes).unwrap();
        let mut calls = 0;
        let err = RowJournal::resume::<JournalError>(&path, mark, &mut |_| {
            calls += 1;
            Ok(())
        })
        .err()
        .unwrap();
        assert!(err.to_string().contains("do not match"), "{err}");
        assert_eq!(calls, 0);
        std::fs::write(&path, &bytes[..ROW_BYTES * 10]).unwrap();
        let err = RowJournal::resume::<JournalError>(&path, mark, &mut |_| Ok(()))
            .err()
            .unwrap();
        assert!(err.to_string().contains("holds 10 rows"), "{err}");
    }
}
