//! `tdex import liggghts --wall-contacts` on hand-written dumps: a heated mantle's wall
//! contacts (`compute wall/gran/local id contactArea`) become the table's wall rows, one per
//! particle and sample whatever the facets it touched, the replay heats the bed through them,
//! and each inconsistent input is refused with the file (and line) at fault.

use crate::cli_import::{edit_line, write_dumps, ATOMS, T0};
use crate::cli_run::TINY_CASE;
use crate::util::*;
use std::path::Path;
use tdex_format::RecordingReader;

const WALL_TEMPERATURE: f64 = 400.0;

/// Contact areas of the hand-written wall frames (m²).
const A1: f64 = 4e-6;
const A2: f64 = 1e-6;
const A3: f64 = 2.25e-6;

/// The wall contacts of a frame: (mesh id, triangle id, LIGGGHTS particle id, area). Mesh 0
/// is the mantle, mesh 1 the end caps. Particle 7 touches the mantle at every sample, through
/// two facets at t0 + 20 (as LIGGGHTS counts them without `curvature`); particle 9 touches an
/// end cap; particle 250 touches the mantle at t0 + 30 only.
fn walls_at(step: u64) -> Vec<(u32, u32, usize, f64)> {
    let mut c = vec![(0, 3, 7, A1), (1, 40, 9, 5e-6)];
    if step == T0 + 20 {
        c.push((0, 4, 7, A2));
    }
    if step == T0 + 30 {
        c.push((0, 11, ATOMS, A3));
    }
    c
}

fn wall_frame(step: u64) -> String {
    let c = walls_at(step);
    let mut s = format!(
        "ITEM: TIMESTEP\n{step}\nITEM: NUMBER OF ENTRIES\n{}\nITEM: BOX BOUNDS ff ff ff\n\
         -0.1 0.1\n-0.1 0.1\n-0.1 0.1\nITEM: ENTRIES c_wc[1] c_wc[2] c_wc[3] c_wc[4] \n",
        c.len()
    );
    for (mesh, tri, i, a) in c {
        s += &format!("{mesh} {tri} {i} {a:e} \n");
    }
    s
}

/// The hand-written atom and contact dumps, the wall dumps `dump_walls.txt` (frames t0 …
/// t0 + 40) and the case, heated or not.
fn write_inputs(dir: &Path, heated: bool) {
    write_dumps(dir);
    let walls: String = (0..=4).map(|k| wall_frame(T0 + 10 * k)).collect();
    std::fs::write(dir.join("dump_walls.txt"), walls).unwrap();
    let case = if heated {
        TINY_CASE.replace(
            "[drum]\n",
            &format!("[drum]\nwall_temperature = {WALL_TEMPERATURE}\n"),
        )
    } else {
        TINY_CASE.to_string()
    };
    std::fs::write(dir.join("tiny.toml"), case).unwrap();
}

