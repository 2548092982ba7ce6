//! The three ways of applying a period's rows (docs/method.md §6). All conserve `Σ C T` between
//! particles; a wall row adds the heat the wall gives.

use super::roles::RoleTemperatures;
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
    pub fn flush(&mut self, temps: &mut RoleTemperatures) {
        for &b in &self.touched {
            let b = b as usize;
            temps.roles[b][0] += self.delta[b];
            self.delta[b] = 0.0;
        }
        self.touched.clear();
        self.group_start = None;
    }
}

/// Applies a whole period's `rows` (in apparition order) to the role temperatures `temps`.
pub fn apply_rows(temps: &mut [f64], rows: &Exchanges, bodies: &Bodies, scheme: Scheme) {
    let mut roles = RoleTemperatures::new(temps, bodies);
    let mut scratch = SyncScratch::default();
    apply_rows_with(&mut roles, rows, bodies, scheme, &mut scratch);
    scratch.flush(&mut roles);
    roles.write_to(temps);
}

/// Applies consecutive rows of a period with caller-owned scratch: a streaming replay calls
/// it batch after batch, and a synchronous group split between two batches stays pending in
/// `scratch` until the start step of a run of rows changes. End the period with [`SyncScratch::flush`].
pub fn apply_rows_with(
    temps: &mut RoleTemperatures,
    rows: &Exchanges,
    bodies: &Bodies,
    scheme: Scheme,
    scratch: &mut SyncScratch,
) {
    // one loop per lookup, monomorphised: the same operations on the same values in the same
    // order either way, so the same bits, but a monodisperse bed's loop loads no `1/C`
    match bodies.uniform_inverse_capacity() {
        Some(inverse) => apply(temps, rows, bodies, Uniform(inverse), scheme, scratch),
        None => apply(temps, rows, bodies, PerRole, scheme, scratch),
    }
}

/// How the loop finds a role's `1/C`, given the role's `[T, 1/C]`.
trait InverseCapacity: Copy {
    fn of(self, role: &[f64; 2]) -> f64;
}

/// Every particle's `1/C` is this one value.
#[derive(Clone, Copy)]
struct Uniform(f64);

impl InverseCapacity for Uniform {
    #[inline(always)]
    fn of(self, _role: &[f64; 2]) -> f64 {
        self.0
    }
}

/// Each role's own `1/C`, beside its temperature.
#[derive(Clone, Copy)]
struct PerRole;

impl InverseCapacity for PerRole {
    #[inline(always)]
    fn of(self, role: &[f64; 2]) -> f64 {
        role[1]
    }
}

