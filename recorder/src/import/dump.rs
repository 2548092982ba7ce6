//! LAMMPS/LIGGGHTS text dumps (`dump custom`, `dump local`): the files a pattern names (plain
//! or gzip, one file per timestep and/or per MPI process), read frame by frame and merged by
//! timestep, every header and row count checked with the file and line named.

use super::ImportError;
use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

/// What a frame lists: particles (`dump custom`) or local entries such as contacts (`dump local`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Items {
    Atoms,
    Entries,
}

impl Items {
    /// The word after `ITEM: NUMBER OF` and `ITEM:` in the frame header.
    fn word(self) -> &'static str {
        match self {
            Items::Atoms => "ATOMS",
            Items::Entries => "ENTRIES",
        }
    }
}

/// One file's part of a frame: its header and its rows as text.
#[derive(Debug)]
pub struct FramePart {
    pub path: PathBuf,
    pub timestep: u64,
    /// Rows declared by `ITEM: NUMBER OF ...`.
    pub count: usize,
    /// Column names of the `ITEM: ATOMS` / `ITEM: ENTRIES` line, and that line's number.
    pub columns: Vec<String>,
    pub columns_line: u64,
    /// The rows, one per line, the first at file line `columns_line + 1`.
    pub rows: String,
}

impl FramePart {
    /// The rows with their file line numbers.
    pub fn lines(&self) -> impl Iterator<Item = (u64, &str)> {
        (self.columns_line + 1..).zip(self.rows.lines())
    }

    /// An error at `line` of this part's file.
    pub fn error(&self, line: u64, detail: String) -> ImportError {
        ImportError::At {
            path: self.path.clone(),
            line,
            detail,
        }
    }
}

/// The files matching `pattern`, sorted by name. Wildcards only in the file name: `*` and `%`
/// (LIGGGHTS' per-timestep and per-process markers) match any run of characters, `?` one.
pub fn expand(pattern: &str) -> Result<Vec<PathBuf>, ImportError> {
    let path = Path::new(pattern);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let no_match = || ImportError::NoFiles {
        pattern: pattern.into(),
    };
    if !name.contains(['*', '%', '?']) {
        return if path.is_file() {
            Ok(vec![path.to_path_buf()])
        } else {
            Err(no_match())
        };
    }
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let entries = std::fs::read_dir(dir).map_err(|error| ImportError::Read {
        path: dir.to_path_buf(),
        error,
    })?;
    let pattern_chars: Vec<char> = name.chars().collect();
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok())
        .filter(|e| {
            let n: Vec<char> = e.file_name().to_string_lossy().chars().collect();
            !n.starts_with(&['.']) && matches(&pattern_chars, &n) && e.path().is_file()
        })
        .map(|e| dir.join(e.file_name()))
        .collect();
    if files.is_empty() {
        return Err(no_match());
    }
    files.sort();
    Ok(files)
}

/// Whether `name` matches the wildcard `pattern` (`*`/`%` any run, `?` one character).
fn matches(pattern: &[char], name: &[char]) -> bool {
    match pattern.split_first() {
        None => name.is_empty(),
        Some(('*' | '%', rest)) => (0..=name.len()).any(|k| matches(rest, &name[k..])),
        Some(('?', rest)) => !name.is_empty() && matches(rest, &name[1..]),
        Some((c, rest)) => name.first() == Some(c) && matches(rest, &name[1..]),
    }
}

/// The largest timestep LIGGGHTS writes (a signed 64-bit `bigint`).
pub const MAX_TIMESTEP: u64 = i64::MAX as u64;

/// The first two bytes of a gzip file.
const GZIP_MAGIC: [u8; 2] = [0x1f, 0x8b];

/// Frames of one file in order; the next frame's timestep is read ahead so that files can be
/// merged by timestep.
struct FrameReader {
    path: PathBuf,
    items: Items,
    lines: Box<dyn BufRead>,
    line: u64,
    text: String,
    /// Timestep and line of the next frame's `ITEM: TIMESTEP`, if any.
    next: Option<(u64, u64)>,
}

impl FrameReader {
    fn open(path: &Path, items: Items) -> Result<Self, ImportError> {
        let read_err = |error| ImportError::Read {
            path: path.to_path_buf(),
            error,
        };
        let mut file = File::open(path).map_err(read_err)?;
        let mut magic = [0u8; 2];
        let gzip = file.read(&mut magic).map_err(read_err)? == 2 && magic == GZIP_MAGIC;
        drop(file);
        let file = File::open(path).map_err(read_err)?;
        Self::new(path, items, gzip, Box::new(file))
    }

    /// [`FrameReader::open`] on the file's bytes already in memory; `path` names it in messages.
    fn from_bytes(path: &Path, items: Items, bytes: Vec<u8>) -> Result<Self, ImportError> {
        let gzip = bytes.starts_with(&GZIP_MAGIC);
        Self::new(path, items, gzip, Box::new(std::io::Cursor::new(bytes)))
    }

