//! The recurrence path through several recorded periods (docs/method.md §6): which recorded
//! period each extrapolated period replays, and where it is entered through a pairing.

use rand_xoshiro::rand_core::{Rng as _, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use tdex_format::extrapolation::Symmetry;

/// How one extrapolated period is entered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// The recorded period after the one just replayed: the DEM's own continuation, the
    /// roles unchanged (no pairing).
    Continue { period: u32 },
    /// From the end of recorded period `from` (the last one, `P`, unless the path leaves
    /// every few periods) to the start of `period`, through the pairing of snapshot
    /// `t_from` to `t_{period − 1}`.
    Jump { from: u32, period: u32 },
}

/// Where the path leaves the recording for a jump.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Leave {
    /// Only at the recording's end `t_P`: every stretch runs to the last recorded period,
    /// which is then replayed at every jump (the paper's method extended to P periods).
    #[default]
    AtEnd,
    /// After every `n` periods replayed in a row (or at `t_P`, sooner), from the end of the
    /// period just replayed, as recurrence CFD leaves from the current state: the path
    /// jumps from many recorded snapshots, and no recorded period is replayed before every
    /// jump.
    Every(std::num::NonZeroU32),
}

impl Step {
    /// The recorded period (1-based) replayed.
    pub fn period(self) -> u32 {
        match self {
            Step::Continue { period } | Step::Jump { period, .. } => period,
        }
    }
}

/// The path policy: start at `t1`, the end of recorded period 1; after period `p < P` go on
/// with `p + 1`; after period `P` (or, leaving every `n`, after `n` periods in a row) jump to
/// the start of a period drawn uniformly from the jump targets (by default all of `1..=P`)
/// other than `p + 1`, the recording's own continuation. A path is a function of
/// `(P, targets, leave, seed)` and the number of periods alone.
#[derive(Debug, Clone)]
pub struct RecurrencePolicy {
    recorded_periods: u32,
    /// The periods a jump may enter, distinct and ascending (`1..=P` unless restricted).
    targets: Vec<u32>,
    leave: Leave,
    rng: Xoshiro256PlusPlus,
    /// The recorded period whose end the roles are at.
    at_end_of: u32,
    /// Periods replayed since the path last jumped (period 1, from `t0`, counts).
    in_a_row: u32,
}

impl RecurrencePolicy {
    /// The path through `recorded_periods` periods (at least 1), its jumps drawn from `seed`
    /// among all the recorded periods.
    pub fn new(recorded_periods: u32, seed: u64) -> Self {
        let recorded_periods = recorded_periods.max(1);
        Self {
            recorded_periods,
            targets: (1..=recorded_periods).collect(),
            leave: Leave::AtEnd,
            rng: Xoshiro256PlusPlus::seed_from_u64(seed),
            at_end_of: 1,
            in_a_row: 1,
        }
    }

    /// The path that leaves the recording as `leave` says.
    pub fn leaving(mut self, leave: Leave) -> Self {
        self.leave = leave;
        self
    }

    /// The path whose jumps enter only the periods `targets` (1-based; the caller checked
    /// them: within `1..=recorded_periods`, at least one). With every period as a target the
    /// path is [`RecurrencePolicy::new`]'s, draw for draw.
    pub fn with_targets(recorded_periods: u32, seed: u64, targets: &[u32]) -> Self {
        let mut policy = Self::new(recorded_periods, seed);
        let targets = distinct_ascending(targets);
        debug_assert!(targets
            .iter()
            .all(|t| (1..=policy.recorded_periods).contains(t)));
        if !targets.is_empty() {
            policy.targets = targets;
        }
        policy
    }

    /// The first `periods` steps of the path.
    pub fn steps(recorded_periods: u32, seed: u64, periods: u32) -> Vec<Step> {
        Self::new(recorded_periods, seed)
            .take(periods as usize)
            .collect()
    }

