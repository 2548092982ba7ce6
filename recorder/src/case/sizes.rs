//! Size classes of a bed: a case's sizes resolved into radii and particle counts.

use super::schema::*;
use super::validate::{refuse, Violation};

/// Most classes a size distribution may have (LIGGGHTS users rarely write more than a
/// dozen templates; each class is its own pairing problem).
pub const MAX_SIZE_CLASSES: usize = 64;
/// How far the fractions of `particles.classes` may sum from 1.
pub const FRACTION_SUM_TOLERANCE: f64 = 1e-6;

/// The bed's sizes: class `c` holds `count[c]` spheres of radius `radius[c]`, radii strictly
/// increasing; the counts sum to the case's particle count.
#[derive(Debug, Clone, PartialEq)]
pub struct SizeClasses {
    pub radius: Vec<f64>,
    pub count: Vec<usize>,
}

impl SizeClasses {
    /// The largest radius (m): it sets the neighbour cells and the insertion lattice.
    pub fn largest(&self) -> f64 {
        self.radius.last().copied().unwrap_or(0.0)
    }

    /// The smallest radius (m): it sets the time step's limit.
    pub fn smallest(&self) -> f64 {
        self.radius.first().copied().unwrap_or(0.0)
    }

    /// Total volume of the spheres (m³).
    pub fn solid_volume(&self) -> f64 {
        self.radius
            .iter()
            .zip(&self.count)
            .map(|(r, &n)| n as f64 * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3))
            .sum()
    }
}

impl ParticlesSpec {
    /// The size classes of a validated case.
    ///
    /// # Panics
    ///
    /// On a case [`super::validate`] refuses (its sizes cannot be resolved).
    pub fn size_classes(&self) -> SizeClasses {
        resolve(self).expect("the sizes of a validated case resolve")
    }

    /// The largest radius of a validated case (m).
    pub fn largest_radius(&self) -> f64 {
        match self.size {
            ParticleSize::Single { radius } => radius,
            _ => self.size_classes().largest(),
        }
    }
}

/// Resolves the sizes into classes, refusing what cannot be a bed: a radius or fraction
/// out of range, fractions that do not sum to one, a class with no particle.
pub(super) fn resolve(p: &ParticlesSpec) -> Result<SizeClasses, Violation> {
    match &p.size {
        ParticleSize::Single { radius } => {
            positive("particles.radius", *radius)?;
            Ok(SizeClasses {
                radius: vec![*radius],
                count: vec![p.count],
            })
        }
        ParticleSize::Classes { classes, fractions } => discrete(p.count, classes, *fractions),
        ParticleSize::Distribution {
            distribution,
            fractions,
        } => continuous(p.count, distribution, *fractions),
    }
}

fn positive(field: &str, v: f64) -> Result<(), Violation> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(refuse(field, v, "must be a finite number > 0"))
    }
}

fn discrete(
    count: usize,
    classes: &[SizeClass],
    basis: FractionBasis,
) -> Result<SizeClasses, Violation> {
    if classes.is_empty() || classes.len() > MAX_SIZE_CLASSES {
        return Err(refuse(
            "particles.classes",
            format!("{} classes", classes.len()),
            format!("give 1 to {MAX_SIZE_CLASSES} classes"),
        ));
    }
    for (k, c) in classes.iter().enumerate() {
        positive(&format!("particles.classes[{k}].radius"), c.radius)?;
        if !(c.fraction.is_finite() && c.fraction > 0.0 && c.fraction <= 1.0) {
            return Err(refuse(
                &format!("particles.classes[{k}].fraction"),
                c.fraction,
                "must lie in (0, 1]",
            ));
        }
        if let Some(j) = classes[..k].iter().position(|o| o.radius == c.radius) {
            return Err(refuse(
                &format!("particles.classes[{k}].radius"),
                c.radius,
                format!("repeats particles.classes[{j}].radius: each class has its own radius"),
            ));
        }
    }
    let sum: f64 = classes.iter().map(|c| c.fraction).sum();
    if (sum - 1.0).abs() > FRACTION_SUM_TOLERANCE {
        return Err(refuse(
            "particles.classes",
            format!("fractions summing to {}", round_sig(sum, 9)),
            format!(
                "the {} fractions must sum to 1 (within {FRACTION_SUM_TOLERANCE:e})",
                basis.name()
            ),
        ));
    }
    let mut sorted: Vec<(usize, SizeClass)> = classes.iter().copied().enumerate().collect();
    sorted.sort_by(|a, b| a.1.radius.total_cmp(&b.1.radius));
    let radius: Vec<f64> = sorted.iter().map(|(_, c)| c.radius).collect();
    let fraction: Vec<f64> = sorted.iter().map(|(_, c)| c.fraction).collect();
    let counts = counts(count, &number_shares(&radius, &fraction, basis));
    if let Some(c) = counts.iter().position(|&n| n == 0) {
        let (k, class) = sorted[c];
        return Err(refuse(
            &format!("particles.classes[{k}].fraction"),
            class.fraction,
            format!(
                "gives no particle of radius {} m among particles.count = {count}: raise the \
                 fraction or the count",
                class.radius
            ),
        ));
    }
    Ok(SizeClasses {
        radius,
        count: counts,
    })
}

