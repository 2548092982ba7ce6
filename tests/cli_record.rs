//! `tdex record` and `tdex inspect` end to end on the tiny drum: the file reads back through
//! the reader API, the Python MCAP readers and `inspect`; neither the thread count nor the
//! vector instructions change it;
//! bad flags and damaged files give clear errors.

use crate::cli_run::TINY_CASE;
use crate::util::*;
use std::path::{Path, PathBuf};
use tdex_format::{FormatError, RecordingReader};

/// The tiny drum with its mantle held at 350 K, so the table has wall rows.
fn heated_case() -> String {
    TINY_CASE.replace(
        "rotation_period = 2.0",
        "rotation_period = 2.0\nwall_temperature = 350.0",
    )
}

fn write_case(dir: &Path, text: &str) -> PathBuf {
    let case = dir.join("tiny.toml");
    std::fs::write(&case, text).unwrap();
    case
}

/// Records `case` for τ = 0.1 s with `extra` flags, asserting success.
fn record(case: &Path, out: &Path, extra: &[&str]) {
    record_in(std::process::Command::new(tdex()), case, out, extra);
}

/// [`record`] by `command` (tdex, with its environment set).
fn record_in(mut command: std::process::Command, case: &Path, out: &Path, extra: &[&str]) {
    let (case, out) = (case.to_str().unwrap(), out.to_str().unwrap());
    command.args(["record", case, "-o", out, "--tau", "0.1", "--json"]);
    let o = command.args(extra).output().expect("tdex starts");
    assert!(
        o.status.success(),
        "record failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// Writes a valid MCAP file of another tool to `path`: one JSON message on `/camera`.
pub(crate) fn write_foreign_mcap(path: &Path) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = mcap::Writer::new(file).unwrap();
    let ch = w
        .add_channel(0, "/camera", "json", &Default::default())
        .unwrap();
    w.write_to_known_channel(
        &mcap::records::MessageHeader {
            channel_id: ch,
            sequence: 0,
            log_time: 0,
            publish_time: 0,
        },
        b"{}",
    )
    .unwrap();
    w.finish().unwrap();
}

fn inspect_json(file: &Path) -> serde_json::Value {
    let o = run_tdex(&["inspect", file.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn a_recording_reads_back_through_the_reader_api_and_inspect() {
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path(), &heated_case());
    let out = dir.path().join("run.mcap");
    record(
        &case,
        &out,
        &["--reference", "2", "--n", "5", "--dtc-max", "20"],
    );
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("partial"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");

    let reader = RecordingReader::open(&out).unwrap();
    let info = reader.info().clone();
    assert_eq!(
        (info.particles, info.sample_every, info.dtc_max_steps),
        (250, 5, 20)
    );
    assert_eq!(info.period_steps, 1000);
    let snaps = reader.snapshots().unwrap();
    assert_eq!(
        snaps.iter().map(|s| s.index).collect::<Vec<_>>(),
        vec![0, 1, 2, 3]
    );
    for s in &snaps {
        assert!((s.time - info.snapshot_time(s.index)).abs() < 1e-9);
    }
    // split start at t0: hot and cold; the heated mantle warms the bed afterwards
    let mean = |k: usize| snaps[k].temp.iter().sum::<f64>() / 250.0;
    assert!((mean(0) - 20.0).abs() < 0.05, "t0 mean {}", mean(0));
    assert!(mean(3) > mean(1) && mean(1) > mean(0));

    let (mut rows, mut wall_rows, mut last_start) = (0u64, 0u64, 0u64);
    for batch in reader.table() {
        let batch = batch.unwrap();
        assert_eq!(batch.first_row, rows);
        for r in &batch.rows {
            assert!(r.start_step >= last_start && r.start_step + r.duration_steps as u64 <= 1000);
            assert!(r.duration_steps % 5 == 0 && r.duration_steps <= 20);
            last_start = r.start_step;
            wall_rows += (r.j >= 250) as u64;
        }
        rows += batch.rows.len() as u64;
    }
    let summary = reader.summary().unwrap();
    assert_eq!((summary.rows, summary.wall_rows), (rows, wall_rows));
    assert!(
        wall_rows > 0 && rows > wall_rows,
        "{rows} rows, {wall_rows} wall rows"
    );
    assert_eq!(reader.info().walls[0].temperature, Some(350.0));

    let json = inspect_json(&out);
    assert_eq!(json["rows"], rows);
    assert_eq!(json["wall_rows"], wall_rows);
    assert_eq!(json["conducting_walls"], 1);
    assert_eq!(json["snapshots"].as_array().unwrap().len(), 4);
    assert!(json["bytes_per_row"].as_f64().unwrap() > 0.0);
    assert!(json["max_cfl"]["cfl"].as_f64().unwrap() > 0.0);
    let collisions: u64 = json["duration_histogram"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["count"].as_u64().unwrap())
        .sum();
    assert_eq!(json["collisions"], collisions);
    assert!(json["suggested_n"].as_u64().unwrap() >= 1);
    let human = run_tdex(&["inspect", out.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&human.stdout);
    assert!(
        text.contains("suggested n") && text.contains(&format!("{rows} rows")),
        "{text}"
    );
}

#[test]
fn the_recording_is_byte_identical_whatever_the_thread_count_up_to_its_costs() {
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path(), TINY_CASE);
    let (a, b) = (dir.path().join("one.mcap"), dir.path().join("two.mcap"));
    record(&case, &a, &["--threads", "1"]);
    record(&case, &b, &["--threads", "2"]);
    let (a, b) = (std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
    let (ca, cb) = (costs_record_offset(&a), costs_record_offset(&b));
    assert_eq!(ca, cb, "the costs record starts at different offsets");
    assert!(
        ca > a.len() / 2,
        "costs must come after the table and snapshots"
    );
    assert!(
        a[..ca] == b[..cb],
        "recordings differ before the costs record"
    );
}

#[test]
fn the_recording_is_byte_identical_whatever_the_vector_instructions_up_to_its_costs() {
    // TDEX_SIMD caps the instructions the engine uses (the pair law on four-lane AVX2
    // registers, one contact at a time, or the widest this CPU has); each must compute the
    // same bits
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path(), TINY_CASE);
    let recording = |simd: Option<&str>| {
        let out = dir
            .path()
            .join(format!("{}.mcap", simd.unwrap_or("widest")));
        let mut command = std::process::Command::new(tdex());
        match simd {
            Some(simd) => command.env("TDEX_SIMD", simd),
            None => command.env_remove("TDEX_SIMD"),
        };
        record_in(command, &case, &out, &["--threads", "1"]);
        let bytes = std::fs::read(out).unwrap();
        let costs = costs_record_offset(&bytes);
        bytes[..costs].to_vec()
    };
    let widest = recording(None);
    for simd in ["avx2", "scalar"] {
        assert!(
            recording(Some(simd)) == widest,
            "TDEX_SIMD={simd} changed the recording"
        );
    }
    // the costs, which depend on the instructions, say which ran
    let scalar = dir.path().join("scalar.mcap");
    let json = inspect_json(&scalar);
    assert_eq!(json["costs"]["vector_instructions"], "scalar", "{json}");
    let text = tdex_ok(&["inspect", scalar.to_str().unwrap()]);
    assert!(text.contains("threads, no vector instructions;"), "{text}");
}

#[test]
fn a_vector_instruction_set_tdex_has_no_build_for_is_refused_before_any_work() {
    let o = std::process::Command::new(tdex())
        .args(["run", "cases/small_drum.toml"])
        .current_dir(repo())
        .env("TDEX_SIMD", "sse9")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("TDEX_SIMD=\"sse9\"") && err.contains("avx512, avx2 or scalar"),
        "{err}"
    );
}

#[test]
fn the_python_mcap_reader_decodes_every_batch_and_snapshot() {
    if !python_with("mcap, mcap_protobuf", "mcap mcap-protobuf-support") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path(), &heated_case());
    for (name, extra) in [
        ("q.mcap", vec!["--reference", "1"]),
        ("x.mcap", vec!["--exact-area"]),
    ] {
        let out = dir.path().join(name);
        record(&case, &out, &extra);
        let json = dir.path().join("inspect.json");
        std::fs::write(&json, serde_json::to_vec(&inspect_json(&out)).unwrap()).unwrap();
        let o = std::process::Command::new("python3")
            .arg(repo().join("tests/python/read_recording.py"))
            .args([&out, &json])
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "python reader: {}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

/// Runs `tdex inspect` on `file` and the reader API over the whole file; both must fail with
/// a message containing `expect` (and inspect with exit code 2).
fn assert_refused(file: &Path, expect: &str) {
    let o = run_tdex(&["inspect", file.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(2),
        "inspect {}: {err}",
        file.display()
    );
    assert!(
        err.contains(expect) && err.contains(&*file.to_string_lossy()),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    let api = RecordingReader::open(file).and_then(|r| {
        r.snapshots()?;
        r.table().try_for_each(|b| b.map(|_| ()))
    });
    let e: FormatError = api.expect_err("the reader API must refuse it");
    assert!(e.to_string().contains(expect), "reader API: {e}");
}

#[test]
fn damaged_foreign_and_missing_files_are_refused_with_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path(), TINY_CASE);
    let good = dir.path().join("good.mcap");
    record(&case, &good, &[]);
    let bytes = std::fs::read(&good).unwrap();

    let missing = dir.path().join("missing.mcap");
    assert_refused(&missing, "cannot open");

    let truncated = dir.path().join("truncated.mcap");
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    assert_refused(&truncated, "truncated");

    let not_mcap = dir.path().join("case.mcap");
    std::fs::write(&not_mcap, TINY_CASE).unwrap();
    assert_refused(&not_mcap, "not an MCAP file");

    // flip bytes in the middle of the table's compressed chunks
    let corrupted = dir.path().join("corrupted.mcap");
    let mut damaged = bytes.clone();
    let mid = damaged.len() / 2;
    for b in &mut damaged[mid..mid + 64] {
        *b ^= 0x5A;
    }
    std::fs::write(&corrupted, &damaged).unwrap();
    assert_refused(&corrupted, "corrupted");

    // a valid MCAP file of another tool
    let foreign = dir.path().join("foreign.mcap");
    write_foreign_mcap(&foreign);
    assert_refused(&foreign, "not a tdex recording");
}

#[test]
fn record_refuses_bad_settings_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path(), TINY_CASE);
    let out = dir.path().join("r.mcap");
    let c = case.to_str().unwrap();
    let o = out.to_str().unwrap();
    let cases: [(&[&str], &str); 6] = [
        (&["--dtc-max", "15"], "--dtc-max = 15"),
        (&["--n", "0"], "--n = 0"),
        (&["--tau", "0.10005"], "multiple of n"),
        (&["--tau=-1"], "--tau = -1"),
        (&["--tau-rev", "0"], "--tau-rev = 0"),
        (&["--threads", "0"], "--threads = 0"),
    ];
    for (extra, expect) in cases {
        let mut args = vec!["record", c, "-o", o];
        args.extend_from_slice(extra);
        let r = run_tdex(&args);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{extra:?}: {err}");
        assert!(err.contains(expect), "{extra:?}: {err}");
    }
    let r = run_tdex(&["record", c, "-o", "/nonexistent-dir/r.mcap"]);
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains("does not exist"));
    assert!(!out.exists(), "nothing may be written for refused settings");
}
