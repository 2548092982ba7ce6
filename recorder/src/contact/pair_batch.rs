//! Touching sphere–sphere pairs gathered into lanes and evaluated together.
//!
//! The contact scan's overlap test is a coin toss for the branch predictor; when the law runs
//! right behind it, every miss throws away the law's long chain of roots and divisions in
//! flight. Gathered here, the law runs over a batch without a branch (`hertz_mindlin` keeps
//! both outcomes of each cap and selects), several contacts per instruction, as wide as the
//! CPU allows ([`Simd`]): on AVX-512 the compiler vectorises the lane loop eight wide; on
//! AVX2, where its cost model declines to, the law runs on four-lane registers (`F64x4`).
//! Every lane does the same IEEE operations as a lone contact would, so the results do not
//! depend on the width.

use super::contact_sphere_sphere::{self as sphere_sphere, SphereState};
use super::{hertz_mindlin, ContactHistory, PairLaw};
use crate::case::RollingModel;
use crate::heat::ConductionLaw;
use crate::math::*;
use crate::simd::Simd;
#[cfg(target_arch = "x86_64")]
use f64x4::F64x4;

// private to this stage: only its AVX2 build makes these values, once the CPU is known to
// have AVX (`PairBatch::with_simd`)
#[cfg(target_arch = "x86_64")]
mod f64x4;

/// Contacts evaluated together: two AVX-512 vectors of doubles.
pub const LANES: usize = 16;
/// Contacts a batch can hold: a full batch and one vector of pushes beyond it (the vector
/// scan pushes up to 8 at once).
const CAPACITY: usize = LANES + 8;

/// The per-particle arrays the law reads.
#[derive(Clone, Copy)]
pub struct SphereArrays<'a> {
    pub pos: &'a [Vec3],
    pub vel: &'a [Vec3],
    pub omega: &'a [Vec3],
    pub radius: &'a [f64],
    pub mass: &'a [f64],
    pub temp: &'a [f64],
}

/// What the law gives each contact of a batch: the force on the holder (the partner gets its
/// negative), both torques, and the heat flow into the holder.
#[derive(Debug, Clone, Copy)]
pub struct PairResponse {
    pub force: Vec3,
    pub torque_holder: Vec3,
    pub torque_partner: Vec3,
    pub heat_flow: f64,
}

/// Touching pairs, one array per field so each lane loop reads a vector; the first
/// [`LANES`] are evaluated together.
pub struct PairBatch {
    /// The instructions the law runs with.
    simd: Simd,
    len: usize,
    /// Contacts evaluated by the last `evaluate` (the first ones pushed).
    ready: usize,
    /// Contacts evaluated since the batch was made: the next evaluated contact's history
    /// goes to this index of the new histories.
    evaluated: usize,
    holder: [u32; CAPACITY],
    partner: [u32; CAPACITY],
    /// Index of the pair's history before this step in the old histories handed to
    /// `evaluate` (a pair that has just touched points at a zero history).
    old: [u32; CAPACITY],
    delta: [[f64; CAPACITY]; 3],
    r2: [f64; CAPACITY],
    lanes: Lanes,
}

/// The law's inputs and outputs in structure-of-arrays form.
struct Lanes {
    vel_i: [[f64; LANES]; 3],
    vel_j: [[f64; LANES]; 3],
    omega_i: [[f64; LANES]; 3],
    omega_j: [[f64; LANES]; 3],
    radius_i: [f64; LANES],
    radius_j: [f64; LANES],
    r_eff: [f64; LANES],
    m_eff: [f64; LANES],
    temp_diff: [f64; LANES],
    shear: [[f64; LANES]; 3],
    roll: [[f64; LANES]; 3],
    force: [[f64; LANES]; 3],
    torque_i: [[f64; LANES]; 3],
    torque_j: [[f64; LANES]; 3],
    heat_flow: [f64; LANES],
}

impl Default for PairBatch {
    /// A batch whose law runs with the instructions the engine uses ([`Simd::in_use`]).
    fn default() -> Self {
        Self::with_simd(Simd::in_use())
    }
}

impl PairBatch {
    /// A batch whose law runs with `simd`, which this CPU must have.
    pub fn with_simd(simd: Simd) -> Self {
        assert!(simd <= Simd::detected(), "{simd:?} is not on this CPU");
        let zero = [0.0; LANES];
        Self {
            simd,
            len: 0,
            ready: 0,
            evaluated: 0,
            holder: [0; CAPACITY],
            partner: [0; CAPACITY],
            old: [0; CAPACITY],
            delta: [[0.0; CAPACITY]; 3],
            r2: [0.0; CAPACITY],
            lanes: Lanes {
                vel_i: [zero; 3],
                vel_j: [zero; 3],
                omega_i: [zero; 3],
                omega_j: [zero; 3],
                radius_i: zero,
                radius_j: zero,
                r_eff: zero,
                m_eff: zero,
                temp_diff: zero,
                shear: [zero; 3],
                roll: [zero; 3],
                force: [zero; 3],
                torque_i: [zero; 3],
                torque_j: [zero; 3],
                heat_flow: zero,
            },
        }
    }
}

