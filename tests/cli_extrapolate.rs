//! `tdex extrapolate`: the memory stated before the work (`--max-memory`), a table that does not fit streamed from the file with the same bytes out as in memory, a limit below the per-particle state refused, `--reproducible` pairings and extrapolations that are the same bytes whatever the thread count, and `--mirror` stated, stored apart and reproducible.

use crate::cli_run::TINY_CASE;
use crate::util::*;
use std::path::{Path, PathBuf};
use std::process::Output;

/// The tiny drum with a heated mantle (wall rows), recorded with `n = 1`, `Δt_c^max = 2`
/// steps: about 250 000 rows, four batches of 65 536 on the wire, so a streamed replay
/// crosses batch boundaries (inside synchronous groups too).
fn many_rows(dir: &Path) -> PathBuf {
    let heated = TINY_CASE.replace(
        "rotation_period = 2.0",
        "rotation_period = 2.0\nwall_temperature = 350.0",
    );
    record(
        dir,
        &heated,
        &["--tau", "0.1", "--n", "1", "--dtc-max", "2"],
    )
}

/// The tiny drum recorded with `--reproducible` into `dir/run.mcap`.
fn tiny_reproducible(dir: &Path) -> PathBuf {
    record(dir, TINY_CASE, &["--reproducible"])
}

/// The case `case` (TOML text) recorded with `flags` into `dir/run.mcap`.
fn record(dir: &Path, case: &str, flags: &[&str]) -> PathBuf {
    let case_file = dir.join("tiny.toml");
    std::fs::write(&case_file, case).unwrap();
    let run = dir.join("run.mcap");
    let mut args = vec![
        "record",
        case_file.to_str().unwrap(),
        "-o",
        run.to_str().unwrap(),
    ];
    args.extend_from_slice(flags);
    tdex_ok(&args);
    run
}

/// `tdex extrapolate RUN --periods 3 -o OUT --json EXTRA…`.
fn extrapolate(run: &Path, out: &Path, extra: &[&str]) -> Output {
    extrapolate_printing(run, out, &[&["--json"], extra].concat())
}

/// `tdex extrapolate RUN --periods 3 -o OUT EXTRA…`: the summary as printed for a reader.
fn extrapolate_printing(run: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "extrapolate",
        run.to_str().unwrap(),
        "--periods",
        "3",
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    run_tdex(&args)
}

