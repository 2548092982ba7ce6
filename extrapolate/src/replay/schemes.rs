//! The three ways of applying a period's rows (docs/method.md §6). All conserve `Σ C T` between
//! particles; a wall row adds the heat the wall gives.

use super::table::{Bodies, Exchange};

/// How the rows update the temperatures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
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

impl Scheme {
    pub const ALL: [Scheme; 3] = [Scheme::Explicit, Scheme::Exact, Scheme::Synchronous];

    /// The scheme's name on the command line and in the files.
    pub fn name(self) -> &'static str {
        match self {
            Scheme::Explicit => "explicit",
            Scheme::Exact => "exact",
            Scheme::Synchronous => "synchronous",
        }
    }
}

impl std::str::FromStr for Scheme {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Scheme::ALL
            .into_iter()
            .find(|scheme| scheme.name() == s)
            .ok_or_else(|| format!("unknown scheme '{s}': use explicit, exact or synchronous"))
    }
}

/// The synchronous scheme's group in progress: the deltas of the rows that started at
/// `group_start`, applied when a row with another start arrives or at [`Self::flush`].
#[derive(Debug, Default, Clone)]
pub struct SyncScratch {
    delta: Vec<f64>,
    touched: Vec<u32>,
    group_start: Option<u32>,
}

impl SyncScratch {
    /// Applies the pending group; call it at the end of every period.
    pub fn flush(&mut self, temps: &mut [f64]) {
        for &b in &self.touched {
            let b = b as usize;
            temps[b] += self.delta[b];
            self.delta[b] = 0.0;
        }
        self.touched.clear();
        self.group_start = None;
    }
}

/// Applies a whole period's `rows` (in apparition order) to the role temperatures `temps`.
pub fn apply_rows(temps: &mut [f64], rows: &[Exchange], bodies: &Bodies, scheme: Scheme) {
    let mut scratch = SyncScratch::default();
    apply_rows_with(temps, rows, bodies, scheme, &mut scratch);
    scratch.flush(temps);
}

/// Applies consecutive rows of a period with caller-owned scratch: a streaming replay calls
/// it batch after batch, and a synchronous group split between two batches stays pending in
/// `scratch` until its start step changes. End the period with [`SyncScratch::flush`].
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
            for e in rows {
                if scratch.group_start != Some(e.start_step) {
                    scratch.flush(temps);
                    scratch.group_start = Some(e.start_step);
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
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bodies: `n` particles of varied capacity and one wall at 350 K.
    fn bodies(n: usize) -> Bodies {
        let capacity: Vec<f64> = (0..n).map(|k| 0.05 + 0.01 * (k % 7) as f64).collect();
        Bodies {
            inverse_capacity: capacity.iter().map(|c| 1.0 / c).collect(),
            capacity,
            wall_temperature: vec![Some(350.0)],
        }
    }

    /// Rows in apparition order with runs of equal starts (synchronous groups) and wall rows.
    fn rows(n: u32, count: u32) -> Vec<Exchange> {
        (0..count)
            .map(|r| {
                let i = (r * 7919) % (n - 1);
                let j = if r % 11 == 0 {
                    n
                } else {
                    i + 1 + (r * 104_729) % (n - 1 - i)
                };
                Exchange {
                    i,
                    j,
                    start_step: r / 5,
                    conductance_time: 1e-4 * (1 + r % 13) as f64,
                }
            })
            .collect()
    }

    /// The streamed replay hands the rows over batch by batch (a synchronous group may
    /// straddle two batches); it must give the same bits as the whole table at once.
    #[test]
    fn a_period_applied_batch_by_batch_gives_the_same_bits_as_the_whole_table() {
        let n = 40;
        let bodies = bodies(n as usize);
        let table = rows(n, 1000);
        let start: Vec<f64> = (0..n).map(|k| 10.0 + (k % 3) as f64 * 10.0).collect();
        for scheme in Scheme::ALL {
            let mut whole = start.clone();
            let mut scratch = SyncScratch::default();
            for _period in 0..3 {
                apply_rows_with(&mut whole, &table, &bodies, scheme, &mut scratch);
                scratch.flush(&mut whole);
            }
            assert_ne!(whole, start, "{scheme:?}: the rows must change something");
            for batch in [1, 2, 7, 64, 333, 999] {
                let mut streamed = start.clone();
                let mut scratch = SyncScratch::default();
                for _period in 0..3 {
                    for chunk in table.chunks(batch) {
                        apply_rows_with(&mut streamed, chunk, &bodies, scheme, &mut scratch);
                    }
                    scratch.flush(&mut streamed);
                }
                let bits = |t: &[f64]| t.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(
                    bits(&streamed),
                    bits(&whole),
                    "{scheme:?}, batches of {batch} rows"
                );
            }
        }
    }
}
