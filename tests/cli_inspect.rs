//! `tdex inspect` on an extrapolation (its pairing, scheme and heat balance), its suggested
//! `n` that `--n` accepts, its histogram's tail said out loud; and the small messages a new
//! user trips over: a missing file named once, temperatures in kelvin.

use crate::cli_compare::record_and_extrapolate;
use crate::cli_record::write_foreign_mcap;
use crate::cli_run::TINY_CASE;
use crate::util::*;
use std::path::{Path, PathBuf};

/// The tiny drum with a heated mantle, recorded for τ = 0.1 s with `n = 1` and
/// `Δt_c^max = 14` steps (the collisions span more than 24 samples, and 14 shares only 2
/// with the 1 000 steps of τ), and extrapolated 3 periods.
fn heated(dir: &Path) -> (PathBuf, PathBuf) {
    let case = dir.join("heated.toml");
    let text = TINY_CASE.replace(
        "rotation_period = 2.0",
        "rotation_period = 2.0\nwall_temperature = 350.0",
    );
    std::fs::write(&case, text).unwrap();
    let (run, extra) = (dir.join("run.mcap"), dir.join("extra.mcap"));
    let (c, r, e) = (
        case.to_str().unwrap(),
        run.to_str().unwrap(),
        extra.to_str().unwrap(),
    );
    tdex_ok(&[
        "record",
        c,
        "-o",
        r,
        "--tau",
        "0.1",
        "--n",
        "1",
        "--dtc-max",
        "14",
    ]);
    tdex_ok(&["extrapolate", r, "--periods", "3", "-o", e]);
    (run, extra)
}

fn json(args: &[&str]) -> serde_json::Value {
    serde_json::from_str(&tdex_ok(args)).expect("stdout is one JSON object")
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs())
}

#[test]
fn inspect_summarises_an_extrapolation_with_its_heat_balance() {
    let dir = tempfile::tempdir().unwrap();
    let (run, extra) = heated(dir.path());
    let e = extra.to_str().unwrap();
    let v = json(&["inspect", e, "--json"]);
    assert_eq!(v["kind"], "extrapolation");
    assert_eq!(v["periods"], 3);
    assert_eq!(v["scheme"], "explicit");
    assert_eq!(v["recording"], run.to_str().unwrap());
    assert_eq!(v["case"], "tiny");
    assert_eq!(v["particles"], 250);
    assert_eq!(v["conducting_walls"], 1);
    assert_eq!(v["pairing"]["particles"], 250);
    let snapshots = v["snapshots"].as_array().unwrap();
    assert_eq!(snapshots.len(), 4, "t1 and three extrapolated periods");
    assert_eq!(snapshots[0]["index"], 1);
    assert_eq!(snapshots[3]["index"], 4);

    // the balance is the extrapolation's own (Σ m c T at t1 and at the end) ...
    let f = |key: &str| v[key].as_f64().unwrap();
    let again = json(&[
        "extrapolate",
        run.to_str().unwrap(),
        "--periods",
        "3",
        "-o",
        dir.path().join("again.mcap").to_str().unwrap(),
        "--json",
    ]);
    let g = |key: &str| again[key].as_f64().unwrap();
    assert!(
        close(f("total_heat_start"), g("total_heat_t1")),
        "{v}\n{again}"
    );
    assert!(
        close(f("total_heat_end"), g("total_heat_end")),
        "{v}\n{again}"
    );
    // ... and the heated mantle gave the bed what it gained
    let (start, end) = (f("total_heat_start"), f("total_heat_end"));
    assert!(
        end > start,
        "the 350 K mantle heats the bed: {start} -> {end}"
    );
    assert!(close(f("wall_heat"), end - start));
    assert!(close(f("heat_relative_change"), (end - start) / start));
    assert!(f("mean_temperature_end") > f("mean_temperature_start"));
    assert!(close(
        f("mean_temperature_start"),
        snapshots[0]["mean_temperature"].as_f64().unwrap()
    ));

    let text = tdex_ok(&["inspect", e]);
    for expected in [
        "extrapolation ",
        "3 periods, explicit scheme",
        run.to_str().unwrap(),
        "certified",
        "Σ m c T",
        "relative change",
        "mean T",
        "1 conducting wall gave",
    ] {
        assert!(text.contains(expected), "{expected:?} missing in\n{text}");
    }
}

#[test]
fn inspect_of_an_adiabatic_extrapolation_shows_the_heat_conserved() {
    let dir = tempfile::tempdir().unwrap();
    let (_, extra) = record_and_extrapolate(dir.path(), 0, 2);
    let v = json(&["inspect", extra.to_str().unwrap(), "--json"]);
    assert_eq!(v["kind"], "extrapolation");
    assert_eq!(v["conducting_walls"], 0);
    assert!(v["wall_heat"].is_null(), "{v}");
    let change = v["heat_relative_change"].as_f64().unwrap();
    assert!(change.abs() < 1e-10, "relative change {change}");
    let text = tdex_ok(&["inspect", extra.to_str().unwrap()]);
    assert!(text.contains("adiabatic"), "{text}");
}

