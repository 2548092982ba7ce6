//! The cost table in the form of the paper's Table 6: complete DEM against the extrapolated
//! DEM for a number of periods, from the costs measured by `record` and `extrapolate`.

use tdex_format::{ExtrapolationCosts, RecordingCosts};

/// Periods of the paper's Table 6.
pub const TABLE_PERIODS: u32 = 100;

/// Where the DEM cost of one period was measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DemPeriodSource {
    /// `seconds_reference / periods`: the DEM run past the recorded periods (`t1`, or `tP`
    /// with several) without the recorder; `periods` is the number it ran.
    Reference { periods: u32 },
    /// `seconds_period − seconds_recorder`: the recorded period without the recorder's share.
    RecordedPeriod,
}

/// The measured costs, in wall-clock seconds.
#[derive(Debug, Clone, PartialEq)]
pub struct CostTable {
    /// DEM to `t0` plus the recorded period without the recorder (both columns).
    pub until_t1: f64,
    /// Pairing of the `t0` and `t1` snapshots (extrapolated column only).
    pub pairing: f64,
    /// Whether the extrapolation reused a stored pairing (`pairing` is then its first cost).
    pub pairing_reused: bool,
    /// Recording overhead (extrapolated column only): the recorder's time (the collision
    /// file) and, with several recorded periods, the DEM of periods 2…P, which the
    /// extrapolation pays for up front to have their tables.
    pub collision_file: f64,
    /// Reading the collision table into memory once, before the first replayed period
    /// (extrapolated column only; 0 for a streamed replay, which reads it every period
    /// within `tau_extra`). The paper's table has no such row; at 80 000 particles it is
    /// seconds, more than a replayed period, so it is counted.
    pub read_table: f64,
    /// DEM seconds per period and where they were measured.
    pub tau_dem: f64,
    pub tau_dem_source: DemPeriodSource,
    /// Extrapolation seconds per period (replay).
    pub tau_extra: f64,
    /// Worker threads of the recording run.
    pub threads: usize,
    /// Its engine's vector instructions (`avx512`, `avx2`, `scalar`; empty if not recorded).
    pub vector_instructions: String,
}

/// `", AVX2 vectors"` and the like after a thread count, or nothing for a recording that
/// does not say.
pub fn vectors_clause(vector_instructions: &str) -> String {
    use recorder::simd::Simd;
    match (vector_instructions, Simd::from_name(vector_instructions)) {
        ("", _) => String::new(),
        (_, Some(simd)) => format!(", {}", simd.vectors()),
        // a name a later tdex may write: shown as it is
        (other, None) => format!(", {other} vectors"),
    }
}

impl CostTable {
    /// The table from a recording's and an extrapolation's costs. `pairing_seconds` is the
    /// pairing summary's `seconds` (the cost of computing it, also when it was reused); when
    /// absent the extrapolation's own `seconds_pairing` is used. `recorded_periods` is the
    /// recording's P: its reference stage ran the `K + 1 − P` periods after `tP`.
    /// `periods_used` is the P' ≤ P the extrapolation replayed (`--recorded-periods`): only
    /// those periods are charged to it.
    pub fn new(
        recording: &RecordingCosts,
        reference_periods: u32,
        recorded_periods: u32,
        periods_used: u32,
        extrapolation: &ExtrapolationCosts,
        pairing_seconds: Option<f64>,
    ) -> Self {
        let recorded_periods = recorded_periods.max(1);
        let periods_used = periods_used.clamp(1, recorded_periods);
        // the DEM's share of one recorded period (the recorder ran beside it)
        let dem_period =
            (recording.seconds_period - recording.seconds_recorder) / recorded_periods as f64;
        let after_recorded =
            tdex_format::periods_after_recorded(recorded_periods, reference_periods);
        let (tau_dem, tau_dem_source) = if after_recorded > 0 && recording.seconds_reference > 0.0 {
            (
                recording.seconds_reference / after_recorded as f64,
                DemPeriodSource::Reference {
                    periods: after_recorded,
                },
            )
        } else {
            (dem_period, DemPeriodSource::RecordedPeriod)
        };
        CostTable {
            until_t1: recording.seconds_to_t0 + dem_period,
            pairing: pairing_seconds
                .filter(|s| s.is_finite() && *s >= 0.0)
                .unwrap_or(extrapolation.seconds_pairing),
            pairing_reused: extrapolation.pairing_reused,
            collision_file: used_seconds(recording, recorded_periods, periods_used) - dem_period,
            read_table: extrapolation.seconds_read_table,
            tau_dem,
            tau_dem_source,
            tau_extra: extrapolation.seconds_per_period,
            threads: recording.threads,
            vector_instructions: recording.vector_instructions.clone(),
        }
    }

