//! The statistical bar: whether an extrapolation passes as one more DEM run, judged over
//! several draws of one case instead of one recording.
//!
//! One recording's median ratio is a noisy figure: a genuine DEM run judged in the
//! extrapolation's seat against the others is at most 1 in only about two windows of three.
//! So the judgement that settles the question is pooled over draws (recordings of the same
//! case with other seeds, or other recorded windows), each compared as `tdex compare` does:
//! the extrapolation's mean median ratio over the draws beside a genuine DEM run's judged in
//! the same seat, each with its standard error over the draws, and the share of compared
//! `t_k` outside the DEM runs' range for both.

use super::verdict::{kelvin, num, SeatMeans};
use super::{CompareError, Comparison, ContrastKind};
use serde::Serialize;
use tdex_format::RecordingInfo;

/// Least draws a pooled verdict is given: with one, `tdex compare`'s own verdict is the
/// judgement, and there is no standard error to weigh it by.
pub const MIN_DRAWS: usize = 2;

/// Least DEM runs (the reference and two twins) in every draw: a DEM run judged in the
/// extrapolation's seat needs two others to measure its distance against.
pub const MIN_DEM_RUNS: usize = 3;

/// How many standard errors of the difference the extrapolation's mean median ratio may
/// stand above the DEM runs' (about a 2.5 % one-sided chance of failing a method that is a
/// DEM run in law).
pub const STANDARD_ERRORS: f64 = 2.0;

/// How much larger (as a share of the compared `t_k`, 10 percentage points) the
/// extrapolation's share outside the DEM runs' range may be than the DEM runs' own.
pub const OUTSIDE_SHARE_MARGIN: f64 = 0.10;

/// Room for float noise when shares (whole counts of `t_k` over the compared ones) are set
/// against their bar, so that a share exactly on the bar counts as on it.
const SHARE_TOLERANCE: f64 = 1e-12;

/// A mean over the draws and its standard error (the sample standard deviation over √n).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MeanSe {
    pub mean: f64,
    pub standard_error: f64,
}

impl MeanSe {
    /// The mean of `values` and its standard error, `s / √n` with the sample standard
    /// deviation `s` (divided by `n − 1`); `None` with fewer than two values, which have no
    /// spread to measure.
    pub fn of(values: &[f64]) -> Option<Self> {
        let n = values.len();
        if n < 2 {
            return None;
        }
        let mean = values.iter().sum::<f64>() / n as f64;
        let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        Some(MeanSe {
            mean,
            standard_error: (variance / n as f64).sqrt(),
        })
    }
}

/// A figure of the extrapolation beside a DEM run's judged in its seat.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Beside<T> {
    pub extrapolation: T,
    pub dem_run: T,
}

/// One draw's figures, from its comparison.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Draw {
    pub recording: String,
    pub extrapolation: String,
    /// The extrapolation's median ratio to the DEM runs' spread over the compared `t_k`.
    pub median_ratio: f64,
    /// Its share of the compared `t_k` outside the DEM runs' range (0 to 1).
    pub outside_share: f64,
    /// The compared `t_k`.
    pub compared: usize,
    /// The DEM runs judged in the seat, each against the others: the mean of their
    /// medians, and of their shares outside the others' range. One figure per draw, since
    /// the runs of one draw share its reference and are not independent of each other.
    pub dem_runs_median_ratio: f64,
    pub dem_runs_outside_share: f64,
    /// The largest error of the group means (the bed mean for a bed without groups) over
    /// the compared `t_k`, and the largest difference between two DEM runs' means there, K.
    pub means_error_max: f64,
    pub means_spread_max: f64,
    /// The means in a DEM run's seat ([`super::Verdict::means_in_seat`]): the share of the
    /// seats (0 to 1) where the extrapolation, and where a DEM run, strays beyond the
    /// others' spread, and how far: the mean of the largest error over the largest spread
    /// (null where a spread is only rounding, as of a conserved bed mean).
    pub means_outside_share_in_seat: f64,
    pub dem_runs_means_outside_share: f64,
    pub means_error_to_spread: Option<f64>,
    pub dem_runs_means_error_to_spread: Option<f64>,
    /// With a wall that conducts heat: the median ratio of each field less its own bed mean
    /// ([`super::verdict::PatternVerdict`]), the extrapolation's beside the mean of the DEM
    /// runs' in the seat; null otherwise (left out of the JSON).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pattern: Option<Beside<f64>>,
    /// The median ratio over the last fifth of the compared `t_k`
    /// ([`super::verdict::LateVerdict`]), the extrapolation's beside the mean of the DEM
    /// runs'; null where the horizon is too short to tell (left out of the JSON).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub late: Option<Beside<f64>>,
    /// Whether the means are the hot and cold group means (else the bed mean).
    #[serde(skip)]
    pub groups: bool,
}

