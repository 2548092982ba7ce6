//! The TOML case file as the user writes it (serde schema; unknown keys refused).

use super::validate::{refuse, Violation};
use serde::{Deserialize, Serialize};

/// A rotating-drum thermal DEM case, exactly as read from a `.toml` file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Free-form name, used in reports.
    #[serde(default)]
    pub name: String,
    /// Seed of every random choice (insertion); same case + seed give the same bytes.
    pub seed: u64,
    pub particles: ParticlesSpec,
    pub material: Material,
    pub contact: ContactSpec,
    #[serde(default)]
    pub conduction: ConductionSpec,
    pub drum: Drum,
    pub time: TimeSpec,
    pub temperature: TemperatureSpec,
}

/// The spheres: how many, and their sizes.
///
/// Read and written through `ParticleFields`, the `[particles]` table as the file spells
/// it: one of `radius`, `classes` or `distribution`, so a one-size case keeps its two keys
/// in a recording's resolved case.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ParticleFields", into = "ParticleFields")]
pub struct ParticlesSpec {
    /// Number of spheres.
    pub count: usize,
    pub size: ParticleSize,
}

/// The sizes of the spheres.
#[derive(Debug, Clone, PartialEq)]
pub enum ParticleSize {
    /// Every sphere of this radius (m).
    Single { radius: f64 },
    /// Spheres of a few radii in given fractions (LIGGGHTS `particletemplate/sphere` with
    /// `particledistribution/discrete`).
    Classes {
        classes: Vec<SizeClass>,
        fractions: FractionBasis,
    },
    /// A truncated normal or log-normal distribution of the radius, cut into classes of
    /// equal width.
    Distribution {
        distribution: Distribution,
        fractions: FractionBasis,
    },
}

/// One radius of a discrete size distribution and its share of the bed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SizeClass {
    /// m
    pub radius: f64,
    /// Share of the particles (by number or by mass, see [`FractionBasis`]), in (0, 1].
    pub fraction: f64,
}

/// Whether the fractions of a size distribution count particles or weigh them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FractionBasis {
    /// Shares of the particle count (EDEM's number distribution).
    #[default]
    Number,
    /// Shares of the bed's mass (LIGGGHTS `particledistribution/discrete`).
    Mass,
}

/// A continuous distribution of the radius, truncated to `[min_radius, max_radius]` and
/// discretised into `classes` bins of equal width: each bin's particles take the bin's
/// middle radius, and its share is the distribution's probability over the bin.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Distribution {
    pub shape: DistributionShape,
    /// Mean of the untruncated distribution of the radius (m).
    pub mean_radius: f64,
    /// Standard deviation of the untruncated distribution of the radius (m).
    pub std_radius: f64,
    /// m
    pub min_radius: f64,
    /// m
    pub max_radius: f64,
    /// Number of classes (bins) the range is cut into.
    pub classes: u32,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DistributionShape {
    Normal,
    /// ln(radius) normal, with the radius's mean and standard deviation as given.
    Lognormal,
}

/// The `[particles]` table as written: every key of every way to give the sizes, checked
/// when it becomes a [`ParticlesSpec`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ParticleFields {
    count: usize,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    classes: Option<Vec<SizeClass>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    distribution: Option<Distribution>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    fractions: Option<FractionBasis>,
}

impl TryFrom<ParticleFields> for ParticlesSpec {
    type Error = Violation;

    /// Refuses a table that gives the sizes in none or several ways, or `fractions` with a
    /// single radius.
    fn try_from(fields: ParticleFields) -> Result<Self, Violation> {
        let ParticleFields {
            count,
            radius,
            classes,
            distribution,
            fractions,
        } = fields;
        let given = [
            radius.map(|_| "radius"),
            classes.as_ref().map(|_| "classes"),
            distribution.map(|_| "distribution"),
        ];
        let given: Vec<&str> = given.into_iter().flatten().collect();
        let size = match (radius, classes, distribution) {
            (Some(radius), None, None) => {
                if let Some(f) = fractions {
                    return Err(refuse(
                        "particles.fractions",
                        format!("\"{}\"", f.name()),
                        "only allowed with particles.classes or particles.distribution",
                    ));
                }
                ParticleSize::Single { radius }
            }
            (None, Some(classes), None) => ParticleSize::Classes {
                classes,
                fractions: fractions.unwrap_or_default(),
            },
            (None, None, Some(distribution)) => ParticleSize::Distribution {
                distribution,
                fractions: fractions.unwrap_or_default(),
            },
            _ => {
                return Err(refuse(
                    "particles",
                    if given.is_empty() {
                        "(no size)".to_string()
                    } else {
                        given.join(" and ")
                    },
                    "give the sizes in exactly one way: radius (one size), classes (a \
                     discrete distribution) or distribution (normal or lognormal)",
                ))
            }
        };
        Ok(ParticlesSpec { count, size })
    }
}

