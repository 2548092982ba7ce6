//! Beds of several particle sizes: the mean temperature of each size class and how far the
//! classes have segregated, for the DEM reference, its further runs and the second field.
//! A rotating drum segregates by size (the small particles gather in the bed's core, the
//! large ones ride outside and meet the wall first), so a bed mean that agrees can hide
//! classes that heat at the wrong pace.

use super::floor::min_max;
use super::SecondKind;
use serde::Serialize;
use tdex_format::Snapshot;

/// More distinct radii than this are a continuous size distribution, not size classes: a
/// table row per radius would say nothing.
pub const MAX_CLASSES: usize = 12;

/// The size classes of a bed: its distinct radii (m), smallest first. A class is one exact
/// radius value, as the engine gives each class one radius.
#[derive(Debug, Clone, PartialEq)]
pub struct SizeClasses {
    pub radii: Vec<f64>,
}

impl SizeClasses {
    /// The distinct radii of `radius`, smallest first: the classes the pairing keeps
    /// ([`tdex_format::size_classes`]).
    pub fn of(radius: &[f64]) -> Self {
        Self {
            radii: tdex_format::size_classes(radius),
        }
    }

    pub fn len(&self) -> usize {
        self.radii.len()
    }

    pub fn is_empty(&self) -> bool {
        self.radii.is_empty()
    }

    /// The class of a particle of radius `r` (None for a radius that is no class's).
    pub fn class_of(&self, r: f64) -> Option<usize> {
        self.radii.binary_search_by(|c| c.total_cmp(&r)).ok()
    }
}

/// The mean temperature of the particles of each radius (K; one radius, so no weighting
/// within a class), in the order of `classes`; NaN for a class with no particle.
pub fn class_mean_temperature(classes: &SizeClasses, radius: &[f64], temp: &[f64]) -> Vec<f64> {
    let mut sum = vec![0.0; classes.len()];
    let mut count = vec![0usize; classes.len()];
    for (&r, &t) in radius.iter().zip(temp) {
        if let Some(c) = classes.class_of(r) {
            sum[c] += t;
            count[c] += 1;
        }
    }
    sum.iter()
        .zip(&count)
        .map(|(&s, &n)| if n > 0 { s / n as f64 } else { f64::NAN })
        .collect()
}

/// The radial segregation of the size classes in one snapshot.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Segregation {
    /// Per class (smallest first): the mean distance of its particles from the bed's
    /// centroid in the cross-section (x, z), over the same mean for all particles. 1: the
    /// class sits where the bed does on average; below 1 it gathers in the core, above 1
    /// outside.
    pub relative_distance: Vec<f64>,
    /// The largest class's relative distance minus the smallest's: 0 for a mixed bed,
    /// positive when the large particles ride outside the small ones (the usual drum
    /// segregation), negative the other way round.
    pub index: f64,
}

/// The radial segregation index of the size classes (see [`Segregation`]).
///
/// The centroid is the mean of all particle centres in the drum's cross-section (x, z; the
/// drum axis is y), and each distance is a particle centre's from it in that plane. A class
/// without particles has a NaN relative distance, as has every class of a bed whose
/// particles all sit on the centroid; the index is then NaN too.
pub fn segregation_index(classes: &SizeClasses, pos: &[[f64; 3]], radius: &[f64]) -> Segregation {
    let n = pos.len().max(1) as f64;
    let (cx, cz) = pos
        .iter()
        .fold((0.0, 0.0), |(x, z), p| (x + p[0] / n, z + p[2] / n));
    let distance = |p: &[f64; 3]| (p[0] - cx).hypot(p[2] - cz);
    let mean_all = pos.iter().map(distance).sum::<f64>() / n;
    let mut sum = vec![0.0; classes.len()];
    let mut count = vec![0usize; classes.len()];
    for (p, &r) in pos.iter().zip(radius) {
        if let Some(c) = classes.class_of(r) {
            sum[c] += distance(p);
            count[c] += 1;
        }
    }
    let relative_distance: Vec<f64> = sum
        .iter()
        .zip(&count)
        .map(|(&s, &k)| {
            if k > 0 && mean_all > 0.0 {
                s / k as f64 / mean_all
            } else {
                f64::NAN
            }
        })
        .collect();
    let index = match (relative_distance.first(), relative_distance.last()) {
        (Some(small), Some(large)) => large - small,
        _ => f64::NAN,
    };
    Segregation {
        relative_distance,
        index,
    }
}

