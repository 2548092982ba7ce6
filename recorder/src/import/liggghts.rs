//! `tdex import liggghts`: a recording built from LIGGGHTS text dumps — the atoms at `t0`,
//! `t1` and every later `t_k` (`dump custom`), the contacts every `n` steps of the period
//! (`compute pair/gran/local` through `dump local`) and, for a heated mantle, the wall
//! contacts (`compute wall/gran/local`) — by the same sampler and writer as `tdex record`,
//! so that it extrapolates exactly like a recording tdex made itself.

use super::dump::{DumpSet, FramePart, Items};
use super::ImportError;
use crate::case::{Case, ContactArea};
use crate::heat::ConductionLaw;
use crate::record::metadata::{recording_info, wall_infos, RunAtT0};
use crate::record::{ContactSampler, RecordOptions};
use crate::wall::WallSet;
use std::path::{Path, PathBuf};
use tdex_format::{RecordingCosts, RecordingSummary, RecordingWriter, Snapshot};

/// The dump file patterns (wildcards in the file name: `*`, `%`, `?`).
#[derive(Debug, Clone)]
pub struct Dumps {
    pub atoms: String,
    pub contacts: String,
    /// The wall contacts of a heated mantle; `None` for adiabatic walls.
    pub walls: Option<WallDumps>,
}

/// The wall contact dumps of a heated mantle (`compute wall/gran/local id contactArea`
/// through `dump local`) and which of the wall fix's meshes is the mantle.
#[derive(Debug, Clone)]
pub struct WallDumps {
    pub pattern: String,
    /// The mantle's place in `fix wall/gran ... meshes` (0-based, as LIGGGHTS writes the
    /// mesh id); the drum's other mesh holds the adiabatic end caps.
    pub mantle_mesh: u32,
}

/// Meshes a drum's wall fix may list: the mantle and the end caps.
pub const DRUM_MESHES: u32 = 2;

/// What an import read and wrote.
#[derive(Debug, Clone)]
pub struct ImportReport {
    pub summary: RecordingSummary,
    /// LIGGGHTS timesteps of `t0` and `t1`.
    pub step_t0: u64,
    pub step_t1: u64,
    /// Atom snapshots found at `t0 + kτ`, k ≥ 2 (consecutive), stored as the DEM reference.
    pub reference_periods: u32,
    /// Contact frames sampled, and frames passed over (outside the period or between samples).
    pub contact_frames: u64,
    pub contact_frames_skipped: u64,
    /// Atom frames passed over (not at a `t0 + kτ`).
    pub atom_frames_skipped: u64,
    /// For a heated mantle: the wall contact frames sampled, and the particle samples that
    /// touched the mantle through several of its facets at once (LIGGGHTS counts a contact a
    /// facet where facets meet at more than `curvature`), merged into one wall row with the
    /// facets' summed `sqrt(a)`.
    pub wall_frames: Option<u64>,
    pub wall_contacts_merged: u64,
}