fn continuous(
    count: usize,
    d: &Distribution,
    basis: FractionBasis,
) -> Result<SizeClasses, Violation> {
    positive("particles.distribution.mean_radius", d.mean_radius)?;
    positive("particles.distribution.std_radius", d.std_radius)?;
    positive("particles.distribution.min_radius", d.min_radius)?;
    positive("particles.distribution.max_radius", d.max_radius)?;
    if d.max_radius <= d.min_radius {
        return Err(refuse(
            "particles.distribution.max_radius",
            d.max_radius,
            format!(
                "must exceed particles.distribution.min_radius = {}",
                d.min_radius
            ),
        ));
    }
    if d.classes == 0 || d.classes as usize > MAX_SIZE_CLASSES {
        return Err(refuse(
            "particles.distribution.classes",
            d.classes,
            format!("must lie in 1..={MAX_SIZE_CLASSES}"),
        ));
    }
    let cdf = |r: f64| match d.shape {
        DistributionShape::Normal => normal_cdf((r - d.mean_radius) / d.std_radius),
        DistributionShape::Lognormal => {
            // ln r ~ N(μ, σ²) with the radius's own mean and standard deviation
            let s2 = (1.0 + (d.std_radius / d.mean_radius).powi(2)).ln();
            let mu = d.mean_radius.ln() - 0.5 * s2;
            normal_cdf((r.ln() - mu) / s2.sqrt())
        }
    };
    let k = d.classes as usize;
    let width = (d.max_radius - d.min_radius) / k as f64;
    let edge = |b: usize| d.min_radius + b as f64 * width;
    let probability: Vec<f64> = (0..k).map(|b| cdf(edge(b + 1)) - cdf(edge(b))).collect();
    let total: f64 = probability.iter().sum();
    if !(total.is_finite() && total > 1e-12) {
        return Err(refuse(
            "particles.distribution",
            format!(
                "{} of mean {} m and standard deviation {} m",
                d.shape.name(),
                d.mean_radius,
                d.std_radius
            ),
            format!(
                "holds no probability between min_radius = {} m and max_radius = {} m",
                d.min_radius, d.max_radius
            ),
        ));
    }
    let radius: Vec<f64> = (0..k).map(|b| edge(b) + 0.5 * width).collect();
    let fraction: Vec<f64> = probability.iter().map(|p| p / total).collect();
    let counts = counts(count, &number_shares(&radius, &fraction, basis));
    // a tail bin too thin for one particle of this bed is left out: the bed is what the
    // distribution gives `count` particles, not a class of none
    let (radius, count): (Vec<f64>, Vec<usize>) = radius
        .into_iter()
        .zip(counts)
        .filter(|&(_, n)| n > 0)
        .unzip();
    Ok(SizeClasses { radius, count })
}

impl DistributionShape {
    pub fn name(self) -> &'static str {
        match self {
            DistributionShape::Normal => "normal",
            DistributionShape::Lognormal => "lognormal",
        }
    }
}

/// Φ(x), the standard normal distribution function.
fn normal_cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x / std::f64::consts::SQRT_2)
}

/// Shares of the particle count: the fractions themselves, or mass fractions divided by
/// each class's sphere mass (∝ r³) and normalised.
fn number_shares(radius: &[f64], fraction: &[f64], basis: FractionBasis) -> Vec<f64> {
    let weights: Vec<f64> = match basis {
        FractionBasis::Number => fraction.to_vec(),
        FractionBasis::Mass => radius
            .iter()
            .zip(fraction)
            .map(|(r, f)| f / r.powi(3))
            .collect(),
    };
    let sum: f64 = weights.iter().sum();
    weights.iter().map(|w| w / sum).collect()
}

/// Whole particle counts from shares that sum to one: each class gets the floor of its
/// share of `total`, and the remaining particles go one each to the largest remainders
/// (ties to the smaller radius), so the counts sum to `total` exactly.
fn counts(total: usize, shares: &[f64]) -> Vec<usize> {
    let exact: Vec<f64> = shares.iter().map(|s| s * total as f64).collect();
    let mut counts: Vec<usize> = exact.iter().map(|x| x.floor() as usize).collect();
    let assigned: usize = counts.iter().sum();
    let mut by_remainder: Vec<usize> = (0..shares.len()).collect();
    by_remainder.sort_by(|&a, &b| {
        let (ra, rb) = (exact[a] - exact[a].floor(), exact[b] - exact[b].floor());
        rb.total_cmp(&ra).then(a.cmp(&b))
    });
    for &c in by_remainder.iter().take(total.saturating_sub(assigned)) {
        counts[c] += 1;
    }
    counts
}