/// The size classes' state in one snapshot.
#[derive(Debug, Clone, Serialize)]
pub struct ClassState {
    pub k: u32,
    /// Simulated time (s).
    pub t: f64,
    /// Mean temperature of the particles of each radius (K), smallest radius first.
    pub mean_temperature: Vec<f64>,
    pub segregation: Segregation,
}

impl ClassState {
    pub fn of(classes: &SizeClasses, s: &Snapshot) -> Self {
        Self {
            k: s.index,
            t: s.time,
            mean_temperature: class_mean_temperature(classes, &s.radius, &s.temp),
            segregation: segregation_index(classes, &s.pos, &s.radius),
        }
    }
}

/// The size classes of a comparison: each class's mean temperature and the segregation
/// index for the DEM reference, its further runs and the second field.
#[derive(Debug, Clone, Serialize)]
pub struct ClassComparison {
    /// The class radii (m), smallest first, and their particle counts (at t1 of the DEM).
    pub radii: Vec<f64>,
    pub particles: Vec<usize>,
    /// Every DEM reference snapshot (k = 0, 1, then the reference).
    pub dem_series: Vec<ClassState>,
    /// The same for each further DEM run (twins first).
    pub dem_runs_series: Vec<Vec<ClassState>>,
    /// The second field at each compared `t_k` (those of the comparison's `periods`).
    pub extra_series: Vec<ClassState>,
    /// The `t_k` judged against the DEM runs' spread: those of the verdict (not the recorded
    /// stretch of an extrapolation) where at least two DEM runs have a snapshot.
    pub judged: Vec<u32>,
    /// Per class, the `judged` t_k where the second field's class mean lies within the
    /// DEM runs' min..max there.
    pub mean_within_spread: Vec<Vec<u32>>,
    /// The `judged` t_k where the second field's segregation index lies within theirs.
    pub index_within_spread: Vec<u32>,
}

impl SizeClasses {
    /// The size classes of a DEM run, from its snapshot at t1 (the first one without it):
    /// None for a bed of one size, or of more than [`MAX_CLASSES`] sizes (see
    /// [`too_many_classes`]), whose comparison has no class section.
    pub fn of_run(dem: &[Snapshot]) -> Option<Self> {
        let first = dem.iter().find(|s| s.index == 1).or(dem.first())?;
        let classes = SizeClasses::of(&first.radius);
        (2..=MAX_CLASSES)
            .contains(&classes.len())
            .then_some(classes)
    }
}

impl ClassComparison {
    /// The class comparison of the DEM reference `dem` and the further runs `others` with
    /// the second field's states at the compared t_k, each with whether the second field was
    /// still the recorded run there (left out of the judgement, as in the verdict).
    pub fn new(
        classes: SizeClasses,
        dem: &[Snapshot],
        others: &[Vec<Snapshot>],
        compared: Vec<(ClassState, bool)>,
    ) -> Self {
        let mut particles = vec![0usize; classes.len()];
        if let Some(first) = dem.iter().find(|s| s.index == 1).or(dem.first()) {
            for &r in &first.radius {
                if let Some(c) = classes.class_of(r) {
                    particles[c] += 1;
                }
            }
        }
        let series = |snaps: &[Snapshot]| -> Vec<ClassState> {
            snaps.iter().map(|s| ClassState::of(&classes, s)).collect()
        };
        let dem_series = series(dem);
        let dem_runs_series: Vec<Vec<ClassState>> = others.iter().map(|o| series(o)).collect();
        let mut judged = Vec::new();
        let mut mean_within_spread = vec![Vec::new(); classes.len()];
        let mut index_within_spread = Vec::new();
        for (extra, within_recording) in &compared {
            let k = extra.k;
            let runs = runs_at(&dem_series, &dem_runs_series, k);
            if *within_recording || runs.len() < 2 {
                continue;
            }
            judged.push(k);
            for (class, within) in mean_within_spread.iter_mut().enumerate() {
                let spread = min_max(runs.iter().map(|s| s.mean_temperature[class]));
                if inside(extra.mean_temperature[class], spread) {
                    within.push(k);
                }
            }
            let spread = min_max(runs.iter().map(|s| s.segregation.index));
            if inside(extra.segregation.index, spread) {
                index_within_spread.push(k);
            }
        }
        Self {
            radii: classes.radii,
            particles,
            dem_series,
            dem_runs_series,
            extra_series: compared.into_iter().map(|(state, _)| state).collect(),
            judged,
            mean_within_spread,
            index_within_spread,
        }
    }