/// Imports the dumps as a recording of one period `τ = opts.period_steps` sampled every
/// `opts.sample_every` steps into `dest`. `t0` is the first atom dump; every atom dump at
/// `t0 + kτ` (k ≥ 2, consecutive) becomes a reference snapshot (`opts.reference_periods` is
/// ignored). The case gives the time step, materials and conduction law.
pub fn import(
    case: &Case,
    case_path: &Path,
    case_toml: &str,
    dumps: &Dumps,
    opts: &RecordOptions,
    dest: &Path,
) -> Result<ImportReport, ImportError> {
    check_dumps(case, case_path, dumps)?;
    let mut sampler =
        ContactSampler::new(opts.sample_every, opts.dtc_max_steps).ok_or_else(|| {
            ImportError::Case(format!(
                "Δt_c^max = {} steps must be a positive multiple of n = {}",
                opts.dtc_max_steps, opts.sample_every
            ))
        })?;
    let atoms = read_snapshots(&dumps.atoms, opts.period_steps, case.time.dt)?;
    let t0 = &atoms.snapshots[0];
    let particles = t0.len() as u32;
    check_particle_count(case, case_path, &atoms)?;
    let mut walls = WallSet::of_drum(&case.drum);
    walls.mantle_temperature = case.drum.wall_temperature;
    let run = RunAtT0 {
        particles,
        r_max: t0.radius.iter().cloned().fold(0.0, f64::max),
        walls: wall_infos(&walls, particles),
        t0: atoms.step_t0 as f64 * case.time.dt,
        step_t0: atoms.step_t0,
    };
    let reference_periods = atoms.snapshots.len() as u32 - 2;
    let opts = RecordOptions {
        reference_periods,
        twins: 0,
        // the dumps hold one period
        recorded_periods: 1,
        twins_from: 1,
        ..opts.clone()
    };
    let info = recording_info(case, case_path, case_toml, &opts, run);
    let mut writer = RecordingWriter::create(dest, info)?;
    writer.write_snapshot(t0)?;

    let contacts = Contacts {
        ids: &atoms.ids,
        radius: &t0.radius,
        law: conduction_law(case),
    };
    let (step_t0, every) = (atoms.step_t0, opts.sample_every as u64);
    // no overflow: the atom dumps hold t1 = t0 + τ, a timestep ≤ dump::MAX_TIMESTEP
    let step_t1 = step_t0 + opts.period_steps;
    let grid = SampleGrid {
        step_t0,
        step_t1,
        every,
    };
    let mut pair_frames = SampledFrames::open(&dumps.contacts, "contact")?;
    let mut wall_frames = match &dumps.walls {
        Some(w) => Some((
            SampledFrames::open(&w.pattern, "wall contact")?,
            WallContacts {
                contacts: &contacts,
                mantle_mesh: w.mantle_mesh,
            },
        )),
        None => None,
    };
    // the contacts dumped at the end of step S are those its forces and conduction used
    // (velocity Verlet computes them on the positions x(S)): sample k = S − t0 − n stands
    // for steps k … k + n − 1 of the period, so the samples are the dumps t0 + n … t1
    let (mut pairs, mut walls, mut merged) = (Vec::new(), Vec::new(), 0u64);
    for s in (step_t0 + every..=step_t1).step_by(every as usize) {
        let parts = pair_frames.frame_at(s, &grid)?;
        contacts.sample(&parts, &mut pairs)?;
        if let Some((frames, wall)) = &mut wall_frames {
            let parts = frames.frame_at(s, &grid)?;
            merged += wall.sample(&parts, &mut walls)?;
            // rows that start at one sample keep the order of (i, j), walls after pairs
            // of the same particle: j = particles + wall
            pairs.extend_from_slice(&walls);
            pairs.sort_by_key(|&(i, j, _)| (i, j));
        }
        sampler.sample(s - step_t0 - every, pairs.iter().copied());
        writer.push_rows(sampler.drain_ready())?;
    }
    writer.push_rows(sampler.finish())?;
    for snapshot in &atoms.snapshots[1..] {
        writer.write_snapshot(snapshot)?;
    }
    // no DEM ran here: every time and the thread count are 0
    let costs = RecordingCosts::default();
    let summary = writer.finish(sampler.duration_histogram().to_vec(), Some(&costs))?;
    Ok(ImportReport {
        summary,
        step_t0,
        step_t1,
        reference_periods,
        contact_frames: pair_frames.sampled,
        contact_frames_skipped: pair_frames.skipped,
        atom_frames_skipped: atoms.skipped,
        wall_frames: wall_frames.map(|(frames, _)| frames.sampled),
        wall_contacts_merged: merged,
    })
}

/// The wall dumps are there exactly when the case heats its mantle, and name one of the
/// drum's meshes as the mantle.
fn check_dumps(case: &Case, case_path: &Path, dumps: &Dumps) -> Result<(), ImportError> {
    match (case.drum.wall_temperature, &dumps.walls) {
        (Some(temperature), None) => {
            return Err(ImportError::HeatedMantleWithoutWallDumps {
                case: case_path.to_path_buf(),
                temperature,
            })
        }
        (None, Some(walls)) => {
            return Err(ImportError::WallDumpsWithoutHeatedMantle {
                case: case_path.to_path_buf(),
                pattern: walls.pattern.clone(),
            })
        }
        _ => {}
    }
    if let Some(w) = dumps
        .walls
        .as_ref()
        .filter(|w| w.mantle_mesh >= DRUM_MESHES)
    {
        return Err(ImportError::Case(format!(
            "the mantle's mesh id {} is not one of the drum's {DRUM_MESHES} meshes (0, 1: \
             their places in `fix wall/gran ... meshes`)",
            w.mantle_mesh
        )));
    }
    Ok(())
}