    /// Reads the first frame's timestep from `source` (gzip-compressed if `gzip`).
    fn new(
        path: &Path,
        items: Items,
        gzip: bool,
        source: Box<dyn Read>,
    ) -> Result<Self, ImportError> {
        let lines: Box<dyn BufRead> = if gzip {
            Box::new(BufReader::with_capacity(
                1 << 16,
                flate2::read::MultiGzDecoder::new(source),
            ))
        } else {
            Box::new(BufReader::with_capacity(1 << 16, source))
        };
        let mut reader = Self {
            path: path.to_path_buf(),
            items,
            lines,
            line: 0,
            text: String::new(),
            next: None,
        };
        reader.next = reader.timestep_header()?;
        if reader.next.is_none() {
            return Err(reader.error(1, "no frame: the file is empty".into()));
        }
        Ok(reader)
    }

    fn error(&self, line: u64, detail: String) -> ImportError {
        ImportError::At {
            path: self.path.clone(),
            line,
            detail,
        }
    }

    /// The next line (without its end), or `None` at the end of the file.
    fn read_line(&mut self) -> Result<Option<&str>, ImportError> {
        self.text.clear();
        let n = self
            .lines
            .read_line(&mut self.text)
            .map_err(|e| self.error(self.line + 1, format!("cannot read: {e}")))?;
        if n == 0 {
            return Ok(None);
        }
        self.line += 1;
        Ok(Some(self.text.trim_end_matches(['\n', '\r'])))
    }

    /// The next line, which must exist: `what` says what was expected there.
    fn expect_line(&mut self, what: &str) -> Result<String, ImportError> {
        match self.read_line()? {
            Some(l) => Ok(l.to_string()),
            None => Err(self.error(
                self.line + 1,
                format!("the file ends where {what} was expected"),
            )),
        }
    }

    /// Reads `ITEM: TIMESTEP` and its value (blank lines before it are allowed only at the end
    /// of the file); `None` at the end of the file.
    fn timestep_header(&mut self) -> Result<Option<(u64, u64)>, ImportError> {
        let item = loop {
            match self.read_line()? {
                None => return Ok(None),
                Some(l) if l.trim().is_empty() => continue,
                Some(l) => break l.trim().to_string(),
            }
        };
        let line = self.line;
        if item != "ITEM: TIMESTEP" {
            return Err(self.error(
                line,
                format!(
                    "`{}` where `ITEM: TIMESTEP` was expected (a frame has more rows than its \
                     `ITEM: NUMBER OF {}`, or this is not a LIGGGHTS text dump)",
                    shorten(&item),
                    self.items.word()
                ),
            ));
        }
        let value = self.expect_line("the timestep")?;
        let step = value
            .trim()
            .parse::<u64>()
            .ok()
            .filter(|&s| s <= MAX_TIMESTEP)
            .ok_or_else(|| {
                self.error(
                    self.line,
                    format!(
                        "timestep `{}` is not a whole number in 0..={MAX_TIMESTEP} (LIGGGHTS' \
                         64-bit signed timestep)",
                        shorten(value.trim())
                    ),
                )
            })?;
        Ok(Some((step, line)))
    }

    /// Reads the frame whose timestep was read ahead; with `skip` its rows are counted but not
    /// kept. Reads the next frame's timestep ahead and checks that it increases.
    fn read_frame(&mut self, skip: bool) -> Result<Option<FramePart>, ImportError> {
        let Some((timestep, frame_line)) = self.next else {
            return Ok(None);
        };
        let word = self.items.word();
        let count_item = self.expect_line(&format!("`ITEM: NUMBER OF {word}`"))?;
        if count_item.trim() != format!("ITEM: NUMBER OF {word}") {
            return Err(self.error(
                self.line,
                format!(
                    "`{}` where `ITEM: NUMBER OF {word}` was expected: is this a {} dump?",
                    shorten(count_item.trim()),
                    match self.items {
                        Items::Atoms => "`dump custom` (atoms)",
                        Items::Entries => "`dump local` (contacts)",
                    }
                ),
            ));
        }
        let value = self.expect_line("the number of rows")?;
        let count = value.trim().parse::<usize>().map_err(|_| {
            self.error(
                self.line,
                format!("`{}` is not a whole number of rows", shorten(value.trim())),
            )
        })?;
        let bounds = self.expect_line("`ITEM: BOX BOUNDS`")?;
        if !bounds.trim_start().starts_with("ITEM: BOX BOUNDS") {
            return Err(self.error(
                self.line,
                format!(
                    "`{}` where `ITEM: BOX BOUNDS` was expected",
                    shorten(bounds.trim())
                ),
            ));
        }
        for _ in 0..3 {
            self.expect_line("a box bound")?;
        }
        let header = self.expect_line(&format!("`ITEM: {word} ...`"))?;
        let columns_line = self.line;
        let columns: Vec<String> = match header.trim().strip_prefix(&format!("ITEM: {word}")) {
            Some(rest) => rest.split_whitespace().map(String::from).collect(),
            None => {
                return Err(self.error(
                    columns_line,
                    format!(
                        "`{}` where `ITEM: {word}` and the column names were expected",
                        shorten(header.trim())
                    ),
                ))
            }
        };
        let mut rows = String::new();
        for k in 0..count {
            let line = match self.read_line()? {
                Some(l) if !l.starts_with("ITEM:") && !l.trim().is_empty() => l,
                _ => {
                    return Err(self.error(
                        self.line.max(columns_line + 1 + k as u64),
                        format!(
                            "the frame of timestep {timestep} (line {frame_line}) declares \
                             {count} rows but has {k}"
                        ),
                    ))
                }
            };
            if !skip {
                rows.push_str(line);
                rows.push('\n');
            }
        }
        self.next = self.timestep_header()?;
        if let Some((next, line)) = self.next {
            if next <= timestep {
                return Err(self.error(
                    line,
                    format!(
                        "timestep {next} after timestep {timestep} (line {frame_line}): the \
                         timesteps of a file must increase"
                    ),
                ));
            }
        }
        Ok(Some(FramePart {
            path: self.path.clone(),
            timestep,
            count,
            columns,
            columns_line,
            rows,
        }))
    }
}