    /// The DEM runs' states at `t_k`: the reference, then every further run that reached it.
    pub fn runs_at(&self, k: u32) -> Vec<&ClassState> {
        runs_at(&self.dem_series, &self.dem_runs_series, k)
    }

    /// The reference's state at `t_k`.
    pub fn dem_at(&self, k: u32) -> Option<&ClassState> {
        self.dem_series.iter().find(|s| s.k == k)
    }

    /// The min..max of the DEM runs' class means at `t_k` (None for one run).
    pub fn mean_spread(&self, class: usize, k: u32) -> Option<(f64, f64)> {
        let runs = self.runs_at(k);
        (runs.len() >= 2)
            .then(|| min_max(runs.iter().map(|s| s.mean_temperature[class])))
            .flatten()
    }

    /// The min..max of the DEM runs' segregation index at `t_k` (None for one run).
    pub fn index_spread(&self, k: u32) -> Option<(f64, f64)> {
        let runs = self.runs_at(k);
        (runs.len() >= 2)
            .then(|| min_max(runs.iter().map(|s| s.segregation.index)))
            .flatten()
    }
}

fn runs_at<'s>(
    dem: &'s [ClassState],
    others: &'s [Vec<ClassState>],
    k: u32,
) -> Vec<&'s ClassState> {
    dem.iter()
        .chain(others.iter().flatten())
        .filter(|s| s.k == k)
        .collect()
}

/// Whether `x` lies within `spread` (min..max, ends included: a second field identical to
/// one of the runs is within).
fn inside(x: f64, spread: Option<(f64, f64)>) -> bool {
    spread.is_some_and(|(lo, hi)| lo <= x && x <= hi)
}

/// The number of distinct radii of a DEM run with more than [`MAX_CLASSES`] of them (None
/// otherwise): such a bed is compared on its bed mean alone, and the text says why.
pub fn too_many_classes(dem: &[Snapshot]) -> Option<usize> {
    let first = dem.iter().find(|s| s.index == 1).or(dem.first())?;
    let n = SizeClasses::of(&first.radius).len();
    (n > MAX_CLASSES).then_some(n)
}

/// A radius in mm without float noise (`1.5`, `0.75`).
pub fn millimetres(r: f64) -> String {
    crate::fmt::sig(r * 1e3, 4)
}

/// A temperature in K to the mK (`-` for none).
pub fn temperature(t: f64) -> String {
    if t.is_nan() {
        "-".into()
    } else {
        format!("{t:.3}")
    }
}

/// A segregation index or relative distance to three decimals (`-` for none).
pub fn dimensionless(x: f64) -> String {
    if x.is_nan() {
        "-".into()
    } else {
        format!("{x:.3}")
    }
}

/// `lo..hi`, or `-` without a spread.
pub fn range(spread: Option<(f64, f64)>, f: impl Fn(f64) -> String) -> String {
    spread.map_or("-".into(), |(lo, hi)| format!("{}..{}", f(lo), f(hi)))
}

/// `class 2 (1.5 mm) mean within the DEM runs' spread at 5 of 6 compared t_k`, one line per
/// class, then the segregation index's; without a spread (one DEM run), one line saying so.
pub fn verdict_lines(c: &ClassComparison) -> Vec<String> {
    let n = c.judged.len();
    if n == 0 {
        return vec![
            "size classes not judged: no compared t_k has two DEM runs to give a spread \
             (record with --twins 2)"
                .into(),
        ];
    }
    let mut lines: Vec<String> = c
        .mean_within_spread
        .iter()
        .enumerate()
        .map(|(class, within)| {
            format!(
                "class {} ({} mm) mean within the DEM runs' spread at {} of {n} compared t_k",
                class + 1,
                millimetres(c.radii[class]),
                within.len()
            )
        })
        .collect();
    lines.push(format!(
        "segregation index within the DEM runs' spread at {} of {n} compared t_k",
        c.index_within_spread.len()
    ));
    lines
}