fn json_of(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// The file up to its costs record (the only part that holds timings).
fn up_to_costs(path: &Path) -> Vec<u8> {
    let bytes = std::fs::read(path).unwrap();
    let name = b"tdex.extrapolation_costs";
    // opcode (1 byte) and record length (8) before the name's length (4)
    let at = bytes
        .windows(name.len())
        .position(|w| w == name)
        .expect("a costs record")
        - 13;
    bytes[..at].to_vec()
}

#[test]
fn a_table_over_the_limit_is_streamed_and_gives_the_same_file_as_in_memory() {
    let dir = tempfile::tempdir().unwrap();
    let run = many_rows(dir.path());
    for scheme in ["explicit", "exact", "synchronous"] {
        let memory_out = dir.path().join(format!("{scheme}-memory.mcap"));
        let o = extrapolate(&run, &memory_out, &["--scheme", scheme]);
        let stated = String::from_utf8_lossy(&o.stderr).into_owned();
        let mem_json = json_of(&o);
        let json = &mem_json;
        let m = &json["memory"];
        let rows = json["rows"].as_u64().unwrap();
        assert!(
            rows > 3 * 65_536,
            "{rows} rows: the table must span several batches"
        );
        assert_eq!(json["table_in_memory"], true);
        assert_eq!(
            (m["table"].as_str(), m["reason"].as_str()),
            (Some("in_memory"), Some("fits"))
        );
        assert_eq!(m["table_bytes"].as_u64(), Some(rows * 16));
        let (in_memory, streamed) = (
            m["in_memory_bytes"].as_u64().unwrap(),
            m["streamed_bytes"].as_u64().unwrap(),
        );
        assert!(
            streamed < in_memory && in_memory - streamed >= rows * 16,
            "{m}"
        );
        assert!(stated.contains("memory        needs"), "{stated}");

        // a limit the streamed replay fits and the table does not
        let streamed_out = dir.path().join(format!("{scheme}-streamed.mcap"));
        let limit = streamed.to_string();
        let o = extrapolate(
            &run,
            &streamed_out,
            &["--scheme", scheme, "--max-memory", &limit],
        );
        let stated = String::from_utf8_lossy(&o.stderr).into_owned();
        let json = json_of(&o);
        let m = &json["memory"];
        assert_eq!(json["table_in_memory"], false, "{stated}");
        assert_eq!(
            (m["table"].as_str(), m["reason"].as_str()),
            (Some("streamed"), Some("too_large"))
        );
        assert_eq!(m["limit_bytes"].as_u64(), Some(streamed));
        assert_eq!(m["limit_source"], "--max-memory");
        for needed in ["streaming from disk", "per period slower", "> limit"] {
            assert!(stated.contains(needed), "missing '{needed}': {stated}");
        }
        assert!(
            up_to_costs(&memory_out) == up_to_costs(&streamed_out),
            "{scheme}: the streamed replay wrote other bytes than the in-memory one"
        );
        assert_eq!(json["total_heat_end"], mem_json["total_heat_end"]);
    }
}

#[test]
fn a_limit_below_the_per_particle_state_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let run = many_rows(dir.path());
    let out = dir.path().join("extra.mcap");
    let o = extrapolate(&run, &out, &["--max-memory", "2M"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for needed in [
        "not enough memory",
        "250 particles",
        "limit of 2.00 MiB (--max-memory)",
        "at least",
        &*run.to_string_lossy(),
    ] {
        assert!(err.contains(needed), "missing '{needed}': {err}");
    }
    assert!(!out.exists(), "no output after a refusal");
    assert!(
        !dir.path().join("run.mcap.pairing.json").exists(),
        "refused before the pairing"
    );

    for (bad, expect) in [
        ("12Q", "not a size"),
        ("100", "at least 1M"),
        ("-1G", "at least 1M"),
    ] {
        let o = extrapolate(&run, &out, &[&format!("--max-memory={bad}")]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad}: {err}");
        assert!(
            err.contains(&format!("--max-memory {bad}")) && err.contains(expect),
            "{bad}: {err}"
        );
    }
    // sizes as a user writes them
    let o = extrapolate(&run, &out, &["--max-memory", "1.5G"]);
    assert_eq!(json_of(&o)["memory"]["limit_bytes"].as_u64(), Some(3 << 29));
}

#[test]
fn reproducible_pairings_and_extrapolations_are_the_same_bytes_on_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let run = tiny_reproducible(dir.path());
    let run_s = run.to_str().unwrap();
    let sidecar = dir.path().join("run.mcap.pairing.json");
    let mut pairings = Vec::new();
    for threads in ["1", "2"] {
        tdex_ok(&["pair", run_s, "--threads", threads, "--reproducible"]);
        pairings.push(std::fs::read(&sidecar).unwrap());
    }
    assert!(
        pairings[0] == pairings[1],
        "the sidecar depends on the threads"
    );
    let text = String::from_utf8_lossy(&pairings[0]);
    assert!(
        !text.contains("seconds") && !text.contains("threads"),
        "{text}"
    );

    // the extrapolation computes its own pairing (no sidecar) on each thread count
    let mut files = Vec::new();
    for threads in ["1", "2"] {
        std::fs::remove_file(&sidecar).unwrap();
        let out = dir.path().join(format!("extra{threads}.mcap"));
        json_of(&extrapolate(
            &run,
            &out,
            &["--threads", threads, "--reproducible"],
        ));
        files.push(std::fs::read(&out).unwrap());
    }
    assert!(
        files[0] == files[1],
        "the extrapolation depends on the threads"
    );
    // the pairing stored by the last run, read back and reused: the same bytes again (the
    // sidecar's floats read back to the bit)
    let reused = dir.path().join("reused.mcap");
    let o = extrapolate(&run, &reused, &["--reproducible"]);
    assert_eq!(json_of(&o)["costs"]["pairing_reused"], true);
    assert!(
        std::fs::read(&reused).unwrap() == files[0],
        "an extrapolation with a reused pairing differs from one that computed it"
    );
    let costs = b"tdex.extrapolation_costs";
    assert!(!files[0].windows(costs.len()).any(|w| w == costs));
    // without the flag the file holds the costs record
    let timed = dir.path().join("timed.mcap");
    json_of(&extrapolate(&run, &timed, &[]));
    assert!(!up_to_costs(&timed).is_empty());
}

/// The sidecars of `tdex extrapolate --mirror` on `run.mcap`: the mirror's pairing and the
/// plain one its check compares it with.
const MIRROR_SIDECARS: [&str; 2] = [
    "run.mcap.pairing.t1-mirror-t0.json",
    "run.mcap.pairing.json",
];

#[test]
fn the_mirror_is_stated_stored_apart_and_the_same_bytes_on_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let run = tiny_reproducible(dir.path());
    let mut files = Vec::new();
    for threads in ["1", "2"] {
        let out = dir.path().join(format!("m{threads}.mcap"));
        let o = extrapolate(
            &run,
            &out,
            &["--mirror", "--threads", threads, "--reproducible"],
        );
        let report = json_of(&o);
        assert_eq!(report["symmetry"], "axial_mirror");
        assert_eq!(report["pairing"]["certified"], true);
        // the check: the mirrored pairing's mean distance beside the plain one's
        let check = &report["mirror_check"][0];
        assert_eq!(
            check["mirrored_mean_diameters"],
            report["pairing"]["mean_distance_diameters"]
        );
        assert!(check["plain_mean_diameters"].as_f64().unwrap() > 0.0);
        files.push(std::fs::read(&out).unwrap());
        let sidecars = MIRROR_SIDECARS.map(|f| std::fs::read(dir.path().join(f)).unwrap());
        // `tdex pair --mirror` computes the same two pairings, and says the same check
        let paired: serde_json::Value = serde_json::from_str(&tdex_ok(&[
            "pair",
            run.to_str().unwrap(),
            "--mirror",
            "--reproducible",
            "--json",
            "--threads",
            threads,
        ]))
        .unwrap();
        assert_eq!(paired["mirror_check"], *check);
        assert_eq!(
            paired["mirror"]["mean_distance_diameters"],
            check["mirrored_mean_diameters"]
        );
        for (f, before) in MIRROR_SIDECARS.iter().zip(&sidecars) {
            assert!(
                std::fs::read(dir.path().join(f)).unwrap() == *before,
                "{f} differs"
            );
            std::fs::remove_file(dir.path().join(f)).unwrap();
        }
    }
    assert!(files[0] == files[1], "the mirror depends on the threads");
    // the mirror's pairing has a sidecar of its own, beside the plain one of its check
    let m = dir.path().join("m.mcap");
    let printed = extrapolate_printing(&run, &m, &["--mirror"]);
    assert!(printed.status.success());
    let text = String::from_utf8(printed.stdout).unwrap();
    assert!(
        text.contains("pairing       t1 to the mirror image of t0: mean distance")
            && text.contains("symmetry      axial mirror")
            && text.contains("mirror check  t1 to t0: mean distance"),
        "{text}"
    );
    assert!(dir
        .path()
        .join("run.mcap.pairing.t1-mirror-t0.json")
        .exists());
    assert!(dir.path().join("run.mcap.pairing.json").exists());
    let inspected = tdex_ok(&["inspect", m.to_str().unwrap()]);
    assert!(
        inspected.contains("t1 to the mirror image of t0")
            && inspected.contains("axial mirror")
            && inspected.contains("mirror check  t1 to t0: mean distance"),
        "{inspected}"
    );
    // the check is stored with the extrapolation: inspect and the report state it
    let stored: serde_json::Value =
        serde_json::from_str(&tdex_ok(&["inspect", m.to_str().unwrap(), "--json"])).unwrap();
    assert!(
        stored["mirror_check"][0]["mirrored_mean_diameters"].as_f64() > Some(0.0),
        "{stored}"
    );
    let report = dir.path().join("report");
    tdex_ok(&[
        "report",
        run.to_str().unwrap(),
        m.to_str().unwrap(),
        "-o",
        report.to_str().unwrap(),
    ]);
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(md.contains("Mirror check"), "{md}");
    // without the flag: no symmetry, no check
    let plain = dir.path().join("p.mcap");
    let report = json_of(&extrapolate(&run, &plain, &[]));
    assert_eq!(report["symmetry"], "none");
    assert!(report.get("mirror_check").is_none());
    let stored = tdex_ok(&["inspect", plain.to_str().unwrap(), "--json"]);
    assert!(!stored.contains("mirror_check"), "{stored}");
    let paired = tdex_ok(&["pair", run.to_str().unwrap(), "--mirror"]);
    assert!(
        paired.contains("mirror image  ") && paired.contains("mirror check  t1 to t0"),
        "{paired}"
    );
}