/// The first 60 characters of a line, for messages.
fn shorten(text: &str) -> String {
    match text.char_indices().nth(60) {
        Some((k, _)) => format!("{}…", &text[..k]),
        None => text.to_string(),
    }
}

/// The frames of a set of dump files merged by timestep: a file is opened when the merge
/// reaches its first timestep and closed after its last, so one file per timestep and
/// process costs no more open files than one file per process.
pub struct DumpSet {
    items: Items,
    /// Files not opened yet, by first timestep (last = earliest).
    pending: Vec<(u64, PathBuf)>,
    open: Vec<FrameReader>,
}

impl DumpSet {
    /// The files matching `pattern`; each one's first header is read (and checked) here.
    pub fn open(pattern: &str, items: Items) -> Result<Self, ImportError> {
        let mut pending = Vec::new();
        for path in expand(pattern)? {
            let reader = FrameReader::open(&path, items)?;
            let (first, _) = reader.next.expect("checked by open");
            pending.push((first, path));
        }
        pending.sort_by(|a, b| b.cmp(a));
        Ok(Self {
            items,
            pending,
            open: Vec::new(),
        })
    }

    /// One dump file whose bytes are already in memory (plain or gzip); `path` names it in
    /// messages. Its first header is read (and checked) here.
    pub fn from_bytes(path: &Path, bytes: Vec<u8>, items: Items) -> Result<Self, ImportError> {
        Ok(Self {
            items,
            pending: Vec::new(),
            open: vec![FrameReader::from_bytes(path, items, bytes)?],
        })
    }

    /// The smallest timestep not read yet, in any file.
    pub fn next_timestep(&self) -> Option<u64> {
        let open = self.open.iter().filter_map(|r| r.next.map(|(t, _)| t));
        let pending = self.pending.last().map(|(t, _)| *t);
        open.chain(pending).min()
    }

    /// Every file's part of the frame at the next timestep, in file-name order (rows left
    /// empty with `skip`); `None` when every file is read.
    pub fn read_next(&mut self, skip: bool) -> Result<Option<(u64, Vec<FramePart>)>, ImportError> {
        let Some(step) = self.next_timestep() else {
            return Ok(None);
        };
        while self.pending.last().is_some_and(|(t, _)| *t == step) {
            let (_, path) = self.pending.pop().expect("checked");
            self.open.push(FrameReader::open(&path, self.items)?);
        }
        self.open.sort_by(|a, b| a.path.cmp(&b.path));
        let mut parts = Vec::new();
        for reader in &mut self.open {
            if reader.next.is_some_and(|(t, _)| t == step) {
                parts.extend(reader.read_frame(skip)?);
            }
        }
        self.open.retain(|r| r.next.is_some());
        Ok(Some((step, parts)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wildcards_match_liggghts_file_names() {
        let m = |p: &str, n: &str| {
            matches(
                &p.chars().collect::<Vec<_>>(),
                &n.chars().collect::<Vec<_>>(),
            )
        };
        assert!(m("dump_atoms.*", "dump_atoms.20000"));
        assert!(m("dump_atoms.*.%.gz", "dump_atoms.20000.1.gz"));
        assert!(m("d.?", "d.7"));
        assert!(!m("d.?", "d.17"));
        assert!(!m("dump_atoms.*", "dump_pairs.20000"));
        assert!(m("*", ""));
    }
}