impl From<ParticlesSpec> for ParticleFields {
    fn from(spec: ParticlesSpec) -> Self {
        let mut fields = ParticleFields {
            count: spec.count,
            radius: None,
            classes: None,
            distribution: None,
            fractions: None,
        };
        match spec.size {
            ParticleSize::Single { radius } => fields.radius = Some(radius),
            ParticleSize::Classes { classes, fractions } => {
                fields.classes = Some(classes);
                fields.fractions = Some(fractions);
            }
            ParticleSize::Distribution {
                distribution,
                fractions,
            } => {
                fields.distribution = Some(distribution);
                fields.fractions = Some(fractions);
            }
        }
        fields
    }
}

impl FractionBasis {
    /// The spelling in a case file.
    pub fn name(self) -> &'static str {
        match self {
            FractionBasis::Number => "number",
            FractionBasis::Mass => "mass",
        }
    }
}

/// Bulk properties of the particle material (the drum wall shares the elastic ones).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// kg/m³
    pub density: f64,
    /// Young's modulus used by the contact law (Pa); often softened.
    pub youngs_modulus: f64,
    /// Poisson's ratio, in [0, 0.5).
    pub poisson_ratio: f64,
    /// W/(m K)
    pub conductivity: f64,
    /// Specific heat capacity, J/(kg K)
    pub heat_capacity: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Rolling resistance model, as LIGGGHTS `rolling_friction`.
    #[serde(default)]
    pub rolling_model: RollingModel,
    pub particle_particle: PairCoefficients,
    pub particle_wall: PairCoefficients,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairCoefficients {
    /// Coefficient of restitution, in (0, 1].
    pub restitution: f64,
    /// Coulomb sliding friction coefficient, ≥ 0.
    pub friction: f64,
    /// Rolling friction coefficient μr, ≥ 0.
    #[serde(default)]
    pub rolling_friction: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RollingModel {
    /// Elastic–plastic spring-dashpot without dashpot (LIGGGHTS `epsd2`).
    #[default]
    Epsd2,
    /// Constant directional torque (LIGGGHTS `cdt`).
    Cdt,
    /// No rolling resistance.
    Off,
}

/// Particle–particle (and heated-wall) conduction options, LIGGGHTS `heat/gran/conduction`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConductionSpec {
    /// Which contact area enters `H = 4KiKj/(Ki+Kj)·sqrt(A)`.
    #[serde(default)]
    pub contact_area: ContactArea,
    /// Real Young's modulus (Pa) of the material: when set, the overlap is corrected by
    /// `(E*/E*_real)^(2/3)` before the area is computed (LIGGGHTS `area_correction yes`).
    #[serde(default)]
    pub youngs_modulus_real: Option<f64>,
}