#[test]
fn inspect_suggests_an_n_that_record_accepts_and_says_what_the_histogram_leaves_out() {
    let dir = tempfile::tempdir().unwrap();
    let (run, _) = heated(dir.path());
    let r = run.to_str().unwrap();
    let v = json(&["inspect", r, "--json"]);
    assert_eq!(v["kind"], "recording");
    let n = v["suggested_n"].as_u64().unwrap();
    let free = v["suggested_n_unconstrained"].as_u64().unwrap();
    let (period, dtc) = (
        v["period_steps"].as_u64().unwrap(),
        v["dtc_max_steps"].as_u64().unwrap(),
    );
    assert_eq!((period, dtc), (1000, 14));
    assert!(n <= free && period % n == 0 && dtc % n == 0, "{v}");
    assert!(
        free > n,
        "the case is chosen so that τ and Δt_c^max limit n: {v}"
    );

    let text = tdex_ok(&["inspect", r]);
    let suggestion: Vec<&str> = text
        .lines()
        .skip_while(|l| !l.starts_with("suggested n"))
        .take(2)
        .collect();
    let joined = suggestion.join("\n");
    assert!(
        suggestion[0].starts_with(&format!("suggested n   {n} steps")),
        "{joined}"
    );
    assert!(
        joined.contains(&format!("n = {free} needs --tau")),
        "what n = {free} needs is said: {joined}"
    );

    // what the line names, `record` takes
    let again = dir.path().join("again.mcap");
    let case = dir.path().join("heated.toml");
    let n_arg = n.to_string();
    tdex_ok(&[
        "record",
        case.to_str().unwrap(),
        "-o",
        again.to_str().unwrap(),
        "--tau",
        "0.1",
        "--n",
        &n_arg,
        "--dtc-max",
        "14",
    ]);

    // more bins than shown: the tail is one line that says so
    let bins = v["duration_histogram"].as_array().unwrap().len();
    assert!(bins > 24, "{bins} bins");
    let shown = text.lines().filter(|l| l.ends_with("% ≤")).count();
    assert_eq!(shown, 24, "{text}");
    let tail = format!("{} more bins", bins - 24);
    assert!(
        text.contains(&tail) && text.contains("--json has them all"),
        "{tail:?} missing in\n{text}"
    );
}

#[test]
fn inspect_names_both_kinds_for_an_mcap_file_of_another_tool() {
    let dir = tempfile::tempdir().unwrap();
    let foreign = dir.path().join("foreign.mcap");
    write_foreign_mcap(&foreign);
    let o = run_tdex(&["inspect", foreign.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("not a tdex recording or extrapolation")
            && err.contains("tdex.recording")
            && err.contains("tdex.extrapolation"),
        "{err}"
    );
}

#[test]
fn a_missing_file_is_named_and_its_reason_given_once() {
    let dir = tempfile::tempdir().unwrap();
    let missing_mcap = dir.path().join("missing.mcap");
    let missing_toml = dir.path().join("missing.toml");
    let out = dir.path().join("out.mcap");
    let (m, t, o) = (
        missing_mcap.to_str().unwrap(),
        missing_toml.to_str().unwrap(),
        out.to_str().unwrap(),
    );
    let commands: [(&[&str], &str); 5] = [
        (&["inspect", m], m),
        (&["extrapolate", m, "--periods", "2", "-o", o], m),
        (&["record", t, "-o", o], t),
        (&["run", t], t),
        (&["pair", m], m),
    ];
    for (args, file) in commands {
        let r = run_tdex(args);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(file), "{args:?} does not name {file}: {err}");
        assert_eq!(
            err.matches("No such file or directory").count(),
            1,
            "{args:?}: {err}"
        );
    }
}

#[test]
fn temperatures_are_refused_in_kelvin() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("cold = 10.0", "cold = -5.0", "temperature.cold = -5 K"),
        ("hot = 30.0", "hot = 0.0", "temperature.hot = 0 K"),
        (
            "rotation_period = 2.0",
            "rotation_period = 2.0\nwall_temperature = -20.0",
            "drum.wall_temperature = -20 K",
        ),
    ];
    for (from, to, expected) in cases {
        assert!(TINY_CASE.contains(from));
        let case = dir.path().join("cold.toml");
        std::fs::write(&case, TINY_CASE.replacen(from, to, 1)).unwrap();
        let r = run_tdex(&["run", case.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{err}");
        assert!(
            err.contains(expected) && err.contains("> 0 K") && err.contains("kelvin"),
            "{expected:?} missing in: {err}"
        );
    }
}

/// `tdex inspect --json run.mcap | head -c 1`: once the reader has gone, tdex ends quietly
/// on the broken pipe (SIGPIPE, as any Unix tool), not with a panic on its next print.
/// The pipe holds one page and the JSON is several pages, so tdex's write waits until every
/// read end is closed, then fails. A read end inherited for a moment by a process spawned
/// beside this test (between its fork and exec) only delays that: the outcome is the same.
#[test]
fn a_reader_that_stops_early_ends_inspect_quietly() {
    use std::os::fd::AsRawFd;
    use std::os::unix::process::ExitStatusExt;
    use std::process::{Command, Stdio};
    let dir = tempfile::tempdir().unwrap();
    let (run, _) = heated(dir.path());
    let page: i32 = 4096;
    let json = tdex_ok(&["inspect", "--json", run.to_str().unwrap()]);
    assert!(
        json.len() > 2 * page as usize,
        "{} bytes of JSON",
        json.len()
    );
    let (reader, writer) = std::io::pipe().unwrap();
    // SAFETY: fcntl on a pipe descriptor this test owns; no memory is passed.
    let capacity = unsafe { libc::fcntl(writer.as_raw_fd(), libc::F_SETPIPE_SZ, page) };
    assert_eq!(capacity, page, "{}", std::io::Error::last_os_error());
    drop(reader);
    let child = Command::new(tdex())
        .args(["inspect", "--json", run.to_str().unwrap()])
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.is_empty(), "{err}");
    assert_eq!(out.status.signal(), Some(libc::SIGPIPE), "{:?}", out.status);
}