    /// Seconds of the complete DEM to reach `t1 + m τ`.
    pub fn total_dem(&self, m: f64) -> f64 {
        self.until_t1 + m * self.tau_dem
    }

    /// Seconds of the extrapolated DEM to reach `t1 + m τ`: the DEM to `t1`, the pairing,
    /// the collision file, reading the table and `m` replayed periods.
    pub fn total_extrapolated(&self, m: f64) -> f64 {
        self.until_t1 + self.one_off() + m * self.tau_extra
    }

    /// What the extrapolation costs before its first period, beyond the DEM to `t1`.
    fn one_off(&self) -> f64 {
        self.pairing + self.collision_file + self.read_table
    }

    /// Speedup of reaching `t1 + m τ` (None if the extrapolation cost nothing measurable).
    pub fn speedup(&self, m: f64) -> Option<f64> {
        ratio(self.total_dem(m), self.total_extrapolated(m))
    }

    /// Speedup of one period.
    pub fn speedup_per_period(&self) -> Option<f64> {
        ratio(self.tau_dem, self.tau_extra)
    }

    /// Periods after `t1` from which the extrapolation is faster than the complete DEM
    /// (None if it never is).
    pub fn break_even_periods(&self) -> Option<f64> {
        let gain = self.tau_dem - self.tau_extra;
        (gain > 0.0).then(|| self.one_off() / gain)
    }
}

/// Wall seconds of the first `used` of the recording's `recorded` periods, DEM and recorder:
/// all of `seconds_period` when every period is used, else the periods' own times (or an
/// even share when the recording kept none).
fn used_seconds(recording: &RecordingCosts, recorded: u32, used: u32) -> f64 {
    if used >= recorded {
        return recording.seconds_period;
    }
    match recording.seconds_each_period.get(..used as usize) {
        Some(each) if recording.seconds_each_period.len() == recorded as usize => each.iter().sum(),
        _ => recording.seconds_period * used as f64 / recorded as f64,
    }
}

