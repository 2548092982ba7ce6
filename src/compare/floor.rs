//! The DEM's own spread at one `t_k` (the "floor"): the cell distances between the DEM runs
//! of one case (the reference and its twins), and the extrapolation's distance to those runs
//! measured the same way, so that the extrapolation is judged as one more run would be.

use super::metrics::eps_abs;
use serde::Serialize;

/// The DEM runs' spread and the extrapolation's place in it, at one `t_k`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Floor {
    /// Mean `ε_abs` (K) over the pairs of DEM runs.
    pub floor_eps_abs: f64,
    /// Smallest and largest `ε_abs` (K) of a pair of DEM runs.
    pub floor_eps_abs_min: f64,
    pub floor_eps_abs_max: f64,
    /// Pairs of DEM runs measured.
    pub floor_pairs: usize,
    /// The extrapolation's mean `ε_abs` (K) to the DEM runs (see [`Departure`]).
    pub eps_abs_to_dem_runs: f64,
    /// `eps_abs_to_dem_runs / floor_eps_abs`; absent when the DEM runs are identical
    /// (floor 0): nothing to judge against, not an infinite ratio.
    pub ratio_to_floor: Option<f64>,
    /// Each DEM run (in the order given) judged as the second field is: its mean `ε_abs` to
    /// the other runs over their mean distance to each other; `None` where those others are
    /// identical. Empty with fewer than three runs (two others are needed for a floor). The
    /// yardstick's own scatter: what a genuine run scores in the second field's seat, with
    /// one run fewer to be judged against.
    pub runs_ratio_to_others: Vec<Option<f64>>,
    /// Each DEM run (in the order given) placed as the second field is in
    /// [`within`]: whether its mean `ε_abs` to the other runs exceeds the largest distance
    /// between two of them. Empty with fewer than three runs, as `runs_ratio_to_others`.
    pub runs_outside_others_range: Vec<bool>,
}

/// Whether an extrapolation is within the DEM runs' own range at one `t_k`: its mean distance
/// `to_runs` to them no larger than the largest distance `max` between two of them.
pub fn within(to_runs: f64, max: f64) -> bool {
    to_runs <= max
}

/// Where the second field left the reference, against where the twins parted from it: which
/// DEM runs its distance is measured to, and whether their spread is a fair floor for it. One
/// answer to both, so that the distance and the verdict's caveat cannot disagree.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Departure {
    /// Where the twins part (the paper's method, twins from the extrapolation's start), or a
    /// second DEM run: one more run, measured to all of them.
    WithTheTwins,
    /// After the twins parted: an extrapolation of several recorded periods is the reference
    /// itself until its first jump `t_left`, so its distance to the reference has had less
    /// time to grow than the runs' distances to each other, which would flatter it. It is
    /// measured to all runs but the reference; the twins parted from that shared past at
    /// `t_parted`, as from each other.
    AfterTheTwins {
        /// `None` for a path that never leaves the reference.
        left: Option<u32>,
        parted: u32,
    },
    /// Before the twins parted at `t_parted` (`--twins-from` later than its start `t_left`):
    /// measured to all runs, but the twins followed the reference past its start, so their
    /// distances have had less time to grow than its own and their floor is narrower than a
    /// fair one for it.
    BeforeTheTwins { left: u32, parted: u32 },
}

impl Departure {
    /// For a second field that is the reference until `t_recorded_until` (its first jump; 1
    /// for the paper's method, 0 for a DEM run, `None` for a path that never jumps) of a
    /// recording whose twins part at `t_twins_from`.
    pub fn of(recorded_until: Option<u32>, twins_from: u32) -> Departure {
        let parted = twins_from;
        match recorded_until {
            None => Departure::AfterTheTwins { left: None, parted },
            Some(left) if left >= 2 && left > parted => Departure::AfterTheTwins {
                left: Some(left),
                parted,
            },
            Some(left) if (1..parted).contains(&left) => Departure::BeforeTheTwins { left, parted },
            Some(_) => Departure::WithTheTwins,
        }
    }

    /// Whether the reference (the first run) is left out of the runs its distance goes to.
    fn skips_the_reference(self) -> bool {
        matches!(self, Departure::AfterTheTwins { .. })
    }

