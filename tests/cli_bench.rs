//! `tdex bench CASE --vs-liggghts`: the LIGGGHTS peer starts from tdex's own bed at t0.

use crate::util::*;

/// `small_drum` with a short settling and spin-up, so that the test reaches t0 in seconds.
fn short_small_drum(dir: &std::path::Path) -> std::path::PathBuf {
    let case = std::fs::read_to_string(repo().join("cases/small_drum.toml")).unwrap();
    let short: Vec<String> = case
        .lines()
        .map(|line| match line.split_whitespace().next() {
            Some("settle") => "settle = 0.2".to_string(),
            Some("spin_up") => "spin_up = 0.3".to_string(),
            _ => line.to_string(),
        })
        .collect();
    let path = dir.join("short_drum.toml");
    std::fs::write(&path, short.join("\n")).unwrap();
    path
}

/// The value after `key=` on the log line that starts with `label`.
fn logged(log: &str, label: &str, key: &str) -> f64 {
    let line = log
        .lines()
        .find(|l| l.starts_with(label))
        .unwrap_or_else(|| panic!("no {label} line in the LIGGGHTS log"));
    let word = line
        .split_whitespace()
        .find_map(|w| w.strip_prefix(&format!("{key}=")))
        .unwrap_or_else(|| panic!("no {key}= on: {line}"));
    word.parse().unwrap()
}

#[test]
fn the_liggghts_peer_runs_from_tdexs_bed_at_t0() {
    if !liggghts_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let case = short_small_drum(dir.path());
    let peer = dir.path().join("peer");
    let out = tdex_ok(&[
        "bench",
        case.to_str().unwrap(),
        "--steps",
        "200",
        "--threads",
        "2",
        "--vs-liggghts",
        "--liggghts-dir",
        peer.to_str().unwrap(),
        "--json",
    ]);
    let bench: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(bench["liggghts_particle_steps_per_s"].as_f64().unwrap() > 0.0);
    assert!(bench["ratio"].as_f64().unwrap() > 0.0);
    let log = std::fs::read_to_string(peer.join("log.liggghts")).unwrap();
    // every particle of tdex's bed read, none inserted by LIGGGHTS
    assert!(log.contains("READ 2000 of 2000 particles at t0"), "{log}");
    assert!(!log.contains("INSERTED"));
    assert_eq!(logged(&log, "HEATING_START", "hot") as u64, 1000);
    // tdex's bed, not a loose one: its contacts per particle are tdex's at t0 within 10 %
    let z_lg = logged(&log, "HEATING_START", "Z");
    let z_tdex = bench["contacts_per_particle"].as_f64().unwrap();
    assert!(
        (z_lg / z_tdex - 1.0).abs() < 0.1,
        "LIGGGHTS {z_lg}, tdex {z_tdex}"
    );
    // an adiabatic drum: the heat of the bed is conserved over the timed steps
    let (q0, q1) = (
        logged(&log, "HEATING_START", "Q"),
        logged(&log, "HEATING_END", "Q"),
    );
    assert!((q1 - q0).abs() <= 1e-9 * q0, "Q {q0} -> {q1}");
}

#[test]
fn the_bench_names_the_vector_instructions_it_ran_with() {
    let dir = tempfile::tempdir().unwrap();
    let case = short_small_drum(dir.path());
    let bench = |simd: &str, json: bool| {
        let mut command = std::process::Command::new(tdex());
        command
            .args(["bench", case.to_str().unwrap(), "--steps", "20"])
            .args(["--threads", "1"])
            .env("TDEX_SIMD", simd);
        if json {
            command.arg("--json");
        }
        let o = command.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap()
    };
    let json: serde_json::Value = serde_json::from_str(&bench("scalar", true)).unwrap();
    assert_eq!(json["vector_instructions"], "scalar");
    let text = bench("scalar", false);
    assert!(
        text.contains("vectors       none (one contact at a time)"),
        "{text}"
    );
}

#[test]
fn a_case_the_deck_cannot_model_is_refused_before_the_dem() {
    let dir = tempfile::tempdir().unwrap();
    let case = short_small_drum(dir.path());
    let text = std::fs::read_to_string(&case).unwrap();
    for (field, from, to, why) in [
        (
            "the Hertz contact area",
            "contact_area = \"overlap\"",
            "contact_area = \"hertz\"",
            "has no Hertz contact area",
        ),
        (
            "a periodic section",
            "end_caps = \"rotating\"",
            "end_caps = \"periodic\"",
            "closes the drum with end caps",
        ),
    ] {
        assert!(text.contains(from), "small_drum no longer sets {from}");
        let changed = dir.path().join("changed.toml");
        std::fs::write(&changed, text.replace(from, to)).unwrap();
        let peer = dir.path().join("peer");
        let o = run_tdex(&[
            "bench",
            changed.to_str().unwrap(),
            "--steps",
            "20",
            "--vs-liggghts",
            "--liggghts-dir",
            peer.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{field}: {err}");
        assert!(
            err.contains("changed.toml") && err.contains(why),
            "{field}: {err}"
        );
        // refused in the plan: no DEM to t0, so no bed written for the peer
        assert!(!peer.exists(), "{field}");
    }
}
