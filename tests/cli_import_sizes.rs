//! A LIGGGHTS 3.8 run of a bed of three sizes in a periodic section, through `tdex import
//! liggghts`, `extrapolate` and `compare`: the snapshots keep every particle's own radius, the
//! table's rows join particles that touch (across the seam too), the pairing keeps each
//! particle in its size class and takes its distances across the seam, the replay conserves
//! Σ C T with each particle's heat capacity from its own radius, and a heated mantle's wall
//! contacts give the bed LIGGGHTS's heat.

use crate::cli_import::{dump_heat, run_liggghts};
use crate::util::*;
use std::path::{Path, PathBuf};
use tdex_format::{ExtrapolationReader, RecordingReader, Snapshot};

/// The class radii (m) and the particles of each.
const RADII: [f64; 3] = [0.003, 0.004, 0.005];
const PER_CLASS: usize = 50;
const PARTICLES: usize = 3 * PER_CLASS;
/// The drum's radius and the section's length along the axis, the period (m).
const DRUM_RADIUS: f64 = 0.05;
const LENGTH: f64 = 0.06;
/// Contacts dumped (and sampled) every this many steps.
const N: &str = "20";

/// 150 spheres of 3, 4 and 5 mm in a periodic section 6 cm long (LIGGGHTS's `insert/pack`
/// cannot place them all in a shorter one), hot and cold halves split along x; t0 = one
/// revolution (1 s, 20000 steps), one more revolution of DEM reference after t1.
fn case_text(heated: bool) -> String {
    format!(
        r#"name = "import_sizes"
seed = 11

[particles]
count = {PARTICLES}
classes = [
  {{ radius = {}, fraction = 0.3333333333 }},
  {{ radius = {}, fraction = 0.3333333333 }},
  {{ radius = {}, fraction = 0.3333333334 }},
]

[material]
density = 2500.0
youngs_modulus = 1.0e7
poisson_ratio = 0.3
conductivity = 100.0
heat_capacity = 840.0

[contact]
rolling_model = "epsd2"
particle_particle = {{ restitution = 0.2, friction = 0.3, rolling_friction = 0.002 }}
particle_wall = {{ restitution = 0.2, friction = 0.5, rolling_friction = 0.002 }}

[conduction]
contact_area = "overlap"

[drum]
radius = {DRUM_RADIUS}
length = {LENGTH}
rotation_period = 1.0
end_caps = "periodic"
{}
[time]
dt = 5.0e-5
settle = 0.2
spin_up = 0.8

[temperature]
mode = "split"
split_axis = "x"
hot = 30.0
cold = 10.0
"#,
        RADII[0],
        RADII[1],
        RADII[2],
        if heated {
            "wall_temperature = 60.0\n"
        } else {
            ""
        }
    )
}

/// The case written into a fresh folder, LIGGGHTS run there with the import's dumps, and the
/// dumps imported into `run.mcap`: the folder, the case, the recording and the import's
/// JSON summary.
fn run_and_import(heated: bool) -> (tempfile::TempDir, PathBuf, PathBuf, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    let case = dir.path().join("sizes.toml");
    std::fs::write(&case, case_text(heated)).unwrap();
    run_liggghts(&case, dir.path(), &["--dumps", N, "1", "--per-proc"]);
    let path = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let run = dir.path().join("run.mcap");
    let mut args = vec![
        "import".to_string(),
        "liggghts".into(),
        "--atoms".into(),
        path("dump_atoms.*.%"),
        "--contacts".into(),
        path("dump_pairs.*"),
        "--case".into(),
        case.to_string_lossy().into_owned(),
        "-o".into(),
        run.to_string_lossy().into_owned(),
        "--n".into(),
        N.into(),
        "--json".into(),
    ];
    if heated {
        args.extend(["--wall-contacts".to_string(), path("dump_walls.*")]);
    }
    let summary = tdex_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    let summary: serde_json::Value = serde_json::from_str(&summary).unwrap();
    (dir, case, run, summary)
}

