//! Per-stage wall-clock timers of the DEM step; they feed the run summary and the speedup report.

use std::time::{Duration, Instant};

/// Time spent in each stage since the counters were created or reset.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Counters {
    /// Displacement check, re-sort and Verlet-list build.
    pub neighbor: Duration,
    /// Sphere–sphere and sphere–wall contact forces and conduction (one pass).
    pub contact: Duration,
    /// Velocity-Verlet half steps and the temperature update.
    pub integrate: Duration,
    pub steps: u64,
    pub particle_steps: u64,
}

impl Counters {
    pub fn total(&self) -> Duration {
        self.neighbor + self.contact + self.integrate
    }

    /// Stage names and times, in pipeline order.
    pub fn stages(&self) -> [(&'static str, Duration); 3] {
        [
            ("neighbor", self.neighbor),
            ("contact", self.contact),
            ("integrate", self.integrate),
        ]
    }

    /// Particle-steps per second of stage time (0 before any step).
    pub fn particle_steps_per_second(&self) -> f64 {
        let t = self.total().as_secs_f64();
        if t > 0.0 {
            self.particle_steps as f64 / t
        } else {
            0.0
        }
    }
}

/// Runs `f` and adds its duration to `slot`.
#[inline]
pub fn timed<R>(slot: &mut Duration, f: impl FnOnce() -> R) -> R {
    let start = Instant::now();
    let r = f();
    *slot += start.elapsed();
    r
}