impl Default for ConductionSpec {
    fn default() -> Self {
        Self {
            contact_area: ContactArea::Overlap,
            youngs_modulus_real: None,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ContactArea {
    /// The sphere–sphere intersection disc (LIGGGHTS default `contact_area overlap`).
    #[default]
    Overlap,
    /// The Hertz contact circle `π R* δ`.
    Hertz,
}

/// A horizontal drum, axis `y` through the origin, gravity `-z`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Drum {
    /// Inner radius of the mantle (m).
    pub radius: f64,
    /// Inner length between the end caps (m).
    pub length: f64,
    /// Seconds per revolution, counter-clockwise seen from +y (z → x).
    pub rotation_period: f64,
    /// Whether the flat end caps turn with the mantle or stand still, or the drum has none
    /// and is periodic along its axis.
    #[serde(default)]
    pub end_caps: EndCaps,
    /// When set, the mantle is held at this temperature (K) from `t0` on and conducts
    /// to the particles touching it; the end caps stay adiabatic.
    #[serde(default)]
    pub wall_temperature: Option<f64>,
    /// Conductivity of the heated mantle (W/(m K)); defaults to the particles'.
    #[serde(default)]
    pub wall_conductivity: Option<f64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EndCaps {
    /// The caps are part of the drum and rotate with it (LIGGGHTS: one rotating mesh).
    #[default]
    Rotating,
    /// The caps are fixed (a kiln's stationary hoods).
    Fixed,
    /// No caps: the drum is a section of a longer kiln, periodic along its axis (LIGGGHTS
    /// `boundary f p f`). A sphere leaving one end face enters through the other, and
    /// spheres touch across the seam.
    Periodic,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    /// DEM time step (s); refused above `MAX_RAYLEIGH_FRACTION` of the Rayleigh time.
    pub dt: f64,
    /// Settling time with the drum at rest after insertion (s).
    pub settle: f64,
    /// Rotation before the temperatures are assigned at `t0` (s).
    pub spin_up: f64,
    /// Heating time simulated by `tdex run` after `t0` (s); default one revolution.
    #[serde(default)]
    pub heating: Option<f64>,
}

/// Initial temperatures assigned at `t0`: the mode selects the fields it needs.
///
/// Read and written through `TemperatureFields`, the `[temperature]` table as the file
/// spells it, so a file names the mode with `mode = "…"` and a recording's resolved case
/// keeps today's keys (every field, `null` where the mode has none).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "TemperatureFields", into = "TemperatureFields")]
pub enum TemperatureSpec {
    /// The bed in two halves across `split_axis`: the half with the smaller coordinate at
    /// `hot`, the other at `cold` (K). The plane is placed so that exactly ⌊N/2⌋ particles
    /// are hot.
    Split {
        hot: f64,
        cold: f64,
        split_axis: Axis,
    },
    /// Every particle at `value` (K). A `split_axis` in the file has no effect here; it is
    /// kept so that the resolved case a recording stores says what the file said.
    Uniform { value: f64, split_axis: Axis },
}

impl TemperatureSpec {
    /// The temperature of every particle before `t0` (K): the uniform value, or the cold
    /// half's (the insertion needs one; the split is made at `t0`).
    pub fn before_t0(&self) -> f64 {
        match *self {
            TemperatureSpec::Split { cold, .. } => cold,
            TemperatureSpec::Uniform { value, .. } => value,
        }
    }
}

/// The `[temperature]` table as written: every key of every mode, checked against the mode
/// when it becomes a [`TemperatureSpec`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TemperatureFields {
    mode: TemperatureMode,
    #[serde(default)]
    hot: Option<f64>,
    #[serde(default)]
    cold: Option<f64>,
    #[serde(default)]
    split_axis: Axis,
    #[serde(default)]
    value: Option<f64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
enum TemperatureMode {
    Split,
    Uniform,
}

impl TryFrom<TemperatureFields> for TemperatureSpec {
    type Error = Violation;

    /// Refuses a key the mode requires and is missing, or one that belongs to the other mode.
    fn try_from(fields: TemperatureFields) -> Result<Self, Violation> {
        let TemperatureFields {
            mode,
            hot,
            cold,
            split_axis,
            value,
        } = fields;
        let required = |field: &str, mode: &str| {
            refuse(
                field,
                "(missing)",
                format!("required when mode = \"{mode}\""),
            )
        };
        let only_in = |field: &str, v: f64, mode: &str| {
            refuse(
                field,
                format!("{v} K"),
                format!("only allowed when mode = \"{mode}\""),
            )
        };
        match mode {
            TemperatureMode::Split => {
                let hot = hot.ok_or_else(|| required("temperature.hot", "split"))?;
                let cold = cold.ok_or_else(|| required("temperature.cold", "split"))?;
                if let Some(v) = value {
                    return Err(only_in("temperature.value", v, "uniform"));
                }
                Ok(TemperatureSpec::Split {
                    hot,
                    cold,
                    split_axis,
                })
            }
            TemperatureMode::Uniform => {
                let value = value.ok_or_else(|| required("temperature.value", "uniform"))?;
                if let Some(h) = hot.or(cold) {
                    return Err(only_in("temperature.hot/cold", h, "split"));
                }
                Ok(TemperatureSpec::Uniform { value, split_axis })
            }
        }
    }
}

impl From<TemperatureSpec> for TemperatureFields {
    fn from(spec: TemperatureSpec) -> Self {
        match spec {
            TemperatureSpec::Split {
                hot,
                cold,
                split_axis,
            } => TemperatureFields {
                mode: TemperatureMode::Split,
                hot: Some(hot),
                cold: Some(cold),
                split_axis,
                value: None,
            },
            TemperatureSpec::Uniform { value, split_axis } => TemperatureFields {
                mode: TemperatureMode::Uniform,
                hot: None,
                cold: None,
                split_axis,
                value: Some(value),
            },
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Axis {
    #[default]
    X,
    Y,
    Z,
}

impl Axis {
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }
}

impl Drum {
    /// The section's period along the axis, when the drum is periodic.
    pub fn axial_period(&self) -> Option<crate::periodic::AxialPeriod> {
        (self.end_caps == EndCaps::Periodic).then_some(crate::periodic::AxialPeriod {
            length: self.length,
        })
    }
}