/// The (LIGGGHTS id, radius) of every particle of the atom dump of timestep `step` (one
/// process), sorted by id.
fn dumped_radii(dir: &Path, step: u64) -> Vec<(u64, f64)> {
    let text = std::fs::read_to_string(dir.join(format!("dump_atoms.{step}.0"))).unwrap();
    let mut lines = text.lines();
    let columns: Vec<&str> = lines
        .by_ref()
        .find(|l| l.starts_with("ITEM: ATOMS"))
        .unwrap()
        .split_whitespace()
        .skip(2)
        .collect();
    let at = |name| columns.iter().position(|c| *c == name).unwrap();
    let (id, r) = (at("id"), at("radius"));
    let mut atoms: Vec<(u64, f64)> = lines
        .map(|l| {
            let v: Vec<&str> = l.split_whitespace().collect();
            (v[id].parse().unwrap(), v[r].parse().unwrap())
        })
        .collect();
    atoms.sort_by_key(|a| a.0);
    atoms
}

/// The class of radius `r` (its place in `RADII`, to the bit); panics on a radius that is no
/// class's.
fn class_of(r: f64) -> usize {
    RADII
        .iter()
        .position(|c| c.to_bits() == r.to_bits())
        .unwrap_or_else(|| panic!("radius {r:e} is none of the classes' {RADII:?}"))
}

/// The particles of each class in `radius`.
fn class_counts(radius: &[f64]) -> [usize; 3] {
    let mut counts = [0; 3];
    for &r in radius {
        counts[class_of(r)] += 1;
    }
    counts
}

/// `b − a` with its axial component taken to the nearest image across the seam, and
/// whether it crossed the seam.
fn across_seam(a: [f64; 3], b: [f64; 3]) -> ([f64; 3], bool) {
    let mut d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let crossed = d[1].abs() > LENGTH / 2.0;
    d[1] -= LENGTH * (d[1] / LENGTH).round();
    (d, crossed)
}

fn norm(d: [f64; 3]) -> f64 {
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// Σ C T (J) of a snapshot, each particle's heat capacity `ρ c (4/3) π r³` from its own radius.
fn heat(s: &Snapshot, info: &tdex_format::RecordingInfo) -> f64 {
    s.radius
        .iter()
        .zip(&s.temp)
        .map(|(r, t)| {
            info.density * info.heat_capacity * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) * t
        })
        .sum()
}

/// Checks the imported snapshots against the atom dumps and returns them (t0, t1, t2): every
/// particle's radius is the one LIGGGHTS dumped for it (tdex id k = the k-th smallest
/// LIGGGHTS id), to the bit, and each class holds its 50 particles.
fn check_snapshots(dir: &Path, reader: &RecordingReader) -> Vec<Snapshot> {
    let info = reader.info();
    assert_eq!(
        (
            info.particles as usize,
            info.period_steps,
            info.reference_periods,
            info.sample_every
        ),
        (PARTICLES, 20000, 1, 20)
    );
    let snaps = reader.snapshots().unwrap();
    assert_eq!(snaps.iter().map(|s| s.index).collect::<Vec<_>>(), [0, 1, 2]);
    for s in &snaps {
        let step = info.step_t0 + s.index as u64 * info.period_steps;
        let dumped = dumped_radii(dir, step);
        assert_eq!(dumped.len(), PARTICLES, "timestep {step}");
        for (k, (id, r)) in dumped.iter().enumerate() {
            assert_eq!(
                s.radius[k].to_bits(),
                r.to_bits(),
                "t_{}: tdex particle {k} (LIGGGHTS id {id}) has radius {:e}, dumped {r:e}",
                s.index,
                s.radius[k]
            );
        }
        assert_eq!(
            class_counts(&s.radius),
            [PER_CLASS; 3],
            "t_{}: particles per class",
            s.index
        );
    }
    snaps
}