/// The atom dump at t0 holds the case's particle count.
fn check_particle_count(
    case: &Case,
    case_path: &Path,
    atoms: &AtomSnapshots,
) -> Result<(), ImportError> {
    let at_t0 = atoms.snapshots[0].len();
    if at_t0 != case.particles.count {
        return Err(ImportError::Case(format!(
            "{}: particles.count = {} but the atom dump at t0 (timestep {}, {}) holds {} \
             particles: give the case the particle count of the LIGGGHTS run",
            case_path.display(),
            case.particles.count,
            atoms.step_t0,
            atoms.files_t0,
            at_t0
        )));
    }
    Ok(())
}

/// The case's conduction law, the mantle's conductivity that of the particles unless given.
fn conduction_law(case: &Case) -> ConductionLaw {
    ConductionLaw::new(
        &case.conduction,
        case.material.conductivity,
        case.drum
            .wall_conductivity
            .unwrap_or(case.material.conductivity),
        case.material.heat_capacity,
        case.material.youngs_modulus,
    )
}

/// The timesteps a period's samples are dumped at: `t0 + n, t0 + 2n, …, t1`.
struct SampleGrid {
    step_t0: u64,
    step_t1: u64,
    every: u64,
}

/// One kind of `dump local` frames (contacts or wall contacts), read in step with the
/// samples: frames between samples or outside the period are passed over.
struct SampledFrames {
    set: DumpSet,
    pattern: String,
    /// What the frames hold, for the messages (`contact`, `wall contact`).
    what: &'static str,
    sampled: u64,
    skipped: u64,
    last: Option<(u64, PathBuf)>,
}

impl SampledFrames {
    fn open(pattern: &str, what: &'static str) -> Result<Self, ImportError> {
        Ok(Self {
            set: DumpSet::open(pattern, Items::Entries)?,
            pattern: pattern.to_string(),
            what,
            sampled: 0,
            skipped: 0,
            last: None,
        })
    }

    /// The frame of timestep `expected` (every file's part), passing over the frames
    /// before it and those off the sample grid.
    fn frame_at(
        &mut self,
        expected: u64,
        grid: &SampleGrid,
    ) -> Result<Vec<FramePart>, ImportError> {
        loop {
            let next = self.set.next_timestep();
            match next {
                Some(s) if s < expected || !(s - grid.step_t0).is_multiple_of(grid.every) => {
                    let (_, parts) = self.set.read_next(true)?.expect("a frame is next");
                    self.last = parts.first().map(|p| (s, p.path.clone()));
                    self.skipped += 1;
                }
                Some(s) if s == expected => {
                    let (_, parts) = self.set.read_next(false)?.expect("a frame is next");
                    self.last = parts.first().map(|p| (s, p.path.clone()));
                    self.sampled += 1;
                    return Ok(parts);
                }
                _ => {
                    // a damaged or misordered frame further on is the more precise error
                    while self.set.read_next(true)?.is_some() {}
                    let what = self.what;
                    let found = match (next, &self.last) {
                        (Some(s), _) => format!("the next {what} dump is at timestep {s}"),
                        (None, Some((s, path))) => {
                            format!("the {what} dumps end at timestep {s} ({})", path.display())
                        }
                        (None, None) => format!("no {what} dump follows t0"),
                    };
                    let (step_t0, step_t1, every) = (grid.step_t0, grid.step_t1, grid.every);
                    let period_steps = step_t1 - step_t0;
                    return Err(ImportError::Inconsistent(format!(
                        "{}: no {what} dump at timestep {expected} (t0 = {step_t0} + {} steps): \
                         the period τ = {period_steps} steps from t0 needs one every n = \
                         {every} steps from t0 + n to t1 = {step_t1}, and {found}; dump the \
                         {what}s every n steps (or give --n as a multiple of their spacing) \
                         for the whole period",
                        self.pattern,
                        expected - step_t0,
                    )));
                }
            }
        }
    }
}

/// The atom snapshots at `t0 + kτ`, in tdex ids.
struct AtomSnapshots {
    step_t0: u64,
    /// LIGGGHTS ids of the particles at `t0`, sorted: tdex id `k` is `ids[k]` (the rank).
    ids: Vec<u64>,
    /// `t0`, `t1`, then the reference snapshots.
    snapshots: Vec<Snapshot>,
    /// The files of the `t0` frame, for messages.
    files_t0: String,
    skipped: u64,
}