impl Draw {
    /// The figures of comparison `c`, refused where they cannot be pooled: fewer than
    /// [`MIN_DEM_RUNS`] DEM runs, or no median ratio for the extrapolation or the runs.
    pub fn of(c: &Comparison) -> Result<Self, CompareError> {
        if c.dem_runs < MIN_DEM_RUNS {
            return Err(CompareError::DrawTooFewRuns {
                recording: c.recording.clone(),
                dem_runs: c.dem_runs,
            });
        }
        let v = &c.verdict;
        let not_judged = || CompareError::DrawNotJudged {
            extrapolation: c.extrapolation.clone(),
            recording: c.recording.clone(),
            verdict: v.text.clone(),
        };
        let mean = |values: &[f64]| {
            (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
        };
        // the share of seats beyond their runs' spread, and the mean error over spread
        let outside_share = |seats: &[SeatMeans]| {
            (!seats.is_empty())
                .then(|| seats.iter().filter(|s| s.outside()).count() as f64 / seats.len() as f64)
        };
        let error_to_spread = |seats: &[SeatMeans]| {
            seats
                .iter()
                .map(SeatMeans::error_to_spread)
                .collect::<Option<Vec<f64>>>()
                .and_then(|r| mean(&r))
        };
        Ok(Draw {
            recording: c.recording.clone(),
            extrapolation: c.extrapolation.clone(),
            median_ratio: v.median_ratio.ok_or_else(not_judged)?,
            outside_share: v.outside_share().ok_or_else(not_judged)?,
            compared: v.compared.len(),
            dem_runs_median_ratio: mean(&v.dem_runs_median_ratio).ok_or_else(not_judged)?,
            dem_runs_outside_share: mean(&v.dem_runs_outside_share).ok_or_else(not_judged)?,
            means_error_max: v.means_error_max.ok_or_else(not_judged)?,
            means_spread_max: v.means_spread_max.ok_or_else(not_judged)?,
            means_outside_share_in_seat: outside_share(&v.means_in_seat).ok_or_else(not_judged)?,
            dem_runs_means_outside_share: outside_share(&v.dem_runs_means)
                .ok_or_else(not_judged)?,
            means_error_to_spread: error_to_spread(&v.means_in_seat),
            dem_runs_means_error_to_spread: error_to_spread(&v.dem_runs_means),
            pattern: v
                .pattern
                .as_ref()
                .and_then(|p| beside_runs(p.median_ratio, &p.dem_runs_median_ratio)),
            late: v
                .late
                .as_ref()
                .and_then(|l| beside_runs(l.median_ratio, &l.dem_runs_median_ratio)),
            groups: c.contrast == ContrastKind::HotCold,
        })
    }

    /// Whether the group (bed) means are within the DEM runs' spread at every compared
    /// `t_k`: the largest error no larger than the largest difference between two runs.
    pub fn means_within_spread(&self) -> bool {
        let means = SeatMeans {
            error_max: self.means_error_max,
            spread_max: self.means_spread_max,
        };
        !means.outside()
    }
}

/// A median ratio beside the mean of the DEM runs' in the seat; `None` without runs.
fn beside_runs(median_ratio: f64, dem_runs_median_ratio: &[f64]) -> Option<Beside<f64>> {
    (!dem_runs_median_ratio.is_empty()).then(|| Beside {
        extrapolation: median_ratio,
        dem_run: dem_runs_median_ratio.iter().sum::<f64>() / dem_runs_median_ratio.len() as f64,
    })
}

/// The pooled judgement over several draws of one case.
#[derive(Debug, Clone, Serialize)]
pub struct Draws {
    pub draws: usize,
    /// Whether the extrapolation passes as one more DEM run over the draws: all three of
    /// `median_ratio_within`, `outside_share_within` and `means_within_spread`.
    pub passes: bool,
    /// The extrapolation's median ratio, and the DEM runs' judged in the seat, over the
    /// draws.
    pub median_ratio: MeanSe,
    pub dem_runs_median_ratio: MeanSe,
    /// The DEM runs' mean plus [`STANDARD_ERRORS`] standard errors of the difference
    /// (`√(SE_x² + SE_dem²)`): the most the extrapolation's mean may be.
    pub median_ratio_bar: f64,
    pub median_ratio_within: bool,
    /// The shares of compared `t_k` outside the DEM runs' range (0 to 1), the
    /// extrapolation's and the DEM runs' in the seat, over the draws.
    pub outside_share: MeanSe,
    pub dem_runs_outside_share: MeanSe,
    /// The DEM runs' mean share plus [`OUTSIDE_SHARE_MARGIN`].
    pub outside_share_bar: f64,
    pub outside_share_within: bool,
    /// Whether every draw has its group (bed) means within the DEM runs' spread, how many
    /// do not, and the largest error over the draws with that draw's spread beside it (K).
    pub means_within_spread: bool,
    pub means_outside_spread_draws: usize,
    pub means_error_max: f64,
    pub means_spread_beside: f64,
    /// The means in a DEM run's seat over the draws, the extrapolation's beside a DEM
    /// run's: how often a genuine run strays beyond the others' spread where the
    /// extrapolation must not, and how far (the largest error over the largest spread; null
    /// unless every draw has one).
    pub means_outside_share_in_seat: MeanSe,
    pub dem_runs_means_outside_share: MeanSe,
    pub means_error_to_spread: Option<MeanSe>,
    pub dem_runs_means_error_to_spread: Option<MeanSe>,
    /// With a wall that conducts heat, the median ratio of each field less its own bed mean
    /// over the draws, the extrapolation's beside a DEM run's in the seat (null unless every
    /// draw has it, and then left out of the JSON). Not part of the judgement: it tells a
    /// miss in the bed mean from one in where the heat is.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pattern: Option<Beside<MeanSe>>,
    /// The median ratio over the last fifth of each draw's compared `t_k`, over the draws,
    /// the extrapolation's beside a DEM run's in the seat (null unless every draw has it,
    /// and then left out of the JSON). Not part of the judgement: a late mean above the whole
    /// horizon's, a DEM run's not, says the error is still growing where the horizon ends.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub late: Option<Beside<MeanSe>>,
    /// Each draw's figures, in the order given.
    pub each: Vec<Draw>,
    /// The judgement in words.
    pub text: String,
}

impl Draws {
    /// The pooled judgement over `each` draw; refused with fewer than [`MIN_DRAWS`].
    ///
    /// It passes when (a) the extrapolation's mean median ratio is at most the DEM runs'
    /// mean in the seat plus two standard errors of the difference, (b) its mean share of
    /// `t_k` outside the DEM runs' range is at most theirs plus 10 percentage points, and
    /// (c) its group means (the bed mean for a bed without groups) are within the DEM runs'
    /// spread at every compared `t_k` of every draw.
    pub fn pool(each: Vec<Draw>) -> Result<Self, CompareError> {
        if each.len() < MIN_DRAWS {
            return Err(CompareError::TooFewDraws { draws: each.len() });
        }
        let over = |figure: fn(&Draw) -> f64| {
            let values: Vec<f64> = each.iter().map(figure).collect();
            MeanSe::of(&values).expect("two draws or more")
        };
        let median_ratio = over(|d| d.median_ratio);
        let dem_runs_median_ratio = over(|d| d.dem_runs_median_ratio);
        let outside_share = over(|d| d.outside_share);
        let dem_runs_outside_share = over(|d| d.dem_runs_outside_share);
        let difference_se = median_ratio
            .standard_error
            .hypot(dem_runs_median_ratio.standard_error);
        let median_ratio_bar = dem_runs_median_ratio.mean + STANDARD_ERRORS * difference_se;
        let median_ratio_within = median_ratio.mean <= median_ratio_bar;
        let outside_share_bar = dem_runs_outside_share.mean + OUTSIDE_SHARE_MARGIN;
        let outside_share_within = outside_share.mean <= outside_share_bar + SHARE_TOLERANCE;
        let means_outside_spread_draws = each.iter().filter(|d| !d.means_within_spread()).count();
        let worst = each
            .iter()
            .max_by(|a, b| a.means_error_max.total_cmp(&b.means_error_max))
            .expect("two draws or more");
        let (means_error_max, means_spread_beside) =
            (worst.means_error_max, worst.means_spread_max);
        let means_within_spread = means_outside_spread_draws == 0;
        let means_outside_share_in_seat = over(|d| d.means_outside_share_in_seat);
        let dem_runs_means_outside_share = over(|d| d.dem_runs_means_outside_share);
        let over_some = |figure: fn(&Draw) -> Option<f64>| {
            let values = each.iter().map(figure).collect::<Option<Vec<f64>>>()?;
            MeanSe::of(&values)
        };
        let means_error_to_spread = over_some(|d| d.means_error_to_spread);
        let dem_runs_means_error_to_spread = over_some(|d| d.dem_runs_means_error_to_spread);
        // a figure that informs: pooled only where every draw has it
        let over_beside = |figure: fn(&Draw) -> Option<Beside<f64>>| {
            let values = each.iter().map(figure).collect::<Option<Vec<_>>>()?;
            let (x, dem): (Vec<f64>, Vec<f64>) =
                values.iter().map(|b| (b.extrapolation, b.dem_run)).unzip();
            Some(Beside {
                extrapolation: MeanSe::of(&x)?,
                dem_run: MeanSe::of(&dem)?,
            })
        };
        let pattern = over_beside(|d| d.pattern);
        let late = over_beside(|d| d.late);
        let passes = median_ratio_within && outside_share_within && means_within_spread;
        let mut pooled = Draws {
            draws: each.len(),
            passes,
            median_ratio,
            dem_runs_median_ratio,
            median_ratio_bar,
            median_ratio_within,
            outside_share,
            dem_runs_outside_share,
            outside_share_bar,
            outside_share_within,
            means_within_spread,
            means_outside_spread_draws,
            means_error_max,
            means_spread_beside,
            means_outside_share_in_seat,
            dem_runs_means_outside_share,
            means_error_to_spread,
            dem_runs_means_error_to_spread,
            pattern,
            late,
            each,
            text: String::new(),
        };
        pooled.text = pooled.words();
        Ok(pooled)
    }

