//! The memory an extrapolation may use: what the machine and the cgroup can still give.

/// The memory an extrapolation may use, and where that figure came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MemoryLimit {
    /// `u64::MAX` when no limit is known.
    pub bytes: u64,
    pub source: String,
}

impl MemoryLimit {
    /// The default: 80 % of what the machine can still give (`MemAvailable` in
    /// /proc/meminfo) and of what the process's cgroup still allows (`memory.max` −
    /// `memory.current`, cgroup v2), whichever is smaller. The 20 % left is for the page
    /// cache holding the recording and for the rest of the machine. Without /proc/meminfo
    /// there is no limit (the table is held in memory, as before `--max-memory`).
    pub fn available() -> Self {
        let mut found: Vec<(u64, &str)> = Vec::new();
        if let Some(kb) = std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|text| meminfo_kb(&text, "MemAvailable:"))
        {
            found.push((kb.saturating_mul(1024), "MemAvailable"));
        }
        if let Some(room) = cgroup_room() {
            found.push((room, "the cgroup's memory.max"));
        }
        match found.into_iter().min() {
            Some((bytes, what)) => Self {
                bytes: bytes / 5 * 4,
                source: format!("80 % of {what}"),
            },
            None => Self {
                bytes: u64::MAX,
                source: "no limit known: no /proc/meminfo".into(),
            },
        }
    }

    /// Whether a limit is known.
    pub fn is_known(&self) -> bool {
        self.bytes != u64::MAX
    }
}

/// A `Key:   123 kB` line of /proc/meminfo, in kB.
fn meminfo_kb(text: &str, key: &str) -> Option<u64> {
    text.lines()
        .find_map(|l| l.strip_prefix(key))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|v| v.parse().ok())
}

/// What the process's cgroup (v2) still allows, if it sets a limit.
fn cgroup_room() -> Option<u64> {
    let own = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let path = own.lines().find_map(|l| l.strip_prefix("0::"))?;
    let dir = std::path::Path::new("/sys/fs/cgroup").join(path.trim_start_matches('/'));
    let read = |name: &str| -> Option<u64> {
        std::fs::read_to_string(dir.join(name))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    // "max" (no limit) does not parse
    let max = read("memory.max")?;
    Some(max.saturating_sub(read("memory.current").unwrap_or(0)))
}