/// Reads every atom frame; keeps those at `t0 + kτ` (t0 = the first) while they follow each
/// other, as snapshots in tdex ids.
fn read_snapshots(pattern: &str, period: u64, dt: f64) -> Result<AtomSnapshots, ImportError> {
    snapshots_of(DumpSet::open(pattern, Items::Atoms)?, pattern, period, dt)
}

/// [`read_snapshots`] of an opened set of atom dumps (`pattern` names them in messages).
fn snapshots_of(
    mut set: DumpSet,
    pattern: &str,
    period: u64,
    dt: f64,
) -> Result<AtomSnapshots, ImportError> {
    let step_t0 = set.next_timestep().expect("a dump set has a frame");
    let mut ids: Vec<u64> = Vec::new();
    let mut snapshots: Vec<Snapshot> = Vec::new();
    let mut files_t0 = String::new();
    let mut seen: Vec<(u64, Vec<PathBuf>)> = Vec::new();
    let mut skipped = 0;
    while let Some(step) = set.next_timestep() {
        let k = (step - step_t0) / period;
        let wanted = (step - step_t0).is_multiple_of(period) && k == snapshots.len() as u64;
        let (_, parts) = set.read_next(!wanted)?.expect("a frame is next");
        if !wanted {
            skipped += 1;
            if seen.len() < 4 {
                seen.push((step, parts.iter().map(|p| p.path.clone()).collect()));
            }
            continue;
        }
        let atoms = parse_atoms(&parts)?;
        let mut snap = if k == 0 {
            files_t0 = file_list(&parts);
            let (snap, t0_ids) = first_snapshot(atoms, &parts, step)?;
            ids = t0_ids;
            snap
        } else {
            later_snapshot(atoms, &ids, &parts, step, step_t0)?
        };
        snap.index = k as u32;
        snap.time = step as f64 * dt;
        snapshots.push(snap);
    }
    if snapshots.len() < 2 {
        let others: Vec<String> = seen
            .iter()
            .map(|(s, files)| format!("{s} ({})", files_display(files)))
            .collect();
        return Err(ImportError::NoAtomDumpAtT1 {
            pattern: pattern.to_string(),
            step_t0,
            step_t1: step_t0.saturating_add(period),
            period,
            others: if others.is_empty() {
                "none".to_string()
            } else {
                others.join(", ")
            },
        });
    }
    Ok(AtomSnapshots {
        step_t0,
        ids,
        snapshots,
        files_t0,
        skipped,
    })
}

/// The atom snapshots an import would take from one dump file held in memory (`path` names
/// it in messages), `τ = period` steps apart; the number of snapshots. For fuzzing.
pub(crate) fn atom_snapshots_of_bytes(
    path: &Path,
    bytes: Vec<u8>,
    period: u64,
) -> Result<usize, ImportError> {
    let set = DumpSet::from_bytes(path, bytes, Items::Atoms)?;
    let atoms = snapshots_of(set, &path.display().to_string(), period, 1e-5)?;
    Ok(atoms.snapshots.len())
}

/// Samples every contact frame of one dump file held in memory (`path` names it in
/// messages) as an import does, the particles of t0 being LIGGGHTS ids `1..=particles` of
/// `radius`, one sample every `every` steps; the rows made. For fuzzing.
pub(crate) fn contact_rows_of_bytes(
    path: &Path,
    bytes: Vec<u8>,
    particles: u64,
    radius: f64,
    every: u32,
) -> Result<usize, ImportError> {
    let ids: Vec<u64> = (1..=particles).collect();
    let radii = vec![radius; ids.len()];
    let contacts = Contacts {
        ids: &ids,
        radius: &radii,
        law: ConductionLaw::new(
            &crate::case::ConductionSpec::default(),
            100.0,
            100.0,
            840.0,
            1e7,
        ),
    };
    let mut sampler = ContactSampler::new(every, 2 * every).expect("a positive multiple");
    let mut set = DumpSet::from_bytes(path, bytes, Items::Entries)?;
    let (mut pairs, mut rows, mut step) = (Vec::new(), 0, 0);
    while let Some((_, parts)) = set.read_next(false)? {
        contacts.sample(&parts, &mut pairs)?;
        sampler.sample(step, pairs.iter().copied());
        rows += sampler.drain_ready().len();
        step += every as u64;
    }
    Ok(rows + sampler.finish().len())
}

