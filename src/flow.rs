//! The bed's flow at one instant (docs/theory.md, "Flow regimes of the drum"): Froude number
//! and Mellmann's regime, the dynamic angle of repose (a line fitted to the free surface),
//! the active-layer thickness and the motion relative to solid-body rotation. Pure functions
//! of the case and one snapshot; the drum turns about +y (z → x), gravity is −z.

use recorder::simulation::GRAVITY;
use recorder::Case;
use serde::Serialize;
use tdex_format::Snapshot;

/// Default `--min-relative`: below this mean speed relative to solid-body rotation (as a
/// fraction of the wall speed ωR) the bed is taken to move with the drum.
pub const MIN_RELATIVE: f64 = 0.01;
/// The active layer ends where the downhill relative velocity falls below this fraction of
/// its maximum over the depth bins.
pub const ACTIVE_FRACTION: f64 = 0.1;
/// Fraction of the bed's width (across the drum, centred) whose top particles define the
/// free surface; the rest, near the mantle, is left out.
pub const SURFACE_KEEP: f64 = 0.8;

/// Froude number `ω² R / g` of the case's drum.
pub fn froude(case: &Case) -> f64 {
    let w = case.angular_velocity();
    w * w * case.drum.radius / GRAVITY
}

/// Mellmann's (2001) forms of transverse motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Regime {
    Slipping,
    Slumping,
    Rolling,
    Cascading,
    Cataracting,
    Centrifuging,
}

impl Regime {
    pub fn name(self) -> &'static str {
        match self {
            Regime::Slipping => "slipping",
            Regime::Slumping => "slumping",
            Regime::Rolling => "rolling",
            Regime::Cascading => "cascading",
            Regime::Cataracting => "cataracting",
            Regime::Centrifuging => "centrifuging",
        }
    }
}

/// Mellmann's Froude ranges (open intervals; centrifuging from 1 on). They overlap: which
/// regime sets in there also depends on the filling degree and the wall friction.
pub const MELLMANN_RANGES: [(Regime, f64, f64); 6] = [
    (Regime::Slipping, 0.0, 1e-4),
    (Regime::Slumping, 1e-5, 1e-3),
    (Regime::Rolling, 1e-4, 1e-2),
    (Regime::Cascading, 1e-3, 1e-1),
    (Regime::Cataracting, 1e-1, 1.0),
    (Regime::Centrifuging, 1.0, f64::INFINITY),
];

/// Every regime whose Mellmann range holds `fr`.
pub fn candidate_regimes(fr: f64) -> Vec<Regime> {
    MELLMANN_RANGES
        .iter()
        .filter(|(r, lo, hi)| {
            if *r == Regime::Centrifuging {
                fr >= *lo
            } else {
                fr > *lo && fr < *hi
            }
        })
        .map(|(r, _, _)| *r)
        .collect()
}

/// One regime per Froude number: where two ranges overlap, the boundary is the geometric
/// middle of the overlap (3.16e-5, 3.16e-4, 3.16e-3); 0.1 and 1 where they only touch.
pub fn regime(fr: f64) -> Regime {
    let mid = |a: f64, b: f64| (a * b).sqrt();
    if fr >= 1.0 {
        Regime::Centrifuging
    } else if fr >= 0.1 {
        Regime::Cataracting
    } else if fr >= mid(1e-3, 1e-2) {
        Regime::Cascading
    } else if fr >= mid(1e-4, 1e-3) {
        Regime::Rolling
    } else if fr >= mid(1e-5, 1e-4) {
        Regime::Slumping
    } else {
        Regime::Slipping
    }
}

/// Least-squares line `z = a + b x` through `points`; None with fewer than two distinct x.
pub fn fit_line(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let n = points.len() as f64;
    if points.len() < 2 {
        return None;
    }
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let mz = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxz: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - mz)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let b = sxz / sxx;
    Some((mz - b * mx, b))
}

/// Angle (degrees, 0..90) of a line of slope `b` to the horizontal.
pub fn angle_degrees(b: f64) -> f64 {
    b.abs().atan().to_degrees()
}

