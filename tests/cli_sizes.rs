//! A bed of three sizes in a periodic section, end to end through the CLI: recorded the same
//! byte for byte on 1 and 2 threads, extrapolated within its size classes, and compared
//! class by class.

use crate::util::*;

/// 120 spheres of 3, 4 and 5 mm radius in a periodic section 3 cm long (six diameters of
/// the largest), a quarter revolution per period.
const SIZES_CASE: &str = r#"
name = "three sizes"
seed = 11
[particles]
count = 120
classes = [
  { radius = 0.003, fraction = 0.3333333333 },
  { radius = 0.004, fraction = 0.3333333333 },
  { radius = 0.005, fraction = 0.3333333334 },
]
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
length = 0.03
rotation_period = 1.0
end_caps = "periodic"
wall_temperature = 400.0
[time]
dt = 5.0e-5
settle = 0.1
spin_up = 0.2
[temperature]
mode = "uniform"
value = 300.0
"#;

#[test]
fn a_periodic_bed_of_three_sizes_records_extrapolates_and_compares_by_class() {
    let dir = tempfile::tempdir().unwrap();
    let case = dir.path().join("sizes.toml");
    std::fs::write(&case, SIZES_CASE).unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    for threads in ["1", "2"] {
        tdex_ok(&[
            "record",
            case.to_str().unwrap(),
            "-o",
            &path(&format!("t{threads}.mcap")),
            "--tau-rev",
            "0.25",
            "--reference",
            "2",
            "--twins",
            "1",
            "--reproducible",
            "--threads",
            threads,
        ]);
    }
    let one = std::fs::read(path("t1.mcap")).unwrap();
    assert!(
        one == std::fs::read(path("t2.mcap")).unwrap(),
        "the recording differs between 1 and 2 threads"
    );
    tdex_ok(&[
        "extrapolate",
        &path("t1.mcap"),
        "--periods",
        "10",
        "-o",
        &path("x.mcap"),
    ]);
    let text = tdex_ok(&["compare", &path("t1.mcap"), &path("x.mcap")]);
    assert!(text.contains("size classes at t_"), "{text}");
    for radius in ["    3 ", "    4 ", "    5 "] {
        assert!(
            text.lines().any(|l| l.contains(radius) && l.contains("40")),
            "no row for the class of radius {radius} mm holding 40 particles:\n{text}"
        );
    }
    assert!(text.contains("segregation index at t_"), "{text}");
    let json: serde_json::Value = serde_json::from_str(&tdex_ok(&[
        "compare",
        &path("t1.mcap"),
        &path("x.mcap"),
        "--json",
    ]))
    .unwrap();
    let classes = &json["size_classes"];
    assert_eq!(
        classes["radii"],
        serde_json::json!([0.003, 0.004, 0.005]),
        "{classes}"
    );
    assert_eq!(
        classes["particles"],
        serde_json::json!([40, 40, 40]),
        "{classes}"
    );
    // the extrapolation judged at every compared t_k after the recorded period
    assert_eq!(
        classes["extra_series"].as_array().map(|s| s.len()),
        json["periods"].as_array().map(|p| p.len()),
        "{classes}"
    );
}