fn files_display(files: &[PathBuf]) -> String {
    let mut names: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
    if names.len() > 3 {
        let more = names.len() - 3;
        names.truncate(3);
        names.push(format!("and {more} more"));
    }
    names.join(", ")
}

fn file_list(parts: &[FramePart]) -> String {
    files_display(&parts.iter().map(|p| p.path.clone()).collect::<Vec<_>>())
}

/// One particle of an atom frame, with where it was read.
struct Atom {
    id: u64,
    pos: [f64; 3],
    vel: [f64; 3],
    radius: f64,
    temp: f64,
    part: usize,
    line: u64,
}

/// Column indexes of the values tdex needs in an atom frame.
struct AtomColumns {
    id: usize,
    pos: [usize; 3],
    vel: [usize; 3],
    radius: usize,
    temp: usize,
}

/// The columns the import needs, with the alternatives LIGGGHTS may write.
const ATOM_COLUMNS: [&[&str]; 9] = [
    &["id"],
    &["x", "xu"],
    &["y", "yu"],
    &["z", "zu"],
    &["vx"],
    &["vy"],
    &["vz"],
    &["radius"],
    &["f_Temp"],
];

impl AtomColumns {
    fn of(part: &FramePart) -> Result<Self, ImportError> {
        let mut at = [0usize; 9];
        for (slot, names) in at.iter_mut().zip(ATOM_COLUMNS) {
            *slot = names
                .iter()
                .find_map(|n| part.columns.iter().position(|c| c == n))
                .ok_or_else(|| {
                    part.error(
                        part.columns_line,
                        format!(
                            "the atom dump has no `{}` column (its columns: {}); tdex needs \
                             `dump ... custom ... id type x y z vx vy vz radius f_Temp` \
                             (docs/liggghts.md)",
                            names[0],
                            part.columns.join(" ")
                        ),
                    )
                })?;
        }
        Ok(Self {
            id: at[0],
            pos: [at[1], at[2], at[3]],
            vel: [at[4], at[5], at[6]],
            radius: at[7],
            temp: at[8],
        })
    }
}

/// The values of a row, which must be as many as the header's columns.
fn row_values<'a>(
    part: &FramePart,
    line: u64,
    text: &'a str,
    values: &mut Vec<&'a str>,
) -> Result<(), ImportError> {
    values.clear();
    values.extend(text.split_ascii_whitespace());
    if values.len() != part.columns.len() {
        return Err(part.error(
            line,
            format!(
                "{} values where the header (line {}) names {} columns ({}): a column is \
                 missing or the row is cut",
                values.len(),
                part.columns_line,
                part.columns.len(),
                part.columns.join(" ")
            ),
        ));
    }
    Ok(())
}

/// The finite number in column `k` of a row.
fn number(part: &FramePart, line: u64, values: &[&str], k: usize) -> Result<f64, ImportError> {
    values[k]
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| {
            part.error(
                line,
                format!(
                    "column `{}`: `{}` is not a finite number",
                    part.columns[k], values[k]
                ),
            )
        })
}

fn parse_atoms(parts: &[FramePart]) -> Result<Vec<Atom>, ImportError> {
    let mut atoms = Vec::with_capacity(parts.iter().map(|p| p.count).sum());
    let mut values = Vec::new();
    for (k, part) in parts.iter().enumerate() {
        let c = AtomColumns::of(part)?;
        for (line, text) in part.lines() {
            row_values(part, line, text, &mut values)?;
            let num = |col| number(part, line, &values, col);
            let id = values[c.id].parse::<u64>().map_err(|_| {
                part.error(
                    line,
                    format!("column `id`: `{}` is not a particle id", values[c.id]),
                )
            })?;
            let radius = num(c.radius)?;
            if radius <= 0.0 {
                return Err(part.error(
                    line,
                    format!("column `radius`: {radius} is not a radius > 0"),
                ));
            }
            atoms.push(Atom {
                id,
                pos: [num(c.pos[0])?, num(c.pos[1])?, num(c.pos[2])?],
                vel: [num(c.vel[0])?, num(c.vel[1])?, num(c.vel[2])?],
                radius,
                temp: num(c.temp)?,
                part: k,
                line,
            });
        }
    }
    Ok(atoms)
}