/// The pair rows (`i < j <` particles) join particles of the recording, with a `sqrt(a)` no
/// larger than the lens of the smaller sphere allows; those of the first sample join spheres
/// that touch at t0, give or take what they move in its first steps, some across the seam
/// and some of two different classes. Returns the wall rows.
fn check_pair_rows(reader: &RecordingReader, t0: &Snapshot) -> Vec<tdex_format::CollisionRow> {
    let n = PARTICLES as u32;
    let (mut pairs, mut walls) = (Vec::new(), Vec::new());
    for row in reader.table().flat_map(|b| b.unwrap().rows) {
        if row.j >= n {
            walls.push(row);
        } else {
            pairs.push(row);
        }
    }
    assert!(pairs.len() > 1000, "{} pair rows", pairs.len());
    let (mut first, mut across, mut mixed) = (0, 0, 0);
    for r in &pairs {
        assert!(r.i < r.j, "{r:?}");
        let (ri, rj) = (t0.radius[r.i as usize], t0.radius[r.j as usize]);
        assert!(
            r.sqrt_area > 0.0 && r.sqrt_area <= 1.001 * std::f64::consts::PI.sqrt() * ri.min(rj),
            "{r:?}: sqrt(a) beyond the lens of radii {ri:e} and {rj:e}"
        );
        if ri != rj {
            mixed += 1;
        }
        if r.start_step == 0 {
            first += 1;
            let (d, crossed) = across_seam(t0.pos[r.i as usize], t0.pos[r.j as usize]);
            // one sample is n = 20 steps of 50 µs: 1 ms, under a millimetre at these speeds
            let gap = norm(d) - (ri + rj);
            assert!(
                gap < 1e-3,
                "{r:?}: particles {} mm apart at t0 (across the seam: {crossed})",
                gap * 1e3
            );
            across += usize::from(crossed);
        }
    }
    eprintln!(
        "pair rows: {}, {first} at the first sample ({across} across the seam), {mixed} \
         between two classes",
        pairs.len()
    );
    assert!(
        first > 50 && across > 0 && mixed > 0,
        "{first} {across} {mixed}"
    );
    walls
}

/// The stored pairing of the recording (`run.mcap.pairing.json`, written by `tdex
/// extrapolate`): three size classes paired apart, every particle at t1 in the role of one of
/// its own radius at t0, and its distance taken across the seam (the section's period in
/// its summary, its total that of the nearest images, some particles paired across).
fn check_pairing(run: &Path, t0: &Snapshot, t1: &Snapshot) {
    let sidecar = PathBuf::from(format!("{}.pairing.json", run.display()));
    let stored: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sidecar).unwrap()).unwrap();
    let summary = &stored["summary"];
    assert_eq!(summary["size_classes"], 3, "{summary}");
    assert_eq!(summary["axial_period"], LENGTH, "{summary}");
    assert_eq!(summary["certified"], true, "{summary}");
    let g: Vec<usize> = stored["g"]
        .as_array()
        .unwrap()
        .iter()
        .map(|q| q.as_u64().unwrap() as usize)
        .collect();
    assert_eq!(g.len(), PARTICLES);
    let mut seen = [false; PARTICLES];
    let (mut total, mut across) = (0.0, 0);
    for (p, &q) in g.iter().enumerate() {
        assert!(
            !std::mem::replace(&mut seen[q], true),
            "role {q} taken twice"
        );
        assert_eq!(
            t1.radius[p].to_bits(),
            t0.radius[q].to_bits(),
            "particle {p} (radius {:e}) in the role of {q} (radius {:e})",
            t1.radius[p],
            t0.radius[q]
        );
        let (d, crossed) = across_seam(t0.pos[q], t1.pos[p]);
        total += norm(d);
        across += usize::from(crossed);
    }
    let stored_total = summary["total_distance_diameters"].as_f64().unwrap()
        * summary["diameter"].as_f64().unwrap();
    assert!(
        (total - stored_total).abs() <= 1e-9 * stored_total,
        "Σ|x1 − x0∘g| across the seam {total} m, the pairing's {stored_total} m"
    );
    eprintln!("pairing: {across} particles paired across the seam");
    assert!(across > 0, "no particle paired across the seam");
}

