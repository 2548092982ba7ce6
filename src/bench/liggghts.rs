//! The LIGGGHTS 3.8 peer of `tdex bench CASE`: the case as a LIGGGHTS deck, run for the same
//! steps on one process.

use crate::cli::BenchPlan;
use anyhow::{bail, Result};
use std::path::{Path, PathBuf};

pub struct PeerRate {
    pub particle_steps_per_s: f64,
    pub seconds: f64,
    pub dir: PathBuf,
}

pub fn run(_plan: &BenchPlan, _dir: Option<&Path>) -> Result<PeerRate> {
    bail!("--vs-liggghts is not built yet")
}
