//! The integer objective shared by every solver: `cost(p, q) = round(|x1[p] − x0[q]| / unit)`.
//!
//! Both the dense oracle and the sparse solver minimise the sum of these integers, so
//! "the sparse total equals the dense total" is an exact statement, not a tolerance.
//! Integer costs also make the dual potentials integers, which is what lets the
//! certificate decide optimality without any floating-point slack in the comparison.

use super::PairingError;

/// Largest cost (in units) we accept for a single pair: a pair cost fits the candidate
/// graph's 32-bit edge costs ([`EdgeCost`]), is exact in an `f64`, and leaves ample
/// headroom in `i64` for sums and potentials.
pub(crate) const MAX_PAIR_UNITS: f64 = u32::MAX as f64;

/// A pair cost as the candidate graph stores it. 32 bits, not 64: the solver's inner
/// loops stream every edge of a row, and on the long kiln (3·10⁶ edges) 8 bytes per edge
/// instead of 12 keep the graph inside the 32 MiB last-level cache (docs/benchmarks.md).
pub(crate) type EdgeCost = u32;
/// Bound on `n · max_pair_cost`: potentials and path lengths of the assignment solver
/// are bounded by it, and it must stay far from `i64::MAX` (2^63).
const MAX_TOTAL_UNITS: f64 = (1u64 << 60) as f64;

/// Squared Euclidean distance between two points.
#[inline]
pub(crate) fn dist2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let (dx, dy, dz) = (a[0] - b[0], a[1] - b[1], a[2] - b[2]);
    dx * dx + dy * dy + dz * dz
}

/// Euclidean distance between two points (metres, or whatever the caller uses).
#[inline]
pub(crate) fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let dx = a[0] - b[0];
    let dy = a[1] - b[1];
    let dz = a[2] - b[2];
    (dx * dx + dy * dy + dz * dz).sqrt()
}

/// Distance across a section periodic along y with period `length`: the y part of `b − a`
/// taken to its nearest image, `Δy − length · round(Δy / length)` (the formula of the DEM
/// engine's seam), then the Euclidean norm. Every periodic cost is computed by this one
/// function, so the sparse solver and the dense oracle agree on every integer.
#[inline]
pub(crate) fn periodic_distance(a: &[f64; 3], b: &[f64; 3], length: f64) -> f64 {
    let dx = a[0] - b[0];
    let dy = nearest_image(a[1] - b[1], length);
    let dz = a[2] - b[2];
    (dx * dx + dy * dy + dz * dz).sqrt()
}

/// An axial difference `dy` taken to its nearest image across a seam of period `length`:
/// `dy − length · round(dy / length)`, the DEM engine's formula.
pub(crate) fn nearest_image(dy: f64, length: f64) -> f64 {
    dy - length * (dy / length).round()
}

/// `y` moved by whole periods into `[−length/2, length/2)` (unchanged when already there),
/// as the DEM engine wraps positions at its seam.
pub(crate) fn wrap(y: f64, length: f64) -> f64 {
    let half = 0.5 * length;
    if (-half..half).contains(&y) {
        y
    } else {
        y - length * ((y + half) / length).floor()
    }
}

/// The diagonal of the joint bounding box of the two snapshots: it bounds every pair
/// distance. Computed per axis first, so that a huge extent shows up as infinity rather
/// than silently wrapping (NaN if a coordinate is).
pub(crate) fn diagonal(x0: &[[f64; 3]], x1: &[[f64; 3]]) -> f64 {
    let (lo, hi) = super::order::bounds(x0, x1);
    distance(&lo, &hi)
}

/// The scaling from distances to integer costs, validated against the data extent.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CostScale {
    unit: f64,
    /// The period along y of a periodic section: distances are then taken to the nearest
    /// image ([`periodic_distance`]).
    period: Option<f64>,
}

impl CostScale {
    /// Checks that `unit` is usable for these snapshots: finite, positive, and not so
    /// small that the largest possible pair cost (the diagonal of the joint bounding box)
    /// overflows the headroom the solver needs.
    pub(crate) fn new(x0: &[[f64; 3]], x1: &[[f64; 3]], unit: f64) -> Result<Self, PairingError> {
        if !(unit.is_finite() && unit > 0.0) {
            return Err(PairingError::InvalidOption {
                name: "unit",
                reason: format!("must be finite and > 0, got {unit}"),
            });
        }
        let diag = diagonal(x0, x1);
        let units = diag / unit;
        let n = x0.len().max(1) as f64;
        if !(units.is_finite() && units <= MAX_PAIR_UNITS && units * n <= MAX_TOTAL_UNITS) {
            return Err(PairingError::CostOverflow {
                extent: diag,
                unit,
                units,
                max_units: MAX_PAIR_UNITS.min(MAX_TOTAL_UNITS / n),
            });
        }
        Ok(Self { unit, period: None })
    }