/// Constants of one evaluation.
#[derive(Clone, Copy)]
pub struct PairConstants<'a> {
    pub law: &'a PairLaw,
    pub heat: &'a ConductionLaw,
    pub dt: f64,
    /// `(R*, m*)` of every pair when all spheres are equal.
    pub uniform_pair: Option<(f64, f64)>,
}

impl PairBatch {
    /// Adds the touching pair `(holder, partner)` whose centres are `delta` apart (`r2` its
    /// squared length) and whose history was `old`; true when the batch is full.
    #[inline(always)]
    pub fn push(
        &mut self,
        holder: usize,
        partner: usize,
        old: usize,
        delta: Vec3,
        r2: f64,
    ) -> bool {
        let l = self.len;
        self.holder[l] = holder as u32;
        self.partner[l] = partner as u32;
        self.old[l] = old as u32;
        for (d, &x) in self.delta.iter_mut().zip(&delta) {
            d[l] = x;
        }
        self.r2[l] = r2;
        self.len += 1;
        self.len >= LANES
    }

    /// Adds the lanes of `hit` among 8 entries of `holder` (partner slots, old history
    /// indices, centre distances `delta` and their squared lengths `r2`), keeping their
    /// order; true when the batch is full. The batch must not be full before.
    ///
    /// # Safety
    ///
    /// The CPU must have AVX-512F and AVX-512VL (the caller checks with
    /// `is_x86_feature_detected!` before taking this path).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl")]
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub fn push_lanes(
        &mut self,
        hit: std::arch::x86_64::__mmask8,
        holder: usize,
        partner: std::arch::x86_64::__m256i,
        old: std::arch::x86_64::__m256i,
        delta: [std::arch::x86_64::__m512d; 3],
        r2: std::arch::x86_64::__m512d,
    ) -> bool {
        use std::arch::x86_64::*;
        let l = self.len;
        debug_assert!(l < LANES);
        // every store writes 8 lanes (room is left for them); only the hits count, and the
        // next push or evaluation overwrites the rest
        // SAFETY: l + 8 <= CAPACITY, so each store stays inside its array
        unsafe {
            let stored = |a: &mut [u32; CAPACITY]| a.as_mut_ptr().add(l) as *mut __m256i;
            _mm256_storeu_si256(stored(&mut self.holder), _mm256_set1_epi32(holder as i32));
            _mm256_storeu_si256(
                stored(&mut self.partner),
                _mm256_maskz_compress_epi32(hit, partner),
            );
            _mm256_storeu_si256(stored(&mut self.old), _mm256_maskz_compress_epi32(hit, old));
            for (a, d) in self.delta.iter_mut().zip(delta) {
                _mm512_storeu_pd(a.as_mut_ptr().add(l), _mm512_maskz_compress_pd(hit, d));
            }
            _mm512_storeu_pd(
                self.r2.as_mut_ptr().add(l),
                _mm512_maskz_compress_pd(hit, r2),
            );
        }
        self.len += hit.count_ones() as usize;
        self.len >= LANES
    }

    /// Evaluates the first [`LANES`] contacts pushed (all if fewer): their histories are
    /// read from `old` and the advanced ones written to `new`, in the order the contacts
    /// were pushed (the batch's `k`-th evaluated contact to `new[k]`). Their responses are
    /// then read with [`PairBatch::response`], and [`PairBatch::consume`] removes them.
    pub fn evaluate(
        &mut self,
        constants: &PairConstants,
        spheres: &SphereArrays,
        old: &[ContactHistory],
        new: &mut [ContactHistory],
    ) {
        let n = self.len.min(LANES);
        self.ready = n;
        if n == 0 {
            return;
        }
        self.gather(n, constants, spheres, old);
        run_lanes(
            self.simd,
            &mut self.lanes,
            &self.delta,
            &self.r2,
            n,
            constants,
        );
        let lanes = &self.lanes;
        let new = &mut new[self.evaluated..self.evaluated + n];
        for (l, history) in new.iter_mut().enumerate() {
            *history = ContactHistory {
                shear: lane3(&lanes.shear, l),
                roll: lane3(&lanes.roll, l),
            };
        }
    }

