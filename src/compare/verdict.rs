//! How far to trust an extrapolation, in one sentence computed from the comparison: does it
//! pass as one more DEM run of the case (median ratio to their spread ≤ 1 and, with three
//! or more DEM runs, within their own range at every compared `t_k`)?

use super::floor::{median, min_max, Departure};
use super::{ContrastKind, PeriodComparison};
use serde::Serialize;

/// Room for float noise when a group (bed) mean error is set against the DEM runs'
/// spread, K: a conserved bed mean differs between runs only by rounding, and so does its
/// error, which must then not fail on the last bits.
const MEANS_TOLERANCE: f64 = 1e-9;

/// A field judged on the group (bed) means against some of the DEM runs, K.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SeatMeans {
    /// Its largest error against the first of those runs (the reference, or without it
    /// the first further run) over the compared `t_k`.
    pub error_max: f64,
    /// The largest difference between two of those runs' means there.
    pub spread_max: f64,
}

impl SeatMeans {
    /// Whether the field strays beyond those runs' spread.
    pub fn outside(&self) -> bool {
        self.error_max > self.spread_max + MEANS_TOLERANCE
    }

    /// How far: the largest error over the largest spread; `None` where the spread is only
    /// rounding, as of a conserved bed mean.
    pub fn error_to_spread(&self) -> Option<f64> {
        (self.spread_max > MEANS_TOLERANCE).then_some(self.error_max / self.spread_max)
    }
}

/// What a verdict's words need beside its figures.
struct Setting {
    dem_runs: usize,
    departure: Departure,
    /// The means are the hot and cold groups' (else the bed's).
    groups: bool,
    /// Whether any compared `t_k` has a floor (two DEM runs or more).
    floors: bool,
    /// The compared periods past the recorded run, which `t_k` lists are counted against.
    past_recording: usize,
}

/// The judgement of a comparison.
#[derive(Debug, Clone, Serialize)]
pub struct Verdict {
    /// Whether the second field passes as one more DEM run; null without a floor.
    pub passes: Option<bool>,
    /// Median, smallest and largest `ratio_to_floor` over the `t_k` that have one.
    pub median_ratio: Option<f64>,
    pub ratio_min: Option<f64>,
    pub ratio_max: Option<f64>,
    /// The `t_k` with a ratio, the extrapolation's own (not `within_recording`).
    pub compared: Vec<u32>,
    /// The `t_k` left out because the extrapolation was still the recorded run there
    /// (`t2 … tP'` of a recurrence path, before its first jump).
    pub within_recording: Vec<u32>,
    /// The `t_k` where the second field's mean distance to the DEM runs exceeds the largest
    /// distance between two of them (with two DEM runs: the `t_k` with a ratio above 1,
    /// which do not fail it, see [`Verdict::of`]).
    pub outside_range: Vec<u32>,
    /// Largest `|extrapolated − DEM|` of the group means (the bed mean for a bed without
    /// groups) over the compared `t_k`, K.
    pub means_error_max: Option<f64>,
    /// Largest difference between two DEM runs' group (bed) means, K; null with one run.
    pub means_spread_max: Option<f64>,
    /// Each DEM run's median ratio over the same `t_k`, judged against the other runs as the
    /// second field is against all of them (the reference first; empty with fewer than three
    /// runs, and then left out of the JSON so one- and two-run outputs keep their bytes):
    /// where a genuine run lands on this bar.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub dem_runs_median_ratio: Vec<f64>,
    /// Each DEM run's share of the compared `t_k` (0 to 1) where it is farther from the other
    /// runs than the two farthest of them are from each other: the second field's
    /// `outside_range` over `compared`, for a genuine run in its seat. Over the same `t_k` as
    /// `dem_runs_median_ratio`, and empty (left out of the JSON) when it is.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub dem_runs_outside_share: Vec<f64>,
    /// With three or more runs, the group (bed) means in the seat of a DEM run: the second
    /// field judged against the runs without each one in turn (in the runs' order), and
    /// each DEM run judged against the others the same way. Both against the same number
    /// of runs, since a spread widens with the runs in it: how often, and how far, a genuine
    /// run strays where the second field does. Empty with fewer runs, and then left out of
    /// the JSON.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub means_in_seat: Vec<SeatMeans>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub dem_runs_means: Vec<SeatMeans>,
    /// With a wall that conducts heat: the same median on each field less its own bed mean
    /// ([`PeriodComparison::pattern`]), beside the DEM runs'; null otherwise (left out of
    /// the JSON). Not part of the judgement, which is on the field: it says whether a miss
    /// is in the bed mean or in where the heat is.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pattern: Option<PatternVerdict>,
    /// The medians over the last fifth of the compared `t_k`, beside each DEM run's: whether
    /// the error is still growing where the horizon ends. Not part of the judgement; null
    /// (left out of the JSON) with fewer than three DEM runs or [`LATE_LEAST_COMPARED`]
    /// compared `t_k`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub late: Option<LateVerdict>,
    /// The verdict in words.
    pub text: String,
}

/// The compared `t_k` a horizon needs for its last fifth to be told: ten of them in it, so
/// that its median is not one instant's.
pub const LATE_LEAST_COMPARED: usize = 50;

/// The median ratio over the last fifth of the compared `t_k`. A replay whose per-period
/// errors add up strays more the longer it runs, while a DEM run's distance to the others
/// stays the same in law: a late median above the whole horizon's, with the DEM runs' not,
/// says a longer horizon will be farther off than the verdict's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LateVerdict {
    /// The first and last `k` of the last fifth.
    pub first: u32,
    pub last: u32,
    pub median_ratio: f64,
    /// Each DEM run's, judged against the others over the same `t_k`.
    pub dem_runs_median_ratio: Vec<f64>,
}

