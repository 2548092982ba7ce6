//! The seam of a drum periodic along its axis (y): positions wrapped into the section,
//! centre-to-centre vectors taken to the nearest image.

use crate::math::Vec3;

/// A section of a long kiln: whatever leaves one end face enters through the other, and
/// particles interact across the seam. `length` is the section's length along y, centred on
/// the origin (`y` in `[-length/2, length/2)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxialPeriod {
    pub length: f64,
}

impl AxialPeriod {
    /// `delta` (a centre-to-centre vector) with its y part taken to the nearest image.
    /// A section at least two of the largest diameters long has one image within contact
    /// reach of any other sphere, so the nearest is the one that can touch.
    #[inline(always)]
    pub fn nearest_image(self, mut delta: Vec3) -> Vec3 {
        delta[1] -= self.length * (delta[1] / self.length).round();
        delta
    }

    /// `y` moved by whole periods into `[-length/2, length/2)`.
    #[inline(always)]
    pub fn wrap(self, y: f64) -> f64 {
        let half = 0.5 * self.length;
        if (-half..half).contains(&y) {
            y
        } else {
            // beyond one period only in a blown-up run, which the inside check reports
            y - self.length * ((y + half) / self.length).floor()
        }
    }
}

/// `delta` to its nearest image in a periodic drum, unchanged in one with end caps.
#[inline(always)]
pub fn nearest_image(delta: Vec3, period: Option<AxialPeriod>) -> Vec3 {
    match period {
        Some(p) => p.nearest_image(delta),
        None => delta,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nearest_image_is_within_half_a_period() {
        let p = AxialPeriod { length: 0.02 };
        assert_eq!(
            p.nearest_image([0.1, 0.019, -0.2]),
            [0.1, 0.019 - 0.02, -0.2]
        );
        assert_eq!(p.nearest_image([0.0, -0.015, 0.0])[1], -0.015 + 0.02);
        assert_eq!(p.nearest_image([0.0, 0.004, 0.0])[1], 0.004);
        assert_eq!(nearest_image([0.0, 0.019, 0.0], None)[1], 0.019);
    }

    #[test]
    fn wrapping_keeps_a_position_in_the_section() {
        let p = AxialPeriod { length: 0.02 };
        assert_eq!(p.wrap(0.005), 0.005);
        assert!((p.wrap(0.011) - (0.011 - 0.02)).abs() < 1e-18);
        assert!((p.wrap(-0.0105) - (-0.0105 + 0.02)).abs() < 1e-18);
        assert_eq!(p.wrap(-0.01), -0.01);
        let y = p.wrap(0.01);
        assert!((-0.01..0.01).contains(&y), "{y}");
    }
}