    /// Whether the means judged are the hot and cold groups' (else the bed's): the draws
    /// are of one case, so the first says it for all.
    pub fn of_groups(&self) -> bool {
        self.each.first().is_some_and(|d| d.groups)
    }

    /// The pooled judgement in words, from its figures.
    fn words(&self) -> String {
        let groups = self.of_groups();
        let n = self.draws;
        let difference_se = self
            .median_ratio
            .standard_error
            .hypot(self.dem_runs_median_ratio.standard_error);
        let ratio_words = format!(
            "mean median ratio {} against {} for a DEM run judged in the same seat, {} the bar \
             of {} (theirs plus two standard errors of the difference)",
            plus_minus(self.median_ratio),
            plus_minus(self.dem_runs_median_ratio),
            if self.median_ratio_within {
                "within"
            } else {
                "above"
            },
            fixed(self.median_ratio_bar, decimals(difference_se, 2)),
        );
        let outside_words = format!(
            "farther than the two farthest DEM runs at {} of the compared t_k against {} for a \
             DEM run in the seat, {} the bar of {} % (theirs plus {} points)",
            percent_plus_minus(self.outside_share),
            percent_plus_minus(self.dem_runs_outside_share),
            if self.outside_share_within {
                "within"
            } else {
                "above"
            },
            fixed(
                100.0 * self.outside_share_bar,
                decimals(100.0 * self.dem_runs_outside_share.standard_error, 0)
            ),
            num(100.0 * OUTSIDE_SHARE_MARGIN),
        );
        let what = if groups { "group means" } else { "bed mean" };
        let where_ = if self.means_within_spread {
            "within the DEM runs' spread at every compared t_k of every draw".to_string()
        } else {
            format!(
                "beyond the DEM runs' spread at some compared t_k in {} of the {n} draws",
                self.means_outside_spread_draws
            )
        };
        let stray = if groups { "stray" } else { "strays" };
        let how_far = match (
            self.means_error_to_spread,
            self.dem_runs_means_error_to_spread,
        ) {
            (Some(x), Some(dem)) => format!(
                " (largest error {} times their spread against {})",
                plus_minus(x),
                plus_minus(dem)
            ),
            _ => String::new(),
        };
        let means_words = format!(
            "{what} {where_} (the largest error {}, in a draw whose DEM runs differ by up to \
             {}); in a DEM run's seat, against the other runs, the extrapolation's {what} \
             {stray} beyond their spread in {} of the seats against {} for a DEM run{how_far}",
            kelvin(self.means_error_max),
            kelvin(self.means_spread_beside),
            percent_plus_minus(self.means_outside_share_in_seat),
            percent_plus_minus(self.dem_runs_means_outside_share),
        );
        let pattern_words = self.pattern.map_or(String::new(), |p| {
            format!(
                "; each field less its own bed mean (where the heat is, apart from how fast the \
                 bed heats): mean median ratio {} against {} for a DEM run",
                plus_minus(p.extrapolation),
                plus_minus(p.dem_run)
            )
        });
        let late_words = self.late.map_or(String::new(), |l| {
            format!(
                "; over the last fifth of each draw's compared t_k: mean median ratio {} \
                 against {} for a DEM run",
                plus_minus(l.extrapolation),
                plus_minus(l.dem_run)
            )
        });
        format!(
            "{} as one more DEM run over the {n} draws: {ratio_words}; {outside_words}; \
             {means_words}{pattern_words}{late_words}",
            if self.passes {
                "passes"
            } else {
                "does not pass"
            }
        )
    }

