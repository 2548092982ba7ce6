//! The temperatures the replay carries, one per role, each stored beside its role's `1/C`:
//! every row reads both for each of its two bodies, at random, so they share a cache line.

use super::table::Bodies;
use super::{move_each_to_roles, ReplayError};

/// The role temperatures of a replay. A role's `1/C` is fixed (it is the particle of that id
/// in the recorded period); only the temperatures move between roles.
#[derive(Debug, Clone, PartialEq)]
pub struct RoleTemperatures {
    /// `[T, 1/C]` of each role. Measured on the 80 000-particle long kiln (AMD EPYC), the
    /// explicit loop over these pairs is faster than over two arrays of 8-byte values even
    /// when it reads no `1/C` at all (docs/benchmarks.md#what-each-accepted-change-bought).
    pub(super) roles: Vec<[f64; 2]>,
}

impl RoleTemperatures {
    /// The temperatures `temps` (K) of the particles of `bodies`, one per role.
    ///
    /// # Panics
    /// If there are not as many temperatures as particles (a caller's error, as an index
    /// out of range would be).
    pub fn new(temps: &[f64], bodies: &Bodies) -> Self {
        assert_eq!(
            temps.len(),
            bodies.particles(),
            "one temperature per particle"
        );
        let roles = temps
            .iter()
            .enumerate()
            .map(|(k, &t)| [t, bodies.inverse_capacity(k)])
            .collect();
        Self { roles }
    }

    pub fn len(&self) -> usize {
        self.roles.len()
    }

    pub fn is_empty(&self) -> bool {
        self.roles.is_empty()
    }

    /// The temperature of each role, in role order (K).
    pub fn temperatures(&self) -> impl ExactSizeIterator<Item = f64> + '_ {
        self.roles.iter().map(|role| role[0])
    }

    /// Copies the temperatures into `temps` (an output snapshot's, one per role).
    ///
    /// # Panics
    /// If `temps` does not hold one value per role.
    pub fn write_to(&self, temps: &mut [f64]) {
        assert_eq!(temps.len(), self.roles.len(), "one temperature per role");
        for (t, role) in temps.iter_mut().zip(&self.roles) {
            *t = role[0];
        }
    }

    /// Moves each temperature to the role its particle plays in the next period,
    /// `T'[g(a)] = T[a]` ([`super::move_to_roles`]), through `next`, a caller-owned buffer.
    pub fn move_to_roles(&mut self, g: &[u32], next: &mut Vec<f64>) -> Result<(), ReplayError> {
        move_each_to_roles(self.temperatures(), g, next)?;
        for (role, &t) in self.roles.iter_mut().zip(next.iter()) {
            role[0] = t;
        }
        Ok(())
    }

    /// `Σ C T` over the particles (J), as [`super::total_heat`] sums it.
    pub fn total_heat(&self, bodies: &Bodies) -> f64 {
        super::heat(self.temperatures(), bodies)
    }
}

#[cfg(test)]
mod tests {
    use super::super::move_to_roles;
    use super::*;

    #[test]
    fn temperatures_move_to_their_roles_and_each_role_keeps_its_own_inverse_capacity() {
        let bodies = Bodies::new(vec![1.0, 2.0, 4.0, 8.0], vec![]);
        let temps = [10.0, 20.0, 30.0, 40.0];
        let mut roles = RoleTemperatures::new(&temps, &bodies);
        let g = [2, 0, 3, 1];
        let mut next = Vec::new();
        roles.move_to_roles(&g, &mut next).unwrap();
        let mut expected = Vec::new();
        move_to_roles(&temps, &g, &mut expected).unwrap();
        assert_eq!(roles.temperatures().collect::<Vec<_>>(), expected);
        assert_eq!(expected, [20.0, 40.0, 10.0, 30.0]);
        let inverse: Vec<f64> = roles.roles.iter().map(|role| role[1]).collect();
        assert_eq!(inverse, [1.0, 0.5, 0.25, 0.125]);
        let mut out = [0.0; 4];
        roles.write_to(&mut out);
        assert_eq!(out, [20.0, 40.0, 10.0, 30.0]);
        assert_eq!(
            roles.total_heat(&bodies).to_bits(),
            super::super::total_heat(&out, &bodies).to_bits()
        );
        assert!(roles.move_to_roles(&g[..3], &mut next).is_err());
    }
}
