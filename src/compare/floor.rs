//! The DEM's own spread at one `t_k` (the "floor"): the cell distances between the DEM runs
//! of one case (the reference and its twins), and the extrapolation's distance to those runs
//! measured the same way, so that the extrapolation is judged as one more run would be.

use super::metrics::{eps_abs, Cells};
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
    /// The extrapolation's mean `ε_abs` (K) to the DEM runs (see [`Against`]).
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
}

/// Whether an extrapolation is within the DEM runs' own range at one `t_k`: its mean distance
/// `to_runs` to them no larger than the largest distance `max` between two of them.
pub fn within(to_runs: f64, max: f64) -> bool {
    to_runs <= max
}

/// The cell means of one field: positions and temperatures in the same order.
pub struct Field<'a> {
    pub pos: &'a [[f64; 3]],
    pub temp: &'a [f64],
}

/// Which DEM runs the second field's distance is measured to: those that parted from its
/// past as early as they parted from each other.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Against {
    /// All of them: an extrapolation that leaves the reference at `t1`, where the twins do,
    /// or a second DEM run.
    AllRuns,
    /// All but the reference (the first run): an extrapolation of several recorded periods
    /// is the reference itself until its first jump, so its distance to the reference has
    /// had less time to grow than the runs' distances to each other, which would flatter it.
    /// The twins parted from that shared past earlier (`t1` unless recorded with
    /// `--twins-from`), as from each other.
    AllButTheReference,
}

impl Against {
    /// For an extrapolation that is the reference until `t_recorded_until` (its first jump;
    /// 1 for the paper's method) of a recording whose twins part at `t_twins_from`: all runs
    /// when it leaves the reference no later than the twins do, else all but the reference.
    pub fn for_extrapolation(recorded_until: u32, twins_from: u32) -> Against {
        if recorded_until >= 2 && recorded_until > twins_from {
            Against::AllButTheReference
        } else {
            Against::AllRuns
        }
    }
}

/// Where the twins parted from the reference, against where the second field left it: whether
/// their spread is a fair floor for it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parting {
    /// No later than the second field left the reference (or it is a DEM run): the twins
    /// have been apart as long as it has.
    NoLater,
    /// At `t_parted`, after the extrapolation left the reference at `t_left`
    /// (`--twins-from` later than its start): the twins followed the reference past the
    /// extrapolation's start, so their distances to it have had less time to grow than the
    /// extrapolation's, and their floor is narrower than a fair one for it.
    After { left: u32, parted: u32 },
}

impl Parting {
    /// For an extrapolation that is the reference until `t_recorded_until` (0 for a DEM run)
    /// of a recording whose twins part at `t_twins_from`.
    pub fn of(recorded_until: u32, twins_from: u32) -> Parting {
        if (1..twins_from).contains(&recorded_until) {
            Parting::After {
                left: recorded_until,
                parted: twins_from,
            }
        } else {
            Parting::NoLater
        }
    }
}