/// In every extrapolated snapshot the particle playing role j (its `id`) has the role's
/// radius.
fn check_roles(extra: &[Snapshot], t0: &Snapshot) {
    for s in extra {
        for (j, &p) in s.id.iter().enumerate() {
            assert_eq!(
                t0.radius[p as usize].to_bits(),
                s.radius[j].to_bits(),
                "t_{}: particle {p} in the role {j} of another radius",
                s.index
            );
        }
    }
}

#[test]
fn a_periodic_liggghts_bed_of_three_sizes_imports_extrapolates_and_compares_by_class() {
    if !liggghts_available() {
        return;
    }
    let started = std::time::Instant::now();
    let (dir, _case, run, imported) = run_and_import(false);
    assert_eq!(imported["contact_frames"], 1000, "{imported}");
    let reader = RecordingReader::open(&run).unwrap();
    let info = reader.info().clone();
    let snaps = check_snapshots(dir.path(), &reader);
    let (t0, t1) = (&snaps[0], &snaps[1]);
    // the walls are adiabatic: no wall rows
    assert!(check_pair_rows(&reader, t0).is_empty());

    let extra = dir.path().join("extra.mcap");
    let (run_s, extra_s) = (run.to_str().unwrap(), extra.to_str().unwrap());
    tdex_ok(&["extrapolate", run_s, "--periods", "3", "-o", extra_s]);
    check_pairing(&run, t0, t1);
    let extrapolated = ExtrapolationReader::open(&extra)
        .unwrap()
        .snapshots()
        .unwrap();
    assert_eq!(
        extrapolated.iter().map(|s| s.index).collect::<Vec<_>>(),
        [1, 2, 3, 4]
    );
    check_roles(&extrapolated, t0);

    // Σ C T, each heat capacity from the particle's own radius: LIGGGHTS's at t0 (its
    // conduction conserves it), the recording's at t1, the extrapolation's at every t_k
    let liggghts = dump_heat(
        &dir.path().join(format!("dump_atoms.{}.0", info.step_t0)),
        info.density,
        info.heat_capacity,
    );
    let recorded = heat(t1, &info);
    assert!(
        (recorded - liggghts).abs() <= 1e-12 * liggghts,
        "Σ C T {recorded} J at t1, LIGGGHTS's {liggghts} J at t0"
    );
    for s in &extrapolated {
        let h = heat(s, &info);
        assert!(
            (h - recorded).abs() <= 1e-12 * recorded,
            "t_{}: Σ C T {h} J, {recorded} J at t1",
            s.index
        );
    }
    // and the extrapolation's own account of it
    let inspected: serde_json::Value =
        serde_json::from_str(&tdex_ok(&["inspect", extra_s, "--json"])).unwrap();
    for key in ["total_heat_start", "total_heat_end"] {
        let h = inspected[key].as_f64().unwrap();
        assert!(
            (h - recorded).abs() <= 1e-12 * recorded,
            "{key} {h} J, {recorded} J"
        );
    }

    // compare: the size-class table, the three classes of 50, judged at t2 (the reference)
    let text = tdex_ok(&["compare", run_s, extra_s]);
    eprint!("{text}");
    assert!(text.contains("size classes at t_2"), "{text}");
    for radius in ["    3 ", "    4 ", "    5 "] {
        assert!(
            text.lines()
                .any(|l| l.contains(radius) && l.contains(" 50 ")),
            "no row for the class of radius {radius} mm holding 50 particles:\n{text}"
        );
    }
    assert!(text.contains("segregation index at t_2"), "{text}");
    let json: serde_json::Value =
        serde_json::from_str(&tdex_ok(&["compare", run_s, extra_s, "--json"])).unwrap();
    let classes = &json["size_classes"];
    assert_eq!(classes["radii"], serde_json::json!(RADII), "{classes}");
    assert_eq!(
        classes["particles"],
        serde_json::json!([PER_CLASS, PER_CLASS, PER_CLASS]),
        "{classes}"
    );
    let series = classes["extra_series"].as_array().unwrap();
    assert_eq!(series.len(), 1, "{classes}");
    assert_eq!(series[0]["k"], 2, "{classes}");
    eprintln!(
        "LIGGGHTS, import, extrapolation and comparison: {:.1} s",
        started.elapsed().as_secs_f64()
    );
}