    /// The instructions the batch's law runs with, one this CPU has: the scan that fills the
    /// batch takes the same.
    #[inline(always)]
    pub fn simd(&self) -> Simd {
        self.simd
    }

    /// Contacts in the batch.
    #[inline(always)]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Contacts evaluated by the last [`PairBatch::evaluate`].
    #[inline(always)]
    pub fn ready(&self) -> usize {
        self.ready
    }

    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Holder slot, partner slot and response of the `l`-th contact pushed.
    #[inline(always)]
    pub fn response(&self, l: usize) -> (usize, usize, PairResponse) {
        let lanes = &self.lanes;
        let response = PairResponse {
            force: lane3(&lanes.force, l),
            torque_holder: lane3(&lanes.torque_i, l),
            torque_partner: lane3(&lanes.torque_j, l),
            heat_flow: lanes.heat_flow[l],
        };
        (self.holder[l] as usize, self.partner[l] as usize, response)
    }

    /// Holder, partner, old history index, `delta` and `r2` of the `l`-th contact pushed.
    #[cfg(test)]
    pub(crate) fn pushed(&self, l: usize) -> (u32, u32, u32, Vec3, f64) {
        assert!(l < self.len);
        let delta = lane3(&self.delta, l);
        (
            self.holder[l],
            self.partner[l],
            self.old[l],
            delta,
            self.r2[l],
        )
    }

    /// Removes the evaluated contacts; those pushed after them move to the front.
    pub fn consume(&mut self) {
        self.skip(self.ready);
    }

    /// Removes the first `ready` contacts pushed (they count as evaluated).
    pub(crate) fn skip(&mut self, ready: usize) {
        let len = self.len;
        assert!(ready <= len);
        if len > ready {
            let rest = ready..len;
            self.holder.copy_within(rest.clone(), 0);
            self.partner.copy_within(rest.clone(), 0);
            self.old.copy_within(rest.clone(), 0);
            for d in &mut self.delta {
                d.copy_within(rest.clone(), 0);
            }
            self.r2.copy_within(rest, 0);
        }
        self.len = len - ready;
        self.ready = 0;
        self.evaluated += ready;
    }

    /// Copies the first `n` lanes' sphere states and old histories into the lane arrays.
    fn gather(
        &mut self,
        n: usize,
        constants: &PairConstants,
        spheres: &SphereArrays,
        old: &[ContactHistory],
    ) {
        let lanes = &mut self.lanes;
        for l in 0..n {
            let (i, j) = (self.holder[l] as usize, self.partner[l] as usize);
            let h = &old[self.old[l] as usize];
            for a in 0..3 {
                lanes.vel_i[a][l] = spheres.vel[i][a];
                lanes.vel_j[a][l] = spheres.vel[j][a];
                lanes.omega_i[a][l] = spheres.omega[i][a];
                lanes.omega_j[a][l] = spheres.omega[j][a];
                lanes.shear[a][l] = h.shear[a];
                lanes.roll[a][l] = h.roll[a];
            }
            let (ri, rj) = (spheres.radius[i], spheres.radius[j]);
            lanes.radius_i[l] = ri;
            lanes.radius_j[l] = rj;
            let (r_eff, m_eff) = constants.uniform_pair.unwrap_or_else(|| {
                sphere_sphere::effective(ri, rj, spheres.mass[i], spheres.mass[j])
            });
            lanes.r_eff[l] = r_eff;
            lanes.m_eff[l] = m_eff;
            lanes.temp_diff[l] = spheres.temp[j] - spheres.temp[i];
        }
    }
}

/// Lane `l` of three lane arrays.
#[inline(always)]
fn lane3<const N: usize>(a: &[[f64; N]; 3], l: usize) -> Vec3 {
    [a[0][l], a[1][l], a[2][l]]
}

/// Runs the law over the first `n` lanes with the instructions `simd`.
fn run_lanes(
    simd: Simd,
    lanes: &mut Lanes,
    delta: &[[f64; CAPACITY]; 3],
    r2: &[f64; CAPACITY],
    n: usize,
    constants: &PairConstants,
) {
    macro_rules! with_model {
        ($f:ident, $lane:ty) => {
            match constants.law.rolling_model {
                RollingModel::Epsd2 => $f::<EPSD2, $lane>(lanes, delta, r2, n, constants),
                RollingModel::Cdt => $f::<CDT, $lane>(lanes, delta, r2, n, constants),
                RollingModel::Off => $f::<OFF, $lane>(lanes, delta, r2, n, constants),
            }
        };
    }
    match simd {
        // the one-contact loop, which the compiler vectorises eight wide for AVX-512
        // SAFETY: a batch's `simd` is one the CPU has (`PairBatch::with_simd`)
        #[cfg(target_arch = "x86_64")]
        Simd::Avx512 => unsafe { with_model!(lanes_avx512, f64) },
        // four contacts per register: the compiler would leave the one-contact loop's AVX2
        // build scalar (docs/benchmarks.md#the-dem-engine-against-liggghts-38)
        // SAFETY: as above
        #[cfg(target_arch = "x86_64")]
        Simd::Avx2 => unsafe { with_model!(lanes_avx2, F64x4) },
        _ => with_model!(law_lanes, f64),
    }
}