fn ratio(a: f64, b: f64) -> Option<f64> {
    (b > 0.0 && a.is_finite() && b.is_finite()).then(|| a / b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's Table 6 (80 000 particles, one thread): 8580 s to t1, pairing 551 s,
    /// collision file 7619 s, 3900 s per τ of DEM and 6 s per τ extrapolated.
    #[test]
    fn the_papers_table_6_is_reproduced() {
        let recording = RecordingCosts {
            seconds_to_t0: 8580.0 - 3900.0,
            seconds_period: 3900.0 + 7619.0,
            seconds_reference: 0.0,
            seconds_recorder: 7619.0,
            seconds_twins: 0.0,
            seconds_each_period: Vec::new(),
            stage_seconds: Default::default(),
            threads: 1,
            vector_instructions: String::new(),
        };
        let extrapolation = ExtrapolationCosts {
            seconds_pairing: 0.0,
            pairing_reused: true,
            seconds_read_table: 0.0,
            seconds_replay: 600.0,
            seconds_per_period: 6.0,
            rows_per_second: 0.0,
            rows: 0,
        };
        let t = CostTable::new(&recording, 0, 1, 1, &extrapolation, Some(551.0));
        assert_eq!(t.until_t1, 8580.0);
        assert_eq!(t.tau_dem_source, DemPeriodSource::RecordedPeriod);
        assert_eq!(t.total_dem(100.0), 398_580.0);
        assert_eq!(t.total_extrapolated(100.0), 17_350.0);
        assert!((t.speedup(100.0).unwrap() - 398_580.0 / 17_350.0).abs() < 1e-12);
        assert_eq!(t.speedup_per_period(), Some(650.0));

        // A reference run gives the DEM period; a missing pairing summary falls back.
        let with_reference = RecordingCosts {
            seconds_reference: 3.0 * 4000.0,
            ..recording
        };
        let t = CostTable::new(&with_reference, 3, 1, 1, &extrapolation, None);
        assert_eq!(t.tau_dem, 4000.0);
        assert_eq!(t.tau_dem_source, DemPeriodSource::Reference { periods: 3 });
        assert_eq!(t.pairing, 0.0);
        assert_eq!(t.until_t1, 8580.0);
    }

    /// Four recorded periods: the DEM to t1 is one of them, the other three and the
    /// recorder are the recording's overhead, and the reference ran the periods after t4.
    #[test]
    fn several_recorded_periods_charge_their_dem_to_the_recording() {
        let recording = RecordingCosts {
            seconds_to_t0: 100.0,
            seconds_period: 4.0 * 50.0 + 20.0,
            seconds_reference: 5.0 * 48.0,
            seconds_recorder: 20.0,
            seconds_twins: 0.0,
            seconds_each_period: vec![55.0; 4],
            stage_seconds: Default::default(),
            threads: 1,
            vector_instructions: String::new(),
        };
        let extrapolation = ExtrapolationCosts {
            seconds_pairing: 2.0,
            pairing_reused: false,
            seconds_read_table: 0.0,
            seconds_replay: 8.0,
            seconds_per_period: 1.0,
            rows_per_second: 0.0,
            rows: 0,
        };
        // K = 8 reference periods: t2…t9, of which t5…t9 ran after the recorded t0…t4
        let t = CostTable::new(&recording, 8, 4, 4, &extrapolation, None);
        assert_eq!(t.until_t1, 150.0);
        assert_eq!(t.collision_file, 170.0);
        assert_eq!(t.tau_dem, 48.0);
        assert_eq!(t.tau_dem_source, DemPeriodSource::Reference { periods: 5 });
        // the reference inside the recorded stretch: the recorded periods give the DEM's τ
        let t = CostTable::new(&recording, 3, 4, 4, &extrapolation, None);
        assert_eq!(t.tau_dem, 50.0);
        assert_eq!(t.tau_dem_source, DemPeriodSource::RecordedPeriod);
        // an extrapolation that replays only the first two: the DEM to t1 as before, the
        // second period (55 s) less the mean DEM share (50 s) counted in it, plus t1's 5 s
        let t = CostTable::new(&recording, 8, 4, 2, &extrapolation, None);
        assert_eq!(t.until_t1, 150.0);
        assert_eq!(t.collision_file, 2.0 * 55.0 - 50.0);
        assert_eq!(t.tau_dem, 48.0);
    }

    /// Reading the table into memory is paid once, before the first replayed period.
    #[test]
    fn reading_the_table_is_a_one_off_cost_of_the_extrapolation() {
        let recording = RecordingCosts {
            seconds_to_t0: 100.0,
            seconds_period: 60.0,
            seconds_reference: 2.0 * 50.0,
            seconds_recorder: 10.0,
            seconds_twins: 0.0,
            seconds_each_period: Vec::new(),
            stage_seconds: Default::default(),
            threads: 2,
            vector_instructions: String::new(),
        };
        let extrapolation = ExtrapolationCosts {
            seconds_pairing: 0.0,
            pairing_reused: true,
            seconds_read_table: 9.0,
            seconds_replay: 1.0,
            seconds_per_period: 0.25,
            rows_per_second: 0.0,
            rows: 0,
        };
        let t = CostTable::new(&recording, 2, 1, 1, &extrapolation, Some(1.0));
        assert_eq!(t.read_table, 9.0);
        // 150 to t1, then 1 + 10 + 9 once and 0.25 per period
        assert_eq!(t.total_extrapolated(100.0), 150.0 + 20.0 + 25.0);
        assert_eq!(t.break_even_periods(), Some(20.0 / 49.75));
    }
}