/// The size classes in `tdex compare`'s text: a table at the last compared `t_k`, the
/// segregation index there, and the verdict lines over all compared `t_k`.
pub fn table(c: &ClassComparison, kind: SecondKind) -> String {
    let Some(last) = c.extra_series.last() else {
        return String::new();
    };
    let k = last.k;
    // the second field's column, as the main table names it
    let second = match kind {
        SecondKind::Extrapolation => "extrapolated",
        SecondKind::Dem => "2nd DEM",
    };
    let dem = c.dem_at(k);
    let of_dem = |f: &dyn Fn(&ClassState) -> String| dem.map_or("-".into(), f);
    let header = [
        "class".to_string(),
        "radius (mm)".into(),
        "particles".into(),
        "DEM".into(),
        "DEM runs min..max".into(),
        second.into(),
        "distance DEM".into(),
        format!("distance {second}"),
    ];
    let rows: Vec<[String; 8]> = c
        .radii
        .iter()
        .enumerate()
        .map(|(class, &r)| {
            [
                (class + 1).to_string(),
                millimetres(r),
                c.particles[class].to_string(),
                of_dem(&|d| temperature(d.mean_temperature[class])),
                range(c.mean_spread(class, k), temperature),
                temperature(last.mean_temperature[class]),
                of_dem(&|d| dimensionless(d.segregation.relative_distance[class])),
                dimensionless(last.segregation.relative_distance[class]),
            ]
        })
        .collect();
    let widths: Vec<usize> = (0..header.len())
        .map(|i| {
            rows.iter()
                .map(|r| r[i].chars().count())
                .chain([header[i].chars().count()])
                .max()
                .unwrap_or(0)
        })
        .collect();
    let line = |cells: &[String]| -> String {
        let cells: Vec<String> = cells
            .iter()
            .zip(&widths)
            .map(|(cell, &w)| format!("{cell:>w$}"))
            .collect();
        cells.join("  ") + "\n"
    };
    let mut s = format!(
        "size classes at t_{k}, the last compared t_k: the mean temperature of the particles \
         of each radius (K), and their distance: the class's mean distance from the bed's \
         centroid in (x, z) over that of all particles (1: no segregation)\n"
    );
    s += &line(&header);
    for r in &rows {
        s += &line(r);
    }
    s += &format!(
        "segregation index at t_{k} (the largest class's distance minus the smallest's; 0: \
         mixed): DEM {}, DEM runs {}, {second} {}\n",
        of_dem(&|d| dimensionless(d.segregation.index)),
        range(c.index_spread(k), dimensionless),
        dimensionless(last.segregation.index),
    );
    for line in verdict_lines(c) {
        s += &line;
        s += "\n";
    }
    s
}

/// Synthetic beds for the tests of the comparison and of the report (which the `tdex`
/// binary's tests reach, so the module is compiled outside `cfg(test)` too).
#[doc(hidden)]
pub mod synthetic {
    use super::*;

    /// A snapshot of particles at `pos` (x, z) with `radius` and `temp`.
    pub fn snapshot(k: u32, bed: &[((f64, f64), f64, f64)]) -> Snapshot {
        Snapshot {
            index: k,
            time: 0.5 * f64::from(k),
            id: (0..bed.len() as u32).collect(),
            pos: bed.iter().map(|&((x, z), _, _)| [x, 0.0, z]).collect(),
            radius: bed.iter().map(|&(_, r, _)| r).collect(),
            temp: bed.iter().map(|&(_, _, t)| t).collect(),
            vel: vec![[0.0; 3]; bed.len()],
        }
    }

    /// A bed of 3 classes: 2 particles of 1 mm in the core, 2 of 1.5 mm between, 2 of 2 mm
    /// outside, the temperatures `base` + the class's offset (0, 10, 20 K).
    pub fn three_classes(k: u32, base: f64) -> Snapshot {
        snapshot(
            k,
            &[
                ((-0.01, 0.0), 0.001, base),
                ((0.01, 0.0), 0.001, base),
                ((0.0, -0.02), 0.0015, base + 10.0),
                ((0.0, 0.02), 0.0015, base + 10.0),
                ((-0.03, 0.0), 0.002, base + 20.0),
                ((0.03, 0.0), 0.002, base + 20.0),
            ],
        )
    }

