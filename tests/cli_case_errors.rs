//! Bad case files are refused through the CLI with a clear message and exit code 2, never a panic.

use crate::cli_run::TINY_CASE;
use crate::util::*;

/// Runs `tdex run` on `text` and returns (exit code, stderr).
fn refuse(text: &str) -> (i32, String) {
    let dir = tempfile::tempdir().unwrap();
    let case = dir.path().join("bad.toml");
    std::fs::write(&case, text).unwrap();
    let out = run_tdex(&["run", case.to_str().unwrap(), "--json"]);
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(!stderr.contains("panicked"), "tdex panicked: {stderr}");
    assert!(
        out.stdout.is_empty(),
        "a refused case printed a result: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(
        stderr.contains("bad.toml"),
        "the message does not name the file: {stderr}"
    );
    (out.status.code().unwrap_or(-1), stderr)
}

/// The tiny case with `from` replaced by `to` (which must occur).
fn edit(from: &str, to: &str) -> String {
    assert!(TINY_CASE.contains(from), "{from:?} not in the tiny case");
    TINY_CASE.replacen(from, to, 1)
}

fn assert_refused(text: &str, expected: &[&str]) {
    let (code, stderr) = refuse(text);
    assert_eq!(code, 2, "exit code for: {stderr}");
    for e in expected {
        assert!(stderr.contains(e), "expected {e:?} in: {stderr}");
    }
}

#[test]
fn unknown_key_is_refused() {
    assert_refused(
        &edit("radius = 0.005", "radius = 0.005\nradiuss = 0.004"),
        &["radiuss"],
    );
}

#[test]
fn wrong_type_is_refused() {
    assert_refused(
        &edit("count = 250", "count = \"many\""),
        &["count", "invalid type"],
    );
}

#[test]
fn non_positive_radius_is_refused() {
    assert_refused(
        &edit("radius = 0.005", "radius = 0.0"),
        &["particles.radius", "= 0", "> 0"],
    );
    assert_refused(
        &edit("radius = 0.005", "radius = -0.001"),
        &["particles.radius", "-0.001"],
    );
}

#[test]
fn restitution_outside_zero_one_is_refused() {
    assert_refused(
        &edit(
            "restitution = 0.2, friction = 0.3",
            "restitution = 1.2, friction = 0.3",
        ),
        &["contact.particle_particle.restitution", "1.2", "(0, 1]"],
    );
    assert_refused(
        &edit(
            "restitution = 0.2, friction = 0.5",
            "restitution = 0.0, friction = 0.5",
        ),
        &["contact.particle_wall.restitution", "(0, 1]"],
    );
}

#[test]
fn poisson_ratio_outside_range_is_refused() {
    assert_refused(
        &edit("poisson_ratio = 0.3", "poisson_ratio = 0.5"),
        &["material.poisson_ratio", "0.5", "[0, 0.5)"],
    );
    assert_refused(
        &edit("poisson_ratio = 0.3", "poisson_ratio = -0.1"),
        &["material.poisson_ratio"],
    );
}

#[test]
fn time_step_above_the_rayleigh_limit_is_refused() {
    assert_refused(
        &edit("dt = 1.0e-4", "dt = 5.0e-4"),
        &["time.dt", "0.0005", "Rayleigh time", "30 %"],
    );
}

#[test]
fn bed_that_does_not_fit_the_drum_is_refused() {
    assert_refused(
        &edit("count = 250", "count = 1000"),
        &["particles.count", "1000", "drum"],
    );
    assert_refused(
        &edit("radius = 0.05\n", "radius = 0.008\n"),
        &["drum.radius", "particle diameter"],
    );
}

#[test]
fn missing_split_temperature_is_refused() {
    assert_refused(&edit("hot = 30.0\n", ""), &["temperature.hot", "split"]);
}

#[test]
fn negative_material_property_is_refused() {
    assert_refused(
        &edit("conductivity = 100.0", "conductivity = -1.0"),
        &["material.conductivity", "-1"],
    );
    assert_refused(
        &edit("rotation_period = 2.0", "rotation_period = 0.0"),
        &["drum.rotation_period"],
    );
}

