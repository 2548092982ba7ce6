//! The three ways of applying a period's rows (docs/method.md §6). All conserve `Σ C T` between
//! particles; a wall row adds the heat the wall gives.

use super::table::{Bodies, Exchanges};

pub use tdex_format::Scheme;

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
pub fn apply_rows(temps: &mut [f64], rows: &Exchanges, bodies: &Bodies, scheme: Scheme) {
    let mut scratch = SyncScratch::default();
    apply_rows_with(temps, rows, bodies, scheme, &mut scratch);
    scratch.flush(temps);
}

/// Applies consecutive rows of a period with caller-owned scratch: a streaming replay calls
/// it batch after batch, and a synchronous group split between two batches stays pending in
/// `scratch` until the start step of a run of rows changes. End the period with [`SyncScratch::flush`].
pub fn apply_rows_with(
    temps: &mut [f64],
    rows: &Exchanges,
    bodies: &Bodies,
    scheme: Scheme,
    scratch: &mut SyncScratch,
) {
    let (runs, rows) = (rows.runs(), rows.rows());
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
            let mut from = 0;
            for run in runs {
                let to = from + run.rows as usize;
                if scratch.group_start != Some(run.start_step) {
                    scratch.flush(temps);
                    scratch.group_start = Some(run.start_step);
                }
                for e in &rows[from..to] {
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
                from = to;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::table::Exchange;
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

    /// Rows in apparition order with their starts, in runs of equal starts (synchronous
    /// groups), and wall rows.
    fn rows(n: u32, count: u32) -> Vec<(Exchange, u32)> {
        (0..count)
            .map(|r| {
                let i = (r * 7919) % (n - 1);
                let j = if r % 11 == 0 {
                    n
                } else {
                    i + 1 + (r * 104_729) % (n - 1 - i)
                };
                let e = Exchange {
                    i,
                    j,
                    conductance_time: 1e-4 * (1 + r % 13) as f64,
                };
                (e, r / 5)
            })
            .collect()
    }

    fn exchanges(rows: &[(Exchange, u32)]) -> Exchanges {
        let mut exchanges = Exchanges::default();
        for &(e, start) in rows {
            exchanges.push(e, start);
        }
        exchanges
    }

    /// The streamed replay hands the rows over batch by batch (a synchronous group may
    /// straddle two batches); it must give the same bits as the whole table at once.
    #[test]
    fn a_period_applied_batch_by_batch_gives_the_same_bits_as_the_whole_table() {
        let n = 40;
        let bodies = bodies(n as usize);
        let table = rows(n, 1000);
        let whole_table = exchanges(&table);
        assert_eq!(whole_table.runs().len(), 200);
        assert_eq!(whole_table.len(), 1000);
        let start: Vec<f64> = (0..n).map(|k| 10.0 + (k % 3) as f64 * 10.0).collect();
        for scheme in Scheme::ALL {
            let mut whole = start.clone();
            let mut scratch = SyncScratch::default();
            for _period in 0..3 {
                apply_rows_with(&mut whole, &whole_table, &bodies, scheme, &mut scratch);
                scratch.flush(&mut whole);
            }
            assert_ne!(whole, start, "{scheme:?}: the rows must change something");
            for batch in [1, 2, 7, 64, 333, 999] {
                let mut streamed = start.clone();
                let mut scratch = SyncScratch::default();
                for _period in 0..3 {
                    for chunk in table.chunks(batch) {
                        let chunk = exchanges(chunk);
                        apply_rows_with(&mut streamed, &chunk, &bodies, scheme, &mut scratch);
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