    /// The class comparison of a 3-class bed with one twin: the twin 0.5 K warmer than the
    /// reference, the extrapolation within their spread at t2 and 1 K too cold at t3.
    pub fn three_class_comparison() -> ClassComparison {
        let dem: Vec<Snapshot> = (0..4)
            .map(|k| three_classes(k, 300.0 + f64::from(k)))
            .collect();
        // the twin from t1 on
        let twin: Vec<Snapshot> = (1..4)
            .map(|k| three_classes(k, 300.5 + f64::from(k)))
            .collect();
        let classes = SizeClasses::of_run(&dem).expect("three classes");
        let compared = [three_classes(2, 302.25), three_classes(3, 302.0)]
            .iter()
            .map(|s| (ClassState::of(&classes, s), false))
            .collect();
        ClassComparison::new(classes, &dem, &[twin], compared)
    }
}

#[cfg(test)]
mod tests {
    use super::synthetic::*;
    use super::*;

    /// `n` points evenly around a circle of radius `rho` about (x, z) = (0.1, −0.2).
    fn ring(n: usize, rho: f64, phase: f64) -> Vec<(f64, f64)> {
        (0..n)
            .map(|i| {
                let a = phase + std::f64::consts::TAU * i as f64 / n as f64;
                (0.1 + rho * a.cos(), -0.2 + rho * a.sin())
            })
            .collect()
    }

    #[test]
    fn classes_are_the_distinct_radii_smallest_first() {
        let c = SizeClasses::of(&[0.002, 0.001, 0.002, 0.0015, 0.001]);
        assert_eq!(c.radii, vec![0.001, 0.0015, 0.002]);
        assert_eq!(c.class_of(0.0015), Some(1));
        assert_eq!(c.class_of(0.0012), None);
        assert_eq!(SizeClasses::of(&[0.001; 4]).len(), 1);
    }

    #[test]
    fn a_class_mean_is_the_plain_mean_of_its_particles() {
        let classes = SizeClasses::of(&[0.001, 0.002]);
        let radius = [0.001, 0.002, 0.001, 0.002, 0.001];
        let temp = [300.0, 400.0, 310.0, 420.0, 320.0];
        assert_eq!(
            class_mean_temperature(&classes, &radius, &temp),
            vec![310.0, 410.0]
        );
        // a class with no particle in this snapshot has no mean
        let three = SizeClasses::of(&[0.001, 0.0015, 0.002]);
        let m = class_mean_temperature(&three, &radius, &temp);
        assert!(m[1].is_nan());
    }

    #[test]
    fn a_core_and_ring_bed_is_segregated_and_a_mix_is_not() {
        // small particles on a disc of radius 1 cm (rings at 0.25, 0.5, 0.75, 1 cm), large
        // ones on a ring at 3 cm about the same centre
        let small: Vec<(f64, f64)> = [0.0025, 0.005, 0.0075, 0.01]
            .iter()
            .flat_map(|&rho| ring(16, rho, 0.1))
            .collect();
        let large = ring(64, 0.03, 0.0);
        let classes = SizeClasses::of(&[0.001, 0.002]);
        let pos: Vec<[f64; 3]> = small
            .iter()
            .chain(&large)
            .map(|&(x, z)| [x, 7.0, z])
            .collect();
        let radius: Vec<f64> = (0..128)
            .map(|i| if i < 64 { 0.001 } else { 0.002 })
            .collect();
        let s = segregation_index(&classes, &pos, &radius);
        // mean distances 0.625 cm and 3 cm, over all 1.8125 cm
        assert!((s.relative_distance[0] - 0.625 / 1.8125).abs() < 1e-12);
        assert!((s.relative_distance[1] - 3.0 / 1.8125).abs() < 1e-12);
        assert!((s.index - 2.375 / 1.8125).abs() < 1e-12);
        assert!(s.index > 1.0);
        // the same positions with the sizes alternating: every ring holds both classes
        let mixed: Vec<f64> = (0..128)
            .map(|i| if i % 2 == 0 { 0.001 } else { 0.002 })
            .collect();
        let m = segregation_index(&classes, &pos, &mixed);
        assert!(m.index.abs() < 1e-12, "{}", m.index);
        // and a random mix of a random bed: close to 0
        let mut state = 7u64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let bed: Vec<[f64; 3]> = (0..4000)
            .map(|_| [uniform() - 0.5, uniform(), 0.5 * uniform()])
            .collect();
        let sizes: Vec<f64> = (0..4000)
            .map(|_| [0.001, 0.0015, 0.002][(3.0 * uniform()) as usize])
            .collect();
        let three = SizeClasses::of(&sizes);
        let r = segregation_index(&three, &bed, &sizes);
        assert_eq!(r.relative_distance.len(), 3);
        assert!(r.index.abs() < 0.05, "{}", r.index);
        assert!(r.relative_distance.iter().all(|d| (d - 1.0).abs() < 0.05));
        // the large ones inside: negative
        let swapped: Vec<f64> = radius.iter().map(|&r| 0.003 - r).collect();
        assert!(segregation_index(&classes, &pos, &swapped).index < -1.0);
    }