    /// The pooled figures as a small table: the extrapolation beside a DEM run in the seat.
    pub fn table(&self) -> String {
        let line = |label: &str, extrapolation: String, dem_run: String| {
            format!("{label:<40} {extrapolation:>16} {dem_run:>20}\n")
        };
        let beside = |label: &str, b: Beside<MeanSe>| {
            line(label, plus_minus(b.extrapolation), plus_minus(b.dem_run))
        };
        let mut s = line(
            "over the draws (mean ± SE)",
            "extrapolation".into(),
            "DEM run in the seat".into(),
        );
        s += &beside(
            "median ratio",
            Beside {
                extrapolation: self.median_ratio,
                dem_run: self.dem_runs_median_ratio,
            },
        );
        s += &line(
            "beyond the DEM runs' range (% t_k)",
            percent_plus_minus(self.outside_share),
            percent_plus_minus(self.dem_runs_outside_share),
        );
        s += &line(
            "means beyond the others' spread (% seats)",
            percent_plus_minus(self.means_outside_share_in_seat),
            percent_plus_minus(self.dem_runs_means_outside_share),
        );
        if let (Some(extrapolation), Some(dem_run)) = (
            self.means_error_to_spread,
            self.dem_runs_means_error_to_spread,
        ) {
            s += &beside(
                "means: largest error / others' spread",
                Beside {
                    extrapolation,
                    dem_run,
                },
            );
        }
        if let Some(p) = self.pattern {
            s += &beside("median ratio less the bed mean", p);
        }
        if let Some(l) = self.late {
            s += &beside("median ratio, last fifth of the t_k", l);
        }
        s
    }
}

/// Whether `draw` (a recording, by its path) is of the same case as `first`: the same case
/// name, particle count and period τ (the draws differ by their seed or their recorded
/// window, and their ratios are measured over periods of one length).
pub fn check_same_case(
    (first, first_info): (&str, &RecordingInfo),
    (draw, info): (&str, &RecordingInfo),
) -> Result<(), CompareError> {
    let name = |i: &RecordingInfo| {
        i.case_resolved
            .get("name")
            .and_then(|v| v.as_str())
            .unwrap_or("")
            .to_string()
    };
    let differs = if name(info) != name(first_info) {
        Some(format!(
            "its case is named \"{}\" and the other's \"{}\"",
            name(info),
            name(first_info)
        ))
    } else if info.particles != first_info.particles {
        Some(format!(
            "it holds {} particles and the other {}",
            info.particles, first_info.particles
        ))
    } else if (info.tau - first_info.tau).abs() > 0.5 * first_info.dt.min(info.dt) {
        Some(format!(
            "its period τ is {} s and the other's {} s",
            crate::fmt::sig(info.tau, 6),
            crate::fmt::sig(first_info.tau, 6)
        ))
    } else {
        None
    };
    match differs {
        Some(what) => Err(CompareError::OtherCase {
            draw: draw.to_string(),
            first: first.to_string(),
            what,
        }),
        None => Ok(()),
    }
}

/// The decimals (at least `least`, at most 6) that show the leading digit of a standard
/// error `se` (`0.13`, `0.05`, `0.001`).
fn decimals(se: f64, least: usize) -> usize {
    if se > 0.0 && se.is_finite() {
        (-se.log10().floor()).clamp(least as f64, 6.0) as usize
    } else {
        least
    }
}

fn fixed(x: f64, decimals: usize) -> String {
    format!("{x:.decimals$}")
}

/// `1.38 ± 0.05`: a mean with the decimals of its standard error.
pub fn plus_minus(m: MeanSe) -> String {
    let d = decimals(m.standard_error, 2);
    format!("{} ± {}", fixed(m.mean, d), fixed(m.standard_error, d))
}

/// `33 ± 8 %`: a share (0 to 1) in percent, with the decimals of its standard error.
pub fn percent_plus_minus(m: MeanSe) -> String {
    let (mean, se) = (100.0 * m.mean, 100.0 * m.standard_error);
    let d = decimals(se, 0);
    format!("{} ± {} %", fixed(mean, d), fixed(se, d))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn draw(median: f64, outside: f64, dem_median: f64, dem_outside: f64) -> Draw {
        Draw {
            recording: "a.mcap".into(),
            extrapolation: "a.extra.mcap".into(),
            median_ratio: median,
            outside_share: outside,
            compared: 10,
            dem_runs_median_ratio: dem_median,
            dem_runs_outside_share: dem_outside,
            means_error_max: 0.01,
            means_spread_max: 0.02,
            means_outside_share_in_seat: 0.0,
            dem_runs_means_outside_share: 0.0,
            means_error_to_spread: Some(0.5),
            dem_runs_means_error_to_spread: Some(0.5),
            pattern: None,
            late: None,
            groups: true,
        }
    }

    #[test]
    fn the_standard_error_is_the_sample_deviation_over_the_root_of_the_count() {
        assert_eq!(MeanSe::of(&[]), None);
        assert_eq!(MeanSe::of(&[1.0]), None);
        // 1, 2, 3: mean 2, sample variance 1, SE 1/√3
        let m = MeanSe::of(&[1.0, 2.0, 3.0]).unwrap();
        assert_eq!(m.mean, 2.0);
        assert!((m.standard_error - 1.0 / 3f64.sqrt()).abs() < 1e-15);
        // two values: SE = |a − b| / 2
        let m = MeanSe::of(&[1.2, 1.6]).unwrap();
        assert!((m.mean - 1.4).abs() < 1e-15);
        assert!((m.standard_error - 0.2).abs() < 1e-15);
        // no spread, no error
        assert_eq!(MeanSe::of(&[0.5; 4]).unwrap().standard_error, 0.0);
    }

    /// (a): the mean median ratio against the DEM runs' mean plus two standard errors of
    /// the difference.
    #[test]
    fn the_mean_median_ratio_may_exceed_the_dem_runs_by_two_standard_errors_of_the_difference() {
        // extrapolation 1.0, 1.2 (mean 1.1, SE 0.1); DEM 0.9, 1.1 (mean 1, SE 0.1): the
        // bar is 1 + 2 √0.02 ≈ 1.283
        let pooled = Draws::pool(vec![draw(1.0, 0.3, 0.9, 0.3), draw(1.2, 0.3, 1.1, 0.3)]).unwrap();
        assert!((pooled.median_ratio.mean - 1.1).abs() < 1e-12);
        assert!((pooled.dem_runs_median_ratio.standard_error - 0.1).abs() < 1e-12);
        assert!((pooled.median_ratio_bar - (1.0 + 2.0 * 0.02f64.sqrt())).abs() < 1e-12);
        assert!(
            pooled.median_ratio_within && pooled.passes,
            "{}",
            pooled.text
        );
        assert!(
            pooled.text.starts_with(
                "passes as one more DEM run over the 2 draws: mean median ratio 1.10 ± 0.10 \
                 against 1.00 ± 0.10 for a DEM run judged in the same seat, within the bar of \
                 1.28"
            ),
            "{}",
            pooled.text
        );
        // the same spread, a mean 0.3 higher: above the bar
        let pooled = Draws::pool(vec![draw(1.3, 0.3, 0.9, 0.3), draw(1.5, 0.3, 1.1, 0.3)]).unwrap();
        assert!(!pooled.median_ratio_within && !pooled.passes);
        assert!(
            pooled.text.starts_with("does not pass")
                && pooled.text.contains("above the bar of 1.28"),
            "{}",
            pooled.text
        );
        // tight draws: a small excess is already a failure
        let pooled = Draws::pool(vec![
            draw(1.05, 0.3, 1.0, 0.3),
            draw(1.05, 0.3, 1.0, 0.3),
            draw(1.05, 0.3, 1.0, 0.3),
        ])
        .unwrap();
        assert_eq!(pooled.median_ratio_bar, 1.0);
        assert!(!pooled.passes);
    }

    /// (b): the outside share may exceed the DEM runs' by 10 points, not more.
    #[test]
    fn the_outside_share_may_exceed_the_dem_runs_by_ten_points() {
        let on_the_bar =
            Draws::pool(vec![draw(1.0, 0.4, 1.0, 0.3), draw(1.0, 0.4, 1.0, 0.3)]).unwrap();
        assert!(on_the_bar.outside_share_within, "{}", on_the_bar.text);
        assert!(on_the_bar.passes);
        assert!(
            on_the_bar.text.contains(
                "farther than the two farthest DEM runs at 40 ± 0 % of the compared t_k \
                 against 30 ± 0 % for a DEM run in the seat, within the bar of 40 % (theirs \
                 plus 10 points)"
            ),
            "{}",
            on_the_bar.text
        );
        let beyond = Draws::pool(vec![draw(1.0, 0.5, 1.0, 0.3), draw(1.0, 0.4, 1.0, 0.3)]).unwrap();
        assert!((beyond.outside_share.mean - 0.45).abs() < 1e-12);
        assert!(!beyond.outside_share_within && !beyond.passes);
        assert!(
            beyond.text.contains("above the bar of 40 %"),
            "{}",
            beyond.text
        );
    }

    /// (c): the group means within the DEM runs' spread in every draw; the failing draws
    /// are counted and the worst error given beside its draw's spread.
    #[test]
    fn the_means_must_be_within_the_spread_in_every_draw() {
        let mut draws = vec![
            draw(1.0, 0.3, 1.0, 0.3),
            draw(1.0, 0.3, 1.0, 0.3),
            draw(1.0, 0.3, 1.0, 0.3),
        ];
        let within = Draws::pool(draws.clone()).unwrap();
        assert!(within.means_within_spread && within.passes);
        assert!(
            within.text.ends_with(
                "group means within the DEM runs' spread at every compared t_k of every draw \
                 (the largest error 0.0100 K, in a draw whose DEM runs differ by up to \
                 0.0200 K); in a DEM run's seat, against the other runs, the extrapolation's \
                 group means stray beyond their spread in 0 ± 0 % of the seats against 0 ± 0 % \
                 for a DEM run (largest error 0.50 ± 0.00 times their spread against 0.50 ± \
                 0.00)"
            ),
            "{}",
            within.text
        );
        draws[1].means_error_max = 0.15;
        draws[1].means_spread_max = 0.03;
        draws[1].means_error_to_spread = Some(5.0);
        // one run of three in the seat beyond the others' spread in the first draw, two in
        // the second: 0.333, 0.667, 0 (mean 1/3, SE 0.192)
        draws[0].dem_runs_means_outside_share = 1.0 / 3.0;
        draws[1].dem_runs_means_outside_share = 2.0 / 3.0;
        draws[1].means_outside_share_in_seat = 1.0;
        let outside = Draws::pool(draws.clone()).unwrap();
        assert!((outside.means_outside_share_in_seat.mean - 1.0 / 3.0).abs() < 1e-15);
        assert!((outside.dem_runs_means_outside_share.mean - 1.0 / 3.0).abs() < 1e-15);
        assert!(
            outside
                .table()
                .contains("means beyond the others' spread (% seats)"),
            "{}",
            outside.table()
        );
        assert!(!outside.means_within_spread && !outside.passes);
        assert_eq!(outside.means_outside_spread_draws, 1);
        assert_eq!(
            (outside.means_error_max, outside.means_spread_beside),
            (0.15, 0.03)
        );
        assert!(
            outside.text.contains(
                "group means beyond the DEM runs' spread at some compared t_k in 1 of the 3 \
                 draws (the largest error 0.150 K, in a draw whose DEM runs differ by up to \
                 0.0300 K); in a DEM run's seat, against the other runs, the extrapolation's \
                 group means stray beyond their spread in 33 ± 33 % of the seats against 33 ± \
                 19 % for a DEM run (largest error 2.00 ± 1.50 times their spread against 0.50 \
                 ± 0.00)"
            ),
            "{}",
            outside.text
        );
        // a conserved bed mean: error and spread both rounding, which does not fail, and
        // whose ratio is not given
        for d in &mut draws {
            d.groups = false;
            d.means_error_max = 3e-14;
            d.means_spread_max = 1e-14;
            d.means_error_to_spread = None;
        }
        let conserved = Draws::pool(draws).unwrap();
        assert!(conserved.means_within_spread, "{}", conserved.text);
        assert_eq!(conserved.means_error_to_spread, None);
        assert!(!conserved.text.contains("times their spread"));
        assert!(
            conserved.text.contains("bed mean within"),
            "{}",
            conserved.text
        );
    }

    #[test]
    fn the_pattern_is_pooled_beside_a_dem_runs_where_every_draw_has_it_and_does_not_judge() {
        let heated = |median: f64, pattern: f64| Draw {
            pattern: Some(Beside {
                extrapolation: pattern,
                dem_run: 1.0,
            }),
            groups: false,
            ..draw(median, 0.3, 1.0, 0.3)
        };
        let draws = vec![heated(1.5, 0.98), heated(1.7, 1.0), heated(1.6, 1.02)];
        let pooled = Draws::pool(draws.clone()).unwrap();
        let pattern = pooled.pattern.unwrap().extrapolation;
        assert!((pattern.mean - 1.0).abs() < 1e-12, "{pattern:?}");
        assert!((pattern.standard_error - 0.02 / 3f64.sqrt()).abs() < 1e-12);
        // the field decides: far above the bar, whatever the pattern
        assert!(!pooled.passes);
        assert!(
            pooled.text.ends_with(
                "; each field less its own bed mean (where the heat is, apart from how fast \
                 the bed heats): mean median ratio 1.00 ± 0.01 against 1.00 ± 0.00 for a DEM run"
            ),
            "{}",
            pooled.text
        );
        assert!(pooled.table().contains("median ratio less the bed mean"));
        // a draw without it (an adiabatic bed's): nothing pooled, nothing said
        let mut mixed = draws;
        mixed[1].pattern = None;
        let pooled = Draws::pool(mixed).unwrap();
        assert_eq!(pooled.pattern, None);
        assert!(!pooled.text.contains("less its own bed mean"));
        assert!(!pooled.table().contains("less the bed mean"));
    }

    #[test]
    fn the_last_fifth_is_pooled_beside_a_dem_runs_where_every_draw_has_it_and_does_not_judge() {
        let growing = |late: f64| Draw {
            late: Some(Beside {
                extrapolation: late,
                dem_run: 1.0,
            }),
            ..draw(1.0, 0.3, 1.0, 0.3)
        };
        let draws = vec![growing(1.2), growing(1.4), growing(1.3)];
        let pooled = Draws::pool(draws.clone()).unwrap();
        let late = pooled.late.unwrap();
        assert!((late.extrapolation.mean - 1.3).abs() < 1e-12, "{late:?}");
        assert!((late.extrapolation.standard_error - 0.1 / 3f64.sqrt()).abs() < 1e-12);
        assert_eq!(late.dem_run.mean, 1.0);
        // the whole horizon decides: it passes, whatever its last fifth
        assert!(pooled.passes, "{}", pooled.text);
        assert!(
            pooled.text.ends_with(
                "; over the last fifth of each draw's compared t_k: mean median ratio 1.30 ± 0.06 \
                 against 1.00 ± 0.00 for a DEM run"
            ),
            "{}",
            pooled.text
        );
        assert!(pooled
            .table()
            .contains("median ratio, last fifth of the t_k"));
        // a draw whose horizon is too short to tell: nothing pooled, nothing said
        let mut mixed = draws;
        mixed[2].late = None;
        let pooled = Draws::pool(mixed).unwrap();
        assert_eq!(pooled.late, None);
        assert!(!pooled.text.contains("last fifth"));
        assert!(!pooled.table().contains("last fifth"));
    }

    #[test]
    fn one_draw_is_refused() {
        let err = Draws::pool(vec![draw(1.0, 0.3, 1.0, 0.3)]).unwrap_err();
        assert!(matches!(err, CompareError::TooFewDraws { draws: 1 }));
        assert!(err.to_string().contains("at least 2 draws"), "{err}");
    }

    #[test]
    fn means_are_written_with_the_decimals_of_their_standard_error() {
        let m = |mean, standard_error| MeanSe {
            mean,
            standard_error,
        };
        assert_eq!(plus_minus(m(1.4112, 0.1304)), "1.41 ± 0.13");
        assert_eq!(plus_minus(m(0.99812, 0.0012)), "0.998 ± 0.001");
        assert_eq!(plus_minus(m(1.0, 0.0)), "1.00 ± 0.00");
        assert_eq!(percent_plus_minus(m(0.952, 0.048)), "95 ± 5 %");
        assert_eq!(percent_plus_minus(m(0.3333, 0.0)), "33 ± 0 %");
        assert_eq!(percent_plus_minus(m(0.125, 0.004)), "12.5 ± 0.4 %");
    }
}