/// The `t0` snapshot, the particles in order of their LIGGGHTS ids (tdex id = rank), and
/// those ids.
fn first_snapshot(
    mut atoms: Vec<Atom>,
    parts: &[FramePart],
    step: u64,
) -> Result<(Snapshot, Vec<u64>), ImportError> {
    atoms.sort_by_key(|a| a.id);
    if let Some(w) = atoms.windows(2).find(|w| w[0].id == w[1].id) {
        let (a, b) = (&w[0], &w[1]);
        return Err(parts[b.part].error(
            b.line,
            format!(
                "particle id {} appears twice at timestep {step} (also at {}:{})",
                b.id,
                parts[a.part].path.display(),
                a.line
            ),
        ));
    }
    let mut snap = Snapshot {
        id: (0..atoms.len() as u32).collect(),
        ..Default::default()
    };
    for a in &atoms {
        snap.pos.push(a.pos);
        snap.vel.push(a.vel);
        snap.radius.push(a.radius);
        snap.temp.push(a.temp);
    }
    Ok((snap, atoms.iter().map(|a| a.id).collect()))
}

/// A later snapshot in tdex ids: every particle of `t0`, and no other.
fn later_snapshot(
    atoms: Vec<Atom>,
    ids: &[u64],
    parts: &[FramePart],
    step: u64,
    step_t0: u64,
) -> Result<Snapshot, ImportError> {
    let n = ids.len();
    let mut snap = Snapshot {
        id: (0..n as u32).collect(),
        pos: vec![[0.0; 3]; n],
        vel: vec![[0.0; 3]; n],
        radius: vec![0.0; n],
        temp: vec![0.0; n],
        ..Default::default()
    };
    let mut seen: Vec<Option<(usize, u64)>> = vec![None; n];
    for a in &atoms {
        let part = &parts[a.part];
        let k = ids.binary_search(&a.id).map_err(|_| {
            part.error(
                a.line,
                format!(
                    "particle id {} is not one of the {n} particles of t0 (timestep {step_t0}): \
                     the snapshots must hold the same particles",
                    a.id
                ),
            )
        })?;
        if let Some((p, line)) = seen[k].replace((a.part, a.line)) {
            return Err(part.error(
                a.line,
                format!(
                    "particle id {} appears twice at timestep {step} (also at {}:{line})",
                    a.id,
                    parts[p].path.display()
                ),
            ));
        }
        snap.pos[k] = a.pos;
        snap.vel[k] = a.vel;
        snap.radius[k] = a.radius;
        snap.temp[k] = a.temp;
    }
    if let Some(k) = seen.iter().position(|s| s.is_none()) {
        return Err(ImportError::Inconsistent(format!(
            "{}: timestep {step} holds {} particles where t0 (timestep {step_t0}) held {n}: \
             particle id {} is missing (the snapshots must hold the same particles)",
            file_list(parts),
            atoms.len(),
            ids[k]
        )));
    }
    Ok(snap)
}

/// Which `compute pair/gran/local` values a contact dump holds, from its column count.
#[derive(Debug, Clone, Copy, PartialEq)]
enum ContactLayout {
    /// `id contactArea`: id1 id2 periodic-flag area.
    IdArea,
    /// `pos id`: x1 y1 z1 x2 y2 z2 id1 id2 periodic-flag (area from the centre distance).
    PosId,
    /// `pos id delta`: as `PosId` then the overlap δ.
    PosIdDelta,
}

impl ContactLayout {
    fn of(part: &FramePart) -> Result<Self, ImportError> {
        match part.columns.len() {
            4 => Ok(Self::IdArea),
            9 => Ok(Self::PosId),
            10 => Ok(Self::PosIdDelta),
            k => Err(part.error(
                part.columns_line,
                format!(
                    "{k} columns ({}): tdex reads the values of `compute pair/gran/local id \
                     contactArea` (4 columns), `pos id` (9) or `pos id delta` (10), all of them \
                     in order, through `dump local` (docs/liggghts.md)",
                    part.columns.join(" ")
                ),
            )),
        }
    }

