//! `tdex run` through the CLI on a tiny drum: the summary and its JSON keys.

use crate::util::*;

/// A 250-particle drum run for a fraction of a second.
pub const TINY_CASE: &str = r#"
name = "tiny"
seed = 5
[particles]
count = 250
radius = 0.005
[material]
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.3
conductivity = 100.0
heat_capacity = 840.0
[contact]
particle_particle = { restitution = 0.2, friction = 0.3, rolling_friction = 0.002 }
particle_wall = { restitution = 0.2, friction = 0.5, rolling_friction = 0.002 }
[drum]
radius = 0.05
length = 0.06
rotation_period = 2.0
[time]
dt = 1.0e-4
settle = 0.2
spin_up = 0.1
heating = 0.2
[temperature]
mode = "split"
hot = 30.0
cold = 10.0
"#;

#[test]
fn run_json_reports_the_documented_keys() {
    let dir = tempfile::tempdir().unwrap();
    let case = dir.path().join("tiny.toml");
    std::fs::write(&case, TINY_CASE).unwrap();
    let out = run_tdex(&["run", case.to_str().unwrap(), "--threads", "2", "--json"]);
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    // stderr is a pipe, as in a background run: a progress line per phase and tenth
    let log = String::from_utf8_lossy(&out.stderr);
    for line in [
        "] settle: 2000 steps",
        "] spin-up: done, 1000 steps in ",
        "] heating: 50 % (1000 of 2000 steps)",
        "] heating: done, 2000 steps in ",
    ] {
        assert!(log.contains(line), "{line} not in:\n{log}");
    }
    let v: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("stdout is one JSON object");
    for key in [
        "particles",
        "threads",
        "steps_heating",
        "particle_steps_per_second",
        "stage_seconds",
        "contacts_per_particle",
        "hot_mean_start",
        "hot_mean_end",
        "cold_mean_start",
        "cold_mean_end",
        "total_heat_start",
        "total_heat_end",
    ] {
        assert!(v.get(key).is_some(), "missing key {key} in {v}");
    }
    assert_eq!(v["particles"], 250);
    assert_eq!(v["steps_heating"], 2000);
    assert_eq!(v["hot_mean_start"], 30.0);
    for stage in ["neighbor", "contact", "integrate"] {
        assert!(v["stage_seconds"][stage].as_f64().unwrap() >= 0.0);
    }
    let (start, end) = (
        v["total_heat_start"].as_f64().unwrap(),
        v["total_heat_end"].as_f64().unwrap(),
    );
    assert!(((end - start) / start).abs() < 1e-12);
    assert!(v["hot_mean_end"].as_f64().unwrap() < 30.0);
}

#[test]
fn run_prints_a_human_summary() {
    let dir = tempfile::tempdir().unwrap();
    let case = dir.path().join("tiny.toml");
    std::fs::write(&case, TINY_CASE).unwrap();
    let out = run_tdex(&["run", case.to_str().unwrap(), "--threads", "1"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for word in [
        "particle-steps/s",
        "hot group",
        "cold group",
        "sum m c T",
        "neighbor",
    ] {
        assert!(text.contains(word), "missing {word:?} in\n{text}");
    }
}
