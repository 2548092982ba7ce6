//! Physical validation of a parsed case: every refusal names the field, the value and the limit.

use super::schema::*;
use super::sizes::{self, SizeClasses};
use crate::insertion;

/// The largest accepted `dt` as a fraction of the Rayleigh time (the paper runs at 23 %;
/// 10–30 % is common DEM practice).
pub const MAX_RAYLEIGH_FRACTION: f64 = 0.30;
/// Largest accepted bed volume (at the random-loose packing 0.6) as a fraction of the drum.
pub const MAX_FILL_FRACTION: f64 = 0.90;
/// Largest neighbour grid a case may need (its cell index alone is 4 bytes a cell).
pub const MAX_GRID_CELLS: f64 = 3.0e7;
/// Packing fraction used to size the settled bed.
const BED_PACKING: f64 = 0.60;

/// A refused value, before the file name is attached.
#[derive(Debug)]
pub struct Violation {
    pub field: String,
    pub value: String,
    pub limit: String,
}

/// The words of [`super::CaseError::Invalid`] after the file name; a refusal made while the
/// file is read (by serde) says them inside the parse error.
impl std::fmt::Display for Violation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} = {} is not allowed: {}",
            self.field, self.value, self.limit
        )
    }
}

pub(super) fn refuse(
    field: &str,
    value: impl std::fmt::Display,
    limit: impl Into<String>,
) -> Violation {
    Violation {
        field: field.to_string(),
        value: value.to_string(),
        limit: limit.into(),
    }
}

fn positive(field: &str, v: f64) -> Result<(), Violation> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(refuse(field, v, "must be a finite number > 0"))
    }
}

/// A temperature, in kelvin: finite and > 0 K (the message says the unit).
fn temperature(field: &str, v: f64) -> Result<(), Violation> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(refuse(
            field,
            format!("{v} K"),
            "must be a finite temperature > 0 K (temperatures are in kelvin)",
        ))
    }
}

fn non_negative(field: &str, v: f64) -> Result<(), Violation> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(refuse(field, v, "must be a finite number >= 0"))
    }
}

/// Rayleigh time `π R sqrt(ρ/G)/(0.1631ν + 0.8766)` of a sphere, `G = E/(2(1+ν))`.
pub fn rayleigh_time(radius: f64, density: f64, youngs_modulus: f64, poisson_ratio: f64) -> f64 {
    let shear_modulus = youngs_modulus / (2.0 * (1.0 + poisson_ratio));
    std::f64::consts::PI * radius * (density / shear_modulus).sqrt()
        / (0.1631 * poisson_ratio + 0.8766)
}

fn pair(prefix: &str, c: &PairCoefficients) -> Result<(), Violation> {
    let e = c.restitution;
    if !(e.is_finite() && e > 0.0 && e <= 1.0) {
        return Err(refuse(
            &format!("{prefix}.restitution"),
            e,
            "must lie in (0, 1]",
        ));
    }
    non_negative(&format!("{prefix}.friction"), c.friction)?;
    non_negative(&format!("{prefix}.rolling_friction"), c.rolling_friction)
}

/// Checks every value of the case against its physical range.
pub fn validate(case: &Case) -> Result<(), Violation> {
    let p = &case.particles;
    if p.count < 2 {
        return Err(refuse("particles.count", p.count, "must be at least 2"));
    }
    if p.count > u32::MAX as usize / 2 {
        return Err(refuse(
            "particles.count",
            p.count,
            format!("must be at most {}", u32::MAX / 2),
        ));
    }
    let sizes = sizes::resolve(p)?;

    let m = &case.material;
    positive("material.density", m.density)?;
    positive("material.youngs_modulus", m.youngs_modulus)?;
    let nu = m.poisson_ratio;
    if !(nu.is_finite() && (0.0..0.5).contains(&nu)) {
        return Err(refuse("material.poisson_ratio", nu, "must lie in [0, 0.5)"));
    }
    positive("material.conductivity", m.conductivity)?;
    positive("material.heat_capacity", m.heat_capacity)?;

    pair("contact.particle_particle", &case.contact.particle_particle)?;
    pair("contact.particle_wall", &case.contact.particle_wall)?;

    if let Some(e_real) = case.conduction.youngs_modulus_real {
        positive("conduction.youngs_modulus_real", e_real)?;
        if e_real < m.youngs_modulus {
            return Err(refuse(
                "conduction.youngs_modulus_real",
                e_real,
                format!(
                    "must be >= material.youngs_modulus = {} (the contact modulus is a softened real one)",
                    m.youngs_modulus
                ),
            ));
        }
    }

    drum(&case.drum, p, &sizes)?;
    time(&case.time, m, &sizes)?;
    // which keys each mode needs was settled when the file was read (`TemperatureSpec`)
    match case.temperature {
        TemperatureSpec::Split { hot, cold, .. } => {
            temperature("temperature.hot", hot)?;
            temperature("temperature.cold", cold)?;
        }
        TemperatureSpec::Uniform { value, .. } => temperature("temperature.value", value)?,
    }

    bed_fits(p, &case.drum, &sizes)
}