    /// Columns of the two particle ids.
    fn ids(self) -> (usize, usize) {
        match self {
            Self::IdArea => (0, 1),
            Self::PosId | Self::PosIdDelta => (6, 7),
        }
    }
}

/// Turns contact frames into the sampler's `(i, j, sqrt(a))` in tdex ids.
struct Contacts<'a> {
    ids: &'a [u64],
    radius: &'a [f64],
    law: ConductionLaw,
}

impl Contacts<'_> {
    /// The touching pairs of one timestep (every file's part), sorted by `(i, j)` and each
    /// pair once, so that the table does not depend on how LIGGGHTS split the bed between
    /// processes.
    fn sample(
        &self,
        parts: &[FramePart],
        pairs: &mut Vec<(u32, u32, f64)>,
    ) -> Result<(), ImportError> {
        pairs.clear();
        let mut values = Vec::new();
        for part in parts {
            let layout = ContactLayout::of(part)?;
            let (c1, c2) = layout.ids();
            for (line, text) in part.lines() {
                row_values(part, line, text, &mut values)?;
                let (i, j) = (
                    self.tdex_id(part, line, &values, c1)?,
                    self.tdex_id(part, line, &values, c2)?,
                );
                if i == j {
                    return Err(part.error(
                        line,
                        format!("particle {} in contact with itself", values[c1]),
                    ));
                }
                if let Some(a) = self.sqrt_area(layout, part, line, &values, i, j)? {
                    pairs.push((i.min(j), i.max(j), a));
                }
            }
        }
        pairs.sort_by_key(|&(i, j, _)| (i, j));
        pairs.dedup_by_key(|&mut (i, j, _)| (i, j));
        Ok(())
    }

    /// The tdex id of the LIGGGHTS id in column `k`, written in full (`%g` would round ids
    /// of a million and more to six digits).
    fn tdex_id(
        &self,
        part: &FramePart,
        line: u64,
        values: &[&str],
        k: usize,
    ) -> Result<u32, ImportError> {
        let text = values[k];
        let id = text
            .parse::<f64>()
            .ok()
            .filter(|v| !text.contains(['e', 'E']) && v.fract() == 0.0 && *v >= 0.0)
            .ok_or_else(|| {
                part.error(
                    line,
                    format!(
                        "column `{}`: `{text}` is not a particle id written in full (use \
                         `dump_modify ... format \"%.0f %.0f %.0f %.17g\"`, docs/liggghts.md)",
                        part.columns[k]
                    ),
                )
            })? as u64;
        self.ids.binary_search(&id).map(|k| k as u32).map_err(|_| {
            part.error(
                line,
                format!(
                    "particle id {id} is not one of the {} particles of the atom dump at t0",
                    self.ids.len()
                ),
            )
        })
    }

    /// `sqrt(a)` of a contact as the case's conduction law computes it; `None` if the pair
    /// does not touch.
    fn sqrt_area(
        &self,
        layout: ContactLayout,
        part: &FramePart,
        line: u64,
        values: &[&str],
        i: u32,
        j: u32,
    ) -> Result<Option<f64>, ImportError> {
        let (ri, rj) = (self.radius[i as usize], self.radius[j as usize]);
        let num = |k| number(part, line, values, k);
        let distance = match layout {
            ContactLayout::IdArea => {
                let area = num(3)?;
                if area <= 0.0 {
                    return Ok(None);
                }
                // LIGGGHTS' contactArea is the lens of the two spheres, the law's default
                if self.law.area == ContactArea::Overlap && self.law.overlap_correction == 1.0 {
                    return Ok(Some(area.sqrt()));
                }
                lens_distance(area, ri, rj)
            }
            ContactLayout::PosId => {
                let d: Vec<f64> = (0..3)
                    .map(|k| Ok(num(k)? - num(k + 3)?))
                    .collect::<Result<_, ImportError>>()?;
                (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
            }
            ContactLayout::PosIdDelta => ri + rj - num(9)?,
        };
        if distance >= ri + rj {
            return Ok(None);
        }
        let area = self.law.pair_area(distance, ri, rj);
        Ok((area > 0.0).then(|| area.sqrt()))
    }
}

/// Turns wall contact frames (`compute wall/gran/local id contactArea`: mesh id, triangle
/// id, particle id, area) into the sampler's wall rows `(i, particles + mantle, sqrt(a))`.
struct WallContacts<'a> {
    contacts: &'a Contacts<'a>,
    /// The mantle's mesh id; the drum's other mesh (the end caps) is adiabatic.
    mantle_mesh: u32,
}