    /// The same scale with distances taken across a seam of period `period` along y
    /// (`None`: plain Euclidean distances). A periodic distance is at most the Euclidean one,
    /// so the bound checked in [`CostScale::new`] still holds.
    pub(crate) fn with_period(self, period: Option<f64>) -> Self {
        Self { period, ..self }
    }

    /// The period along y, if the section is periodic.
    #[inline]
    pub(crate) fn period(&self) -> Option<f64> {
        self.period
    }

    /// The distance the costs are made of: Euclidean, or periodic along y.
    #[inline]
    pub(crate) fn distance(&self, a: &[f64; 3], b: &[f64; 3]) -> f64 {
        match self.period {
            None => distance(a, b),
            Some(length) => periodic_distance(a, b, length),
        }
    }

    /// The length of one integer cost unit.
    #[inline]
    pub(crate) fn unit(&self) -> f64 {
        self.unit
    }

    /// Integer cost of a distance: `round(d / unit)`, halves rounded away from zero.
    /// Hence `cost >= d / unit − 0.5`, the inequality the certificate relies on.
    ///
    /// Written with a truncation instead of `f64::round`, which the baseline x86-64 target
    /// compiles to a call into libm (1 % of the long kiln's pairing in `perf`). The same
    /// integer: `x = d / unit` is finite, at least 0 and far below 2⁵³ (`CostScale::new`
    /// bounds it), so `x − trunc(x)` is exact and compares with 0.5 exactly.
    #[inline]
    pub(crate) fn cost_of_distance(&self, d: f64) -> i64 {
        let x = d / self.unit;
        let whole = x as i64;
        whole + i64::from(x - whole as f64 >= 0.5)
    }

    /// Integer cost of the pair (t1 point `a`, t0 point `b`).
    #[inline]
    pub(crate) fn cost(&self, a: &[f64; 3], b: &[f64; 3]) -> i64 {
        self.cost_of_distance(self.distance(a, b))
    }

    /// [`CostScale::cost`] as the graph stores it: every pair distance is at most the
    /// diagonal checked in [`CostScale::new`], so the cost fits.
    #[inline]
    pub(crate) fn edge_cost(&self, a: &[f64; 3], b: &[f64; 3]) -> EdgeCost {
        let c = self.cost(a, b);
        debug_assert!((0..=i64::from(EdgeCost::MAX)).contains(&c));
        c as EdgeCost
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_is_half_away_from_zero() {
        let s = CostScale::new(&[[0.0; 3]], &[[10.0, 0.0, 0.0]], 1.0).unwrap();
        assert_eq!(s.cost_of_distance(2.5), 3);
        assert_eq!(s.cost_of_distance(2.4999), 2);
        assert_eq!(s.cost(&[0.0; 3], &[3.0, 4.0, 0.0]), 5);
        // The largest double below 0.5 (where `floor(x + 0.5)` would give 1), halves and
        // their neighbours, and large costs: the same as `f64::round`.
        let below_half = 0.5f64.next_down();
        assert_eq!(s.cost_of_distance(below_half), 0);
        for x in [0.0f64, 0.5, 1.5, 7.5, 1e9 + 0.5, 4.0e9 - 0.5, 123_456.789] {
            for y in [x, x.next_up(), x.next_down().max(0.0)] {
                assert_eq!(s.cost_of_distance(y), y.round() as i64, "{y}");
            }
        }
    }

    #[test]
    fn periodic_distances_take_the_nearest_image() {
        let s = CostScale::new(&[[0.0; 3]], &[[10.0, 0.0, 0.0]], 1.0)
            .unwrap()
            .with_period(Some(10.0));
        assert_eq!(s.distance(&[0.0, 4.5, 0.0], &[0.0, -4.5, 0.0]), 1.0);
        assert_eq!(s.distance(&[3.0, 1.0, 0.0], &[0.0, 5.0, 0.0]), 5.0);
        assert_eq!(s.cost(&[0.0, -4.0, 0.0], &[0.0, 4.0, 0.0]), 2);
        assert_eq!(wrap(5.0, 10.0), -5.0);
        assert_eq!(wrap(-5.0, 10.0), -5.0);
        assert_eq!(wrap(2.5, 10.0), 2.5);
        assert_eq!(wrap(-7.0, 10.0), 3.0);
    }

    #[test]
    fn rejects_units_that_overflow() {
        let e = CostScale::new(&[[0.0; 3]], &[[1.0e9, 0.0, 0.0]], 1e-9).unwrap_err();
        assert!(matches!(e, PairingError::CostOverflow { .. }), "{e}");
        let e = CostScale::new(&[[0.0; 3]], &[[f64::MAX, 0.0, 0.0]], 1.0).unwrap_err();
        assert!(matches!(e, PairingError::CostOverflow { .. }), "{e}");
        let e = CostScale::new(&[[0.0; 3]], &[[0.0; 3]], 0.0).unwrap_err();
        assert!(
            matches!(e, PairingError::InvalidOption { name: "unit", .. }),
            "{e}"
        );
    }
}
