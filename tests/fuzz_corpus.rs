//! The fuzz regression corpus (`tests/corpus/<target>/`, docs/reliability.md) replayed through the fuzz targets' own entry points: every input returns, never panics.

use recorder::fuzzing;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;

fn corpus(target: &str) -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/corpus")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

/// Every file of every target's corpus returns `Ok` or an error naming the input file;
/// a seed (`seed-*`, a real file tdex wrote or reads) is accepted by at least one reader;
/// a minimised crasher (`crash-*`, once a panic, abort or runaway allocation) is refused
/// by every reader of its target.
#[test]
fn every_corpus_input_returns_and_every_crasher_is_refused_naming_the_file() {
    let mut replayed = 0;
    for target in fuzzing::TARGETS {
        let files = corpus(target);
        assert!(
            files.iter().any(|f| name_of(f).starts_with("seed-")),
            "tests/corpus/{target} has no seed"
        );
        let file_name = fuzzing::file_name(target).unwrap();
        for file in files {
            let bytes = std::fs::read(&file).unwrap();
            let outcomes = catch_unwind(AssertUnwindSafe(|| fuzzing::run(target, &bytes)))
                .unwrap_or_else(|_| panic!("{target}: {} panicked", file.display()))
                .unwrap();
            for error in outcomes.iter().filter_map(|r| r.as_ref().err()) {
                assert!(
                    error.starts_with(file_name),
                    "{target}: {}: the error does not name the file: {error}",
                    file.display()
                );
            }
            let name = name_of(&file);
            if name.starts_with("seed-") {
                assert!(
                    outcomes.iter().any(|r| r.is_ok()),
                    "{target}: seed {} refused: {outcomes:?}",
                    file.display()
                );
            }
            if name.starts_with("crash-") {
                assert!(
                    outcomes.iter().all(|r| r.is_err()),
                    "{target}: crasher {} accepted: {outcomes:?}",
                    file.display()
                );
            }
            replayed += 1;
        }
    }
    assert!(replayed >= fuzzing::TARGETS.len());
}

fn name_of(file: &std::path::Path) -> String {
    file.file_name().unwrap().to_string_lossy().into_owned()
}