/// The free surface seen across the drum: the x axis (across the drum, perpendicular to its
/// axis y) cut into bins of `bin` m; in each bin the highest particle top `z + r`, at the
/// bin's particle x. Only bins whose centre lies in the middle `keep` of the bed's x extent
/// are kept (the surface bends up at the mantle).
pub fn surface_points(pos: &[[f64; 3]], radius: &[f64], bin: f64, keep: f64) -> Vec<(f64, f64)> {
    if pos.is_empty() || bin.is_nan() || bin <= 0.0 {
        return Vec::new();
    }
    let (lo, hi) = pos
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p[0]), h.max(p[0]))
        });
    let bins = (((hi - lo) / bin).floor() as usize + 1).max(1);
    let mut top: Vec<Option<(f64, f64)>> = vec![None; bins];
    for (p, r) in pos.iter().zip(radius) {
        let b = (((p[0] - lo) / bin) as usize).min(bins - 1);
        let z = p[2] + r;
        if top[b].is_none_or(|(_, zt)| z > zt) {
            top[b] = Some((p[0], z));
        }
    }
    let (centre, half) = (0.5 * (lo + hi), 0.5 * keep * (hi - lo));
    top.iter()
        .enumerate()
        .filter(|(b, _)| (lo + (*b as f64 + 0.5) * bin - centre).abs() <= half + 1e-12)
        .filter_map(|(_, t)| *t)
        .collect()
}

/// Velocity of solid-body rotation at `p` for angular velocity `w` about +y (z → x).
pub fn solid_body(w: f64, p: [f64; 3]) -> [f64; 3] {
    [w * p[2], 0.0, -w * p[0]]
}

/// Mean speed relative to solid-body rotation over the bed, as a fraction of the wall speed
/// `ω R` (0: the bed turns with the drum).
pub fn relative_speed(snapshot: &Snapshot, w: f64, drum_radius: f64) -> f64 {
    if snapshot.is_empty() || w * drum_radius <= 0.0 {
        return 0.0;
    }
    let sum: f64 = snapshot
        .pos
        .iter()
        .zip(&snapshot.vel)
        .map(|(p, v)| {
            let s = solid_body(w, *p);
            ((v[0] - s[0]).powi(2) + (v[1] - s[1]).powi(2) + (v[2] - s[2]).powi(2)).sqrt()
        })
        .sum();
    sum / snapshot.len() as f64 / (w * drum_radius)
}

/// The active layer measured under a fitted surface `z = a + b x`.
#[derive(Debug, Clone, Serialize)]
pub struct ActiveLayer {
    /// Thickness (m): depth where the downhill velocity relative to solid-body rotation
    /// first falls below `ACTIVE_FRACTION` of its maximum, below the bin of the maximum.
    pub thickness: f64,
    /// Whether the velocity stayed above the threshold down to the deepest bin (the whole
    /// depth measured flows; `thickness` is then that depth).
    pub whole_depth: bool,
    /// The profile: bin top depth (m), bin mean downhill relative velocity (m/s), particles.
    pub profile: Vec<(f64, f64, usize)>,
}

/// The active layer under the surface line `(a, b)` in the central band of the bed (the
/// middle half of the surface points' x range), with depth bins of `bin` m.
pub fn active_layer(
    pos: &[[f64; 3]],
    vel: &[[f64; 3]],
    w: f64,
    line: (f64, f64),
    x_range: (f64, f64),
    bin: f64,
) -> Option<ActiveLayer> {
    let (a, b) = line;
    let norm = (1.0 + b * b).sqrt();
    // downhill unit tangent in the x-z plane
    let (mut tx, mut tz) = (1.0 / norm, b / norm);
    if tz > 0.0 {
        (tx, tz) = (-tx, -tz);
    }
    let (centre, half) = (
        0.5 * (x_range.0 + x_range.1),
        0.25 * (x_range.1 - x_range.0),
    );
    let mut sums: Vec<(f64, usize)> = Vec::new();
    for (p, v) in pos.iter().zip(vel) {
        if (p[0] - centre).abs() > half {
            continue;
        }
        let depth = ((a + b * p[0] - p[2]) / norm).max(0.0);
        let s = solid_body(w, *p);
        let u = (v[0] - s[0]) * tx + (v[2] - s[2]) * tz;
        let k = (depth / bin) as usize;
        if sums.len() <= k {
            sums.resize(k + 1, (0.0, 0));
        }
        sums[k].0 += u;
        sums[k].1 += 1;
    }
    let profile: Vec<(f64, f64, usize)> = sums
        .iter()
        .enumerate()
        .filter(|(_, (_, c))| *c > 0)
        .map(|(k, (s, c))| (k as f64 * bin, s / *c as f64, *c))
        .collect();
    let (top, max) = profile
        .iter()
        .enumerate()
        .max_by(|x, y| x.1 .1.total_cmp(&y.1 .1))
        .map(|(i, p)| (i, p.1))?;
    if max.is_nan() || max <= 0.0 {
        return None;
    }
    let end = profile[top..]
        .iter()
        .find(|p| p.1 < ACTIVE_FRACTION * max)
        .map(|p| p.0);
    let deepest = profile.last().map_or(0.0, |p| p.0 + bin);
    Some(ActiveLayer {
        thickness: end.unwrap_or(deepest),
        whole_depth: end.is_none(),
        profile,
    })
}