    /// A start drawn uniformly from `1..=P` by Lemire's multiply-shift: the high word of
    /// `x · P` for a uniform 64-bit `x`. Each start gets either ⌊2⁶⁴/P⌋ or ⌈2⁶⁴/P⌉ of the 2⁶⁴
    /// values of `x`, so no start is more likely than another by more than P/2⁶⁴ ≤ 2⁻⁵⁸
    /// relative (P ≤ 64): far below anything 100 or even 10⁶ periods could detect, and
    /// without the rejection loop that would make the number of draws depend on the values.
    /// One recorded period draws nothing: the paper's method uses no generator; nor does a
    /// single jump target.
    ///
    /// Leaving before `t_P`, the continuation `p + 1` is no jump and is not drawn; with no
    /// other target the path goes on along the recording (`None`).
    fn draw_start(&mut self) -> Option<u32> {
        let next = self.at_end_of + 1;
        let skip = self.targets.binary_search(&next).ok();
        let n = (self.targets.len() - usize::from(skip.is_some())) as u128;
        if n == 0 {
            return None;
        }
        if self.recorded_periods == 1 || n == 1 {
            return Some(self.targets[usize::from(skip == Some(0))]);
        }
        let drawn = ((u128::from(self.rng.next_u64()) * n) >> 64) as usize;
        Some(self.targets[drawn + usize::from(skip.is_some_and(|at| drawn >= at))])
    }

    /// Whether the path leaves the recording after the period it has just replayed.
    fn leaves_now(&self) -> bool {
        self.at_end_of == self.recorded_periods
            || match self.leave {
                Leave::AtEnd => false,
                Leave::Every(n) => self.in_a_row >= n.get(),
            }
    }
}

impl Iterator for RecurrencePolicy {
    type Item = Step;

    fn next(&mut self) -> Option<Step> {
        let jump = if self.leaves_now() {
            self.draw_start()
        } else {
            None
        };
        let step = match jump {
            Some(period) => Step::Jump {
                from: self.at_end_of,
                period,
            },
            None => Step::Continue {
                period: self.at_end_of + 1,
            },
        };
        self.in_a_row = match step {
            Step::Jump { .. } => 1,
            Step::Continue { .. } => self.in_a_row + 1,
        };
        self.at_end_of = step.period();
        Some(step)
    }
}

/// Whether each step replays its period as the mirror image of the recording: under
/// [`Symmetry::AxialMirror`] every jump enters the mirror image of the orientation it
/// leaves (the first period, from `t1`, is the recording's own), so that no two periods
/// joined by a pairing replay the same image; without a symmetry, never.
pub fn mirrored(steps: &[Step], symmetry: Symmetry) -> Vec<bool> {
    steps
        .iter()
        .scan(false, |mirrored, step| {
            if symmetry == Symmetry::AxialMirror && matches!(step, Step::Jump { .. }) {
                *mirrored = !*mirrored;
            }
            Some(*mirrored)
        })
        .collect()
}

/// `periods` each once, in increasing order.
pub fn distinct_ascending(periods: &[u32]) -> Vec<u32> {
    let mut periods = periods.to_vec();
    periods.sort_unstable();
    periods.dedup();
    periods
}