const EPSD2: u8 = 0;
const CDT: u8 = 1;
const OFF: u8 = 2;

/// What the lane loop runs on: `WIDTH` contacts' values, read from the start of a lane
/// array's slice and written back there.
pub(super) trait Lane: Real {
    const WIDTH: usize;
    fn load(a: &[f64]) -> Self;
    fn store(self, a: &mut [f64]);
}

impl Lane for f64 {
    const WIDTH: usize = 1;
    #[inline(always)]
    fn load(a: &[f64]) -> Self {
        a[0]
    }
    #[inline(always)]
    fn store(self, a: &mut [f64]) {
        a[0] = self;
    }
}

/// `law_lanes` compiled for a CPU feature (called only once the feature is detected).
macro_rules! law_lanes_for {
    ($name:ident, $feature:literal) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feature)]
        fn $name<const MODEL: u8, T: Lane>(
            lanes: &mut Lanes,
            delta: &[[f64; CAPACITY]; 3],
            r2: &[f64; CAPACITY],
            n: usize,
            constants: &PairConstants,
        ) {
            law_lanes::<MODEL, T>(lanes, delta, r2, n, constants)
        }
    };
}
law_lanes_for!(lanes_avx512, "avx512f");
law_lanes_for!(lanes_avx2, "avx2");