/// `x` to `digits` significant digits, for messages (no float noise).
fn round_sig(x: f64, digits: i32) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let scale = 10f64.powi(digits - 1 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(count: usize, size: ParticleSize) -> ParticlesSpec {
        ParticlesSpec { count, size }
    }

    fn classes(pairs: &[(f64, f64)], fractions: FractionBasis) -> ParticleSize {
        ParticleSize::Classes {
            classes: pairs
                .iter()
                .map(|&(radius, fraction)| SizeClass { radius, fraction })
                .collect(),
            fractions,
        }
    }

    #[test]
    fn number_fractions_give_counts_that_sum_to_the_bed() {
        let s = resolve(&spec(
            1001,
            classes(
                &[(0.002, 0.3), (0.001, 0.3), (0.003, 0.4)],
                FractionBasis::Number,
            ),
        ))
        .unwrap();
        assert_eq!(s.radius, vec![0.001, 0.002, 0.003]);
        // 300.3, 300.3, 400.4: the one left over goes to the largest remainder
        assert_eq!(s.count, vec![300, 300, 401]);
        assert_eq!(s.count.iter().sum::<usize>(), 1001);
    }

    #[test]
    fn mass_fractions_count_more_of_the_small_spheres() {
        // equal masses of r and 2r: eight times as many small spheres
        let s = resolve(&spec(
            900,
            classes(&[(0.001, 0.5), (0.002, 0.5)], FractionBasis::Mass),
        ))
        .unwrap();
        assert_eq!(s.count, vec![800, 100]);
        let mass = |c: usize| s.count[c] as f64 * s.radius[c].powi(3);
        assert!((mass(0) / mass(1) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_truncated_normal_is_cut_into_bins_weighted_by_its_probability() {
        let d = Distribution {
            shape: DistributionShape::Normal,
            mean_radius: 1.0e-3,
            std_radius: 0.15e-3,
            min_radius: 0.55e-3,
            max_radius: 1.45e-3,
            classes: 3,
        };
        let s = resolve(&spec(
            100_000,
            ParticleSize::Distribution {
                distribution: d,
                fractions: FractionBasis::Number,
            },
        ))
        .unwrap();
        assert_eq!(s.radius.len(), 3);
        assert!((s.radius[1] - 1.0e-3).abs() < 1e-15);
        // bins of ±1σ around the mean, and 1σ..3σ on each side, truncated at ±3σ:
        // Φ(1) − Φ(−1) = 0.682689, over Φ(3) − Φ(−3) = 0.997300
        let middle = 0.682_689_492 / 0.997_300_204;
        assert!(
            (s.count[1] as f64 / 1e5 - middle).abs() < 2e-5,
            "{:?}",
            s.count
        );
        assert_eq!(s.count[0], s.count[2]);
        assert_eq!(s.count.iter().sum::<usize>(), 100_000);
    }

    #[test]
    fn a_lognormal_keeps_the_mean_radius_it_was_given() {
        let d = Distribution {
            shape: DistributionShape::Lognormal,
            mean_radius: 1.0e-3,
            std_radius: 0.2e-3,
            min_radius: 0.1e-3,
            max_radius: 5.0e-3,
            classes: 64,
        };
        let s = resolve(&spec(
            1_000_000,
            ParticleSize::Distribution {
                distribution: d,
                fractions: FractionBasis::Number,
            },
        ))
        .unwrap();
        let n: usize = s.count.iter().sum();
        let mean: f64 = s
            .radius
            .iter()
            .zip(&s.count)
            .map(|(r, &c)| r * c as f64)
            .sum::<f64>()
            / n as f64;
        // the bins are 0.077 mm wide, so the binned mean is within a fraction of one
        assert!((mean / 1.0e-3 - 1.0).abs() < 2e-3, "{mean}");
        // skewed to the right: more probability above the mean than a normal's tail has
        let above: usize = s
            .radius
            .iter()
            .zip(&s.count)
            .filter(|(r, _)| **r > 1.4e-3)
            .map(|(_, &c)| c)
            .sum();
        assert!(above as f64 / n as f64 > 0.03, "{above}");
    }

    #[test]
    fn fractions_that_do_not_sum_to_one_are_refused_with_their_sum() {
        let v = resolve(&spec(
            100,
            classes(&[(0.001, 0.3), (0.002, 0.6)], FractionBasis::Number),
        ))
        .unwrap_err();
        assert_eq!(v.field, "particles.classes");
        assert_eq!(v.value, "fractions summing to 0.9");
        assert!(v.limit.contains("must sum to 1"), "{}", v.limit);
    }

    #[test]
    fn a_class_with_no_particle_or_a_repeated_radius_is_refused() {
        let v = resolve(&spec(
            10,
            classes(&[(0.001, 0.99), (0.002, 0.01)], FractionBasis::Number),
        ))
        .unwrap_err();
        assert_eq!(v.field, "particles.classes[1].fraction");
        assert!(
            v.limit.contains("no particle of radius 0.002 m"),
            "{}",
            v.limit
        );
        let v = resolve(&spec(
            10,
            classes(&[(0.001, 0.5), (0.001, 0.5)], FractionBasis::Number),
        ))
        .unwrap_err();
        assert_eq!(v.field, "particles.classes[1].radius");
    }
}
