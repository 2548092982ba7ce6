//! The LIGGGHTS 3.8 peer of `tdex bench CASE`: the case written as a LIGGGHTS deck (same
//! materials, Hertz + history + rolling, conduction, the drum as an STL mesh turned by
//! `fix move/mesh`), started from tdex's own bed at t0 and run on one process for the same steps.

use crate::cli::BenchPlan;
use anyhow::{bail, Context, Result};
use recorder::case::{Case, ContactArea, EndCaps, ParticleSize, RollingModel, TemperatureSpec};
use recorder::particles::ParticleSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The deck, with `@name@` placeholders (shared with `tests/liggghts/deck_from_case.py`).
const DECK: &str = include_str!("liggghts_deck.in");
/// The deck's `@start@` here: the bed read from tdex's state at t0 (the Python script's
/// `liggghts_start_settle.in` lets LIGGGHTS insert and settle its own bed instead, which
/// costs the settling and spin-up again, and `insert/pack` cannot place a dense fill).
const START_FROM_STATE: &str = include_str!("liggghts_start_state.in");
/// The LIGGGHTS data file of tdex's bed at t0, read by the deck.
const STATE_FILE: &str = "t0.data";
/// Facets around the drum's circumference.
const FACETS_AROUND: usize = 96;
/// Target length (m) of one mantle facet along the axis.
const FACET_LENGTH: f64 = 0.02;

pub struct PeerRate {
    pub particle_steps_per_s: f64,
    pub seconds: f64,
    pub dir: PathBuf,
}

/// Whether the deck can reproduce `case`: checked in the plan, before the DEM to `t0`.
pub fn check_deck(case: &Case) -> Result<()> {
    DeckBed::of(case)?;
    DrumMeshes::of(case.drum.end_caps)?;
    Ok(())
}

/// Writes tdex's bed at `t0` and the deck into `dir` (a new temporary directory if `None`), to
/// be run by [`run`]; returns the directory. Called at `t0`, before tdex's timed steps, so that
/// the bed is written as it streams out rather than kept.
pub fn prepare(plan: &BenchPlan, at_t0: &ParticleSet, dir: Option<&Path>) -> Result<PathBuf> {
    let dir = match dir {
        Some(d) => d.to_path_buf(),
        None => std::env::temp_dir().join(format!("tdex-bench-liggghts-{}", std::process::id())),
    };
    tdex_format::output::create_dir_all(&dir)?;
    tdex_format::output::write_with(&dir.join(STATE_FILE), |out| {
        write_state(&plan.case, at_t0, out)
    })?;
    write_deck(&plan.case, &plan.case_path, plan.steps, &dir)?;
    Ok(dir)
}

/// Runs `liggghts` in the directory [`prepare`] wrote and reads the rate of its last run (the
/// heated phase) from the log.
pub fn run(plan: &BenchPlan, dir: PathBuf) -> Result<PeerRate> {
    let bar = crate::progress::spinner(
        plan.json,
        &format!("LIGGGHTS 3.8, 1 process, in {}", dir.display()),
    );
    // LIGGGHTS's console log, written as it runs (like its own log.liggghts): a diagnostic
    // for a failed run, not an output, so it is not written atomically
    let screen = std::fs::File::create(dir.join("screen.txt"))
        .with_context(|| format!("cannot write {}", dir.join("screen.txt").display()))?;
    let status = Command::new("liggghts")
        .args(["-in", "in.drum", "-log", "log.liggghts", "-echo", "none"])
        .current_dir(&dir)
        .stdout(screen.try_clone()?)
        .stderr(screen)
        .status();
    bar.finish_and_clear();
    let status = match status {
        Ok(s) => s,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => bail!(
            "--vs-liggghts: `liggghts` is not on PATH (install LIGGGHTS 3.8: apt-get install -y liggghts)"
        ),
        Err(e) => return Err(e).context("cannot start liggghts"),
    };
    if !status.success() {
        bail!(
            "liggghts failed ({status}); see {}",
            dir.join("screen.txt").display()
        );
    }
    let log_path = dir.join("log.liggghts");
    let log = std::fs::read_to_string(&log_path)
        .with_context(|| format!("cannot read {}", log_path.display()))?;
    let (seconds, steps, atoms) = last_loop_time(&log)
        .with_context(|| format!("{}: no 'Loop time' line", log_path.display()))?;
    if steps != plan.steps || atoms != plan.case.particles.count as u64 {
        bail!(
            "{}: the last run was {steps} steps with {atoms} atoms, expected {} steps with {} atoms",
            log_path.display(),
            plan.steps,
            plan.case.particles.count
        );
    }
    Ok(PeerRate {
        particle_steps_per_s: (steps * atoms) as f64 / seconds,
        seconds,
        dir,
    })
}

