//! `tdex extrapolate --max-memory`: the memory stated before the work, a table that does not fit streamed from the file with the same bytes out as in memory, and a limit below the per-particle state refused.

use crate::cli_run::TINY_CASE;
use crate::util::*;
use std::path::{Path, PathBuf};
use std::process::Output;

/// The tiny drum with a heated mantle (wall rows), recorded with `n = 1`, `Δt_c^max = 2`
/// steps: about 250 000 rows, four batches of 65 536 on the wire, so a streamed replay
/// crosses batch boundaries (inside synchronous groups too).
fn many_rows(dir: &Path) -> PathBuf {
    let case = dir.join("tiny.toml");
    let heated = TINY_CASE.replace(
        "rotation_period = 2.0",
        "rotation_period = 2.0\nwall_temperature = 350.0",
    );
    std::fs::write(&case, heated).unwrap();
    let run = dir.join("run.mcap");
    tdex_ok(&[
        "record",
        case.to_str().unwrap(),
        "-o",
        run.to_str().unwrap(),
        "--tau",
        "0.1",
        "--n",
        "1",
        "--dtc-max",
        "2",
    ]);
    run
}

fn extrapolate(run: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "extrapolate",
        run.to_str().unwrap(),
        "--periods",
        "3",
        "-o",
        out.to_str().unwrap(),
        "--json",
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
        assert_eq!(m["table_bytes"].as_u64(), Some(rows * 24));
        let (in_memory, streamed) = (
            m["in_memory_bytes"].as_u64().unwrap(),
            m["streamed_bytes"].as_u64().unwrap(),
        );
        assert!(
            streamed < in_memory && in_memory - streamed >= rows * 24,
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