/// The same bed under a mantle held at 60 °C: its wall contacts (one mesh, the mantle, in a
/// periodic section) become wall rows of particles that touch it, for every class, and the
/// heat the mantle gives the bed, each particle's heat capacity from its own radius, is
/// LIGGGHTS's: over the recorded period with the table replayed from t0 (measured +0.07 %),
/// and over the first extrapolated period against LIGGGHTS's continuation (measured −0.7 %).
#[test]
fn a_heated_periodic_liggghts_bed_of_three_sizes_imports_its_wall_contacts() {
    if !liggghts_available() {
        return;
    }
    let (dir, _case, run, imported) = run_and_import(true);
    assert_eq!(imported["wall_frames"], 1000, "{imported}");
    let reader = RecordingReader::open(&run).unwrap();
    let info = reader.info().clone();
    assert_eq!(info.walls[0].temperature, Some(60.0));
    let snaps = check_snapshots(dir.path(), &reader);
    let t0 = &snaps[0];
    let walls = check_pair_rows(&reader, t0);
    // the mantle is body `particles + 0`; rows of its first sample are particles at its
    // surface at t0
    let mut touched = [0usize; 3];
    for r in &walls {
        assert_eq!(r.j, PARTICLES as u32, "{r:?}: not the mantle");
        assert!((r.i as usize) < PARTICLES && r.sqrt_area > 0.0, "{r:?}");
        let (p, radius) = (t0.pos[r.i as usize], t0.radius[r.i as usize]);
        if r.start_step == 0 {
            let out = (p[0] * p[0] + p[2] * p[2]).sqrt() + radius;
            assert!(
                (out - DRUM_RADIUS).abs() < 1e-3,
                "{r:?}: the particle reaches {out} m from the axis at t0"
            );
        }
        touched[class_of(radius)] += 1;
    }
    eprintln!("wall rows by class: {touched:?}");
    assert!(touched.iter().all(|&k| k > 0), "{touched:?}");

    let inspected: serde_json::Value =
        serde_json::from_str(&tdex_ok(&["inspect", run.to_str().unwrap(), "--json"])).unwrap();
    let recorded = &inspected["recorded_wall_heat"];
    eprintln!("recorded period's wall heat: {recorded}");
    let dem = recorded["dem"].as_f64().unwrap();
    let (step_t1, step_t2) = (
        info.step_t0 + info.period_steps,
        info.step_t0 + 2 * info.period_steps,
    );
    let liggghts = |step: u64| {
        dump_heat(
            &dir.path().join(format!("dump_atoms.{step}.0")),
            info.density,
            info.heat_capacity,
        )
    };
    assert!(
        (dem - (liggghts(step_t1) - liggghts(info.step_t0))).abs() <= 1e-9 * dem,
        "{recorded}"
    );
    assert!(
        recorded["relative_difference"].as_f64().unwrap().abs() < 0.01,
        "{recorded}"
    );

    let extra = dir.path().join("extra.mcap");
    tdex_ok(&[
        "extrapolate",
        run.to_str().unwrap(),
        "--periods",
        "1",
        "-o",
        extra.to_str().unwrap(),
    ]);
    check_pairing(&run, t0, &snaps[1]);
    let extrapolated = ExtrapolationReader::open(&extra)
        .unwrap()
        .snapshots()
        .unwrap();
    check_roles(&extrapolated, t0);
    let (start, end) = (&extrapolated[0], extrapolated.last().unwrap());
    assert_eq!((start.index, end.index), (1, 2));
    let replayed = heat(end, &info) - heat(start, &info);
    let gained = liggghts(step_t2) - liggghts(step_t1);
    eprintln!("first extrapolated period's wall heat: {replayed} J, LIGGGHTS {gained} J");
    assert!(
        (replayed - gained).abs() < 0.02 * gained,
        "the extrapolation's mantle gave {replayed} J, LIGGGHTS's {gained} J"
    );
}