/// The floor of `runs` (at least two DEM runs at the same `t_k`, the reference first) and
/// the distance of `second` (cell means already computed) to those `against` names, on
/// `cells`. `None` with fewer than two runs or when no cell holds particles of both fields
/// of some pair.
pub fn floor(
    cells: &Cells,
    runs: &[Field],
    second: &[Option<f64>],
    against: Against,
) -> Option<Floor> {
    if runs.len() < 2 {
        return None;
    }
    let means: Vec<Vec<Option<f64>>> = runs.iter().map(|r| cells.means(r.pos, r.temp)).collect();
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
    let skip = match against {
        Against::AllRuns => 0,
        Against::AllButTheReference => 1,
    };
    let to_runs = means[skip..]
        .iter()
        .map(|m| eps_abs(m, second).map(|(e, _)| e))
        .collect::<Option<Vec<f64>>>()?;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let floor_eps_abs = mean(&pairs);
    let eps_abs_to_dem_runs = mean(&to_runs);
    let runs_ratio_to_others = if n < 3 {
        Vec::new()
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
                (floor > 0.0).then(|| mean(&to_others) / floor)
            })
            .collect()
    };
    Some(Floor {
        floor_eps_abs,
        floor_eps_abs_min: pairs.iter().copied().fold(f64::INFINITY, f64::min),
        floor_eps_abs_max: pairs.iter().copied().fold(0.0, f64::max),
        floor_pairs: pairs.len(),
        eps_abs_to_dem_runs,
        ratio_to_floor: (floor_eps_abs > 0.0).then(|| eps_abs_to_dem_runs / floor_eps_abs),
        runs_ratio_to_others,
    })
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reference_is_left_out_only_when_the_extrapolation_follows_it_past_the_twins_parting() {
        // the paper's method, and twins that part where the extrapolation starts
        use Against::{AllButTheReference, AllRuns};
        assert_eq!(Against::for_extrapolation(1, 1), AllRuns);
        assert_eq!(Against::for_extrapolation(2, 2), AllRuns);
        assert_eq!(Against::for_extrapolation(3, 3), AllRuns);
        // an extrapolation that starts before the twins part (its verdict says so)
        assert_eq!(Against::for_extrapolation(1, 2), AllRuns);
        // several recorded periods, twins from t1 or from a snapshot before the start
        assert_eq!(Against::for_extrapolation(2, 1), AllButTheReference);
        assert_eq!(Against::for_extrapolation(3, 2), AllButTheReference);
        // a path that never jumps (u32::MAX) stays the reference throughout
        assert_eq!(Against::for_extrapolation(u32::MAX, 4), AllButTheReference);
    }

    #[test]
    fn the_twins_part_late_only_after_an_extrapolation_left_the_reference() {
        assert_eq!(Parting::of(1, 2), Parting::After { left: 1, parted: 2 });
        assert_eq!(Parting::of(2, 3), Parting::After { left: 2, parted: 3 });
        for (recorded_until, twins_from) in [(1, 1), (2, 2), (3, 2), (u32::MAX, 4), (0, 3)] {
            // 0: a second DEM run, which never was the reference
            assert_eq!(Parting::of(recorded_until, twins_from), Parting::NoLater);
        }
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
        let f = floor(&cells(), &[dem, twin], &extra, Against::AllRuns).unwrap();
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
        // the extrapolation halfway between them: 0.5 K from each
        let f = floor(&cells(), &runs, &[Some(16.0), Some(35.0)], Against::AllRuns).unwrap();
        assert_eq!(f.floor_eps_abs, 1.0);
        assert_eq!((f.floor_eps_abs_min, f.floor_eps_abs_max), (1.0, 1.0));
        assert_eq!(f.eps_abs_to_dem_runs, 0.5);
        assert_eq!(f.ratio_to_floor, Some(0.5));
        assert!(within(f.eps_abs_to_dem_runs, f.floor_eps_abs_max));
        // a field 3 K off in the first cell is farther than the runs are from each other
        let far = floor(&cells(), &runs, &[Some(19.0), Some(35.0)], Against::AllRuns).unwrap();
        assert_eq!(far.eps_abs_to_dem_runs, 1.5);
        assert_eq!(far.ratio_to_floor, Some(1.5));
        assert!(!within(far.eps_abs_to_dem_runs, far.floor_eps_abs_max));
        // one run alone has no floor
        assert_eq!(
            floor(
                &cells(),
                &runs[..1],
                &[Some(15.0), Some(35.0)],
                Against::AllRuns
            ),
            None
        );
        // the field of the DEM itself (an extrapolation still on the reference): half the
        // floor to both runs, the whole floor to the twin alone
        let on_dem = [Some(15.0), Some(35.0)];
        let all = floor(&cells(), &runs, &on_dem, Against::AllRuns).unwrap();
        assert_eq!(all.ratio_to_floor, Some(0.5));
        let twins = floor(&cells(), &runs, &on_dem, Against::AllButTheReference).unwrap();
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
        let f = floor(&cells(), &runs, &on_first, Against::AllRuns).unwrap();
        // run 0: to the others (1 + 5) / 2 = 3, their distance 4; run 1: (1 + 4) / 2 over 5;
        // run 2: (5 + 4) / 2 over 1
        assert_eq!(
            f.runs_ratio_to_others,
            vec![Some(3.0 / 4.0), Some(2.5 / 5.0), Some(4.5)]
        );
        // the floor and the second field's ratio are those of all three runs
        assert_eq!(f.floor_eps_abs, 10.0 / 3.0);
        assert_eq!(f.eps_abs_to_dem_runs, 2.0);
        // two runs: neither has a floor of others to be judged against
        let two = floor(&cells(), &runs[..2], &on_first, Against::AllRuns).unwrap();
        assert!(two.runs_ratio_to_others.is_empty());
        // identical others give no ratio, not an infinite one
        let same = [temps[0], temps[0], temps[1]];
        let runs: Vec<Field> = same.iter().map(|t| Field { pos: &POS, temp: t }).collect();
        let f = floor(&cells(), &runs, &on_first, Against::AllRuns).unwrap();
        assert_eq!(f.runs_ratio_to_others[2], None);
        assert_eq!(f.runs_ratio_to_others[0], Some(0.5));
    }

    #[test]
    fn the_median_of_an_even_count_is_the_mean_of_the_middle_two() {
        assert_eq!(median(&[]), None);
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
    }
}
