//! Every file tdex writes: a hidden temporary file beside the destination, fsynced, renamed into place, the directory fsynced; a failure leaves the previous file as it was and says why.
//!
//! The temporary file is `.<name>.partial-<pid>` in the destination's directory (the same
//! filesystem, so the rename is atomic: a reader sees the old file or the new one, never a
//! mix). [`AtomicFile`] streams into it (the MCAP writers); [`write_atomically`] writes a
//! whole file; [`OutputSet`] replaces several files together (a report, a VTK series): all
//! are written and synced before the first is renamed, so a full disk leaves every previous
//! file in place. Any error or early drop removes the temporary files.

use std::fs::File;
use std::io::{self, BufWriter, ErrorKind, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// Buffer of an [`AtomicFile`]: large writes (MCAP chunks) go through in few system calls.
const BUFFER_BYTES: usize = 1 << 20;

/// Why an output could not be written, in plain words, naming the destination and saying
/// what became of the file that was there before.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot {action}: {}; {}", dest.display(), reason(&self.error, &self.dir), self.previous_note())]
pub struct OutputError {
    /// The file (or directory) that was to be written.
    pub dest: PathBuf,
    /// What failed: `write`, `create the directory`.
    pub action: &'static str,
    /// The directory the reason speaks of (where the disk is full, the permission missing).
    pub dir: PathBuf,
    /// Whether a previous file was at `dest` (it is left as it was).
    pub previous: bool,
    pub error: io::Error,
}

impl crate::Classify for OutputError {
    /// An output that cannot be written is the run's fault, never the input's.
    fn fault(&self) -> crate::Fault {
        crate::Fault::Run
    }
}

impl OutputError {
    /// An error while writing `dest` (through its temporary file).
    pub fn writing(dest: &Path, error: io::Error) -> Self {
        Self {
            dest: dest.to_path_buf(),
            action: "write",
            dir: parent_dir(dest).to_path_buf(),
            previous: dest.exists(),
            error,
        }
    }

    /// An error while creating the directory `dir` (the reason names its parent).
    pub fn creating_dir(dir: &Path, error: io::Error) -> Self {
        let mut existing = parent_dir(dir);
        // the reason speaks of the nearest directory that exists (where the create failed)
        while !existing.is_dir() && existing.parent().is_some() {
            existing = parent_dir(existing);
        }
        Self {
            dest: dir.to_path_buf(),
            action: "create the directory",
            dir: existing.to_path_buf(),
            previous: false,
            error,
        }
    }

    /// The directory of `dest` could not be fsynced after the rename: the new file is in
    /// place, but a crash could still undo the rename.
    pub fn syncing_dir(dest: &Path, error: io::Error) -> Self {
        Self {
            dest: dest.to_path_buf(),
            action: "sync the directory after writing",
            dir: parent_dir(dest).to_path_buf(),
            previous: true,
            error,
        }
    }

    /// The I/O error kind behind it (`StorageFull`, `PermissionDenied`, ...).
    pub fn kind(&self) -> ErrorKind {
        self.error.kind()
    }

    fn previous_note(&self) -> String {
        if self.action.starts_with("sync") {
            "the new file is in place, but a crash may still undo its rename".into()
        } else if self.action != "write" {
            "nothing was created".into()
        } else if self.previous {
            format!(
                "the previous {} was left as it was",
                file_name(&self.dest).display()
            )
        } else {
            "no file was left at that path".into()
        }
    }
}

/// The plain-words reason of an I/O error met while writing into `dir`.
fn reason(error: &io::Error, dir: &Path) -> String {
    let dir = dir.display();
    match error.kind() {
        ErrorKind::StorageFull => {
            format!("no space left on device: the disk holding {dir} is full")
        }
        ErrorKind::QuotaExceeded => {
            format!("disk quota exceeded: your quota on the disk holding {dir} is used up")
        }
        ErrorKind::FileTooLarge => format!(
            "file too large: the file size limit (ulimit -f) or the largest file the filesystem \
             holding {dir} allows was reached"
        ),
        ErrorKind::PermissionDenied => format!("permission denied: cannot write in {dir}"),
        ErrorKind::ReadOnlyFilesystem => {
            format!("read-only file system: {dir} is on a disk mounted read-only")
        }
        ErrorKind::NotFound => format!("the directory {dir} does not exist"),
        ErrorKind::NotADirectory => format!("a part of the path {dir} is a file, not a directory"),
        ErrorKind::IsADirectory => "the destination is a directory".into(),
        _ => format!("{error} (in {dir})"),
    }
}

/// The directory holding `path` (`.` for a bare file name).
fn parent_dir(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

fn file_name(path: &Path) -> &Path {
    path.file_name().map_or(path, Path::new)
}

/// The name of `dest`'s temporary files without the process id: `.<name>.partial-`.
fn temp_prefix(dest: &Path) -> String {
    let name = dest.file_name().map_or_else(
        || "tdex-output".into(),
        |n| n.to_string_lossy().into_owned(),
    );
    format!(".{name}.partial-")
}

/// The hidden temporary file beside `dest`: `.<name>.partial-<pid>`.
pub fn temp_path(dest: &Path) -> PathBuf {
    dest.with_file_name(format!("{}{}", temp_prefix(dest), std::process::id()))
}

/// Removes the temporary files of `dest` left by processes that no longer run (a killed
/// run, before its work is resumed); on systems without `/proc` it leaves them.
pub fn remove_stale_temps(dest: &Path) {
    let dir = parent_dir(dest);
    let prefix = temp_prefix(dest);
    let (Ok(entries), true) = (std::fs::read_dir(dir), Path::new("/proc/self").exists()) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .to_string_lossy()
            .strip_prefix(&prefix)
            .map(str::to_owned)
        else {
            continue;
        };
        let dead = !pid.is_empty()
            && pid.bytes().all(|b| b.is_ascii_digit())
            && !Path::new("/proc").join(&pid).exists();
        if dead {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Makes a rename or a new file in `dir` durable (its directory entry survives a crash).
pub fn sync_dir(dir: &Path) -> io::Result<()> {
    File::open(dir)?.sync_all()
}

/// `create_dir_all` whose error says why in plain words.
pub fn create_dir_all(dir: &Path) -> Result<(), OutputError> {
    std::fs::create_dir_all(dir).map_err(|e| OutputError::creating_dir(dir, e))
}

/// A file being written to its temporary path; [`AtomicFile::commit`] moves it into place.
/// Dropped without a commit (an error, a panic), it removes its temporary file.
pub struct AtomicFile {
    writer: Option<BufWriter<File>>,
    temp: PathBuf,
    dest: PathBuf,
}

impl AtomicFile {
    /// Creates the temporary file for `dest` (replacing a stale one of this process).
    pub fn create(dest: &Path) -> Result<Self, OutputError> {
        let temp = temp_path(dest);
        let file = File::create(&temp).map_err(|e| OutputError::writing(dest, e))?;
        Ok(Self {
            writer: Some(BufWriter::with_capacity(BUFFER_BYTES, file)),
            temp,
            dest: dest.to_path_buf(),
        })
    }

    pub fn dest(&self) -> &Path {
        &self.dest
    }

    /// An I/O error met while writing this file, as an [`OutputError`].
    pub fn error(&self, error: io::Error) -> OutputError {
        OutputError::writing(&self.dest, error)
    }

    fn writer(&mut self) -> &mut BufWriter<File> {
        self.writer
            .as_mut()
            .expect("an AtomicFile is written only before its commit")
    }

    /// Flushes and fsyncs the temporary file; the rename is left to [`Staged::commit`].
    pub fn stage(mut self) -> Result<Staged, OutputError> {
        let writer = self.writer.take().expect("staged once");
        let synced = writer
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|file| file.sync_all());
        let staged = Staged {
            temp: std::mem::take(&mut self.temp),
            dest: std::mem::take(&mut self.dest),
            renamed: false,
        };
        // from here the Staged value owns (and on error removes) the temporary file
        match synced {
            Ok(()) => Ok(staged),
            Err(e) => Err(OutputError::writing(&staged.dest, e)),
        }
    }

    /// Flushes, fsyncs, renames into place and fsyncs the directory; returns the destination.
    pub fn commit(self) -> Result<PathBuf, OutputError> {
        let staged = self.stage()?;
        let dest = staged.rename()?;
        sync_dir(parent_dir(&dest)).map_err(|e| OutputError::syncing_dir(&dest, e))?;
        Ok(dest)
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.writer().write(buf)
    }
    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.writer().write_all(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.writer().flush()
    }
}

/// The MCAP writer seeks back to patch chunk headers.
impl Seek for AtomicFile {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        self.writer().seek(pos)
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if let Some(writer) = self.writer.take() {
            // the buffer is thrown away, not flushed: the file goes anyway
            let (file, _) = writer.into_parts();
            drop(file);
            let _ = std::fs::remove_file(&self.temp);
        }
    }
}

/// A complete, fsynced temporary file waiting for its rename; dropped unrenamed, it is removed.
pub struct Staged {
    temp: PathBuf,
    dest: PathBuf,
    renamed: bool,
}

impl Staged {
    pub fn dest(&self) -> &Path {
        &self.dest
    }

    /// Renames the file into place (the directory is not synced: see [`Staged::commit`]).
    fn rename(mut self) -> Result<PathBuf, OutputError> {
        std::fs::rename(&self.temp, &self.dest).map_err(|e| OutputError::writing(&self.dest, e))?;
        self.renamed = true;
        Ok(std::mem::take(&mut self.dest))
    }

    /// Renames into place and fsyncs the directory.
    pub fn commit(self) -> Result<PathBuf, OutputError> {
        let dest = self.rename()?;
        sync_dir(parent_dir(&dest)).map_err(|e| OutputError::syncing_dir(&dest, e))?;
        Ok(dest)
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.renamed && !self.temp.as_os_str().is_empty() {
            let _ = std::fs::remove_file(&self.temp);
        }
    }
}

/// Writes `bytes` to `dest` atomically (temporary file, fsync, rename, directory fsync).
pub fn write_atomically(dest: &Path, bytes: &[u8]) -> Result<PathBuf, OutputError> {
    write_with(dest, |w| w.write_all(bytes))
}

/// Writes `dest` atomically with `fill` writing its content.
pub fn write_with(
    dest: &Path,
    fill: impl FnOnce(&mut AtomicFile) -> io::Result<()>,
) -> Result<PathBuf, OutputError> {
    let mut file = AtomicFile::create(dest)?;
    fill(&mut file).map_err(|e| file.error(e))?;
    file.commit()
}

/// Several files replaced together: each is written and fsynced to its temporary file as it
/// is added; [`OutputSet::commit`] renames them all, in the order added. An error before
/// the commit (a full disk) leaves every previous file in place and removes the temporaries.
#[derive(Default)]
pub struct OutputSet {
    staged: Vec<Staged>,
}

impl OutputSet {
    pub fn new() -> Self {
        Self::default()
    }

    /// Writes `bytes` for `dest` (not yet in place).
    pub fn add(&mut self, dest: &Path, bytes: &[u8]) -> Result<(), OutputError> {
        let mut file = AtomicFile::create(dest)?;
        file.write_all(bytes).map_err(|e| file.error(e))?;
        self.staged.push(file.stage()?);
        Ok(())
    }

    /// Renames every file into place, then fsyncs their directories; returns the files.
    pub fn commit(self) -> Result<Vec<PathBuf>, OutputError> {
        let mut written = Vec::with_capacity(self.staged.len());
        for staged in self.staged {
            written.push(staged.rename()?);
        }
        let mut synced: Option<&Path> = None;
        for dest in &written {
            let dir = parent_dir(dest);
            if synced != Some(dir) {
                sync_dir(dir).map_err(|e| OutputError::syncing_dir(dest, e))?;
                synced = Some(dir);
            }
        }
        Ok(written)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("tdex-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn a_file_replaces_the_previous_one_and_leaves_no_temporary() {
        let dir = scratch("replace");
        let dest = dir.join("out.txt");
        std::fs::write(&dest, b"old").unwrap();
        write_atomically(&dest, b"new content").unwrap();
        assert_eq!(std::fs::read(&dest).unwrap(), b"new content");
        assert_eq!(names(&dir), ["out.txt"]);
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_failed_fill_keeps_the_previous_file_and_removes_the_temporary() {
        let dir = scratch("fail");
        let dest = dir.join("out.txt");
        std::fs::write(&dest, b"old").unwrap();
        let err = write_with(&dest, |w| {
            w.write_all(b"half")?;
            Err(io::Error::from(ErrorKind::StorageFull))
        })
        .unwrap_err();
        let text = err.to_string();
        assert!(text.contains(&*dest.to_string_lossy()), "{text}");
        assert!(text.contains("no space left on device"), "{text}");
        assert!(
            text.contains(&format!("the disk holding {} is full", dir.display())),
            "{text}"
        );
        assert!(
            text.contains("the previous out.txt was left as it was"),
            "{text}"
        );
        assert_eq!(std::fs::read(&dest).unwrap(), b"old");
        assert_eq!(names(&dir), ["out.txt"]);
        // an unfinished file dropped mid-way goes too
        let mut f = AtomicFile::create(&dir.join("other.txt")).unwrap();
        f.write_all(b"x").unwrap();
        drop(f);
        assert_eq!(names(&dir), ["out.txt"]);
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn every_reason_is_in_plain_words() {
        let dir = Path::new("/data/runs");
        for (kind, expect) in [
            (
                ErrorKind::StorageFull,
                "no space left on device: the disk holding /data/runs is full",
            ),
            (ErrorKind::FileTooLarge, "file too large"),
            (
                ErrorKind::PermissionDenied,
                "permission denied: cannot write in /data/runs",
            ),
            (ErrorKind::ReadOnlyFilesystem, "read-only file system"),
            (ErrorKind::QuotaExceeded, "disk quota exceeded"),
            (
                ErrorKind::NotFound,
                "the directory /data/runs does not exist",
            ),
        ] {
            let text = reason(&io::Error::from(kind), dir);
            assert!(text.contains(expect), "{kind:?}: {text}");
        }
        // raw errnos map the same way (Linux)
        let full = io::Error::from_raw_os_error(28);
        assert!(reason(&full, dir).starts_with("no space left on device"));
        let big = io::Error::from_raw_os_error(27);
        assert!(reason(&big, dir).starts_with("file too large"));
        let err = OutputError::writing(Path::new("/data/runs/run.mcap"), full);
        assert!(
            err.to_string().ends_with("no file was left at that path"),
            "{err}"
        );
    }

    #[test]
    fn a_set_is_renamed_only_when_every_file_was_written() {
        let dir = scratch("set");
        std::fs::write(dir.join("a"), b"old a").unwrap();
        std::fs::write(dir.join("b"), b"old b").unwrap();
        {
            let mut set = OutputSet::new();
            set.add(&dir.join("a"), b"new a").unwrap();
            // the second file cannot be written: its directory is missing
            let err = set.add(&dir.join("missing/b"), b"new b").unwrap_err();
            assert_eq!(err.kind(), ErrorKind::NotFound);
        }
        assert_eq!(std::fs::read(dir.join("a")).unwrap(), b"old a");
        assert_eq!(names(&dir), ["a", "b"]);
        let mut set = OutputSet::new();
        set.add(&dir.join("a"), b"new a").unwrap();
        set.add(&dir.join("b"), b"new b").unwrap();
        assert_eq!(
            std::fs::read(dir.join("a")).unwrap(),
            b"old a",
            "nothing in place before the commit"
        );
        let written = set.commit().unwrap();
        assert_eq!(written, [dir.join("a"), dir.join("b")]);
        assert_eq!(std::fs::read(dir.join("b")).unwrap(), b"new b");
        assert_eq!(names(&dir), ["a", "b"]);
        std::fs::remove_dir_all(dir).unwrap();
    }
}