fn import(dir: &Path, walls: Option<&str>, out: &Path) -> std::process::Output {
    let p = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let mut args = vec![
        "import".to_string(),
        "liggghts".into(),
        "--atoms".into(),
        p("dump_atoms.*"),
        "--contacts".into(),
        p("dump_pairs.txt"),
        "--case".into(),
        p("tiny.toml"),
        "-o".into(),
        out.to_str().unwrap().into(),
        "--tau".into(),
        "0.003".into(),
        "--n".into(),
        "10".into(),
        "--dtc-max".into(),
        "20".into(),
        "--exact-area".into(),
        "--json".into(),
    ];
    if let Some(w) = walls {
        args.extend(["--wall-contacts".to_string(), p(w)]);
    }
    run_tdex(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// The heated inputs written in a fresh folder and imported with their wall dumps into
/// `run.mcap` there: the folder, the recording and the import's JSON summary.
fn import_heated() -> (tempfile::TempDir, std::path::PathBuf, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    write_inputs(dir.path(), true);
    let out = dir.path().join("run.mcap");
    let o = import(dir.path(), Some("dump_walls.txt"), &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary = serde_json::from_slice(&o.stdout).unwrap();
    (dir, out, summary)
}

#[test]
fn wall_contacts_become_one_wall_row_per_particle_and_sample() {
    let (_dir, out, summary) = import_heated();
    assert_eq!(summary["wall_frames"], 3);
    assert_eq!(summary["wall_contacts_merged"], 1, "{summary}");

    let reader = RecordingReader::open(&out).unwrap();
    let mantle = reader.info().walls[0].clone();
    assert_eq!(mantle.temperature, Some(WALL_TEMPERATURE));
    assert!(reader.info().walls[1..]
        .iter()
        .all(|w| w.temperature.is_none()));
    let body = ATOMS as u32; // the mantle is body `particles + 0`
    let mut walls: Vec<_> = reader
        .table()
        .flat_map(|b| b.unwrap().rows)
        .filter(|r| r.j >= body)
        .map(|r| (r.i, r.j, r.start_step, r.duration_steps, r.sqrt_area))
        .collect();
    walls.sort_by(|a, b| a.partial_cmp(b).unwrap());
    // samples at t0 + 10, 20, 30; Δt_c^max = 2 samples; the two facets at t0 + 20 one row
    // with their summed sqrt(a); the end cap (adiabatic) makes no row
    let (s1, s2, s3) = (A1.sqrt(), A2.sqrt(), A3.sqrt());
    assert_eq!(
        walls,
        [
            (6, body, 0, 20, (s1 + (s1 + s2)) / 2.0),
            (6, body, 20, 10, s1),
            (body - 1, body, 20, 10, s3),
        ]
    );
}

#[test]
fn the_replay_heats_the_bed_through_the_imported_wall_rows() {
    let (dir, run, _) = import_heated();
    let extra = dir.path().join("extra.mcap");
    let (run_s, extra_s) = (run.to_str().unwrap(), extra.to_str().unwrap());
    tdex_ok(&["extrapolate", run_s, "--periods", "1", "-o", extra_s]);
    let v: serde_json::Value =
        serde_json::from_str(&tdex_ok(&["inspect", extra_s, "--json"])).unwrap();
    let wall_heat = v["wall_heat"].as_f64().expect("a wall heat");
    let gained = v["total_heat_end"].as_f64().unwrap() - v["total_heat_start"].as_f64().unwrap();
    assert!(
        (gained - wall_heat).abs() <= 1e-9 * wall_heat,
        "{gained} {wall_heat}"
    );

    // H = 4 K Kw / (K + Kw) sqrt(a) = 200 sqrt(a) W/K for K = Kw = 100 W/(m K), over each
    // row's steps of 1e-4 s, from the particles' temperatures at t1 (the pairing of the
    // hand-written snapshots is the identity); a period heats them by far less than 0.1 % of
    // the 370 K to the mantle, so the first-order sum holds to that
    let t1 = |id: usize| 30.0 - if id > ATOMS / 2 { 20.0 } else { 0.0 } + 30.0 * 1e-3;
    let (s1, s2, s3) = (A1.sqrt(), A2.sqrt(), A3.sqrt());
    let expected = 200.0
        * 1e-4
        * ((WALL_TEMPERATURE - t1(7)) * ((2.0 * s1 + s2) / 2.0 * 20.0 + s1 * 10.0)
            + (WALL_TEMPERATURE - t1(ATOMS)) * s3 * 10.0);
    assert!(
        (wall_heat - expected).abs() < 1e-3 * expected,
        "wall heat {wall_heat} J, expected {expected} J"
    );
}

/// Imports with `walls` into a fresh folder whose inputs `damage` changed, and checks the
/// refusal: exit code 2, every `expect` in the message, no recording written.
fn assert_refused(heated: bool, walls: Option<&str>, damage: impl FnOnce(&Path), expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    write_inputs(dir.path(), heated);
    damage(dir.path());
    let out = dir.path().join("run.mcap");
    let o = import(dir.path(), walls, &out);
    let err = String::from_utf8_lossy(&o.stderr).replace(&format!("{}/", dir.path().display()), "");
    assert_eq!(o.status.code(), Some(2), "{err}");
    for e in expect {
        assert!(err.contains(e), "expected `{e}` in: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists(), "no recording may be written");
}

#[test]
fn a_heated_mantle_without_wall_dumps_and_wall_dumps_without_one_are_refused() {
    assert_refused(
        true,
        None,
        |_| {},
        &[
            "tiny.toml: drum.wall_temperature = 400 K",
            "give --wall-contacts",
        ],
    );
    assert_refused(
        false,
        Some("dump_walls.txt"),
        |_| {},
        &[
            "dump_walls.txt: wall contact dumps for",
            "whose walls are adiabatic",
            "set drum.wall_temperature",
        ],
    );
}

#[test]
fn a_wall_dump_without_the_needed_columns_or_with_an_unknown_mesh_is_refused() {
    // line 20: the column names of the first sampled frame (t0 + 10; the frame at t0 is
    // passed over unread)
    assert_refused(
        true,
        Some("dump_walls.txt"),
        |d| {
            edit_line(&d.join("dump_walls.txt"), 20, " c_wc[4] ", " ");
        },
        &[
            "dump_walls.txt:20: 3 columns",
            "compute wall/gran/local id contactArea",
        ],
    );
    // the first row of the frame at t0 + 10 names a third mesh
    assert_refused(
        true,
        Some("dump_walls.txt"),
        |d| {
            edit_line(&d.join("dump_walls.txt"), 21, "0 3 7 ", "2 3 7 ");
        },
        &["dump_walls.txt:21: mesh id `2` is not one of the drum's 2 meshes"],
    );
    // a wall frame missing inside the period
    assert_refused(
        true,
        Some("dump_walls.txt"),
        |d| {
            let text = std::fs::read_to_string(d.join("dump_walls.txt")).unwrap();
            let cut = text
                .find(&format!("ITEM: TIMESTEP\n{}\n", T0 + 20))
                .unwrap();
            let next = text
                .find(&format!("ITEM: TIMESTEP\n{}\n", T0 + 30))
                .unwrap();
            std::fs::write(
                d.join("dump_walls.txt"),
                format!("{}{}", &text[..cut], &text[next..]),
            )
            .unwrap();
        },
        &["dump_walls.txt: no wall contact dump at timestep 1020"],
    );
}