    /// The one a second DEM run or the paper's method has; left out of `tdex compare
    /// --json`, so that their outputs keep their bytes.
    pub fn is_with_the_twins(&self) -> bool {
        *self == Departure::WithTheTwins
    }

    /// The runs the distance goes to when they are not all of them, in words for the
    /// outputs ("its mean distance to …"), so that a reader is never told "the DEM runs"
    /// where the reference was left out.
    pub fn runs_measured_to(self) -> Option<String> {
        match self {
            Departure::AfterTheTwins { left, parted } => {
                let until = left.map_or("throughout".to_string(), |k| format!("until t{k}"));
                Some(format!(
                    "the DEM runs other than the reference (it is the reference {until}; the \
                     twins parted at t{parted})"
                ))
            }
            Departure::WithTheTwins | Departure::BeforeTheTwins { .. } => None,
        }
    }
}

/// The floor of the DEM runs whose cell means are `means` (at least two at the same `t_k`,
/// the reference first) and the distance of the second field's, `second`, to those its
/// `departure` names. `None` with fewer than two runs or when no cell holds particles of
/// both fields of some pair.
pub fn floor(
    means: &[Vec<Option<f64>>],
    second: &[Option<f64>],
    departure: Departure,
) -> Option<Floor> {
    if means.len() < 2 {
        return None;
    }
    // distance[i][j] between runs i and j (both halves filled)
    let n = means.len();
    let mut distance = vec![vec![0.0; n]; n];
    let mut pairs = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            let d = eps_abs(&means[i], &means[j])?.0;
            distance[i][j] = d;
            distance[j][i] = d;
            pairs.push(d);
        }
    }
    let skip = usize::from(departure.skips_the_reference());
    let to_runs = means[skip..]
        .iter()
        .map(|m| eps_abs(m, second).map(|(e, _)| e))
        .collect::<Option<Vec<f64>>>()?;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let floor_eps_abs = mean(&pairs);
    let eps_abs_to_dem_runs = mean(&to_runs);
    // each run in the second field's seat: its mean distance to the others, over their mean
    // distance to each other (the ratio) and against their largest (the range)
    let (runs_ratio_to_others, runs_outside_others_range) = if n < 3 {
        (Vec::new(), Vec::new())
    } else {
        (0..n)
            .map(|c| {
                let to_others: Vec<f64> =
                    (0..n).filter(|&j| j != c).map(|j| distance[c][j]).collect();
                let among: Vec<f64> = (0..n)
                    .flat_map(|a| (a + 1..n).map(move |b| (a, b)))
                    .filter(|&(a, b)| a != c && b != c)
                    .map(|(a, b)| distance[a][b])
                    .collect();
                let floor = mean(&among);
                let max = among.iter().copied().fold(0.0, f64::max);
                let to_others = mean(&to_others);
                (
                    (floor > 0.0).then(|| to_others / floor),
                    !within(to_others, max),
                )
            })
            .unzip()
    };
    Some(Floor {
        floor_eps_abs,
        floor_eps_abs_min: pairs.iter().copied().fold(f64::INFINITY, f64::min),
        floor_eps_abs_max: pairs.iter().copied().fold(0.0, f64::max),
        floor_pairs: pairs.len(),
        eps_abs_to_dem_runs,
        ratio_to_floor: (floor_eps_abs > 0.0).then(|| eps_abs_to_dem_runs / floor_eps_abs),
        runs_ratio_to_others,
        runs_outside_others_range,
    })
}

/// The floor of the pattern: [`floor`] on each field's cell means less its own bed
/// mean (`run_bed_means[i]` of run `i`, `second_bed_mean`). A bed heated through a wall
/// heats at a rate the recorded periods set; less its bed mean, a field that heats
/// uniformly a little too fast or too slowly is as near the DEM runs as the pattern of its
/// heat allows, so the two floors tell a miss in the bed mean from one in where the heat is.
pub fn pattern_floor(
    means: &[Vec<Option<f64>>],
    run_bed_means: &[f64],
    second: &[Option<f64>],
    second_bed_mean: f64,
    departure: Departure,
) -> Option<PatternFloor> {
    let less = |cells: &[Option<f64>], bed_mean: f64| -> Vec<Option<f64>> {
        cells.iter().map(|m| m.map(|m| m - bed_mean)).collect()
    };
    let runs: Vec<Vec<Option<f64>>> = means
        .iter()
        .zip(run_bed_means)
        .map(|(m, &bed_mean)| less(m, bed_mean))
        .collect();
    let f = floor(&runs, &less(second, second_bed_mean), departure)?;
    Some(PatternFloor {
        ratio_to_floor: f.ratio_to_floor,
        dem_runs_ratio_to_others: f.runs_ratio_to_others,
    })
}