/// `(seconds, steps, atoms)` of the last "Loop time of S on P procs for N steps with A atoms".
fn last_loop_time(log: &str) -> Option<(f64, u64, u64)> {
    let line = log.lines().rev().find(|l| l.starts_with("Loop time of "))?;
    let words: Vec<&str> = line.split_whitespace().collect();
    // Loop time of S on P procs for N steps with A atoms
    Some((
        words.get(3)?.parse().ok()?,
        words.get(8)?.parse().ok()?,
        words.get(11)?.parse().ok()?,
    ))
}

/// Writes the LIGGGHTS data file (`read_data`, `atom_style granular`) of the bed: the box of
/// the deck, then every particle's type, diameter, density and position, and its velocity and
/// angular velocity, at full precision (`{:?}` prints the shortest decimal that reads back to
/// the same `f64`).
fn write_state(
    case: &Case,
    bed: &ParticleSet,
    out: &mut impl std::io::Write,
) -> std::io::Result<()> {
    let (bx, by) = box_half_widths(case);
    write!(
        out,
        "LIGGGHTS data file: the bed of tdex case '{}' at t0\n\n{} atoms\n2 atom types\n\n\
         {:?} {bx:?} xlo xhi\n{:?} {by:?} ylo yhi\n{:?} {bx:?} zlo zhi\n\nAtoms\n\n",
        case.name,
        bed.len(),
        -bx,
        -by,
        -bx,
    )?;
    let density = case.material.density;
    for k in 0..bed.len() {
        let [x, y, z] = bed.pos[k];
        let diameter = 2.0 * bed.radius[k];
        writeln!(
            out,
            "{} 1 {diameter:?} {density:?} {x:?} {y:?} {z:?}",
            k + 1
        )?;
    }
    write!(out, "\nVelocities\n\n")?;
    for k in 0..bed.len() {
        let ([vx, vy, vz], [wx, wy, wz]) = (bed.vel[k], bed.omega[k]);
        writeln!(out, "{} {vx:?} {vy:?} {vz:?} {wx:?} {wy:?} {wz:?}", k + 1)?;
    }
    Ok(())
}

/// Half-widths of the deck's box across (x, z) and along (y) the drum: a centimetre beyond it.
fn box_half_widths(case: &Case) -> (f64, f64) {
    (case.drum.radius + 0.01, case.drum.length / 2.0 + 0.01)
}

/// What of the case the deck reproduces: LIGGGHTS 3.8's conduction and the deck's insertion
/// cover one size, a split start, the overlap contact area and an adiabatic drum closed by caps.
struct DeckBed {
    hot: f64,
    cold: f64,
    /// The split axis' index (0 = x, 1 = y, 2 = z).
    axis: usize,
    radius: f64,
}

impl DeckBed {
    fn of(case: &Case) -> Result<Self> {
        let TemperatureSpec::Split {
            hot,
            cold,
            split_axis,
        } = case.temperature
        else {
            bail!("--vs-liggghts: the deck needs temperature.mode = \"split\" (the case has a uniform start)");
        };
        if case.conduction.contact_area != ContactArea::Overlap {
            bail!("--vs-liggghts: LIGGGHTS 3.8 heat/gran/conduction has no Hertz contact area (the case sets conduction.contact_area = \"hertz\")");
        }
        if case.drum.wall_temperature.is_some() {
            bail!(
                "--vs-liggghts: the deck has no heated wall (the case sets drum.wall_temperature)"
            );
        }
        let ParticleSize::Single { radius } = case.particles.size else {
            bail!("--vs-liggghts: the deck inserts spheres of one size (the case gives several)");
        };
        Ok(Self {
            hot,
            cold,
            axis: split_axis.index(),
            radius,
        })
    }
}

