//! Software prefetch of the data the next pair task will read, spread over the current
//! task's work. Once the state and lists outgrow the last-level cache, the hardware
//! prefetchers do not keep up with the twenty-odd arrays a pair task reads at once
//! (measured in docs/benchmarks.md: −9 % at 100 000 particles, −11 % at 400 000, but +7 % at
//! 20 000, where everything is in the cache already, so the stage asks for it only above
//! the cache size). A prefetch is a hint: it never faults and changes no result.

use std::ops::Range;
use std::sync::OnceLock;

/// Where the cache size cannot be read (the size of this project's machine's).
const DEFAULT_LAST_LEVEL_CACHE: usize = 32 << 20;
/// Cache line.
const LINE: usize = 64;
/// Arrays one task prefetches at most.
const MAX_RANGES: usize = 16;

/// Bytes of the largest cache of CPU 0, from Linux's sysfs (32 MiB where it cannot be read).
pub fn last_level_cache_bytes() -> usize {
    static BYTES: OnceLock<usize> = OnceLock::new();
    *BYTES.get_or_init(|| read_last_level_cache().unwrap_or(DEFAULT_LAST_LEVEL_CACHE))
}

fn read_last_level_cache() -> Option<usize> {
    let dir = std::path::Path::new("/sys/devices/system/cpu/cpu0/cache");
    let mut best: Option<(u32, usize)> = None;
    for entry in std::fs::read_dir(dir).ok()? {
        let path = entry.ok()?.path();
        let read = |name: &str| std::fs::read_to_string(path.join(name)).ok();
        let (Some(level), Some(size)) = (read("level"), read("size")) else {
            continue;
        };
        let level: u32 = level.trim().parse().ok()?;
        let size = parse_size(size.trim())?;
        if best.is_none_or(|(l, _)| level > l) {
            best = Some((level, size));
        }
    }
    best.map(|(_, size)| size)
}

/// `32768K`, `1M`, `512` (bytes).
fn parse_size(text: &str) -> Option<usize> {
    let (digits, unit) = match text.char_indices().find(|(_, c)| !c.is_ascii_digit()) {
        Some((at, _)) => text.split_at(at),
        None => (text, ""),
    };
    let value: usize = digits.parse().ok()?;
    let scale = match unit {
        "" => 1,
        "K" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        _ => return None,
    };
    value.checked_mul(scale)
}

/// The address and element size of an array, taken before it is split among tasks, so a
/// task can prefetch parts of it that another task owns.
#[derive(Debug, Clone, Copy)]
pub struct ArrayAddress {
    base: usize,
    element: usize,
    len: usize,
}

impl ArrayAddress {
    pub fn of<T>(array: &[T]) -> Self {
        Self {
            base: array.as_ptr() as usize,
            element: std::mem::size_of::<T>(),
            len: array.len(),
        }
    }

    pub fn bytes(&self) -> usize {
        self.len * self.element
    }
}

/// Element ranges of several arrays, each prefetched up to the same fraction of its length
/// as the task that holds this advances through its own work.
#[derive(Debug, Default)]
pub struct Prefetch {
    /// Next line to prefetch, first and end byte of each range.
    ranges: [(usize, usize, usize); MAX_RANGES],
    len: usize,
}

impl Prefetch {
    /// Adds elements `elements` of `array` (cut to its length; beyond `MAX_RANGES`
    /// ranges, ignored).
    pub fn add(&mut self, array: ArrayAddress, elements: Range<usize>) {
        let (start, end) = (elements.start.min(array.len), elements.end.min(array.len));
        if start >= end || self.len == MAX_RANGES {
            return;
        }
        let first = array.base + start * array.element;
        let last = array.base + end * array.element;
        self.ranges[self.len] = (first & !(LINE - 1), first, last);
        self.len += 1;
    }

    /// Prefetches every range up to `done` (0 to 1) of its length.
    #[inline(always)]
    pub fn advance(&mut self, done: f64) {
        let done = done.clamp(0.0, 1.0);
        for (next, first, last) in &mut self.ranges[..self.len] {
            let target = *first + ((*last - *first) as f64 * done) as usize;
            while *next < target {
                prefetch_line(*next);
                *next += LINE;
            }
        }
    }
}

#[inline(always)]
fn prefetch_line(address: usize) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is a hint that never faults and reads nothing into the program;
    // the address lies inside an array that outlives the task (see `ArrayAddress`)
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>(address as *const i8);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = address;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cache_sizes_parse_in_the_units_sysfs_writes() {
        assert_eq!(parse_size("32768K"), Some(32 << 20));
        assert_eq!(parse_size("1M"), Some(1 << 20));
        assert_eq!(parse_size("512"), Some(512));
        assert_eq!(parse_size("12Q"), None);
        assert_eq!(parse_size(""), None);
        assert!(last_level_cache_bytes() > 0);
    }

    #[test]
    fn ranges_advance_line_by_line_up_to_the_fraction_and_stay_in_the_array() {
        let array = vec![0u64; 1000];
        let address = ArrayAddress::of(&array);
        let mut prefetch = Prefetch::default();
        prefetch.add(address, 100..2000); // cut to the array's 1 000 elements
        prefetch.add(address, 10..10); // empty: not kept
        assert_eq!(prefetch.len, 1);
        let (_, first, last) = prefetch.ranges[0];
        assert_eq!(last - first, 900 * 8);
        prefetch.advance(0.5);
        let next = prefetch.ranges[0].0;
        assert!(next >= first + 450 * 8 && next < first + 450 * 8 + LINE);
        prefetch.advance(0.25); // never goes back
        assert_eq!(prefetch.ranges[0].0, next);
        prefetch.advance(2.0);
        assert!(prefetch.ranges[0].0 >= last && prefetch.ranges[0].0 < last + LINE);
    }
}
