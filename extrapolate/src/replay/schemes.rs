//! The three ways of applying a period's rows (DESIGN.md §6). All conserve `Σ C T` between
//! particles; a wall row adds the heat the wall gives.

use super::table::{Bodies, Exchange};

/// How the rows update the temperatures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    /// The paper's: rows one after the other, `Q = H (T_k − T_l)` held for `m`.
    Explicit,
    /// Rows one after the other, each relaxing its pair exactly:
    /// `ΔT ← ΔT · exp(−H m (1/C_k + 1/C_l))`; unconditionally stable.
    Exact,
    /// Rows with the same start applied at once from the temperatures before them, as the
    /// DEM updates all contacts of a step together.
    Synchronous,
}

impl std::str::FromStr for Scheme {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "explicit" => Ok(Scheme::Explicit),
            "exact" => Ok(Scheme::Exact),
            "synchronous" => Ok(Scheme::Synchronous),
            other => Err(format!(
                "unknown scheme '{other}': use explicit, exact or synchronous"
            )),
        }
    }
}

/// Scratch space of the synchronous scheme (kept between calls to avoid reallocating).
#[derive(Debug, Default, Clone)]
pub struct SyncScratch {
    delta: Vec<f64>,
    touched: Vec<u32>,
}

/// Applies `rows` (in apparition order) to the role temperatures `temps`.
pub fn apply_rows(temps: &mut [f64], rows: &[Exchange], bodies: &Bodies, scheme: Scheme) {
    let mut scratch = SyncScratch::default();
    apply_rows_with(temps, rows, bodies, scheme, &mut scratch);
}

/// [`apply_rows`] with caller-owned scratch (streaming replays call it batch after batch;
/// a synchronous group split across two batches is completed by the next call, since the
/// pending deltas stay in `scratch` until the start step changes).
pub fn apply_rows_with(
    temps: &mut [f64],
    rows: &[Exchange],
    bodies: &Bodies,
    scheme: Scheme,
    scratch: &mut SyncScratch,
) {
    let n = bodies.particles() as u32;
    let wall_t = |j: u32| bodies.wall_temperature[(j - n) as usize];
    match scheme {
        Scheme::Explicit => {
            for e in rows {
                let (k, l) = (e.i as usize, e.j as usize);
                if e.j < n {
                    let q = e.conductance_time * (temps[k] - temps[l]);
                    temps[k] -= q * bodies.inverse_capacity[k];
                    temps[l] += q * bodies.inverse_capacity[l];
                } else if let Some(tw) = wall_t(e.j) {
                    temps[k] -= e.conductance_time * (temps[k] - tw) * bodies.inverse_capacity[k];
                }
            }
        }
        Scheme::Exact => {
            for e in rows {
                let (k, l) = (e.i as usize, e.j as usize);
                let ik = bodies.inverse_capacity[k];
                if e.j < n {
                    let il = bodies.inverse_capacity[l];
                    let d = temps[k] - temps[l];
                    // heat moved: the part of ΔT that relaxes, over (1/C_k + 1/C_l)
                    let q = -d * (-e.conductance_time * (ik + il)).exp_m1() / (ik + il);
                    temps[k] -= q * ik;
                    temps[l] += q * il;
                } else if let Some(tw) = wall_t(e.j) {
                    temps[k] = tw + (temps[k] - tw) * (-e.conductance_time * ik).exp();
                }
            }
        }
        Scheme::Synchronous => {
            if scratch.delta.len() != temps.len() {
                scratch.delta = vec![0.0; temps.len()];
            }
            let mut group_start = None;
            for e in rows {
                if group_start != Some(e.start_step) {
                    flush(temps, scratch);
                    group_start = Some(e.start_step);
                }
                let (k, l) = (e.i as usize, e.j as usize);
                let q = if e.j < n {
                    e.conductance_time * (temps[k] - temps[l])
                } else if let Some(tw) = wall_t(e.j) {
                    e.conductance_time * (temps[k] - tw)
                } else {
                    continue;
                };
                scratch.delta[k] -= q * bodies.inverse_capacity[k];
                scratch.touched.push(e.i);
                if e.j < n {
                    scratch.delta[l] += q * bodies.inverse_capacity[l];
                    scratch.touched.push(e.j);
                }
            }
            flush(temps, scratch);
        }
    }
}

/// Applies the pending synchronous deltas.
fn flush(temps: &mut [f64], scratch: &mut SyncScratch) {
    for &b in &scratch.touched {
        let b = b as usize;
        temps[b] += scratch.delta[b];
        scratch.delta[b] = 0.0;
    }
    scratch.touched.clear();
}