/// The drum's extents against the largest sphere, and its motion and wall.
fn drum(d: &Drum, p: &ParticlesSpec, sizes: &SizeClasses) -> Result<(), Violation> {
    positive("drum.radius", d.radius)?;
    positive("drum.length", d.length)?;
    match &p.size {
        ParticleSize::Single { radius } => {
            for (field, extent) in [("drum.radius", d.radius), ("drum.length", d.length)] {
                if extent <= 2.0 * radius {
                    return Err(refuse(
                        field,
                        extent,
                        format!("must exceed the particle diameter {}", 2.0 * radius),
                    ));
                }
            }
        }
        // the refusal names the class, the size the user can change
        _ => {
            let largest = sizes.largest();
            if d.radius.min(d.length) <= 2.0 * largest {
                let field = match &p.size {
                    ParticleSize::Classes { classes, .. } => format!(
                        "particles.classes[{}].radius",
                        classes
                            .iter()
                            .position(|c| c.radius == largest)
                            .unwrap_or(0)
                    ),
                    _ => "particles.distribution.max_radius".to_string(),
                };
                return Err(refuse(
                    &field,
                    largest,
                    format!(
                        "a sphere's diameter must be less than the drum's radius ({} m) and length ({} m)",
                        d.radius, d.length
                    ),
                ));
            }
        }
    }
    if d.end_caps == EndCaps::Periodic && d.length < 4.0 * sizes.largest() {
        // shorter, a sphere could touch two images of another across the seam
        return Err(refuse(
            "drum.length",
            d.length,
            format!(
                "a periodic section must be at least two of the largest particle diameters long (2 × {} m = {} m)",
                2.0 * sizes.largest(),
                4.0 * sizes.largest()
            ),
        ));
    }
    positive("drum.rotation_period", d.rotation_period)?;
    if let Some(tw) = d.wall_temperature {
        temperature("drum.wall_temperature", tw)?;
    }
    if let Some(kw) = d.wall_conductivity {
        positive("drum.wall_conductivity", kw)?;
    }

    Ok(())
}

/// The time step against the smallest spheres' Rayleigh time, and the phases' lengths.
fn time(t: &TimeSpec, m: &Material, sizes: &SizeClasses) -> Result<(), Violation> {
    let nu = m.poisson_ratio;
    positive("time.dt", t.dt)?;
    // the smallest spheres have the shortest contacts: they bound the step
    let smallest = sizes.smallest();
    let t_rayleigh = rayleigh_time(smallest, m.density, m.youngs_modulus, nu);
    if t.dt > MAX_RAYLEIGH_FRACTION * t_rayleigh {
        let of = if sizes.radius.len() > 1 {
            format!(" of the smallest spheres (radius {smallest} m),")
        } else {
            String::new()
        };
        return Err(refuse(
            "time.dt",
            t.dt,
            format!(
                "must be <= {:.0} % of the Rayleigh time{of} {:.4e} s, i.e. <= {:.4e} s (dt is {:.1} % of it)",
                MAX_RAYLEIGH_FRACTION * 100.0,
                t_rayleigh,
                MAX_RAYLEIGH_FRACTION * t_rayleigh,
                100.0 * t.dt / t_rayleigh
            ),
        ));
    }
    non_negative("time.settle", t.settle)?;
    non_negative("time.spin_up", t.spin_up)?;
    if let Some(h) = t.heating {
        positive("time.heating", h)?;
    }

    Ok(())
}

/// Whether the settled bed fits the drum, its neighbour grid the machine, and its insertion
/// the room there is.
fn bed_fits(p: &ParticlesSpec, d: &Drum, sizes: &SizeClasses) -> Result<(), Violation> {
    // The settled bed must fit, and insertion must have room for every particle.
    let bed_volume = sizes.solid_volume() / BED_PACKING;
    let drum_volume = std::f64::consts::PI * d.radius * d.radius * d.length;
    if bed_volume > MAX_FILL_FRACTION * drum_volume {
        return Err(refuse(
            "particles.count",
            p.count,
            format!(
                "the bed ({:.3e} m³ at packing {BED_PACKING}) would fill {:.0} % of the drum ({:.3e} m³); at most {:.0} % is allowed",
                bed_volume,
                100.0 * bed_volume / drum_volume,
                drum_volume,
                MAX_FILL_FRACTION * 100.0
            ),
        ));
    }
    // The neighbour grid spans the drum in cells of a diameter and a skin: a drum thousands
    // of radii wide would ask the run for a grid larger than the machine, so it is refused
    // here, before any work. Counted in cells of one diameter (an upper bound).
    let largest = sizes.largest();
    let cell = 2.0 * largest;
    let grid_cells = (2.0 * (d.radius / cell + 1.0)).powi(2) * (d.length / cell + 2.0);
    if grid_cells > MAX_GRID_CELLS {
        return Err(refuse(
            "drum.radius",
            d.radius,
            format!(
                "with particles of radius {largest} m the neighbour grid would have {grid_cells:.2e} cells (drum {} m long); at most {MAX_GRID_CELLS:.0e} are allowed: use larger particles or a smaller drum",
                d.length
            ),
        ));
    }
    if sizes.radius.len() > 1 {
        let fill = insertion::random_fill(sizes, d.radius, d.length);
        if fill > insertion::MAX_RANDOM_FILL {
            return Err(refuse(
                "particles.count",
                p.count,
                format!(
                    "the spheres take {:.0} % of the drum's volume; spheres of several sizes are inserted at random, which places at most {:.0} %: lower the count or lengthen the drum (the bed then settles)",
                    100.0 * fill,
                    100.0 * insertion::MAX_RANDOM_FILL
                ),
            ));
        }
        return Ok(());
    }
    let sites = insertion::lattice_site_count(largest, d.radius, d.length, p.count);
    if sites < p.count {
        return Err(refuse(
            "particles.count",
            p.count,
            format!("the drum has room for only {sites} particles on the insertion lattice"),
        ));
    }
    Ok(())
}