/// What one snapshot says about the flow.
#[derive(Debug, Clone, Serialize)]
pub struct FlowMeasure {
    /// Dynamic angle of repose (degrees) and the fitted surface `z = a + b x`.
    pub angle_degrees: Option<f64>,
    pub surface_line: Option<(f64, f64)>,
    pub surface_points: usize,
    pub active_layer: Option<ActiveLayer>,
    /// Mean speed relative to solid-body rotation / (ωR).
    pub relative_speed: f64,
}

/// Measures the flow in `snapshot` of a drum of `radius` turning at `w`; bins one mean
/// particle diameter wide.
pub fn measure(snapshot: &Snapshot, w: f64, radius: f64) -> FlowMeasure {
    let d = snapshot.mean_diameter();
    let points = surface_points(&snapshot.pos, &snapshot.radius, d, SURFACE_KEEP);
    let line = fit_line(&points);
    let x_range = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p.0), h.max(p.0))
        });
    let active = line.and_then(|l| active_layer(&snapshot.pos, &snapshot.vel, w, l, x_range, d));
    FlowMeasure {
        angle_degrees: line.map(|l| angle_degrees(l.1)),
        surface_line: line,
        surface_points: points.len(),
        active_layer: active,
        relative_speed: relative_speed(snapshot, w, radius),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn froude_numbers_of_the_papers_speeds_give_its_regimes() {
        // the small drum (R = 0.1 m): 15 s/rev rolling, 5 s/rev cascading, 0.1 s/rev
        // centrifuging (Haydar Figure 11)
        let fr = |t: f64| (2.0 * std::f64::consts::PI / t).powi(2) * 0.1 / GRAVITY;
        assert!((fr(15.0) - 1.789e-3).abs() < 1e-6, "{}", fr(15.0));
        assert_eq!(regime(fr(15.0)), Regime::Rolling);
        assert_eq!(regime(fr(5.0)), Regime::Cascading);
        assert_eq!(regime(fr(0.1)), Regime::Centrifuging);
        assert!((fr(0.1) - 40.24).abs() < 0.01);
    }

    #[test]
    fn regimes_follow_mellmanns_ranges() {
        assert_eq!(regime(1e-6), Regime::Slipping);
        assert_eq!(regime(1e-4), Regime::Slumping);
        assert_eq!(regime(1e-3), Regime::Rolling);
        assert_eq!(regime(0.05), Regime::Cascading);
        assert_eq!(regime(0.1), Regime::Cataracting);
        assert_eq!(regime(0.99), Regime::Cataracting);
        assert_eq!(regime(1.0), Regime::Centrifuging);
        assert_eq!(
            candidate_regimes(5e-3),
            vec![Regime::Rolling, Regime::Cascading]
        );
        assert_eq!(candidate_regimes(2.0), vec![Regime::Centrifuging]);
        assert_eq!(candidate_regimes(0.5), vec![Regime::Cataracting]);
        // every Froude number has its regime among the candidates
        for e in -60..10 {
            let fr = 10f64.powf(e as f64 / 10.0) * 1.0001;
            assert!(candidate_regimes(fr).contains(&regime(fr)), "Fr = {fr}");
        }
    }

    #[test]
    fn a_line_through_exact_points_is_recovered() {
        let pts: Vec<(f64, f64)> = (0..10)
            .map(|i| {
                let x = i as f64 * 0.01 - 0.05;
                (x, 0.02 - 0.6 * x)
            })
            .collect();
        let (a, b) = fit_line(&pts).unwrap();
        assert!((a - 0.02).abs() < 1e-12 && (b + 0.6).abs() < 1e-12);
        assert!((angle_degrees(b) - 0.6f64.atan().to_degrees()).abs() < 1e-12);
        assert!((angle_degrees(-1.0) - 45.0).abs() < 1e-12);
        assert!(fit_line(&pts[..1]).is_none());
        assert!(fit_line(&[(1.0, 0.0), (1.0, 2.0)]).is_none());
    }

    /// A bed of spheres stacked under a plane of slope −tan 30° on a 2-radius grid: the
    /// fitted angle is 30° within the grid's roughness.
    #[test]
    fn the_surface_of_a_tilted_bed_gives_its_angle() {
        let r = 0.005;
        let slope = -(30f64.to_radians().tan());
        let (mut pos, mut radius) = (Vec::new(), Vec::new());
        for i in 0..40 {
            let x = -0.1 + (i as f64 + 0.5) * 2.0 * r;
            for j in 0..60 {
                let z = -0.15 + (j as f64 + 0.5) * 2.0 * r;
                if z + r <= 0.01 + slope * x {
                    for y in [-0.01, 0.01] {
                        pos.push([x, y, z]);
                        radius.push(r);
                    }
                }
            }
        }
        let pts = surface_points(&pos, &radius, 2.0 * r, SURFACE_KEEP);
        assert!(pts.len() >= 20, "{}", pts.len());
        let (_, b) = fit_line(&pts).unwrap();
        assert!(
            (angle_degrees(b) - 30.0).abs() < 1.0,
            "{}",
            angle_degrees(b)
        );
    }

    /// A layer flowing downhill at 1 m/s over a bed in solid-body rotation: the active layer
    /// is the flowing layer's thickness.
    #[test]
    fn the_active_layer_ends_where_the_relative_flow_stops() {
        let w = 2.0;
        let (a, b) = (0.0, -0.5); // surface z = −0.5 x: downhill is +x
        let norm = (1.0f64 + b * b).sqrt();
        let down = [1.0 / norm, 0.0, b / norm];
        let (mut pos, mut vel) = (Vec::new(), Vec::new());
        for i in 0..21 {
            let x = -0.05 + i as f64 * 0.005;
            for k in 0..12 {
                let depth = (k as f64 + 0.5) * 0.005;
                let p = [x, 0.0, a + b * x - depth * norm];
                let s = solid_body(w, p);
                let u = if depth < 0.02 { 1.0 } else { 0.0 };
                pos.push(p);
                vel.push([s[0] + u * down[0], 0.0, s[2] + u * down[2]]);
            }
        }
        let layer = active_layer(&pos, &vel, w, (a, b), (-0.05, 0.05), 0.005).unwrap();
        assert!((layer.thickness - 0.02).abs() < 1e-9, "{layer:?}");
        assert!(!layer.whole_depth);
        // solid-body rotation everywhere: no active layer
        let still: Vec<[f64; 3]> = pos.iter().map(|p| solid_body(w, *p)).collect();
        assert!(active_layer(&pos, &still, w, (a, b), (-0.05, 0.05), 0.005).is_none());
    }

    #[test]
    fn a_bed_turning_with_the_drum_has_no_relative_speed() {
        let w = 3.0;
        let pos = vec![[0.01, 0.0, -0.04], [-0.03, 0.01, -0.02], [0.0, 0.0, -0.09]];
        let snapshot = Snapshot {
            index: 1,
            time: 0.0,
            id: vec![0, 1, 2],
            vel: pos.iter().map(|p| solid_body(w, *p)).collect(),
            radius: vec![0.005; 3],
            temp: vec![0.0; 3],
            pos,
        };
        assert!(relative_speed(&snapshot, w, 0.1) < 1e-15);
        let mut moving = snapshot.clone();
        moving.vel[0][0] += 0.3 * 3.0 * 0.1 * 3.0; // one of three particles at 0.9 ωR
        assert!((relative_speed(&moving, w, 0.1) - 0.3).abs() < 1e-12);
    }
}