/// The floor of each field less its own bed mean, at one `t_k` ([`pattern_floor`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PatternFloor {
    /// The second field's mean distance to the DEM runs over theirs to each other.
    pub ratio_to_floor: Option<f64>,
    /// Each DEM run judged as the second field is, against the others (empty with fewer
    /// than three runs, and then left out of the JSON).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub dem_runs_ratio_to_others: Vec<Option<f64>>,
}

/// The median of `values` (the mean of the middle two for an even count); `None` if empty.
pub fn median(values: &[f64]) -> Option<f64> {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(v[n / 2]),
        _ => Some(0.5 * (v[n / 2 - 1] + v[n / 2])),
    }
}

/// Min and max of `values`, NaN left out (None when nothing is left): the range of the DEM
/// runs' figures a verdict sets a figure beside.
pub fn min_max(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .filter(|v| !v.is_nan())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((f64::min(lo, v), f64::max(hi, v))),
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::metrics::Cells;

    /// One field's particles: positions and temperatures in the same order.
    struct Field<'a> {
        pos: &'a [[f64; 3]],
        temp: &'a [f64],
    }

    /// [`floor`] of `runs` on `cells`.
    fn floor_of(
        cells: &Cells,
        runs: &[Field],
        second: &[Option<f64>],
        departure: Departure,
    ) -> Option<Floor> {
        let means: Vec<Vec<Option<f64>>> =
            runs.iter().map(|r| cells.means(r.pos, r.temp)).collect();
        floor(&means, second, departure)
    }

    #[test]
    fn the_departure_names_the_runs_measured_to_and_a_late_parting() {
        use Departure::{AfterTheTwins, BeforeTheTwins, WithTheTwins};
        // the paper's method, twins that part where the extrapolation starts, a DEM run
        for (recorded_until, twins_from) in [(1, 1), (2, 2), (3, 3), (0, 1), (0, 3)] {
            assert_eq!(
                Departure::of(Some(recorded_until), twins_from),
                WithTheTwins
            );
        }
        // several recorded periods, twins from t1 or from a snapshot before the start; a
        // path that never jumps (None) stays the reference throughout
        assert_eq!(
            Departure::of(Some(2), 1),
            AfterTheTwins {
                left: Some(2),
                parted: 1
            }
        );
        assert_eq!(
            Departure::of(Some(3), 2),
            AfterTheTwins {
                left: Some(3),
                parted: 2
            }
        );
        let never = Departure::of(None, 4);
        assert_eq!(
            never,
            AfterTheTwins {
                left: None,
                parted: 4
            }
        );
        // an extrapolation that starts before the twins part (its verdict says so)
        assert_eq!(
            Departure::of(Some(1), 2),
            BeforeTheTwins { left: 1, parted: 2 }
        );
        assert_eq!(
            Departure::of(Some(2), 3),
            BeforeTheTwins { left: 2, parted: 3 }
        );
        // the reference is left out only for one that followed it past the twins' parting
        assert!(never.skips_the_reference());
        assert!(!WithTheTwins.skips_the_reference());
        assert!(!Departure::of(Some(1), 2).skips_the_reference());
        // and the outputs say so where (and only where) the reference is left out
        assert_eq!(
            Departure::of(Some(2), 1).runs_measured_to().as_deref(),
            Some(
                "the DEM runs other than the reference (it is the reference until t2; the \
                 twins parted at t1)"
            )
        );
        assert_eq!(
            never.runs_measured_to().as_deref(),
            Some(
                "the DEM runs other than the reference (it is the reference throughout; the \
                 twins parted at t4)"
            )
        );
        assert_eq!(
            serde_json::to_value(never).unwrap(),
            serde_json::json!({"kind": "after_the_twins", "left": null, "parted": 4})
        );
        assert_eq!(WithTheTwins.runs_measured_to(), None);
        assert_eq!(Departure::of(Some(1), 2).runs_measured_to(), None);
    }

    fn cells() -> Cells {
        Cells::from_seeds(vec![[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    }

    const POS: [[f64; 3]; 4] = [
        [-0.5, 0.0, 0.0],
        [-1.5, 0.0, 0.0],
        [0.5, 0.0, 0.0],
        [1.5, 0.0, 0.0],
    ];

    #[test]
    fn a_twin_identical_to_the_dem_gives_floor_zero_and_no_ratio() {
        let temp = [10.0, 20.0, 30.0, 40.0];
        let dem = Field {
            pos: &POS,
            temp: &temp,
        };
        let twin = Field {
            pos: &POS,
            temp: &temp,
        };
        let extra = [Some(16.0), Some(35.0)];
        let f = floor_of(&cells(), &[dem, twin], &extra, Departure::WithTheTwins).unwrap();
        assert_eq!(f.floor_eps_abs, 0.0);
        assert_eq!(f.floor_eps_abs_max, 0.0);
        assert_eq!(f.eps_abs_to_dem_runs, 0.5);
        // absent, not infinite: a floor of 0 gives nothing to divide by
        assert_eq!(f.ratio_to_floor, None);
        assert!(!within(f.eps_abs_to_dem_runs, f.floor_eps_abs_max));
    }

    #[test]
    fn the_floor_is_the_runs_distance_and_the_ratio_the_extrapolations_over_it() {
        let (t_dem, t_twin) = ([10.0, 20.0, 30.0, 40.0], [12.0, 22.0, 30.0, 40.0]);
        // cell means: DEM (15, 35), twin (17, 35): they differ by 1 K on average
        let runs = [
            Field {
                pos: &POS,
                temp: &t_dem,
            },
            Field {
                pos: &POS,
                temp: &t_twin,
            },
        ];
        // one more run, measured to both
        let with = Departure::WithTheTwins;
        // the extrapolation halfway between them: 0.5 K from each
        let f = floor_of(&cells(), &runs, &[Some(16.0), Some(35.0)], with).unwrap();
        assert_eq!(f.floor_eps_abs, 1.0);
        assert_eq!((f.floor_eps_abs_min, f.floor_eps_abs_max), (1.0, 1.0));
        assert_eq!(f.eps_abs_to_dem_runs, 0.5);
        assert_eq!(f.ratio_to_floor, Some(0.5));
        assert!(within(f.eps_abs_to_dem_runs, f.floor_eps_abs_max));
        // a field 3 K off in the first cell is farther than the runs are from each other
        let far = floor_of(&cells(), &runs, &[Some(19.0), Some(35.0)], with).unwrap();
        assert_eq!(far.eps_abs_to_dem_runs, 1.5);
        assert_eq!(far.ratio_to_floor, Some(1.5));
        assert!(!within(far.eps_abs_to_dem_runs, far.floor_eps_abs_max));
        // one run alone has no floor
        assert_eq!(
            floor_of(&cells(), &runs[..1], &[Some(15.0), Some(35.0)], with),
            None
        );
        // the field of the DEM itself (an extrapolation still on the reference): half the
        // floor to both runs, the whole floor to the twin alone
        let on_dem = [Some(15.0), Some(35.0)];
        let all = floor_of(&cells(), &runs, &on_dem, with).unwrap();
        assert_eq!(all.ratio_to_floor, Some(0.5));
        let twins = floor_of(&cells(), &runs, &on_dem, Departure::of(Some(2), 1)).unwrap();
        assert_eq!(twins.eps_abs_to_dem_runs, 1.0);
        assert_eq!(twins.ratio_to_floor, Some(1.0));
        assert_eq!(twins.floor_eps_abs, all.floor_eps_abs);
    }

    /// Each run judged against the others as the second field is: a run far from two that
    /// agree scores high, and they score low, since their pool holds it.
    #[test]
    fn each_run_is_judged_against_the_others_as_the_second_field_is() {
        let temps = [
            [10.0, 20.0, 30.0, 40.0], // cell means (15, 35)
            [12.0, 22.0, 30.0, 40.0], // (17, 35): 1 K from the first on average
            [20.0, 30.0, 30.0, 40.0], // (25, 35): 5 and 4 K from the others
        ];
        let runs: Vec<Field> = temps.iter().map(|t| Field { pos: &POS, temp: t }).collect();
        let on_first = [Some(15.0), Some(35.0)];
        let f = floor_of(&cells(), &runs, &on_first, Departure::WithTheTwins).unwrap();
        // run 0: to the others (1 + 5) / 2 = 3, their distance 4; run 1: (1 + 4) / 2 over 5;
        // run 2: (5 + 4) / 2 over 1
        assert_eq!(
            f.runs_ratio_to_others,
            vec![Some(3.0 / 4.0), Some(2.5 / 5.0), Some(4.5)]
        );
        // and placed against the others' range as the second field is: run 0 (3) and run 1
        // (2.5) are within the other pair's distance (4, 5), run 2 (4.5) is beyond 1
        assert_eq!(f.runs_outside_others_range, vec![false, false, true]);
        // the floor and the second field's ratio are those of all three runs
        assert_eq!(f.floor_eps_abs, 10.0 / 3.0);
        assert_eq!(f.eps_abs_to_dem_runs, 2.0);
        // two runs: neither has a floor of others to be judged against
        let two = floor_of(&cells(), &runs[..2], &on_first, Departure::WithTheTwins).unwrap();
        assert!(two.runs_ratio_to_others.is_empty());
        assert!(two.runs_outside_others_range.is_empty());
        // identical others give no ratio, not an infinite one
        let same = [temps[0], temps[0], temps[1]];
        let runs: Vec<Field> = same.iter().map(|t| Field { pos: &POS, temp: t }).collect();
        let f = floor_of(&cells(), &runs, &on_first, Departure::WithTheTwins).unwrap();
        assert_eq!(f.runs_ratio_to_others[2], None);
        assert_eq!(f.runs_ratio_to_others[0], Some(0.5));
    }

    #[test]
    fn less_the_bed_mean_a_field_heated_uniformly_too_fast_scores_as_its_pattern() {
        // three DEM runs' cell means, bed means 25, 26 and 27 K (two cells of equal weight)
        let runs = vec![
            vec![Some(15.0), Some(35.0)],
            vec![Some(17.0), Some(35.0)],
            vec![Some(19.0), Some(35.0)],
        ];
        let beds = [25.0, 26.0, 27.0];
        // the second field: the middle run's pattern, 3 K warmer everywhere
        let warm = [Some(20.0), Some(38.0)];
        let field = floor(&runs, &warm, Departure::WithTheTwins).unwrap();
        let pattern = pattern_floor(&runs, &beds, &warm, 29.0, Departure::WithTheTwins).unwrap();
        // on the field it is far from the runs (4, 3 and 2 K against their 4/3 K apart);
        // less the bed means the runs are (−10, 10), (−9, 9), (−8, 8), again 4/3 K apart on
        // average, and the second field (−9, 9) is the middle one: 1, 0 and 1 K from them
        assert_eq!(field.ratio_to_floor, Some(3.0 / (4.0 / 3.0)));
        assert_eq!(pattern.ratio_to_floor, Some((2.0 / 3.0) / (4.0 / 3.0)));
        // each DEM run judged the same way: the middle run as the second field, the outer
        // two 1.5 from the others against their 1
        assert_eq!(
            pattern.dem_runs_ratio_to_others,
            vec![Some(1.5 / 1.0), Some(1.0 / 2.0), Some(1.5 / 1.0)]
        );
        // a field whose heat is elsewhere, (−4, 4) less its bed mean: the pattern sees it
        // (6, 5 and 4 K from the runs)
        let moved = [Some(25.0), Some(33.0)];
        let off = pattern_floor(&runs, &beds, &moved, 29.0, Departure::WithTheTwins).unwrap();
        assert_eq!(off.ratio_to_floor, Some(5.0 / (4.0 / 3.0)));
    }

    #[test]
    fn the_median_of_an_even_count_is_the_mean_of_the_middle_two() {
        assert_eq!(median(&[]), None);
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
    }
}