/// [`apply_rows_with`] with the roles' `1/C` found by `inverse`.
fn apply(
    temps: &mut RoleTemperatures,
    rows: &Exchanges,
    bodies: &Bodies,
    inverse: impl InverseCapacity,
    scheme: Scheme,
    scratch: &mut SyncScratch,
) {
    let (runs, rows) = (rows.runs(), rows.rows());
    let n = bodies.particles() as u32;
    let wall_t = |j: u32| bodies.wall_temperature((j - n) as usize);
    let t = &mut temps.roles[..];
    match scheme {
        Scheme::Explicit => {
            for e in rows {
                let (k, l) = (e.i as usize, e.j as usize);
                if e.j < n {
                    let q = e.conductance_time * (t[k][0] - t[l][0]);
                    let ik = inverse.of(&t[k]);
                    t[k][0] -= q * ik;
                    let il = inverse.of(&t[l]);
                    t[l][0] += q * il;
                } else if let Some(tw) = wall_t(e.j) {
                    let ik = inverse.of(&t[k]);
                    t[k][0] -= e.conductance_time * (t[k][0] - tw) * ik;
                }
            }
        }
        Scheme::Exact => {
            for e in rows {
                let (k, l) = (e.i as usize, e.j as usize);
                let ik = inverse.of(&t[k]);
                if e.j < n {
                    let il = inverse.of(&t[l]);
                    let d = t[k][0] - t[l][0];
                    // heat moved: the part of ΔT that relaxes, over (1/C_k + 1/C_l)
                    let q = -d * (-e.conductance_time * (ik + il)).exp_m1() / (ik + il);
                    t[k][0] -= q * ik;
                    t[l][0] += q * il;
                } else if let Some(tw) = wall_t(e.j) {
                    t[k][0] = tw + (t[k][0] - tw) * (-e.conductance_time * ik).exp();
                }
            }
        }
        Scheme::Synchronous => {
            if scratch.delta.len() != t.len() {
                scratch.delta = vec![0.0; t.len()];
            }
            let mut from = 0;
            for run in runs {
                let to = from + run.rows as usize;
                if scratch.group_start != Some(run.start_step) {
                    scratch.flush(temps);
                    scratch.group_start = Some(run.start_step);
                }
                let t = &temps.roles[..];
                for e in &rows[from..to] {
                    let (k, l) = (e.i as usize, e.j as usize);
                    let q = if e.j < n {
                        e.conductance_time * (t[k][0] - t[l][0])
                    } else if let Some(tw) = wall_t(e.j) {
                        e.conductance_time * (t[k][0] - tw)
                    } else {
                        continue;
                    };
                    scratch.delta[k] -= q * inverse.of(&t[k]);
                    scratch.touched.push(e.i);
                    if e.j < n {
                        scratch.delta[l] += q * inverse.of(&t[l]);
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
        Bodies::new(capacity, vec![Some(350.0)])
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

    fn bits(temps: &RoleTemperatures) -> Vec<u64> {
        temps.temperatures().map(f64::to_bits).collect()
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
        let start = RoleTemperatures::new(&start, &bodies);
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
                assert_eq!(
                    bits(&streamed),
                    bits(&whole),
                    "{scheme:?}, batches of {batch} rows"
                );
            }
        }
    }

    /// Three periods of `rows` from `start` with `inverse` as the loop's lookup.
    fn three_periods(
        start: &RoleTemperatures,
        rows: &Exchanges,
        bodies: &Bodies,
        inverse: impl InverseCapacity,
        scheme: Scheme,
    ) -> RoleTemperatures {
        let mut temps = start.clone();
        let mut scratch = SyncScratch::default();
        for _period in 0..3 {
            apply(&mut temps, rows, bodies, inverse, scheme, &mut scratch);
            scratch.flush(&mut temps);
        }
        temps
    }

    /// [`three_periods`] with the lookup [`apply_rows_with`] chooses for `bodies`.
    fn three_periods_as_chosen(
        start: &RoleTemperatures,
        rows: &Exchanges,
        bodies: &Bodies,
        scheme: Scheme,
    ) -> RoleTemperatures {
        let mut temps = start.clone();
        let mut scratch = SyncScratch::default();
        for _period in 0..3 {
            apply_rows_with(&mut temps, rows, bodies, scheme, &mut scratch);
            scratch.flush(&mut temps);
        }
        temps
    }

    /// A monodisperse bed's loop uses one constant `1/C` and reads no role's own: the same
    /// bits as reading each role's. A polydisperse bed's loop reads each role's.
    #[test]
    fn a_uniform_inverse_capacity_gives_the_bits_of_the_per_role_ones_and_only_when_uniform() {
        let n = 40;
        let table = exchanges(&rows(n, 1000));
        let start: Vec<f64> = (0..n).map(|k| 10.0 + (k % 3) as f64 * 10.0).collect();
        let equal = Bodies::new(vec![0.07; n as usize], vec![Some(350.0)]);
        let uniform = equal.uniform_inverse_capacity().expect("equal capacities");
        assert_eq!(uniform, 1.0 / 0.07);
        let varied = bodies(n as usize);
        assert_eq!(varied.uniform_inverse_capacity(), None);
        for scheme in Scheme::ALL {
            let from = RoleTemperatures::new(&start, &equal);
            let per_role = three_periods(&from, &table, &equal, PerRole, scheme);
            let constant = three_periods(&from, &table, &equal, Uniform(uniform), scheme);
            assert_ne!(per_role, from, "{scheme:?}: the rows must change something");
            assert_eq!(bits(&constant), bits(&per_role), "{scheme:?}");
            let chosen = three_periods_as_chosen(&from, &table, &equal, scheme);
            assert_eq!(bits(&chosen), bits(&per_role), "{scheme:?}");

            // varied capacities: each role's own 1/C, not the first one's
            let from = RoleTemperatures::new(&start, &varied);
            let per_role = three_periods(&from, &table, &varied, PerRole, scheme);
            let first = Uniform(varied.inverse_capacity(0));
            let wrong = three_periods(&from, &table, &varied, first, scheme);
            assert_ne!(bits(&wrong), bits(&per_role), "{scheme:?}");
            let chosen = three_periods_as_chosen(&from, &table, &varied, scheme);
            assert_eq!(bits(&chosen), bits(&per_role), "{scheme:?}");
        }
    }

    /// The slice form of a whole period is the role form: the same bits.
    #[test]
    fn apply_rows_on_a_slice_gives_the_bits_of_the_role_temperatures() {
        let n = 40;
        let bodies = bodies(n as usize);
        let table = exchanges(&rows(n, 1000));
        let start: Vec<f64> = (0..n).map(|k| 10.0 + (k % 3) as f64 * 10.0).collect();
        for scheme in Scheme::ALL {
            let mut slice = start.clone();
            apply_rows(&mut slice, &table, &bodies, scheme);
            let mut roles = RoleTemperatures::new(&start, &bodies);
            let mut scratch = SyncScratch::default();
            apply_rows_with(&mut roles, &table, &bodies, scheme, &mut scratch);
            scratch.flush(&mut roles);
            let slice_bits: Vec<u64> = slice.iter().map(|t| t.to_bits()).collect();
            assert_eq!(slice_bits, bits(&roles), "{scheme:?}");
            assert_ne!(slice, start, "{scheme:?}");
        }
    }
}
