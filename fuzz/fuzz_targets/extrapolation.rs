//! Fuzz target `extrapolation`: Bytes as a tdex extrapolation: open, info, costs, every snapshot.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Ok or Err are both fine; a panic, an abort or a runaway allocation is a finding.
    let _ = recorder::fuzzing::run("extrapolation", data);
});
