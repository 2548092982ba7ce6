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
    /// From the end of the last recorded period to the start of `period`, through the
    /// pairing of snapshot `t_P` to `t_{period − 1}`.
    Jump { period: u32 },
}

impl Step {
    /// The recorded period (1-based) replayed.
    pub fn period(self) -> u32 {
        match self {
            Step::Continue { period } | Step::Jump { period } => period,
        }
    }
}

/// The path policy: start at `t1`, the end of recorded period 1; after period `p < P` go on
/// with `p + 1`; after period `P` jump to the start of a period drawn uniformly from the jump
/// targets (by default all of `1..=P`). A path is a function of `(P, targets, seed)` and the
/// number of periods alone.
#[derive(Debug, Clone)]
pub struct RecurrencePolicy {
    recorded_periods: u32,
    /// The periods a jump may enter, distinct and ascending (`1..=P` unless restricted).
    targets: Vec<u32>,
    rng: Xoshiro256PlusPlus,
    /// The recorded period whose end the roles are at.
    at_end_of: u32,
}

impl RecurrencePolicy {
    /// The path through `recorded_periods` periods (at least 1), its jumps drawn from `seed`
    /// among all the recorded periods.
    pub fn new(recorded_periods: u32, seed: u64) -> Self {
        let recorded_periods = recorded_periods.max(1);
        Self {
            recorded_periods,
            targets: (1..=recorded_periods).collect(),
            rng: Xoshiro256PlusPlus::seed_from_u64(seed),
            at_end_of: 1,
        }
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
    fn draw_start(&mut self) -> u32 {
        let n = self.targets.len() as u128;
        if self.recorded_periods == 1 || n == 1 {
            return self.targets[0];
        }
        self.targets[((u128::from(self.rng.next_u64()) * n) >> 64) as usize]
    }
}

impl Iterator for RecurrencePolicy {
    type Item = Step;

    fn next(&mut self) -> Option<Step> {
        let step = if self.at_end_of < self.recorded_periods {
            Step::Continue {
                period: self.at_end_of + 1,
            }
        } else {
            Step::Jump {
                period: self.draw_start(),
            }
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

/// The starts (1-based periods) the path jumps to, each once, in increasing order: the
/// pairings it needs.
pub fn starts(steps: &[Step]) -> Vec<u32> {
    let jumps: Vec<u32> = steps
        .iter()
        .filter_map(|s| match s {
            Step::Jump { period } => Some(*period),
            Step::Continue { .. } => None,
        })
        .collect();
    distinct_ascending(&jumps)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn periods(steps: &[Step]) -> Vec<u32> {
        steps.iter().map(|s| s.period()).collect()
    }

    #[test]
    fn one_recorded_period_always_jumps_to_itself_without_drawing() {
        let steps = RecurrencePolicy::steps(1, 7, 5);
        assert_eq!(steps, vec![Step::Jump { period: 1 }; 5]);
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
                Step::Jump { period } => {
                    assert_eq!(at_end_of, 3, "a jump only from the recording's end");
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
            if let Step::Jump { period } = s {
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
}
