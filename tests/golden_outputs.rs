//! The outputs of a fixed set of runs, byte for byte: `tests/golden/run.sh` makes them
//! (recordings of one period with reference periods, a twin, a heated mantle and another
//! sampling; pairing sidecars; an extrapolation with each scheme, streamed and in memory;
//! compare and inspect JSON, all `--reproducible`) and `tests/golden/SHA256` holds their
//! sums as tdex wrote them before several recorded periods were added: a recording of one
//! period, and everything made from it, must stay the paper's method to the byte.
//! A deliberate change of a format regenerates the list (`bash tests/golden/run.sh
//! target/release/tdex DIR && cp DIR/SHA256 tests/golden/SHA256`) and says why in its
//! commit (docs/architecture.md#byte-identity-of-the-refactoring).

use crate::util::{repo, tdex};
use std::process::Command;

#[test]
fn one_recorded_period_gives_the_same_bytes_as_before() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("golden");
    let status = Command::new("bash")
        .arg(repo().join("tests/golden/run.sh"))
        .arg(tdex())
        .arg(&out)
        .status()
        .expect("bash runs tests/golden/run.sh");
    assert!(status.success(), "tests/golden/run.sh failed");
    let sums = |text: String| -> Vec<(String, String)> {
        let mut sums: Vec<(String, String)> = text
            .lines()
            .filter_map(|l| l.split_once("  "))
            .map(|(sum, file)| (file.to_string(), sum.to_string()))
            .collect();
        sums.sort();
        sums
    };
    let expected = sums(std::fs::read_to_string(repo().join("tests/golden/SHA256")).unwrap());
    let made = sums(std::fs::read_to_string(out.join("SHA256")).unwrap());
    assert_eq!(
        expected.len(),
        14,
        "tests/golden/SHA256 lists the 14 outputs"
    );
    let changed: Vec<&String> = expected
        .iter()
        .zip(&made)
        .filter(|(e, m)| e != m)
        .map(|(e, _)| &e.0)
        .collect();
    assert!(
        changed.is_empty() && expected.len() == made.len(),
        "outputs changed: {changed:?} (expected {} files, made {})",
        expected.len(),
        made.len()
    );
}
