//! Replay of a recorded collision table through the pairing (docs/method.md §6, Haydar
//! Algorithm 3): temperatures live per role, move to their new roles at each period
//! boundary, and every row exchanges heat between its two bodies.

pub mod memory;
mod roles;
mod schemes;
mod table;

pub use memory::{MemoryNeeds, MemoryPlan, ModeReason, TableMode};
pub use roles::RoleTemperatures;
pub use schemes::{apply_rows, apply_rows_with, Scheme, SyncScratch};
pub use table::{
    period_batches, scan, scan_period, Bodies, CflRow, Exchange, Exchanges, StartRun, Table,
    TableScan,
};

/// Why a table cannot be replayed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    #[error(
        "the explicit scheme is unstable on this table: row {row} (bodies {i} and {j}, m = {duration_steps} steps, sqrt(a) = {sqrt_area:.4e} m) has CFL number c = H m (1/C_k + 1/C_l) = {cfl:.4} ≥ 1; \
         the explicit scheme needs c < 1 on every row (c scales with m; the exact scheme is unconditionally stable)"
    )]
    Cfl {
        row: u64,
        i: u32,
        j: u32,
        duration_steps: u32,
        sqrt_area: f64,
        cfl: f64,
    },
    #[error("pairing of {got} roles for {expected} particles")]
    Roles { got: usize, expected: usize },
    #[error(
        "not enough memory: even with the table streamed from the file, {particles} particles need {} \
         (per-particle state {}, pairing {}, buffers {}), more than the limit of {} ({limit_source}); \
         the replay needs a limit of at least {}",
        memory::human_bytes(*needed),
        memory::human_bytes(*particle_bytes),
        if *pairing_bytes == 0 { "stored".to_string() } else { memory::human_bytes(*pairing_bytes) },
        memory::human_bytes(*buffer_bytes),
        memory::human_bytes(*limit),
        memory::human_bytes(*needed)
    )]
    Memory {
        particles: u64,
        needed: u64,
        particle_bytes: u64,
        pairing_bytes: u64,
        buffer_bytes: u64,
        limit: u64,
        limit_source: String,
    },
}

impl CflRow {
    /// The explicit scheme's refusal of a table whose worst row is this one.
    pub fn refusal(&self) -> ReplayError {
        ReplayError::Cfl {
            row: self.row,
            i: self.i,
            j: self.j,
            duration_steps: self.duration_steps,
            sqrt_area: self.sqrt_area,
            cfl: self.cfl,
        }
    }
}

/// Moves what role `a` holds (a temperature, or the id of the particle playing it) to the
/// role it plays in the next period: `next[g[a]] = temps[a]`.
pub fn move_to_roles<T: Copy + Default>(
    temps: &[T],
    g: &[u32],
    next: &mut Vec<T>,
) -> Result<(), ReplayError> {
    move_each_to_roles(temps.iter().copied(), g, next)
}

/// [`move_to_roles`] of the values `held`, one per role in role order.
fn move_each_to_roles<T: Copy + Default>(
    held: impl ExactSizeIterator<Item = T>,
    g: &[u32],
    next: &mut Vec<T>,
) -> Result<(), ReplayError> {
    if g.len() != held.len() {
        return Err(ReplayError::Roles {
            got: g.len(),
            expected: held.len(),
        });
    }
    next.clear();
    next.resize(g.len(), T::default());
    for (t, &to) in held.zip(g) {
        next[to as usize] = t;
    }
    Ok(())
}

/// `Σ C T` over the particles (J).
pub fn total_heat(temps: &[f64], bodies: &Bodies) -> f64 {
    heat(temps.iter().copied(), bodies)
}

/// [`total_heat`] of the temperatures `temps`, one per particle in order.
fn heat(temps: impl Iterator<Item = f64>, bodies: &Bodies) -> f64 {
    temps.zip(bodies.capacity()).map(|(t, c)| t * c).sum()
}