#[test]
fn truncated_file_is_refused() {
    let cut = &TINY_CASE[..TINY_CASE.find("[drum]").unwrap() + 10];
    assert_refused(cut, &["not a valid case file"]);
    let (code, _) = refuse(&TINY_CASE[..TINY_CASE.len() / 3]);
    assert_eq!(code, 2);
}

#[test]
fn missing_file_is_refused() {
    let out = run_tdex(&["run", "/nonexistent/dir/case.toml"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("/nonexistent/dir/case.toml") && stderr.contains("cannot read"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"));
}

#[test]
fn zero_threads_is_refused() {
    let out = run_tdex(&[
        "run",
        repo().join("cases/small_drum.toml").to_str().unwrap(),
        "--threads",
        "0",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--threads"));
}

#[test]
fn every_shipped_case_is_valid() {
    for entry in std::fs::read_dir(repo().join("cases")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            recorder::case::load(&path).unwrap_or_else(|e| panic!("{e}"));
        }
    }
}

#[test]
fn a_drum_too_wide_for_its_neighbour_grid_is_refused_before_any_work() {
    // 30 particles of 0.1 µm in a 3 cm drum: valid sizes, but ~10^13 grid cells
    let tiny_grains =
        edit("count = 250", "count = 30").replacen("radius = 0.005", "radius = 1.0e-7", 1);
    assert_refused(
        &tiny_grains.replacen("dt = 1.0e-4", "dt = 1.0e-9", 1),
        &["drum.radius", "neighbour grid", "at most 3e7"],
    );
}

/// The tiny case with three size classes (radii in m, number fractions) instead of its
/// one radius.
fn with_classes(classes: &str) -> String {
    edit(
        "radius = 0.005",
        &format!("classes = [{classes}]\nfractions = \"number\""),
    )
}

#[test]
fn size_classes_whose_fractions_do_not_sum_to_one_are_refused_with_their_sum() {
    assert_refused(
        &with_classes(
            "{ radius = 0.003, fraction = 0.3 }, { radius = 0.004, fraction = 0.3 }, { radius = 0.005, fraction = 0.3 }",
        ),
        &["particles.classes", "fractions summing to 0.9", "must sum to 1"],
    );
}

#[test]
fn a_size_class_too_large_for_the_drum_is_refused_by_its_index() {
    // the drum is 0.05 m in radius: a 0.03 m sphere is 0.06 m across
    assert_refused(
        &with_classes("{ radius = 0.003, fraction = 0.5 }, { radius = 0.03, fraction = 0.5 }"),
        &[
            "particles.classes[1].radius = 0.03",
            "drum's radius (0.05 m)",
        ],
    );
}

#[test]
fn a_time_step_over_the_smallest_class_limit_is_refused() {
    // dt = 1e-4 s suits 5 mm spheres, not 1 mm ones (Rayleigh time 8.6e-5 s)
    assert_refused(
        &with_classes("{ radius = 0.001, fraction = 0.5 }, { radius = 0.005, fraction = 0.5 }"),
        &[
            "time.dt = 0.0001",
            "smallest spheres (radius 0.001 m)",
            "Rayleigh time",
        ],
    );
}

#[test]
fn sizes_given_twice_or_not_at_all_are_refused() {
    assert_refused(
        &edit(
            "radius = 0.005",
            "radius = 0.005\nclasses = [{ radius = 0.004, fraction = 1.0 }]",
        ),
        &["particles", "radius and classes", "exactly one way"],
    );
    assert_refused(
        &edit("radius = 0.005", "fractions = \"mass\""),
        &["particles", "(no size)"],
    );
}

#[test]
fn a_periodic_section_shorter_than_two_largest_diameters_is_refused() {
    // spheres of 5 mm radius: the section must be at least 0.02 m long
    let short = edit(
        "rotation_period = 2.0",
        "rotation_period = 2.0\nend_caps = \"periodic\"",
    )
    .replacen("length = 0.06", "length = 0.015", 1);
    assert_refused(
        &short,
        &[
            "drum.length = 0.015",
            "periodic section",
            "two of the largest particle diameters",
            "0.02 m",
        ],
    );
}
