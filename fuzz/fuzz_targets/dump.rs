//! Fuzz target `dump`: Bytes (plain or gzip) as a LIGGGHTS atom dump and as a contact dump, read as `tdex import liggghts` reads them.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Ok or Err are both fine; a panic, an abort or a runaway allocation is a finding.
    let _ = recorder::fuzzing::run("dump", data);
});