/// The drum as LIGGGHTS meshes: one turning mesh, or a turning mantle and fixed caps.
struct DrumMeshes {
    /// STL file, with the mantle, with the caps.
    files: Vec<(&'static str, bool, bool)>,
    fixes: &'static str,
    count: usize,
    names: &'static str,
    /// The mesh `fix move/mesh` turns.
    rotating: &'static str,
}

impl DrumMeshes {
    fn of(end_caps: EndCaps) -> Result<Self> {
        Ok(match end_caps {
            EndCaps::Rotating => Self {
                files: vec![("drum.stl", true, true)],
                fixes: "fix drum all mesh/surface file drum.stl type 2",
                count: 1,
                names: "drum",
                rotating: "drum",
            },
            EndCaps::Fixed => Self {
                files: vec![
                    ("drum_mantle.stl", true, false),
                    ("drum_caps.stl", false, true),
                ],
                fixes: "fix mantle all mesh/surface file drum_mantle.stl type 2\nfix caps all mesh/surface file drum_caps.stl type 2",
                count: 2,
                names: "mantle caps",
                rotating: "mantle",
            },
            EndCaps::Periodic => bail!("--vs-liggghts: the deck closes the drum with end caps (the case sets drum.end_caps = \"periodic\")"),
        })
    }

