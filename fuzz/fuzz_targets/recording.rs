//! Fuzz target `recording`: Bytes as a tdex recording: open, info, summary, costs, snapshots, the whole table.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Ok or Err are both fine; a panic, an abort or a runaway allocation is a finding.
    let _ = recorder::fuzzing::run("recording", data);
});