impl LateVerdict {
    /// Over the last fifth of `compared` (the `t_k` with a ratio, in order, and `ratios`
    /// theirs) of `periods`;
    /// `None` with fewer than three DEM runs or [`LATE_LEAST_COMPARED`] compared `t_k`.
    fn of(
        periods: &[&PeriodComparison],
        compared: &[u32],
        ratios: &[f64],
        dem_runs: usize,
    ) -> Option<Self> {
        if dem_runs < 3 || compared.len() < LATE_LEAST_COMPARED {
            return None;
        }
        let start = compared.len() - compared.len() / 5;
        let late = &compared[start..];
        let dem_runs_median_ratio = runs_medians(periods, late, dem_runs, |p| {
            Some(&p.dem_runs_ratio_to_others)
        });
        if dem_runs_median_ratio.is_empty() {
            return None;
        }
        Some(Self {
            first: *late.first()?,
            last: *late.last()?,
            median_ratio: median(&ratios[start..])?,
            dem_runs_median_ratio,
        })
    }
}

/// The median ratio of each field less its own bed mean, over the compared `t_k`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PatternVerdict {
    pub median_ratio: f64,
    /// Each DEM run's, judged against the others the same way (empty with fewer than three
    /// runs, and then left out of the JSON).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub dem_runs_median_ratio: Vec<f64>,
}

impl PatternVerdict {
    /// Over the `compared` `t_k` of `periods`; `None` unless every one of them has a pattern
    /// ratio.
    fn of(periods: &[&PeriodComparison], compared: &[u32], dem_runs: usize) -> Option<Self> {
        let ratios = periods
            .iter()
            .filter(|p| compared.contains(&p.k))
            .map(|p| p.pattern.as_ref()?.ratio_to_floor)
            .collect::<Option<Vec<f64>>>()?;
        Some(Self {
            median_ratio: median(&ratios)?,
            dem_runs_median_ratio: runs_medians(periods, compared, dem_runs, |p| {
                p.pattern.as_ref().map(|f| &f.dem_runs_ratio_to_others)
            }),
        })
    }
}

