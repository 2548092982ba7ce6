//! Several recorded periods replayed along a recurrence path, on synthetic
//! recordings written with `RecordingWriter`: the identity through the recorded stretch, the
//! path's seed, heat over 500 periods, `P' = 1` as the paper's method, the refusal of
//! `P' > P`, streamed against in memory; the axial mirror's images and pairings; near starts
//! refused on a path that leaves from every end.

mod common;

use extrapolate::replay::{self, Bodies, Exchanges, Scheme};
use extrapolate::{
    extrapolate_recording, ExtrapolateError, ExtrapolationOutcome, ExtrapolationRequest,
    JumpStarts, Leave, MemoryLimit, TableChoice,
};
use rand_xoshiro::rand_core::{Rng as _, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::path::{Path, PathBuf};
use tdex_format::extrapolation::{Roles, Symmetry};
use tdex_format::{
    CollisionRow, ExtrapolationReader, Fault, RecordingInfo, RecordingReader, RecordingWriter,
    Snapshot,
};

/// Particles of the synthetic bed: a 4 × 4 × 4 lattice.
const SIDE: usize = 4;
const N: usize = SIDE * SIDE * SIDE;
/// Steps of one period.
const TAU: u64 = 1000;
/// Rows of each recorded period.
const ROWS: usize = 300;
/// The case's seed in `case_resolved` (the path's default seed).
const CASE_SEED: u64 = 5;

struct Draw(Xoshiro256PlusPlus);

impl Draw {
    fn new(seed: u64) -> Self {
        Self(Xoshiro256PlusPlus::seed_from_u64(seed))
    }
    fn unit(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn below(&mut self, n: usize) -> usize {
        (self.0.next_u64() % n as u64) as usize
    }
}

fn info(recorded_periods: u32) -> RecordingInfo {
    common::recording_info(
        N,
        TAU,
        recorded_periods,
        serde_json::json!({ "seed": CASE_SEED }),
    )
}

/// Snapshot `t_index`: the lattice's sites dealt to the particles in a shuffled order and
/// jittered (every snapshot another shuffle, so the pairings move roles), equal radii (the
/// jumps then move heat between equal capacities: `Σ C T` holds across them).
fn snapshot(index: u32, draw: &mut Draw) -> Snapshot {
    let mut sites: Vec<usize> = (0..N).collect();
    for i in (1..N).rev() {
        sites.swap(i, draw.below(i + 1));
    }
    let pos = sites
        .iter()
        .map(|&s| {
            let (x, y, z) = (s % SIDE, (s / SIDE) % SIDE, s / (SIDE * SIDE));
            [x, y, z].map(|c| 0.011 * c as f64 + 0.002 * (draw.unit() - 0.5))
        })
        .collect();
    Snapshot {
        index,
        time: (index as u64 * TAU) as f64 * 1e-5,
        id: (0..N as u32).collect(),
        pos,
        radius: vec![0.005; N],
        vel: (0..N).map(|_| [draw.unit(), 0.0, -draw.unit()]).collect(),
        temp: (0..N).map(|_| 300.0 + 100.0 * draw.unit()).collect(),
    }
}

/// The rows of recorded period `p` (0-based), in apparition order, starting in
/// `[p τ, (p+1) τ)`, with runs of equal starts (synchronous groups).
fn period_rows(p: u64, draw: &mut Draw) -> Vec<CollisionRow> {
    (0..ROWS)
        .map(|r| {
            let i = draw.below(N - 1);
            let j = i + 1 + draw.below(N - 1 - i);
            // groups of equal starts, each row ending inside its period
            let start = (r as u64 * (TAU - 10) / ROWS as u64) / 3 * 3;
            CollisionRow {
                i: i as u32,
                j: j as u32,
                start_step: p * TAU + start,
                duration_steps: 1 + draw.below(10) as u32,
                sqrt_area: 1e-3 * (0.5 + draw.unit()),
            }
        })
        .collect()
}

/// A synthetic recording of `periods` periods: snapshots `t0 … tP` and each period's rows,
/// all drawn from `seed`; the rows and snapshots of its first periods are those of a
/// recording of fewer periods with the same seed.
struct Synthetic {
    snapshots: Vec<Snapshot>,
    rows: Vec<Vec<CollisionRow>>,
}

impl Synthetic {
    fn new(periods: u32, seed: u64) -> Self {
        let mut draw = Draw::new(seed);
        let snapshots = (0..=periods).map(|k| snapshot(k, &mut draw)).collect();
        let mut draw = Draw::new(seed ^ 0x5eed);
        let rows = (0..periods as u64)
            .map(|p| period_rows(p, &mut draw))
            .collect();
        Self { snapshots, rows }
    }

    /// Writes the first `periods` periods (with snapshots `t0 … t_periods`) to `path`.
    fn write(&self, path: &Path, periods: u32) -> PathBuf {
        self.write_as(path, info(periods))
    }

    /// [`Synthetic::write`] as the recording of a tdex drum (its case has a `[drum]`): the
    /// axial mirror is allowed.
    fn write_drum(&self, path: &Path, periods: u32) -> PathBuf {
        let mut info = info(periods);
        info.case_resolved["drum"] = serde_json::json!({ "radius": 0.05, "length": 0.05 });
        self.write_as(path, info)
    }

    fn write_as(&self, path: &Path, info: RecordingInfo) -> PathBuf {
        let periods = info.recorded_periods;
        let mut writer = RecordingWriter::create(path, info).unwrap();
        for s in &self.snapshots[..=periods as usize] {
            writer.write_snapshot(s).unwrap();
        }
        for rows in &self.rows[..periods as usize] {
            writer.push_rows(rows.iter().copied()).unwrap();
        }
        writer.finish(vec![0; 4], None).unwrap();
        path.to_path_buf()
    }
}

fn request(recording: &Path, output: &Path, periods: u32) -> ExtrapolationRequest {
    ExtrapolationRequest {
        reproducible: true,
        ..ExtrapolationRequest::new(
            recording.to_path_buf(),
            periods,
            output.to_path_buf(),
            MemoryLimit {
                bytes: u64::MAX,
                source: "test".into(),
            },
        )
    }
}

fn run(request: &ExtrapolationRequest) -> ExtrapolationOutcome {
    extrapolate_recording(request, |_| {}).unwrap()
}

fn snapshots(path: &Path) -> Vec<Snapshot> {
    ExtrapolationReader::open(path)
        .unwrap()
        .snapshots()
        .unwrap()
}

fn bits(t: &[f64]) -> Vec<u64> {
    t.iter().map(|x| x.to_bits()).collect()
}

/// The path an extrapolation file followed.
fn replayed(path: &Path) -> Vec<u32> {
    match &ExtrapolationReader::open(path).unwrap().info().roles {
        Roles::Path(p) => p.replayed.clone(),
        Roles::Pairing(_) => panic!("{}: one recorded period", path.display()),
    }
}

#[test]
fn the_recorded_stretch_replays_the_tables_in_order_with_no_pairing() {
    let dir = tempfile::tempdir().unwrap();
    let syn = Synthetic::new(3, 1);
    let rec = syn.write(&dir.path().join("run.mcap"), 3);
    let info = info(3);
    let bodies = Bodies::of(&info, &syn.snapshots[0]);
    for scheme in Scheme::ALL {
        let out = dir.path().join(format!("{}.mcap", scheme.name()));
        let mut req = request(&rec, &out, 6);
        req.scheme = scheme;
        run(&req);
        let snaps = snapshots(&out);
        assert_eq!(snaps.len(), 7);

        // t2, t3: tables 2 and 3 applied in order from the DEM temperatures at t1, roles
        // and particles unchanged, at the DEM's own positions of t2 and t3
        let mut expected = syn.snapshots[1].temp.clone();
        for k in 2..=3 {
            let mut table = Exchanges::default();
            for r in &syn.rows[k - 1] {
                table.push_row(r, &info, 0);
            }
            replay::apply_rows(&mut expected, &table, &bodies, scheme);
            // the file holds t1 … t7
            let s = &snaps[k - 1];
            assert_eq!(s.index, k as u32);
            assert_eq!(bits(&s.temp), bits(&expected), "{scheme:?} at t{k}");
            assert_ne!(s.temp, syn.snapshots[1].temp, "the rows change something");
            assert_eq!(s.id, (0..N as u32).collect::<Vec<_>>());
            assert_eq!(s.pos, syn.snapshots[k].pos);
            assert_eq!(s.vel, syn.snapshots[k].vel);
        }

        // past t3 the path jumps to the start of a recorded period m and follows the
        // recording from there: the positions are always those of the end of the period
        // just replayed, and the particles change roles at the jumps only
        let path = replayed(&out);
        assert_eq!(path[..2], [2, 3]);
        for (k, &p) in path.iter().enumerate() {
            let s = &snaps[k + 1];
            assert_eq!(s.pos, syn.snapshots[p as usize].pos, "t{}", k + 2);
            let jumped = p != if k == 0 { 2 } else { path[k - 1] + 1 };
            assert_eq!(
                s.id != snaps[k].id,
                jumped,
                "ids move at the jumps only (t{})",
                k + 2
            );
        }
    }
}

#[test]
fn the_same_seed_gives_the_same_bytes_and_another_seed_another_path() {
    let dir = tempfile::tempdir().unwrap();
    let rec = Synthetic::new(3, 2).write(&dir.path().join("run.mcap"), 3);
    let out = |name: &str, seed: Option<u64>| {
        let out = dir.path().join(name);
        let mut req = request(&rec, &out, 40);
        req.path_seed = seed;
        let outcome = run(&req);
        (std::fs::read(&out).unwrap(), replayed(&out), outcome)
    };
    let (a, path_a, computed) = out("a.mcap", Some(7));
    assert!(
        !computed.costs.pairing_reused,
        "the first run computes the pairings"
    );
    // the second run reuses the sidecars the first stored: the same bytes all the same
    let (b, path_b, reused) = out("b.mcap", Some(7));
    assert!(reused.costs.pairing_reused, "the pairings are reused");
    assert_eq!(a, b, "same seed, same bytes");
    assert_eq!(path_a, path_b);
    let (c, path_c, _) = out("c.mcap", Some(8));
    assert_ne!(path_a, path_c, "another seed, another path");
    assert_ne!(a, c);
    // no seed: the case's
    let (d, path_d, _) = out("d.mcap", None);
    let (e, _, _) = out("e.mcap", Some(CASE_SEED));
    assert_eq!(d, e);
    let Roles::Path(p) = &ExtrapolationReader::open(&dir.path().join("d.mcap"))
        .unwrap()
        .info()
        .roles
        .clone()
    else {
        panic!("a path")
    };
    assert_eq!((p.seed, p.recorded_periods), (CASE_SEED, 3));
    assert_eq!(p.replayed, path_d);

    // one pairing per start the path jumped to, tP to t_{m−1}, each in its own sidecar
    let mut starts: Vec<u32> = p.pairings.iter().map(|q| q.start).collect();
    assert!(p.pairings.iter().all(|q| q.end == 3));
    let mut jumped: Vec<u32> = path_d
        .windows(2)
        .filter(|w| w[1] != w[0] + 1)
        .map(|w| w[1] - 1)
        .collect();
    jumped.sort_unstable();
    jumped.dedup();
    starts.sort_unstable();
    assert_eq!(starts, jumped);
    for start in 0..3 {
        let sidecar = tdex_format::sidecar::path_between(&rec, 3, start);
        assert_eq!(sidecar.exists(), starts.contains(&start), "{start}");
    }
    assert!(!dir.path().join("run.mcap.pairing.json").exists());
}

#[test]
fn heat_is_conserved_over_500_periods_of_a_path() {
    let dir = tempfile::tempdir().unwrap();
    let syn = Synthetic::new(3, 3);
    let rec = syn.write(&dir.path().join("run.mcap"), 3);
    let bodies = Bodies::of(&info(3), &syn.snapshots[0]);
    for scheme in [Scheme::Explicit, Scheme::Exact] {
        let out = dir.path().join("long.mcap");
        let mut req = request(&rec, &out, 500);
        req.scheme = scheme;
        let outcome = run(&req);
        let path = replayed(&out);
        assert!(
            path.windows(2).filter(|w| w[1] != w[0] + 1).count() > 100,
            "the path jumps"
        );
        let snaps = snapshots(&out);
        let last = snaps.last().unwrap();
        assert_eq!(last.index, 501);
        let start = replay::total_heat(&syn.snapshots[1].temp, &bodies);
        for end in [
            outcome.total_heat_end,
            replay::total_heat(&last.temp, &bodies),
        ] {
            assert!(
                ((end - start) / start).abs() < 1e-12,
                "{scheme:?}: {start} J at t1, {end} J at t501"
            );
        }
        // and the bed has mixed: the spread of the temperatures is far smaller than at t1
        let spread = |t: &[f64]| {
            t.iter().copied().fold(f64::MIN, f64::max) - t.iter().copied().fold(f64::MAX, f64::min)
        };
        assert!(spread(&last.temp) < 0.1 * spread(&syn.snapshots[1].temp));
    }
}

#[test]
fn one_recorded_period_of_three_is_the_papers_method_on_the_first() {
    let dir = tempfile::tempdir().unwrap();
    let syn = Synthetic::new(3, 4);
    let three = syn.write(&dir.path().join("three.mcap"), 3);
    let one = syn.write(&dir.path().join("one.mcap"), 1);
    for scheme in Scheme::ALL {
        let of_three = dir.path().join("of_three.mcap");
        let mut req = request(&three, &of_three, 12);
        req.scheme = scheme;
        req.recorded_periods = Some(1);
        run(&req);
        let of_one = dir.path().join("of_one.mcap");
        let mut req = request(&one, &of_one, 12);
        req.scheme = scheme;
        run(&req);
        let (a, b) = (snapshots(&of_three), snapshots(&of_one));
        assert_eq!(a.len(), 13);
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(bits(&x.temp), bits(&y.temp), "{scheme:?} at t{}", x.index);
            assert_eq!((&x.id, &x.pos), (&y.id, &y.pos));
        }
        assert_ne!(a[12].id, a[1].id, "the pairing moves the particles");
        // the file says pairing, not path: the paper's method
        let info = ExtrapolationReader::open(&of_three).unwrap().info().clone();
        assert!(matches!(info.roles, Roles::Pairing(_)));
    }
    // both stored the pairing of t1 to t0 under the name it always had
    assert!(dir.path().join("three.mcap.pairing.json").exists());
    assert!(dir.path().join("one.mcap.pairing.json").exists());
}

#[test]
fn more_recorded_periods_than_recorded_are_refused_naming_both() {
    let dir = tempfile::tempdir().unwrap();
    let rec = Synthetic::new(3, 5).write(&dir.path().join("run.mcap"), 3);
    for asked in [0, 4] {
        let mut req = request(&rec, &dir.path().join("x.mcap"), 3);
        req.recorded_periods = Some(asked);
        let e = extrapolate_recording(&req, |_| {}).unwrap_err();
        assert!(matches!(e, ExtrapolateError::RecordedPeriods { .. }), "{e}");
        assert_eq!(extrapolate::fault_of(&e), Some(Fault::Input));
        let text = e.to_string();
        assert!(
            text.contains(&format!("{asked} recorded periods asked for"))
                && text.contains("holds 3")
                && text.contains("run.mcap"),
            "{text}"
        );
        assert!(!dir.path().join("x.mcap").exists());
    }
}

#[test]
fn streamed_and_in_memory_give_the_same_temperatures_along_a_path() {
    let dir = tempfile::tempdir().unwrap();
    let rec = Synthetic::new(4, 6).write(&dir.path().join("run.mcap"), 4);
    let reader = RecordingReader::open(&rec).unwrap();
    assert_eq!(
        reader.summary().unwrap().period_rows,
        vec![ROWS as u64; 4],
        "the writer counted each period's rows"
    );
    for scheme in Scheme::ALL {
        let (mem, streamed) = (dir.path().join("mem.mcap"), dir.path().join("str.mcap"));
        let outcome = run(&ExtrapolationRequest {
            scheme,
            ..request(&rec, &mem, 30)
        });
        assert_eq!(outcome.rows, 4 * ROWS as u64);
        let outcome = run(&ExtrapolationRequest {
            scheme,
            table: TableChoice::Streamed,
            ..request(&rec, &streamed, 30)
        });
        assert_eq!(outcome.memory.mode, replay::TableMode::Streamed);
        assert_eq!(
            std::fs::read(&mem).unwrap(),
            std::fs::read(&streamed).unwrap(),
            "{scheme:?}"
        );
        // two recorded periods of the four: a path through periods 1 and 2 alone
        let two = dir.path().join("two.mcap");
        run(&ExtrapolationRequest {
            scheme,
            recorded_periods: Some(2),
            ..request(&rec, &two, 30)
        });
        assert!(replayed(&two).iter().all(|&p| (1..=2).contains(&p)));
    }
}

/// `pos` with `y` negated: the mirror image in the drum's mid-plane.
fn mirror(pos: &[[f64; 3]]) -> Vec<[f64; 3]> {
    pos.iter().map(|&[x, y, z]| [x, -y, z]).collect()
}

#[test]
fn the_axial_mirror_alternates_the_images_through_the_pairing_of_t1_with_the_mirrored_t0() {
    let dir = tempfile::tempdir().unwrap();
    let syn = Synthetic::new(1, 7);
    let rec = syn.write_drum(&dir.path().join("run.mcap"), 1);
    let info = info(1);
    let bodies = Bodies::of(&info, &syn.snapshots[0]);
    // the pairing every jump goes through: t1 to the mirror image of t0
    let (t0, t1) = (&syn.snapshots[0], &syn.snapshots[1]);
    let image = extrapolate::cache::start_image(t0, Symmetry::AxialMirror);
    assert_eq!(image.pos, mirror(&t0.pos));
    let mirrored = extrapolate::cache::compute(&image, t1, None).unwrap();
    let plain = extrapolate::cache::compute(t0, t1, None).unwrap();
    let g = mirrored.g.clone();
    let check = extrapolate::MirrorCheck {
        end: 1,
        start: 0,
        plain_mean_diameters: plain.summary.mean_distance_diameters,
        mirrored_mean_diameters: mirrored.summary.mean_distance_diameters,
    };
    let plain = plain.g;
    assert_ne!(g, plain, "the mirror image is paired otherwise");
    let mut table = Exchanges::default();
    for r in &syn.rows[0] {
        table.push_row(r, &info, 0);
    }
    for scheme in Scheme::ALL {
        let out = dir.path().join("m.mcap");
        let outcome = run(&ExtrapolationRequest {
            scheme,
            symmetry: Symmetry::AxialMirror,
            ..request(&rec, &out, 6)
        });
        assert_eq!(outcome.symmetry, Symmetry::AxialMirror);
        // the mirrored pairing stated beside the plain one of the same snapshots
        assert_eq!(outcome.mirror_check, [check]);
        let snaps = snapshots(&out);
        let written = ExtrapolationReader::open(&out).unwrap().info().clone();
        assert_eq!(written.symmetry, Symmetry::AxialMirror);
        assert!(matches!(written.roles, Roles::Pairing(_)));
        let mut expected = t1.temp.clone();
        let mut ids: Vec<u32> = (0..N as u32).collect();
        let mut next = Vec::new();
        assert_eq!(snaps.len(), 7, "t1 … t7");
        for (k, s) in snaps.iter().enumerate().skip(1) {
            replay::move_to_roles(&expected, &g, &mut next).unwrap();
            std::mem::swap(&mut expected, &mut next);
            let mut moved = Vec::new();
            replay::move_to_roles(&ids, &g, &mut moved).unwrap();
            ids = moved;
            replay::apply_rows(&mut expected, &table, &bodies, scheme);
            assert_eq!(bits(&s.temp), bits(&expected), "{scheme:?} at t{}", k + 1);
            // odd periods are the mirror image of the recording, even ones the recording
            let (pos, vel) = if k % 2 == 1 {
                (mirror(&t1.pos), mirror(&t1.vel))
            } else {
                (t1.pos.clone(), t1.vel.clone())
            };
            assert_eq!((&s.pos, &s.vel), (&pos, &vel), "t{}", k + 1);
            assert_eq!(s.id, ids, "the particles move with their heat");
        }
        let start = replay::total_heat(&t1.temp, &bodies);
        assert!(((outcome.total_heat_end - start) / start).abs() < 1e-12);
    }
    // the mirror's pairing in its own sidecar, and the plain one its check used in its own
    assert!(tdex_format::sidecar::path_to_mirror_image(&rec, 1, 0).exists());
    assert!(dir.path().join("run.mcap.pairing.json").exists());
    // without the mirror: the paper's method, another result, and no check
    let plain_out = dir.path().join("p.mcap");
    assert!(run(&request(&rec, &plain_out, 6)).mirror_check.is_empty());
    assert_ne!(
        snapshots(&plain_out)[6].temp,
        snapshots(&dir.path().join("m.mcap"))[6].temp
    );
}

#[test]
fn along_a_path_the_mirror_flips_the_image_at_every_jump() {
    let dir = tempfile::tempdir().unwrap();
    let syn = Synthetic::new(3, 8);
    let rec = syn.write_drum(&dir.path().join("run.mcap"), 3);
    let out = dir.path().join("m.mcap");
    run(&ExtrapolationRequest {
        symmetry: Symmetry::AxialMirror,
        ..request(&rec, &out, 40)
    });
    let path = replayed(&out);
    let snaps = snapshots(&out);
    let mut mirrored = false;
    let mut previous = 1;
    for (k, &p) in path.iter().enumerate() {
        if p != previous + 1 {
            mirrored = !mirrored;
        }
        previous = p;
        let end = &syn.snapshots[p as usize].pos;
        let expected = if mirrored { mirror(end) } else { end.clone() };
        assert_eq!(snaps[k + 1].pos, expected, "t{}", k + 2);
    }
    assert!(path.windows(2).filter(|w| w[1] != w[0] + 1).count() > 5);
    // each start jumped to is paired with its mirror image, in sidecars of their own
    let Roles::Path(p) = ExtrapolationReader::open(&out)
        .unwrap()
        .info()
        .roles
        .clone()
    else {
        panic!("a path")
    };
    for q in &p.pairings {
        assert!(tdex_format::sidecar::path_to_mirror_image(&rec, 3, q.start).exists());
    }
}

#[test]
fn the_axial_mirror_is_refused_for_a_recording_without_a_drum() {
    let dir = tempfile::tempdir().unwrap();
    let rec = Synthetic::new(1, 9).write(&dir.path().join("run.mcap"), 1);
    let out = dir.path().join("x.mcap");
    let e = extrapolate_recording(
        &ExtrapolationRequest {
            symmetry: Symmetry::AxialMirror,
            ..request(&rec, &out, 3)
        },
        |_| {},
    )
    .unwrap_err();
    assert!(matches!(e, ExtrapolateError::NoMirrorImage { .. }), "{e}");
    assert_eq!(extrapolate::fault_of(&e), Some(Fault::Input));
    let text = e.to_string();
    assert!(
        text.contains("run.mcap") && text.contains("[drum]"),
        "{text}"
    );
    assert!(!out.exists());
}

#[test]
fn near_starts_are_refused_on_a_path_that_leaves_from_every_end() {
    let dir = tempfile::tempdir().unwrap();
    let rec = Synthetic::new(3, 5).write(&dir.path().join("run.mcap"), 3);
    let mut req = request(&rec, &dir.path().join("x.mcap"), 6);
    req.jumps = JumpStarts::Nearest(std::num::NonZeroU32::MIN);
    req.leave = Leave::Every(std::num::NonZeroU32::MIN);
    let e = extrapolate_recording(&req, |_| {}).unwrap_err();
    assert!(
        matches!(
            e,
            ExtrapolateError::NearestLeavingEvery {
                used: 3,
                every: 1,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(extrapolate::fault_of(&e), Some(Fault::Input));
    let text = e.to_string();
    assert!(text.contains("run.mcap") && text.contains("t3"), "{text}");
    assert!(!dir.path().join("x.mcap").exists());
    // either alone is a path
    req.leave = Leave::AtEnd;
    run(&req);
    req.jumps = JumpStarts::Every;
    req.leave = Leave::Every(std::num::NonZeroU32::MIN);
    run(&req);
}