    #[test]
    fn three_classes_are_tabled_and_judged_against_the_dem_runs() {
        let c = three_class_comparison();
        assert_eq!(c.radii, vec![0.001, 0.0015, 0.002]);
        assert_eq!(c.particles, vec![2, 2, 2]);
        assert_eq!(c.judged, vec![2, 3]);
        assert_eq!(c.mean_within_spread, vec![vec![2]; 3]);
        // nothing moves: the index is the DEM's at both t_k
        assert_eq!(c.index_within_spread, vec![2, 3]);
        assert_eq!(
            c.extra_series[1].mean_temperature,
            vec![302.0, 312.0, 322.0]
        );
        let text = table(&c, SecondKind::Extrapolation);
        let rows: Vec<Vec<&str>> = text
            .lines()
            .map(|l| l.split_whitespace().collect())
            .collect();
        assert!(
            text.starts_with("size classes at t_3, the last compared t_k:"),
            "{text}"
        );
        assert_eq!(
            rows[2],
            [
                "1",
                "1",
                "2",
                "303.000",
                "303.000..303.500",
                "302.000",
                "0.500",
                "0.500"
            ]
        );
        assert_eq!(
            rows[3],
            [
                "2",
                "1.5",
                "2",
                "313.000",
                "313.000..313.500",
                "312.000",
                "1.000",
                "1.000"
            ]
        );
        assert_eq!(
            rows[4],
            [
                "3",
                "2",
                "2",
                "323.000",
                "323.000..323.500",
                "322.000",
                "1.500",
                "1.500"
            ]
        );
        assert!(
            text.contains("DEM 1.000, DEM runs 1.000..1.000, extrapolated 1.000\n"),
            "{text}"
        );
        assert!(text.contains(
            "class 2 (1.5 mm) mean within the DEM runs' spread at 1 of 2 compared t_k\n"
        ));
        assert!(text
            .ends_with("segregation index within the DEM runs' spread at 2 of 2 compared t_k\n"));
    }

    #[test]
    fn without_a_twin_nothing_is_judged() {
        let dem: Vec<Snapshot> = (0..3).map(|k| three_classes(k, 300.0)).collect();
        let classes = SizeClasses::of_run(&dem).expect("three classes");
        let compared = vec![(ClassState::of(&classes, &three_classes(2, 301.0)), false)];
        let c = ClassComparison::new(classes, &dem, &[], compared);
        assert!(c.judged.is_empty());
        assert_eq!(
            verdict_lines(&c),
            [
                "size classes not judged: no compared t_k has two DEM runs to give a spread \
              (record with --twins 2)"
            ]
        );
    }

    #[test]
    fn a_bed_of_one_size_has_no_class_comparison() {
        let one = |k: u32| {
            snapshot(
                k,
                &[((0.0, 0.0), 0.001, 300.0), ((0.01, 0.0), 0.001, 310.0)],
            )
        };
        let dem: Vec<Snapshot> = (0..3).map(one).collect();
        assert_eq!(SizeClasses::of_run(&dem), None);
        assert_eq!(too_many_classes(&dem), None);
        // nor a continuous distribution, which is said instead
        let many: Vec<Snapshot> = (0..2)
            .map(|k| {
                let bed: Vec<((f64, f64), f64, f64)> = (0..20)
                    .map(|i| {
                        (
                            (0.01 * f64::from(i), 0.0),
                            0.001 + 1e-5 * f64::from(i),
                            300.0,
                        )
                    })
                    .collect();
                snapshot(k, &bed)
            })
            .collect();
        assert_eq!(SizeClasses::of_run(&many), None);
        assert_eq!(too_many_classes(&many), Some(20));
    }
}