    fn write(&self, case: &Case, dir: &Path) -> Result<()> {
        for &(file, mantle, caps) in &self.files {
            let stl = drum_stl(case.drum.radius, case.drum.length, mantle, caps);
            tdex_format::output::write_atomically(&dir.join(file), stl.as_bytes())?;
        }
        Ok(())
    }
}

/// Writes `in.drum` and the drum mesh for `case`, heating for `heating_steps` after `t0`.
fn write_deck(case: &Case, case_path: &Path, heating_steps: u64, dir: &Path) -> Result<()> {
    let bed = DeckBed::of(case)?;
    let meshes = DrumMeshes::of(case.drum.end_caps)?;
    meshes.write(case, dir)?;
    let mut values = deck_values(case, case_path, &bed, &meshes);
    values.extend(split_values(case, &bed));
    values.push(("nheat", heating_steps.to_string()));
    values.push(("heat_runs", format!("run {heating_steps}")));
    let start = fill(START_FROM_STATE, &values)?;
    values.push(("start", start));
    let deck = fill(DECK, &values)?;
    tdex_format::output::write_atomically(&dir.join("in.drum"), deck.as_bytes())?;
    Ok(())
}

/// The template's values for the case's materials, contact laws and drum.
fn deck_values(
    case: &Case,
    case_path: &Path,
    bed: &DeckBed,
    meshes: &DrumMeshes,
) -> Vec<(&'static str, String)> {
    let (m, pp, pw) = (
        &case.material,
        &case.contact.particle_particle,
        &case.contact.particle_wall,
    );
    let e_real = case.conduction.youngs_modulus_real;
    vec![
        (
            "case",
            case_path
                .file_name()
                .map_or(String::new(), |f| f.to_string_lossy().into()),
        ),
        ("name", case.name.clone()),
        ("seed", case.seed.to_string()),
        ("box", format!("read_data       {STATE_FILE}")),
        ("skin", (0.4 * bed.radius).to_string()),
        ("E", m.youngs_modulus.to_string()),
        ("nu", m.poisson_ratio.to_string()),
        ("k", m.conductivity.to_string()),
        ("cp", m.heat_capacity.to_string()),
        ("N", case.particles.count.to_string()),
        ("dt", case.time.dt.to_string()),
        ("e_pp", pp.restitution.to_string()),
        ("e_pw", pw.restitution.to_string()),
        ("mu_pp", pp.friction.to_string()),
        ("mu_pw", pw.friction.to_string()),
        ("mur_pp", pp.rolling_friction.to_string()),
        ("mur_pw", pw.rolling_friction.to_string()),
        (
            "rolling",
            match case.contact.rolling_model {
                RollingModel::Epsd2 => "epsd2",
                RollingModel::Cdt => "cdt",
                RollingModel::Off => "off",
            }
            .into(),
        ),
        (
            "E_real_fix",
            e_real.map_or(String::new(), |e| {
                format!("fix m8 all property/global youngsModulusOriginal peratomtype {e} {e}")
            }),
        ),
        (
            "area_corr",
            if e_real.is_some() { "yes" } else { "no" }.into(),
        ),
        ("mesh_fixes", meshes.fixes.into()),
        ("n_meshes", meshes.count.to_string()),
        ("meshes", meshes.names.into()),
        ("rotating", meshes.rotating.into()),
        ("period", case.drum.rotation_period.to_string()),
        // the import test's dumps (tests/liggghts/deck_from_case.py --dumps) are not timed here
        ("pair_compute", String::new()),
    ]
}

/// The template's values for the split start: the temperatures and the bisected plane.
fn split_values(case: &Case, bed: &DeckBed) -> Vec<(&'static str, String)> {
    // The split plane's extent along its axis: the box's half-width on that axis.
    let (across, along) = box_half_widths(case);
    let ext = if bed.axis == 1 { along } else { across };
    let block = |upper: &str| {
        let mut b = ["INF"; 6];
        b[2 * bed.axis + 1] = upper;
        b.join(" ")
    };
    vec![
        ("T_init", (0.5 * (bed.hot + bed.cold)).to_string()),
        ("T_hot", bed.hot.to_string()),
        ("T_cold", bed.cold.to_string()),
        ("ax", ["x", "y", "z"][bed.axis].into()),
        ("ext", ext.to_string()),
        ("tmp_block", block("${mid}")),
        ("hot_block", block("${split}")),
    ]
}

/// `template` with every `@key@` replaced by its value.
fn fill(template: &str, values: &[(&str, String)]) -> Result<String> {
    let mut out = String::with_capacity(template.len() + 512);
    let mut rest = template;
    while let Some(at) = rest.find('@') {
        out.push_str(&rest[..at]);
        let after = &rest[at + 1..];
        let end = after
            .find('@')
            .context("the LIGGGHTS deck template: an unclosed @placeholder@")?;
        let key = &after[..end];
        let value = values
            .iter()
            .find(|(k, _)| *k == key)
            .with_context(|| format!("the LIGGGHTS deck template: no value for @{key}@"))?;
        out.push_str(&value.1);
        rest = &after[end + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// An ASCII STL of the drum (axis y through the origin): the mantle and/or the end caps.
fn drum_stl(r: f64, l: f64, mantle: bool, caps: bool) -> String {
    let ring: Vec<(f64, f64)> = (0..FACETS_AROUND)
        .map(|k| {
            let a = 2.0 * std::f64::consts::PI * k as f64 / FACETS_AROUND as f64;
            (r * a.cos(), r * a.sin())
        })
        .collect();
    let along = ((l / FACET_LENGTH).ceil() as usize).max(1);
    let ys: Vec<f64> = (0..=along)
        .map(|j| -l / 2.0 + l * j as f64 / along as f64)
        .collect();
    let mut out = String::from("solid drum\n");
    let mut facet = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        let s = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let s = if s > 0.0 { s } else { 1.0 };
        let _ = writeln!(
            out,
            "facet normal {:.9e} {:.9e} {:.9e}\n outer loop",
            n[0] / s,
            n[1] / s,
            n[2] / s
        );
        for p in [a, b, c] {
            let _ = writeln!(out, " vertex {:.12e} {:.12e} {:.12e}", p[0], p[1], p[2]);
        }
        out.push_str(" endloop\nendfacet\n");
    };
    for k in 0..FACETS_AROUND {
        let ((x0, z0), (x1, z1)) = (ring[k], ring[(k + 1) % FACETS_AROUND]);
        if mantle {
            for w in ys.windows(2) {
                let (y0, y1) = (w[0], w[1]);
                facet([x0, y0, z0], [x1, y0, z1], [x1, y1, z1]);
                facet([x0, y0, z0], [x1, y1, z1], [x0, y1, z0]);
            }
        }
        if caps {
            let (lo, hi) = (-l / 2.0, l / 2.0);
            facet([0.0, lo, 0.0], [x1, lo, z1], [x0, lo, z0]);
            facet([0.0, hi, 0.0], [x0, hi, z0], [x1, hi, z1]);
        }
    }
    out.push_str("endsolid drum\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_rate_of_the_last_run() {
        let log = "Loop time of 1.5 on 1 procs for 100 steps with 2000 atoms\n\
                   ...\nLoop time of 12.25 on 1 procs for 5000 steps with 20000 atoms\n";
        assert_eq!(last_loop_time(log), Some((12.25, 5000, 20000)));
        assert_eq!(last_loop_time("no runs"), None);
    }
}