/// The jumps the path makes, each `(from, period)` once, in increasing order: the pairings
/// it needs (of `t_from` to the start of `period`).
pub fn jumps(steps: &[Step]) -> Vec<(u32, u32)> {
    let mut jumps: Vec<(u32, u32)> = steps
        .iter()
        .filter_map(|s| match *s {
            Step::Jump { from, period } => Some((from, period)),
            Step::Continue { .. } => None,
        })
        .collect();
    jumps.sort_unstable();
    jumps.dedup();
    jumps
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The starts (1-based periods) the path jumps to, each once, in increasing order.
    fn starts(steps: &[Step]) -> Vec<u32> {
        let starts: Vec<u32> = jumps(steps).iter().map(|&(_, period)| period).collect();
        distinct_ascending(&starts)
    }

    fn periods(steps: &[Step]) -> Vec<u32> {
        steps.iter().map(|s| s.period()).collect()
    }

    #[test]
    fn one_recorded_period_always_jumps_to_itself_without_drawing() {
        let steps = RecurrencePolicy::steps(1, 7, 5);
        assert_eq!(steps, vec![Step::Jump { from: 1, period: 1 }; 5]);
        // the seed plays no part
        assert_eq!(RecurrencePolicy::steps(1, 8, 5), steps);
        assert_eq!(starts(&steps), [1]);
    }

    #[test]
    fn the_path_follows_the_recording_then_jumps_from_its_end() {
        let steps = RecurrencePolicy::steps(3, 11, 200);
        // t1 is the end of period 1: periods 2 and 3 follow with no pairing
        assert_eq!(
            steps[..2],
            [Step::Continue { period: 2 }, Step::Continue { period: 3 }]
        );
        let mut at_end_of = 1;
        for s in &steps {
            match *s {
                Step::Continue { period } => assert_eq!(period, at_end_of + 1),
                Step::Jump { from, period } => {
                    assert_eq!(
                        (from, at_end_of),
                        (3, 3),
                        "a jump only from the recording's end"
                    );
                    assert!((1..=3).contains(&period));
                }
            }
            at_end_of = s.period();
        }
        // every start is reached in 200 periods (each is drawn with probability 1/3)
        assert_eq!(starts(&steps), [1, 2, 3]);
    }

    #[test]
    fn a_path_is_a_function_of_its_seed() {
        let a = RecurrencePolicy::steps(4, 1, 300);
        assert_eq!(RecurrencePolicy::steps(4, 1, 300), a);
        assert_ne!(RecurrencePolicy::steps(4, 2, 300), a);
        // a longer path begins with the shorter one
        assert_eq!(RecurrencePolicy::steps(4, 1, 100)[..], a[..100]);
    }

    /// The draws are value-stable: xoshiro256++ seeded by `seed_from_u64` is fixed by its
    /// crate, and the files record the path; a change here changes every P > 1 output.
    #[test]
    fn the_draws_of_a_fixed_seed_are_pinned() {
        let steps = RecurrencePolicy::steps(3, 0, 12);
        assert_eq!(periods(&steps), PINNED_SEED_0_P3);
    }

    const PINNED_SEED_0_P3: [u32; 12] = [2, 3, 1, 2, 3, 2, 3, 2, 3, 1, 2, 3];

    #[test]
    fn restricted_jumps_enter_only_their_targets_and_all_targets_are_the_default() {
        let all = RecurrencePolicy::with_targets(5, 9, &[5, 1, 2, 3, 4, 4])
            .take(200)
            .collect::<Vec<_>>();
        assert_eq!(all, RecurrencePolicy::steps(5, 9, 200));
        let near: Vec<Step> = RecurrencePolicy::with_targets(5, 9, &[5, 4])
            .take(200)
            .collect();
        assert_eq!(
            near[..4],
            [
                Step::Continue { period: 2 },
                Step::Continue { period: 3 },
                Step::Continue { period: 4 },
                Step::Continue { period: 5 }
            ]
        );
        assert_eq!(starts(&near), [4, 5]);
        // one target: no draw, the same jump every time
        let one: Vec<Step> = RecurrencePolicy::with_targets(3, 9, &[2])
            .take(20)
            .collect();
        assert_eq!(starts(&one), [2]);
    }

    #[test]
    fn the_mirror_flips_the_image_at_every_jump_and_never_along_the_recording() {
        let steps = RecurrencePolicy::steps(3, 11, 60);
        let mirrored = super::mirrored(&steps, Symmetry::AxialMirror);
        let mut image = false;
        for (s, &m) in steps.iter().zip(&mirrored) {
            if let Step::Jump { .. } = s {
                image = !image;
            }
            assert_eq!(m, image);
        }
        // the first periods continue the recording from t1: its own image
        assert_eq!(mirrored[..2], [false, false]);
        assert!(mirrored.contains(&true));
        // one recorded period: every period is a jump, the images alternate
        let one = RecurrencePolicy::steps(1, 0, 5);
        assert_eq!(
            super::mirrored(&one, Symmetry::AxialMirror),
            [true, false, true, false, true]
        );
        assert_eq!(super::mirrored(&one, Symmetry::None), [false; 5]);
    }

    #[test]
    fn the_starts_are_drawn_uniformly() {
        let p = 5;
        let n = 100_000;
        let mut counts = [0u32; 5];
        let mut policy = RecurrencePolicy::new(p, 42);
        for s in policy.by_ref().take(n) {
            if let Step::Jump { period, .. } = s {
                counts[period as usize - 1] += 1;
            }
        }
        let jumps: u32 = counts.iter().sum();
        let expected = f64::from(jumps) / f64::from(p);
        for c in counts {
            // 5 standard deviations of a binomial count
            let sd = (expected * (1.0 - 1.0 / f64::from(p))).sqrt();
            assert!((f64::from(c) - expected).abs() < 5.0 * sd, "{counts:?}");
        }
    }

    fn leaving_every(p: u32, n: u32, seed: u64, periods: usize) -> Vec<Step> {
        let every = Leave::Every(std::num::NonZeroU32::new(n).expect("n > 0"));
        RecurrencePolicy::new(p, seed)
            .leaving(every)
            .take(periods)
            .collect()
    }

    #[test]
    fn leaving_every_n_jumps_after_n_in_a_row_from_where_the_path_stands() {
        let steps = leaving_every(8, 3, 5, 2000);
        // t1 ends period 1, which counts: periods 2 and 3 follow, then a jump from t3
        assert_eq!(
            steps[..2],
            [Step::Continue { period: 2 }, Step::Continue { period: 3 }]
        );
        assert!(matches!(steps[2], Step::Jump { from: 3, .. }));
        let (mut at_end_of, mut in_a_row) = (1, 1);
        for s in &steps {
            match *s {
                Step::Continue { period } => {
                    assert_eq!(period, at_end_of + 1);
                    assert!(in_a_row < 3, "no stretch longer than 3");
                    in_a_row += 1;
                }
                Step::Jump { from, period } => {
                    assert_eq!(from, at_end_of);
                    assert!(
                        in_a_row == 3 || from == 8,
                        "a jump after 3 in a row or at t8"
                    );
                    assert_ne!(period, from + 1, "the continuation is no jump");
                    in_a_row = 1;
                }
            }
            at_end_of = s.period();
        }
        // jumps leave from every end a stretch of 3 reaches (t3 … t8) and enter every start
        let jumps = jumps(&steps);
        let mut ends: Vec<u32> = jumps.iter().map(|&(from, _)| from).collect();
        ends.dedup();
        assert_eq!(ends, (3..=8).collect::<Vec<_>>());
        assert_eq!(starts(&steps), (1..=8).collect::<Vec<_>>());
        // and every recorded period is replayed, none at every jump
        let mut counts = [0u32; 8];
        for s in &steps {
            counts[s.period() as usize - 1] += 1;
        }
        assert!(counts.iter().all(|&c| c > 100), "{counts:?}");
    }

    #[test]
    fn leaving_every_n_is_a_function_of_its_seed_and_n() {
        let a = leaving_every(6, 2, 1, 300);
        assert_eq!(leaving_every(6, 2, 1, 300), a);
        assert_ne!(leaving_every(6, 2, 2, 300), a);
        assert_ne!(leaving_every(6, 3, 1, 300), a);
        // with n at least P the path leaves only at the end, draw for draw
        assert_eq!(
            leaving_every(6, 6, 1, 300),
            RecurrencePolicy::steps(6, 1, 300)
        );
        assert_eq!(
            leaving_every(6, 9, 1, 300),
            RecurrencePolicy::steps(6, 1, 300)
        );
    }

    #[test]
    fn leaving_with_the_continuation_as_the_only_target_goes_on() {
        // targets 2 and 3 of 3, leaving after every period: from t1 only 3 is a jump; from
        // t2 only 2 (3 continues); from t3 either
        let every = Leave::Every(std::num::NonZeroU32::MIN);
        let steps: Vec<Step> = RecurrencePolicy::with_targets(3, 4, &[2, 3])
            .leaving(every)
            .take(300)
            .collect();
        assert_eq!(steps[0], Step::Jump { from: 1, period: 3 });
        for (s, &before) in steps[1..].iter().zip(&steps) {
            if let Step::Jump { from, period } = *s {
                assert_eq!(from, before.period());
                assert_ne!(period, from + 1);
                assert!([2, 3].contains(&period));
            }
        }
    }
}
