//! Contact forces: the Hertz–Mindlin law with history and rolling resistance, one file per pair kind.

pub mod contact_sphere_sphere;
pub mod contact_sphere_wall;
pub mod hertz_mindlin;
pub mod narrow_phase;
pub mod pair_batch;
pub mod pair_sample;
pub mod rolling;

pub use hertz_mindlin::{ContactHistory, ContactKinematics, ContactResponse, PairLaw};