/// The law for lanes `0..n`, `T::WIDTH` contacts at a time: the same functions a lone
/// contact goes through, inlined into a loop without branches. The lanes from `n` up to the
/// next multiple of the width are evaluated too, on whatever the arrays hold there, and
/// never read.
#[inline(always)]
fn law_lanes<const MODEL: u8, T: Lane>(
    lanes: &mut Lanes,
    delta: &[[f64; CAPACITY]; 3],
    r2: &[f64; CAPACITY],
    n: usize,
    constants: &PairConstants,
) {
    let model = match MODEL {
        EPSD2 => RollingModel::Epsd2,
        CDT => RollingModel::Cdt,
        _ => RollingModel::Off,
    };
    let PairConstants { law, heat, dt, .. } = *constants;
    let n = n.min(LANES);
    for chunk in 0..n.div_ceil(T::WIDTH) {
        let l = chunk * T::WIDTH;
        let at = |a: &[f64]| T::load(&a[l..]);
        let at3 = |a: &[[f64; LANES]; 3]| [at(&a[0]), at(&a[1]), at(&a[2])];
        let si = SphereState {
            pos: [T::splat(0.0); 3], // the kinematics read only `delta`
            vel: at3(&lanes.vel_i),
            omega: at3(&lanes.omega_i),
            radius: at(&lanes.radius_i),
            mass: T::splat(0.0), // (R*, m*) come in lane arrays
        };
        let sj = SphereState {
            vel: at3(&lanes.vel_j),
            omega: at3(&lanes.omega_j),
            radius: at(&lanes.radius_j),
            ..si
        };
        let c = sphere_sphere::kinematics(
            &si,
            &sj,
            [at(&delta[0]), at(&delta[1]), at(&delta[2])],
            at(r2),
            (at(&lanes.r_eff), at(&lanes.m_eff)),
        );
        let mut history = ContactHistory {
            shear: at3(&lanes.shear),
            roll: at3(&lanes.roll),
        };
        let resp = hertz_mindlin::respond_with(model, law, &c.kinematics, &mut history, dt);
        let torque_i = resp.torque_on_i(c.lever_i);
        let torque_j = resp.torque_on_partner(c.lever_j);
        let conductance = T::splat(heat.pair_conductivity)
            * heat.pair_area(c.distance, si.radius, sj.radius).sqrt();
        let heat_flow = conductance * at(&lanes.temp_diff);
        for a in 0..3 {
            history.shear[a].store(&mut lanes.shear[a][l..]);
            history.roll[a].store(&mut lanes.roll[a][l..]);
            resp.force[a].store(&mut lanes.force[a][l..]);
            torque_i[a].store(&mut lanes.torque_i[a][l..]);
            torque_j[a].store(&mut lanes.torque_j[a][l..]);
        }
        heat_flow.store(&mut lanes.heat_flow[l..]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::ContactArea;
    use crate::contact::pair_sample::{sample_heat, sample_law, PairSample};

    #[test]
    fn a_batch_gives_every_contact_the_bits_it_gets_alone() {
        // every build this CPU can run: the scalar loop, AVX2's four-lane registers and the
        // AVX-512 build of the loop
        for simd in Simd::available() {
            batch_against_lone_contacts(simd);
        }
    }

    fn batch_against_lone_contacts(simd: Simd) {
        for model in [RollingModel::Epsd2, RollingModel::Cdt, RollingModel::Off] {
            for area in [ContactArea::Overlap, ContactArea::Hertz] {
                let law = sample_law(model);
                let heat = sample_heat(area);
                let constants = PairConstants {
                    law: &law,
                    heat: &heat,
                    dt: 1e-4,
                    uniform_pair: None,
                };
                // 37 pairs: two full batches and a part-filled one
                let sample = PairSample::random(7, 37);
                let spheres = sample.spheres();
                let SphereArrays {
                    pos,
                    vel,
                    omega,
                    radius,
                    mass,
                    temp,
                } = spheres;
                let start = &sample.history;
                let mut batched = vec![ContactHistory::default(); start.len()];
                let mut responses = vec![];
                let mut batch = PairBatch::with_simd(simd);
                let mut evaluate = |batch: &mut PairBatch| {
                    batch.evaluate(&constants, &spheres, start, &mut batched);
                    responses.extend((0..batch.ready()).map(|l| batch.response(l)));
                    batch.consume();
                };
                for p in 0..start.len() {
                    let delta = sub(pos[2 * p], pos[2 * p + 1]);
                    if batch.push(2 * p, 2 * p + 1, p, delta, norm2(delta)) {
                        evaluate(&mut batch);
                    }
                }
                evaluate(&mut batch);
                assert_eq!(responses.len(), start.len());

                let (mut sliding, mut capped) = (0, 0);
                for (p, &(i, j, r)) in responses.iter().enumerate() {
                    assert_eq!((i, j), (2 * p, 2 * p + 1));
                    let state = |k: usize| SphereState {
                        pos: pos[k],
                        vel: vel[k],
                        omega: omega[k],
                        radius: radius[k],
                        mass: mass[k],
                    };
                    let (si, sj) = (state(i), state(j));
                    let delta = sub(si.pos, sj.pos);
                    let eff = sphere_sphere::effective(si.radius, sj.radius, si.mass, sj.mass);
                    let c = sphere_sphere::kinematics(&si, &sj, delta, norm2(delta), eff);
                    let mut alone = start[p];
                    let resp = hertz_mindlin::respond(&law, &c.kinematics, &mut alone, 1e-4);
                    let flow = heat.pair_conductivity
                        * heat.pair_area(c.distance, si.radius, sj.radius).sqrt()
                        * (temp[j] - temp[i]);
                    let bits = |v: Vec3| v.map(f64::to_bits);
                    assert_eq!(
                        bits(r.force),
                        bits(resp.force),
                        "{simd:?} {model:?} pair {p}"
                    );
                    assert_eq!(bits(r.torque_holder), bits(resp.torque_on_i(c.lever_i)));
                    assert_eq!(
                        bits(r.torque_partner),
                        bits(resp.torque_on_partner(c.lever_j))
                    );
                    assert_eq!(r.heat_flow.to_bits(), flow.to_bits());
                    assert_eq!(bits(batched[p].shear), bits(alone.shear));
                    assert_eq!(bits(batched[p].roll), bits(alone.roll));
                    // a sliding contact's tangential force is at the Coulomb limit
                    let en = c.kinematics.normal;
                    let fn_mag = dot(resp.force, en);
                    let ft = norm2(tangential(resp.force, en)).sqrt();
                    sliding += usize::from((ft - law.friction * fn_mag.abs()).abs() < 1e-9 * ft);
                    // a capped rolling spring is at μr R* |Fn|
                    let m_max = law.rolling_friction * c.kinematics.r_eff * fn_mag.abs();
                    let m = norm2(alone.roll).sqrt();
                    capped += usize::from((m - m_max).abs() < 1e-9 * m_max);
                }
                // the sample holds both outcomes of each cap
                assert!(
                    sliding > 0 && sliding < start.len(),
                    "{model:?}: {sliding} sliding"
                );
                if model == RollingModel::Epsd2 {
                    assert!(capped > 0 && capped < start.len(), "{capped} capped");
                }
            }
        }
    }
}
