//! `tdex bench`: measured figures for docs/benchmarks.md, each against its peer in the same run.

mod engine;
mod liggghts;
mod record;

pub use engine::engine;
pub use liggghts::check_deck;
pub use record::record;

/// Peak resident memory of this process so far (bytes), from `VmHWM` in `/proc/self/status`;
/// `None` where the kernel does not say.
pub fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