impl WallContacts<'_> {
    /// The particles touching the mantle at one timestep, in id order, each once: a
    /// particle touching several of the mantle's facets (LIGGGHTS counts a contact a facet
    /// where they meet at more than `curvature`, so at every edge with its default 0.256°)
    /// gets one row whose `sqrt(a)` is the facets' sum, so that it conducts what LIGGGHTS
    /// conducted. Returns how many particles were merged so.
    fn sample(
        &self,
        parts: &[FramePart],
        walls: &mut Vec<(u32, u32, f64)>,
    ) -> Result<u64, ImportError> {
        walls.clear();
        let mantle = self.contacts.ids.len() as u32; // body `particles + 0`: WallKind::DRUM
        let mut values = Vec::new();
        for part in parts {
            if part.columns.len() != 4 {
                return Err(part.error(
                    part.columns_line,
                    format!(
                        "{} columns ({}): tdex reads the values of `compute wall/gran/local id \
                         contactArea` (4 columns: mesh id, triangle id, particle id, contact \
                         area) through `dump local` (docs/liggghts.md)",
                        part.columns.len(),
                        part.columns.join(" ")
                    ),
                ));
            }
            for (line, text) in part.lines() {
                row_values(part, line, text, &mut values)?;
                let mesh = number(part, line, &values, 0)?;
                if mesh == f64::from(self.mantle_mesh) {
                    let i = self.contacts.tdex_id(part, line, &values, 2)?;
                    let area = number(part, line, &values, 3)?;
                    if area > 0.0 {
                        walls.push((i, mantle, self.sqrt_area(area, i)));
                    }
                } else if mesh.fract() != 0.0 || !(0.0..f64::from(DRUM_MESHES)).contains(&mesh) {
                    return Err(part.error(
                        line,
                        format!(
                            "mesh id `{}` is not one of the drum's {DRUM_MESHES} meshes (0, 1: \
                             their places in `fix wall/gran ... meshes`; the mantle is mesh {})",
                            values[0], self.mantle_mesh
                        ),
                    ));
                }
            }
        }
        walls.sort_by_key(|&(i, _, _)| i);
        let mut merged = 0;
        walls.dedup_by(|later, first| {
            let same = later.0 == first.0;
            if same {
                first.2 += later.2;
                merged += 1;
            }
            same
        });
        Ok(merged)
    }

    /// `sqrt(a)` of a contact of disc area `area` between particle `i` and the mantle, as
    /// the case's law computes it (LIGGGHTS's wall `contactArea` is the disc
    /// `π (2Rδ − δ²)` where the sphere cuts the wall).
    fn sqrt_area(&self, area: f64, i: u32) -> f64 {
        let law = &self.contacts.law;
        if law.overlap_correction == 1.0 {
            return area.sqrt();
        }
        let r = self.contacts.radius[i as usize];
        let overlap = r - (r * r - area / std::f64::consts::PI).max(0.0).sqrt();
        law.wall_sqrt_area(overlap, r)
    }
}

/// The centre distance `r` of two spheres whose lens (intersection disc) has area `a`: the
/// larger root `u = r²` of `u² − (s² + d² − 4a/π) u + s²d² = 0`, `s = ri + rj`, `d = ri − rj`.
fn lens_distance(area: f64, ri: f64, rj: f64) -> f64 {
    let (s2, d2) = ((ri + rj) * (ri + rj), (ri - rj) * (ri - rj));
    let b = s2 + d2 - 4.0 * area / std::f64::consts::PI;
    ((b + (b * b - 4.0 * s2 * d2).max(0.0).sqrt()) / 2.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::ConductionSpec;

    #[test]
    fn the_lens_distance_inverts_the_lens_area() {
        let law = ConductionLaw::new(&ConductionSpec::default(), 100.0, 100.0, 840.0, 1e7);
        for (r, ri, rj) in [(0.0099, 0.005, 0.005), (0.00895, 0.005, 0.004)] {
            let a = law.pair_area(r, ri, rj);
            assert!(
                (lens_distance(a, ri, rj) - r).abs() < 1e-12,
                "{r} {ri} {rj}"
            );
        }
    }
}
