//! Analytic walls: the rotating cylinder mantle of the drum and its flat end caps.

use crate::case::{Drum, EndCaps};
use crate::math::*;

/// A wall surface. The drum axis is `y` through the origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Wall {
    /// Inside of a cylinder of `radius` about the y axis (the drum mantle).
    Mantle { radius: f64 },
    /// The plane through `point` with unit `normal` pointing into the free side.
    Plane { point: Vec3, normal: Vec3 },
}

/// Whether a wall moves with the drum rotation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WallMotion {
    Rotating,
    Fixed,
}

/// A sphere touching a wall.
#[derive(Debug, Clone, Copy)]
pub struct WallContact {
    pub overlap: f64,
    /// Unit normal from the wall towards the sphere centre.
    pub normal: Vec3,
    /// Velocity of the wall surface at the contact point.
    pub surface_velocity: Vec3,
}

/// The walls of a case, their motion, and which of them conducts heat.
#[derive(Debug, Clone, PartialEq)]
pub struct WallSet {
    pub walls: Vec<(Wall, WallMotion)>,
    /// Drum angular velocity about +y (rad/s); counter-clockwise seen from +y (z → x).
    pub angular_velocity: f64,
    /// Temperature of the heated mantle; `None` = adiabatic walls.
    pub mantle_temperature: Option<f64>,
}

impl WallSet {
    /// A drum of `radius` and `length` with its two end caps (at rest until spun up).
    pub fn drum(radius: f64, length: f64, end_caps: WallMotion) -> Self {
        let half = 0.5 * length;
        Self {
            walls: vec![
                (Wall::Mantle { radius }, WallMotion::Rotating),
                (
                    Wall::Plane {
                        point: [0.0, -half, 0.0],
                        normal: [0.0, 1.0, 0.0],
                    },
                    end_caps,
                ),
                (
                    Wall::Plane {
                        point: [0.0, half, 0.0],
                        normal: [0.0, -1.0, 0.0],
                    },
                    end_caps,
                ),
            ],
            angular_velocity: 0.0,
            mantle_temperature: None,
        }
    }

    /// The walls of a case's drum: the mantle and its end caps, or the mantle alone in a
    /// periodic section.
    pub fn of_drum(drum: &Drum) -> Self {
        let caps = match drum.end_caps {
            EndCaps::Rotating => WallMotion::Rotating,
            EndCaps::Fixed => WallMotion::Fixed,
            EndCaps::Periodic => {
                return Self {
                    walls: vec![(
                        Wall::Mantle {
                            radius: drum.radius,
                        },
                        WallMotion::Rotating,
                    )],
                    angular_velocity: 0.0,
                    mantle_temperature: None,
                }
            }
        };
        Self::drum(drum.radius, drum.length, caps)
    }

    pub fn len(&self) -> usize {
        self.walls.len()
    }

    pub fn is_empty(&self) -> bool {
        self.walls.is_empty()
    }

    /// The contact of a sphere with wall `w`, if it touches.
    #[inline(always)]
    pub fn contact(&self, w: usize, pos: Vec3, radius: f64) -> Option<WallContact> {
        let (wall, motion) = self.walls[w];
        let (overlap, normal, point) = match wall {
            Wall::Mantle { radius: rd } => {
                let rho = (pos[0] * pos[0] + pos[2] * pos[2]).sqrt();
                let overlap = rho + radius - rd;
                if overlap <= 0.0 || rho == 0.0 {
                    return None;
                }
                let inward = [-pos[0] / rho, 0.0, -pos[2] / rho];
                (overlap, inward, [-inward[0] * rd, pos[1], -inward[2] * rd])
            }
            Wall::Plane { point, normal } => {
                let gap = dot(sub(pos, point), normal);
                let overlap = radius - gap;
                if overlap <= 0.0 {
                    return None;
                }
                (overlap, normal, sub(pos, scale(normal, gap)))
            }
        };
        let surface_velocity = match motion {
            WallMotion::Rotating => cross([0.0, self.angular_velocity, 0.0], point),
            WallMotion::Fixed => [0.0; 3],
        };
        Some(WallContact {
            overlap,
            normal,
            surface_velocity,
        })
    }

    /// Distance from the surface of a sphere to wall `w` (negative when they overlap): the
    /// broad-phase test that lists the sphere as a candidate of the wall.
    #[inline(always)]
    pub fn gap(&self, w: usize, pos: Vec3, radius: f64) -> f64 {
        match self.walls[w].0 {
            Wall::Mantle { radius: rd } => rd - (pos[0] * pos[0] + pos[2] * pos[2]).sqrt() - radius,
            Wall::Plane { point, normal } => dot(sub(pos, point), normal) - radius,
        }
    }

    /// Temperature of wall `w` if it conducts (only the mantle can be heated).
    #[inline(always)]
    pub fn temperature(&self, w: usize) -> Option<f64> {
        match self.walls[w].0 {
            Wall::Mantle { .. } => self.mantle_temperature,
            Wall::Plane { .. } => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mantle_overlap_normal_and_velocity() {
        let mut walls = WallSet::drum(0.1, 0.2, WallMotion::Rotating);
        walls.angular_velocity = 2.0;
        // sphere at the bottom, pushed 1 mm into the mantle
        let c = walls.contact(0, [0.0, 0.0, -0.096], 0.005).unwrap();
        assert!((c.overlap - 0.001).abs() < 1e-12);
        assert_eq!(c.normal, [0.0, 0.0, 1.0]);
        // ω × p with p = (0, 0, −R): the bottom moves towards −x (z → x rotation)
        assert!((c.surface_velocity[0] + 0.2).abs() < 1e-12);
        assert!(walls.contact(0, [0.0, 0.0, -0.094], 0.005).is_none());
    }

    #[test]
    fn end_caps_face_inwards() {
        let walls = WallSet::drum(0.1, 0.2, WallMotion::Fixed);
        let c = walls.contact(2, [0.0, 0.098, 0.0], 0.005).unwrap();
        assert!((c.overlap - 0.003).abs() < 1e-12);
        assert_eq!(c.normal, [0.0, -1.0, 0.0]);
        assert_eq!(c.surface_velocity, [0.0; 3]);
        assert!(walls.contact(1, [0.0, 0.098, 0.0], 0.005).is_none());
    }
}
