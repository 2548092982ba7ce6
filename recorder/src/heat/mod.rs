//! Heat conduction through contacts (LIGGGHTS `heat/gran/conduction`) and from a heated mantle.

pub mod conduction_sphere_sphere;
pub mod conduction_sphere_wall;

pub use conduction_sphere_sphere::ConductionLaw;