/// A number with two significant decimals at most, without float noise.
pub(crate) fn num(x: f64) -> String {
    if x.abs() >= 1e4 {
        return format!("{x:.1e}");
    }
    let s = if x.abs() >= 10.0 {
        format!("{x:.1}")
    } else {
        format!("{x:.2}")
    };
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The decimals (2 to 6) that put `x`, rounded, on the same side of 1 as `x` itself.
fn decimals_beside_one(x: f64) -> usize {
    let side = x.partial_cmp(&1.0);
    let mut decimals = 2;
    while decimals < 6
        && format!("{x:.decimals$}")
            .parse::<f64>()
            .unwrap_or(x)
            .partial_cmp(&1.0)
            != side
    {
        decimals += 1;
    }
    decimals
}

/// A median ratio with the decimals that put it on its side of 1 (`0.997`, not `1`, for
/// a median that passes; `1.004` for one that does not).
fn beside_one(x: f64) -> String {
    if x > 1.0 {
        return above_one(x);
    }
    let decimals = decimals_beside_one(x);
    let s = format!("{x:.decimals$}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// A ratio said to exceed 1, with the decimals that show it does (`1.004`, not `1`).
fn above_one(x: f64) -> String {
    let decimals = decimals_beside_one(x);
    format!("{x:.decimals$}")
}

/// A temperature difference in K with a precision fit for it.
pub(crate) fn kelvin(x: f64) -> String {
    let digits = if x == 0.0 {
        0
    } else {
        (2 - x.abs().log10().floor() as i64).clamp(0, 6) as usize
    };
    format!("{x:.digits$} K")
}

/// `t2…t7`, `t2, t5`, `t3`, or `t2…t4, t9`: runs of consecutive `k` as ranges; more than
/// four runs are counted instead (`41 of the 100 compared t_k`).
fn instants(ks: &[u32], compared: usize) -> String {
    let mut runs: Vec<(u32, u32)> = Vec::new();
    for &k in ks {
        match runs.last_mut() {
            Some((_, last)) if *last + 1 == k => *last = k,
            _ => runs.push((k, k)),
        }
    }
    if runs.len() > 4 {
        return format!("{} of the {compared} compared t_k", ks.len());
    }
    runs.iter()
        .map(|&(a, b)| match b - a {
            0 => format!("t{a}"),
            1 => format!("t{a}, t{b}"),
            _ => format!("t{a}…t{b}"),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

impl Verdict {
    /// The verdict on `periods` measured against `dem_runs` DEM runs.
    ///
    /// It passes when the median of `ratio_to_floor` over the compared `t_k` is at most 1
    /// and, with three or more DEM runs, the second field is within the runs' own range
    /// (no farther from them than their farthest pair) at every compared `t_k`. With two
    /// DEM runs (one twin) the range is one distance per `t_k`, so staying within it at
    /// every `t_k` would be a ratio ≤ 1 at every `t_k`, which a method identical to the DEM
    /// in law misses at about half of them: the median alone decides, and the `t_k` above
    /// 1 are named. The `t_k` where the extrapolation was still the recorded run
    /// ([`PeriodComparison::within_recording`]) are left out: there it is the DEM itself.
    /// Where the twins parted from the reference after the extrapolation left it
    /// ([`Departure::BeforeTheTwins`]), the judgement stands but says its floor is narrower
    /// than a fair one; where its distance went to the runs other than the reference
    /// ([`Departure::AfterTheTwins`]), it says so.
    pub fn of(
        periods: &[PeriodComparison],
        dem_runs: usize,
        departure: Departure,
        contrast: ContrastKind,
    ) -> Self {
        let within_recording: Vec<u32> = periods
            .iter()
            .filter(|p| p.within_recording)
            .map(|p| p.k)
            .collect();
        let floors = periods.iter().any(|p| p.floor_eps_abs.is_some());
        let periods: Vec<&PeriodComparison> =
            periods.iter().filter(|p| !p.within_recording).collect();
        let rated: Vec<(u32, f64)> = periods
            .iter()
            .filter_map(|p| Some((p.k, p.ratio_to_floor?)))
            .collect();
        let ratios: Vec<f64> = rated.iter().map(|r| r.1).collect();
        let compared: Vec<u32> = rated.iter().map(|r| r.0).collect();
        // only where there is a ratio: before the twins part (`--twins-from`) the runs are
        // one, and there is no range to be outside of
        let outside_range: Vec<u32> = periods
            .iter()
            .filter(|p| p.ratio_to_floor.is_some() && p.outside_floor_range())
            .map(|p| p.k)
            .collect();
        // group means (bed mean for a bed without groups): the extrapolation's error and the
        // DEM runs' own spread
        let groups = contrast == ContrastKind::HotCold;
        let (error, spread) = means_error_and_spread(&periods, groups);
        let (means_in_seat, dem_runs_means) = means_in_seats(&periods, groups, dem_runs);
        let median_ratio = median(&ratios);
        let dem_runs_median_ratio = runs_medians(&periods, &compared, dem_runs, |p| {
            Some(&p.dem_runs_ratio_to_others)
        });
        let pattern = PatternVerdict::of(&periods, &compared, dem_runs);
        let late = LateVerdict::of(&periods, &compared, &ratios, dem_runs);
        let dem_runs_outside_share = if dem_runs_median_ratio.is_empty() {
            Vec::new()
        } else {
            runs_outside_shares(&periods, &compared, dem_runs)
        };
        let one_pair = dem_runs == 2;
        let passes = median_ratio.map(|m| m <= 1.0 && (one_pair || outside_range.is_empty()));
        let (lo, hi) = (
            ratios.iter().copied().fold(f64::INFINITY, f64::min),
            ratios.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        );
        let setting = Setting {
            dem_runs,
            departure,
            groups,
            floors,
            past_recording: periods.len(),
        };
        let mut verdict = Self {
            passes,
            median_ratio,
            ratio_min: (!ratios.is_empty()).then_some(lo),
            ratio_max: (!ratios.is_empty()).then_some(hi),
            compared,
            within_recording,
            outside_range,
            means_error_max: error,
            means_spread_max: spread,
            dem_runs_median_ratio,
            dem_runs_outside_share,
            means_in_seat,
            dem_runs_means,
            pattern,
            late,
            text: String::new(),
        };
        verdict.text = verdict.words(&setting);
        verdict
    }

    /// The verdict in words, from its figures and its `setting`.
    fn words(&self, setting: &Setting) -> String {
        match (self.passes, self.median_ratio) {
            (Some(true), Some(m)) => self.passing_words(setting, m),
            (Some(false), Some(m)) => self.failing_words(setting, m),
            _ => self.unjudged_words(setting),
        }
    }

    /// What follows a judged verdict's head: the yardstick beside the median (how the DEM
    /// runs themselves score on it, and how often each is beyond the others' range), then
    /// the recorded span left out, the means, the pattern and whose distance it is.
    fn tail_words(&self, setting: &Setting) -> String {
        [
            yardstick_words(
                self.median_ratio,
                &self.dem_runs_median_ratio,
                &self.dem_runs_outside_share,
                self.compared.len(),
                self.outside_range.len(),
            ),
            self.left_out_words(),
            self.means_words(setting),
            self.pattern_words(),
            self.late_words(),
            self.runs_note(setting),
        ]
        .concat()
    }

    /// "passes as one more DEM run: …", with the median `m`.
    fn passing_words(&self, setting: &Setting, m: f64) -> String {
        let beyond = if self.outside_range.is_empty() {
            "never beyond the farthest two".to_string()
        } else {
            // only with one pair of runs (see `of`): say where, and why it passes
            format!(
                "farther from the two DEM runs than they are from each other at {}, as a \
                 further DEM run would be at about half the t_k (one twin: the median decides)",
                instants(&self.outside_range, setting.past_recording)
            )
        };
        format!(
            "passes as one more DEM run: its distance to the DEM runs is {} times theirs to \
             each other over {} (median {}), {beyond}{}",
            self.range_words(),
            instants(&self.compared, self.compared.len()),
            beside_one(m),
            self.tail_words(setting),
        )
    }

    /// "does not pass as one more DEM run: …", with the median `m`.
    fn failing_words(&self, setting: &Setting, m: f64) -> String {
        let beyond = if self.outside_range.is_empty() {
            String::new()
        } else {
            format!(
                "; farther {} at {}",
                if setting.dem_runs == 2 {
                    "from the two DEM runs than they are from each other"
                } else {
                    "than the two farthest DEM runs"
                },
                instants(&self.outside_range, setting.past_recording)
            )
        };
        // with three runs their range is still narrow: an exchangeable further run falls
        // outside it at some t_k most of the time, so a narrow miss is read through the
        // median; a genuine DEM run's median lay within 0.96-1.08 (docs/validation.md),
        // hence 1.1. (With two runs the median decides.)
        let few = if setting.dem_runs == 3 && !self.outside_range.is_empty() && m <= 1.1 {
            format!(
                " (with only {} DEM runs, a genuine further DEM run also falls outside their \
                 range at some t_k: read the median ratio)",
                setting.dem_runs
            )
        } else {
            String::new()
        };
        let median = if m > 1.0 {
            format!("{} > 1", above_one(m))
        } else {
            num(m)
        };
        format!(
            "does not pass as one more DEM run: {} times the DEM runs' distance to each other \
             over {} (median {median}){beyond}{few}{}",
            self.range_words(),
            instants(&self.compared, self.compared.len()),
            self.tail_words(setting),
        )
    }

    /// Why there is no judgement: nothing compared past the recording, no spread, or one
    /// DEM run.
    fn unjudged_words(&self, setting: &Setting) -> String {
        let means = self.means_words(setting);
        if setting.floors && self.compared.is_empty() && !self.within_recording.is_empty() {
            format!(
                "not judged: at every compared t_k ({}) the extrapolation is still the \
                 recorded run, which it follows until its first jump through a pairing; \
                 compare t_k past the recorded periods{means}",
                instants(&self.within_recording, self.within_recording.len())
            )
        } else if setting.floors {
            format!(
                "the {} DEM runs are identical at every compared t_k (floor 0): there is no \
                 spread to judge the extrapolation against{means}",
                setting.dem_runs
            )
        } else {
            format!(
                "not judged: one DEM run alone is no yardstick, since two runs of a chaotic \
                 flow part by particle diameters within a period (record with --twins 2 to \
                 measure the DEM's own spread){means}"
            )
        }
    }

    /// The ratio's range over the compared `t_k` ("0.9–1.03", or the one ratio).
    fn range_words(&self) -> String {
        match (self.ratio_min, self.ratio_max) {
            (Some(lo), Some(hi)) if self.compared.len() > 1 => format!("{}–{}", num(lo), num(hi)),
            (Some(only), _) => num(only),
            _ => String::new(),
        }
    }

    /// The group (bed) means' largest error, beside the DEM runs' spread.
    fn means_words(&self, setting: &Setting) -> String {
        let what = if setting.groups {
            "group means"
        } else {
            "bed mean"
        };
        match (self.means_error_max, self.means_spread_max) {
            (Some(e), Some(s)) => format!(
                "; {what} within {} of the DEM's (the DEM runs differ by up to {})",
                kelvin(e),
                kelvin(s)
            ),
            (Some(e), None) => format!("; {what} within {} of the DEM's", kelvin(e)),
            _ => String::new(),
        }
    }

    /// The pattern beside the field, where a heated wall moves the bed mean.
    fn pattern_words(&self) -> String {
        let Some(p) = &self.pattern else {
            return String::new();
        };
        let dem =
            min_max(p.dem_runs_median_ratio.iter().copied()).map_or(String::new(), |(lo, hi)| {
                format!(
                    ", each DEM run's judged the same way {}–{}",
                    num(lo),
                    num(hi)
                )
            });
        format!(
            "; each field less its own bed mean (where the heat is, apart from how fast the bed \
             heats): median ratio {}{dem}",
            beside_one(p.median_ratio)
        )
    }

    /// The last fifth of the horizon beside the DEM runs' over it, where there is one.
    fn late_words(&self) -> String {
        let Some(l) = &self.late else {
            return String::new();
        };
        let Some((lo, hi)) = min_max(l.dem_runs_median_ratio.iter().copied()) else {
            return String::new();
        };
        format!(
            "; over the last fifth, t{}…t{}: median ratio {}, each DEM run's {}–{}",
            l.first,
            l.last,
            beside_one(l.median_ratio),
            num(lo),
            num(hi)
        )
    }

    /// The recorded span, named so that a reader knows why the verdict starts later.
    fn left_out_words(&self) -> String {
        if self.within_recording.is_empty() {
            return String::new();
        }
        format!(
            "; {} left out, where the extrapolation is still the recorded run",
            instants(&self.within_recording, self.within_recording.len())
        )
    }

    /// Which runs its distance went to and how fair their spread is, where it is not simply
    /// all of them.
    fn runs_note(&self, setting: &Setting) -> String {
        match setting.departure {
            _ if setting.dem_runs < 2 || self.median_ratio.is_none() => String::new(),
            Departure::BeforeTheTwins { left, parted } => {
                let fair_from = parted + 1;
                format!(
                    "; the twins parted from the DEM at t{parted}, after the extrapolation left \
                     it (t{left}): their spread from t{fair_from} on is narrower than a fair \
                     floor for it"
                )
            }
            _ => setting
                .departure
                .runs_measured_to()
                .map_or(String::new(), |runs| {
                    format!("; its distance measured to {runs}")
                }),
        }
    }

    /// The share of the compared `t_k` (0 to 1) where the second field is outside the DEM
    /// runs' range; `None` where none was compared.
    pub fn outside_share(&self) -> Option<f64> {
        (!self.compared.is_empty())
            .then(|| self.outside_range.len() as f64 / self.compared.len() as f64)
    }
}

/// Each DEM run's median of its `ratios` at a `t_k` ([`PeriodComparison::
/// dem_runs_ratio_to_others`], or the pattern's) over the `compared` `t_k` (empty unless all
/// `dem_runs` ≥ 3 runs were judged at every one of them, so that each median is over the
/// same instants as the second field's).
fn runs_medians(
    periods: &[&PeriodComparison],
    compared: &[u32],
    dem_runs: usize,
    ratios: impl Fn(&PeriodComparison) -> Option<&Vec<Option<f64>>>,
) -> Vec<f64> {
    if dem_runs < 3 || compared.is_empty() {
        return Vec::new();
    }
    let Some(at) = periods
        .iter()
        .filter(|p| compared.contains(&p.k))
        .map(|p| ratios(p))
        .collect::<Option<Vec<&Vec<Option<f64>>>>>()
    else {
        return Vec::new();
    };
    (0..dem_runs)
        .map(|run| {
            at.iter()
                .map(|ratios| ratios.get(run).copied().flatten())
                .collect::<Option<Vec<f64>>>()
                .and_then(|r| median(&r))
        })
        .collect::<Option<Vec<f64>>>()
        .unwrap_or_default()
}

/// Each DEM run's share of the `compared` `t_k` where [`PeriodComparison::
/// dem_runs_outside_others_range`] holds: its `outside_range` over `compared`, as the second
/// field's. Empty unless all `dem_runs` ≥ 3 runs were judged (had a ratio) at every compared
/// `t_k`, the condition of [`runs_medians`], so that both are over the same instants.
fn runs_outside_shares(
    periods: &[&PeriodComparison],
    compared: &[u32],
    dem_runs: usize,
) -> Vec<f64> {
    if dem_runs < 3 || compared.is_empty() {
        return Vec::new();
    }
    let at: Vec<&PeriodComparison> = periods
        .iter()
        .filter(|p| compared.contains(&p.k))
        .copied()
        .collect();
    let judged = at.iter().all(|p| {
        p.dem_runs_outside_others_range.len() == dem_runs
            && (0..dem_runs).all(|run| {
                p.dem_runs_ratio_to_others
                    .get(run)
                    .copied()
                    .flatten()
                    .is_some()
            })
    });
    if !judged {
        return Vec::new();
    }
    (0..dem_runs)
        .map(|run| {
            let outside = at
                .iter()
                .filter(|p| p.dem_runs_outside_others_range[run])
                .count();
            outside as f64 / at.len() as f64
        })
        .collect()
}

/// One group's (the bed's, for a bed without groups) means at one `t_k`: the second
/// field's, and the DEM runs' (the reference first, then the further runs).
type GroupMeans = (f64, Vec<f64>);

/// Per compared period, each group's means.
fn group_means(p: &PeriodComparison, groups: bool) -> Vec<GroupMeans> {
    let with_reference = |dem: f64, runs: &[f64]| [&[dem][..], runs].concat();
    if groups {
        [
            (p.hot_mean_extra, p.hot_mean_dem, &p.dem_runs_hot_mean),
            (p.cold_mean_extra, p.cold_mean_dem, &p.dem_runs_cold_mean),
        ]
        .into_iter()
        .filter_map(|(e, d, runs)| Some((e?, with_reference(d?, runs))))
        .collect()
    } else {
        vec![(
            p.bed_mean_extra,
            with_reference(p.bed_mean_dem, &p.dem_runs_bed_mean),
        )]
    }
}

/// The largest difference between two of `means`.
fn spread_of(means: impl Iterator<Item = f64> + Clone) -> f64 {
    let hi = means.clone().fold(f64::NEG_INFINITY, f64::max);
    let lo = means.fold(f64::INFINITY, f64::min);
    hi - lo
}

/// The largest error of the group means (the bed mean for a bed without groups) against the
/// DEM's over `periods`, and the largest spread of the DEM runs' own (`None` without runs).
fn means_error_and_spread(
    periods: &[&PeriodComparison],
    groups: bool,
) -> (Option<f64>, Option<f64>) {
    let mut error: Option<f64> = None;
    let mut spread: Option<f64> = None;
    for p in periods {
        for (extra, runs) in group_means(p, groups) {
            error = Some(error.unwrap_or(0.0).max((extra - runs[0]).abs()));
            if runs.len() > 1 {
                spread = Some(spread.unwrap_or(0.0).max(spread_of(runs.iter().copied())));
            }
        }
    }
    (error, spread)
}

/// The means in the seats, with `dem_runs` ≥ 3 runs: the second field judged against the
/// runs without run `j` (for each `j`, in order), then each run `i` judged against the
/// others, both as [`SeatMeans`] against two or more runs of the same count, so that a
/// spread of as many runs stands beside each (the range of three runs is on average half
/// as wide again as that of two). Both empty with fewer runs, or where a period lacks a
/// run's means.
fn means_in_seats(
    periods: &[&PeriodComparison],
    groups: bool,
    dem_runs: usize,
) -> (Vec<SeatMeans>, Vec<SeatMeans>) {
    let means: Vec<GroupMeans> = periods
        .iter()
        .flat_map(|p| group_means(p, groups))
        .collect();
    if dem_runs < 3 || means.is_empty() || means.iter().any(|(_, runs)| runs.len() != dem_runs) {
        return (Vec::new(), Vec::new());
    }
    // `judged` against the runs but `left_out`, over every period and group
    let seat = |judged: &dyn Fn(&GroupMeans) -> f64, left_out: usize| {
        let (mut error, mut spread) = (0.0_f64, 0.0_f64);
        for at in &means {
            let others = || {
                at.1.iter()
                    .enumerate()
                    .filter(move |(i, _)| *i != left_out)
                    .map(|(_, m)| *m)
            };
            let first = others().next().expect("two others or more");
            error = error.max((judged(at) - first).abs());
            spread = spread.max(spread_of(others()));
        }
        SeatMeans {
            error_max: error,
            spread_max: spread,
        }
    };
    let second_field = (0..dem_runs).map(|j| seat(&|at| at.0, j)).collect();
    let runs = (0..dem_runs).map(|i| seat(&|at| at.1[i], i)).collect();
    (second_field, runs)
}

/// The yardstick beside the median: how the DEM runs score judged the same way against the
/// others (`runs_medians`), how many lie above the extrapolation's median, and how often each
/// is beyond the others' range (`outside_shares` of the `compared` t_k) beside the
/// extrapolation's `outside` count; empty without a median or without such runs.
fn yardstick_words(
    median_ratio: Option<f64>,
    runs_medians: &[f64],
    outside_shares: &[f64],
    compared: usize,
    outside: usize,
) -> String {
    match (median_ratio, min_max(runs_medians.iter().copied())) {
        (Some(m), Some((lo, hi))) => {
            let above = runs_medians.iter().filter(|&&r| r > m).count();
            let n = compared;
            let counts: Vec<usize> = outside_shares
                .iter()
                .map(|share| (share * n as f64).round() as usize)
                .collect();
            let beyond = match (counts.iter().min(), counts.iter().max()) {
                (Some(lo), Some(hi)) => format!(
                    "; farther from the others than their farthest two at {} of the {n} \
                     compared t_k (the extrapolation: {})",
                    if lo == hi {
                        lo.to_string()
                    } else {
                        format!("{lo}–{hi}")
                    },
                    outside
                ),
                _ => String::new(),
            };
            format!(
                "; each DEM run judged the same way against the others: medians {}–{}, {above} of the \
                 {} above the extrapolation's{beyond}",
                num(lo),
                num(hi),
                runs_medians.len()
            )
        }
        _ => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `t_k` whose second field is `ratio` times the mean floor from the DEM runs, with
    /// the floor's farthest pair `spread` times its mean (1 for one pair of runs).
    fn period(k: u32, ratio: f64, spread: f64) -> PeriodComparison {
        let floor = 0.4;
        PeriodComparison {
            k,
            t: f64::from(k),
            eps_abs: ratio * floor,
            cells_used: 200,
            eps_rel: Some(ratio * floor / 10.0),
            energy_error: None,
            hot_mean_dem: Some(310.0),
            hot_mean_extra: Some(310.05),
            cold_mean_dem: Some(300.0),
            cold_mean_extra: Some(299.98),
            bed_mean_dem: 305.0,
            bed_mean_extra: 305.0,
            contrast: Some(10.0),
            floor_eps_abs: Some(floor),
            floor_eps_abs_min: Some(floor / spread),
            floor_eps_abs_max: Some(floor * spread),
            floor_eps_rel: Some(floor / 10.0),
            eps_abs_to_dem_runs: Some(ratio * floor),
            ratio_to_floor: Some(ratio),
            dem_runs_ratio_to_others: Vec::new(),
            dem_runs_outside_others_range: Vec::new(),
            floor_energy_error: None,
            dem_runs_hot_mean: vec![310.04],
            dem_runs_cold_mean: vec![300.01],
            dem_runs_bed_mean: vec![305.0],
            pattern: None,
            within_recording: false,
        }
    }

    fn verdict(ratios: &[f64], spread: f64, dem_runs: usize) -> Verdict {
        let periods: Vec<PeriodComparison> = (2..)
            .zip(ratios)
            .map(|(k, &r)| period(k, r, spread))
            .collect();
        Verdict::of(
            &periods,
            dem_runs,
            Departure::WithTheTwins,
            ContrastKind::HotCold,
        )
    }

    /// With one twin the range is the one pair's distance, so a ratio above 1 at some t_k
    /// does not fail an extrapolation whose median is at most 1 (the demo's figures); the
    /// median above 1 does.
    #[test]
    fn with_one_twin_the_median_decides() {
        let v = verdict(&[0.96, 1.04, 0.78, 0.88, 0.96, 0.95], 1.0, 2);
        assert_eq!(v.passes, Some(true), "{}", v.text);
        assert_eq!(v.outside_range, vec![3]);
        assert!(
            v.text.starts_with("passes as one more DEM run"),
            "{}",
            v.text
        );
        let median = format!("(median {})", num(v.median_ratio.unwrap()));
        assert!(v.text.contains(&median), "{}", v.text);
        assert!(v.text.contains("each other at t3, "), "{}", v.text);
        let v = verdict(&[1.03, 1.02, 1.14, 1.14, 1.34, 1.28], 1.0, 2);
        assert_eq!(v.passes, Some(false), "{}", v.text);
        assert!(v.text.contains("median 1.14 > 1"), "{}", v.text);
        assert!(!v.text.contains("read the median"), "{}", v.text);
        let v = verdict(&[0.9, 0.8, 0.95], 1.0, 2);
        assert_eq!(v.passes, Some(true));
        assert!(
            v.text.contains("never beyond the farthest two"),
            "{}",
            v.text
        );
    }

    /// The t_k where the extrapolation is still the recorded run are left out of the
    /// verdict (and named); with nothing else left, nothing is judged.
    #[test]
    fn the_recorded_stretch_is_left_out() {
        let mut periods: Vec<PeriodComparison> = [0.5, 1.02, 1.04, 0.9]
            .iter()
            .zip(2..)
            .map(|(&r, k)| period(k, r, 1.0))
            .collect();
        periods[0].within_recording = true;
        let v = Verdict::of(&periods, 2, Departure::WithTheTwins, ContrastKind::HotCold);
        assert_eq!(v.within_recording, vec![2]);
        assert_eq!(v.compared, vec![3, 4, 5]);
        assert_eq!(v.median_ratio, Some(1.02));
        assert_eq!(v.passes, Some(false), "{}", v.text);
        assert!(v.text.contains("over t3…t5"), "{}", v.text);
        assert!(v.text.contains("t2 left out"), "{}", v.text);
        let v = Verdict::of(
            &periods[..1],
            2,
            Departure::WithTheTwins,
            ContrastKind::HotCold,
        );
        assert_eq!(v.passes, None);
        assert!(
            v.text.starts_with("not judged: at every compared t_k (t2)"),
            "{}",
            v.text
        );
    }

    /// With three or more runs the range is the farthest pair's distance: a t_k beyond it
    /// fails the verdict whatever the median, and with three runs a narrow miss says to read
    /// the median.
    #[test]
    fn with_more_runs_every_t_k_must_be_within_their_range() {
        let v = verdict(&[0.96, 1.04, 0.78, 0.88, 0.96, 0.95], 1.05, 3);
        assert_eq!(v.passes, Some(true), "{}", v.text);
        assert!(v.outside_range.is_empty());
        let v = verdict(&[0.96, 1.10, 0.78, 0.88, 0.96, 0.95], 1.05, 3);
        assert_eq!(v.passes, Some(false), "{}", v.text);
        assert_eq!(v.outside_range, vec![3]);
        assert!(v.text.contains("read the median ratio"), "{}", v.text);
        let v = verdict(&[0.96, 1.10, 0.78, 0.88, 0.96, 0.95], 1.05, 5);
        assert_eq!(v.passes, Some(false), "{}", v.text);
        assert!(!v.text.contains("read the median"), "{}", v.text);
    }

    /// With three or more runs each run is judged against the others over the same t_k,
    /// and the verdict says where the extrapolation's median falls among theirs.
    #[test]
    fn the_dem_runs_own_medians_stand_beside_the_extrapolations() {
        let mut periods: Vec<PeriodComparison> = [0.96, 1.04, 0.78, 0.88, 0.96, 0.95]
            .iter()
            .zip(2..)
            .map(|(&r, k)| period(k, r, 1.5))
            .collect();
        for (p, straggler) in periods.iter_mut().zip([1.2, 1.4, 1.3, 1.3, 1.5, 1.1]) {
            p.dem_runs_ratio_to_others = vec![Some(0.8), Some(0.9), Some(1.0), Some(straggler)];
            // the straggler beyond the others' range where its ratio is above 1.25
            p.dem_runs_outside_others_range = vec![false, false, false, straggler > 1.25];
        }
        let v = Verdict::of(&periods, 4, Departure::WithTheTwins, ContrastKind::HotCold);
        assert_eq!(v.dem_runs_median_ratio, vec![0.8, 0.9, 1.0, 1.3]);
        assert!(
            v.text
                .contains("each DEM run judged the same way against the others: medians 0.8–1.3, 2 of the 4 above the extrapolation's"),
            "{}",
            v.text
        );
        // the straggler is beyond the others at 4 of the 6 t_k, the others never; the
        // extrapolation never beyond the runs' range (spread 1.5 above its ratios)
        assert_eq!(v.dem_runs_outside_share, vec![0.0, 0.0, 0.0, 4.0 / 6.0]);
        assert_eq!(v.outside_share(), Some(0.0));
        assert!(
            v.text.contains(
                "farther from the others than their farthest two at 0–4 of the 6 compared t_k \
                 (the extrapolation: 0)"
            ),
            "{}",
            v.text
        );
        // the recorded stretch is left out of the runs' medians as of the extrapolation's
        periods[0].within_recording = true;
        periods[0].dem_runs_ratio_to_others[3] = Some(9.0);
        let v = Verdict::of(&periods, 4, Departure::WithTheTwins, ContrastKind::HotCold);
        assert_eq!(v.dem_runs_median_ratio[3], 1.3);
        // t2 (the straggler's 1.2, within) left out: 4 of the 5 compared t_k
        assert_eq!(v.dem_runs_outside_share[3], 4.0 / 5.0);
        // a run missing at one compared t_k: no medians, and nothing said
        periods[2].dem_runs_ratio_to_others.pop();
        let v = Verdict::of(&periods, 4, Departure::WithTheTwins, ContrastKind::HotCold);
        assert!(v.dem_runs_median_ratio.is_empty());
        assert!(v.dem_runs_outside_share.is_empty());
        assert!(!v.text.contains("each DEM run"), "{}", v.text);
    }

    /// A replay that strays more the longer it runs: its median over the last fifth of the
    /// compared t_k stands beside each DEM run's there, told apart from the whole
    /// horizon's; a horizon too short for ten t_k in its last fifth, or fewer than three
    /// runs, gives none.
    #[test]
    fn the_last_fifth_of_the_horizon_is_told_beside_the_dem_runs() {
        let late_periods = |n: usize| -> Vec<PeriodComparison> {
            (0..n)
                .map(|i| {
                    // 1.0 over the first four fifths, 1.5 over the last
                    let growing = if i >= n - n / 5 { 1.5 } else { 1.0 };
                    let mut p = period(2 + i as u32, growing, 2.0);
                    p.dem_runs_ratio_to_others = vec![Some(0.9), Some(1.0), Some(1.1)];
                    p.dem_runs_outside_others_range = vec![false; 3];
                    p
                })
                .collect()
        };
        let periods = late_periods(60);
        let v = Verdict::of(&periods, 3, Departure::WithTheTwins, ContrastKind::HotCold);
        assert_eq!(v.median_ratio, Some(1.0));
        let late = v.late.as_ref().expect("60 compared t_k and three runs");
        // the last 12 of t2…t61
        assert_eq!((late.first, late.last), (50, 61));
        assert_eq!(late.median_ratio, 1.5);
        assert_eq!(late.dem_runs_median_ratio, vec![0.9, 1.0, 1.1]);
        assert!(
            v.text.contains(
                "; over the last fifth, t50…t61: median ratio 1.50, each DEM run's 0.9–1.1"
            ),
            "{}",
            v.text
        );
        // 49 compared t_k: too few to tell
        let v = Verdict::of(
            &late_periods(49),
            3,
            Departure::WithTheTwins,
            ContrastKind::HotCold,
        );
        assert_eq!(v.late, None);
        assert!(!v.text.contains("last fifth"), "{}", v.text);
        // two runs: no DEM run to judge in the seat
        let v = Verdict::of(&periods, 2, Departure::WithTheTwins, ContrastKind::HotCold);
        assert_eq!(v.late, None);
        let json = serde_json::to_string(&v).unwrap();
        assert!(!json.contains("late"), "{json}");
    }

    /// Each DEM run is judged on the means as the second field is: its error against the
    /// first of the others beside the others' own spread. A run far from the two others
    /// misses; the two close ones do not, and fewer than three runs give nothing.
    #[test]
    fn each_dem_run_is_judged_on_the_means_in_the_seat() {
        let mut p = period(2, 1.0, 1.5);
        p.dem_runs_bed_mean = vec![305.1, 305.5];
        let mut q = period(3, 1.0, 1.5);
        q.dem_runs_bed_mean = vec![305.05, 305.45];
        let periods = [p.clone(), q];
        let v = Verdict::of(&periods, 3, Departure::WithTheTwins, ContrastKind::WallBed);
        // the reference: 0.1 from the first twin, the twins 0.4 apart; the first twin 0.1
        // from the reference, beside 0.5; the second 0.5 from the reference, beside 0.1
        let outside = |v: &Verdict| -> Vec<bool> {
            v.dem_runs_means.iter().map(SeatMeans::outside).collect()
        };
        assert_eq!(outside(&v), vec![false, false, true]);
        let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
        let seat = v.dem_runs_means[2];
        assert!(
            close(seat.error_max, 0.5) && close(seat.spread_max, 0.1),
            "{seat:?}"
        );
        // the extrapolation (305.0 throughout) without the reference: 0.1 from the first
        // twin beside their 0.4; without a twin: 0 from the reference, beside 0.5 and 0.1
        let errors: Vec<(f64, f64)> = v
            .means_in_seat
            .iter()
            .map(|s| (s.error_max, s.spread_max))
            .collect();
        for (got, want) in errors.iter().zip([(0.1, 0.4), (0.0, 0.5), (0.0, 0.1)]) {
            assert!(close(got.0, want.0) && close(got.1, want.1), "{errors:?}");
        }
        // the groups' means: the hot twin 0.04 from the reference, the cold 0.01
        p.dem_runs_hot_mean = vec![310.04, 310.5];
        p.dem_runs_cold_mean = vec![300.01, 300.02];
        let v = Verdict::of(
            &[p.clone()],
            3,
            Departure::WithTheTwins,
            ContrastKind::HotCold,
        );
        assert_eq!(outside(&v), vec![false, false, true]);
        let v = Verdict::of(&[p], 2, Departure::WithTheTwins, ContrastKind::HotCold);
        assert!(v.dem_runs_means.is_empty() && v.means_in_seat.is_empty());
    }

    /// Twins that parted after the extrapolation left the reference: the judgement stands
    /// and says why its floor is narrow; with one DEM run there is no floor to qualify.
    #[test]
    fn a_late_parting_is_said_beside_the_judgement() {
        let periods: Vec<PeriodComparison> = [0.96, 1.04, 0.9]
            .iter()
            .zip(2..)
            .map(|(&r, k)| period(k, r, 1.0))
            .collect();
        let late = Departure::BeforeTheTwins { left: 1, parted: 2 };
        let fair = Verdict::of(&periods, 2, Departure::WithTheTwins, ContrastKind::HotCold);
        let v = Verdict::of(&periods, 2, late, ContrastKind::HotCold);
        assert_eq!(v.passes, fair.passes);
        assert_eq!(v.median_ratio, fair.median_ratio);
        assert_eq!(
            v.text,
            format!(
                "{}; the twins parted from the DEM at t2, after the extrapolation left it (t1): \
                 their spread from t3 on is narrower than a fair floor for it",
                fair.text
            )
        );
        let alone = Verdict::of(&periods, 1, late, ContrastKind::HotCold);
        assert!(!alone.text.contains("twins parted"), "{}", alone.text);
        // measured without the reference (it followed the reference past the parting): the
        // same judgement, which says so
        let after = Departure::AfterTheTwins {
            left: Some(3),
            parted: 2,
        };
        let v = Verdict::of(&periods, 2, after, ContrastKind::HotCold);
        assert_eq!((v.passes, v.median_ratio), (fair.passes, fair.median_ratio));
        assert_eq!(
            v.text,
            format!(
                "{}; its distance measured to the DEM runs other than the reference (it is the \
                 reference until t3; the twins parted at t2)",
                fair.text
            )
        );
    }

    #[test]
    fn numbers_are_written_without_float_noise() {
        assert_eq!(num(0.15000000000000002), "0.15");
        assert_eq!(num(1.0), "1");
        assert_eq!(above_one(1.0015), "1.002");
        assert_eq!(above_one(1.18), "1.18");
        assert_eq!(beside_one(0.9968), "0.997");
        assert_eq!(beside_one(0.96), "0.96");
        assert_eq!(beside_one(1.0), "1");
        assert_eq!(beside_one(1.0015), "1.002");
        assert_eq!(num(12.34), "12.3");
        assert_eq!(num(55769240392.9), "5.6e10");
        assert_eq!(kelvin(0.0812), "0.0812 K");
        assert_eq!(kelvin(1.234), "1.23 K");
        assert_eq!(instants(&[2, 3, 4], 6), "t2…t4");
        assert_eq!(instants(&[2, 5], 6), "t2, t5");
        assert_eq!(instants(&[2, 3, 4, 9], 9), "t2…t4, t9");
        assert_eq!(instants(&[2, 4, 6, 8, 10], 9), "5 of the 9 compared t_k");
    }
}
