//! The step kernel with two-spring damage and plasticity (docs/model.md §2, §6–9) on the slot layout.
//!
//! Same shape as the elastic kernel (`kernel.rs`): two gather passes, parallel over particles,
//! no scatter and no allocation, so results do not depend on the thread count. State variables
//! (w_t, w_c, the plastic stretch states) have a committed value, read by both passes of a
//! step, and a trial value written by pass 1; [`DamageKernel::commit`] swaps them once per step
//! (reading B of docs/model.md §4: elastic forces from the current positions, state variables from
//! the previous step).
//!
//! 1. Each particle, from its slots: elastic stretch S_e = S_T − ½(S_Ps,ij + S_Ps,ji) (3.38),
//!    damage factor d (3.37), bθ_i = b_i·Σ_m √d_im·S_e,im; then strain, criteria stress,
//!    damage and plastic flow → trial state.
//!    Where the law's bond factor is the two springs in series ([`DamageLaw::SERIES_DAMAGE`])
//!    and the CPU has AVX, the slot loop runs four particles at a time (`avx::slot_block`,
//!    bit-identical to `slot_pass`; `tests::pass_state_simd_matches_scalar_bitwise`).
//!    Pass 1 leaves each slot's d·(a_i + a_j)·S_e and d in the slot cache ([`SlotCache`],
//!    blocks of four particles).
//! 2. Each particle gathers F_b,ij = ½(d_ij·(a_i + a_j)·S_e,ij + √d_ij·(bθ_i + bθ_j)) along
//!    e_ij, with the bond damper scaled by d_ij, and integrates; e_ij and √d_ij are
//!    recomputed as pass 1 computed them. With AVX, four particles at a time
//!    (`avx::force_block`, for any law: it reads only the slot cache and the positions),
//!    bit-identical to `particle_force` (the same test, three whole steps); the
//!    central-difference update is four lanes wide in 2D and lane by lane in 3D.
//!
//! **Decision (erratum to (3.36)).** As written, F_s,ij = d_ij·a·S_e,ij + b·Σ_m d_im·S_e,im
//! leaves the dilatation term on a bond whose particle is fully damaged: a broken particle i
//! still feels ½·b_j·θ_j from each neighbour j, although the source states (its point 4
//! after (3.37)) that the bond force then vanishes. Multiplying the whole force state by d_ij
//! would fix that but scale the b-term by d² under uniform damage, so a uniformly damaged
//! particle would not carry (1−w) of its elastic stress (measured: tension peaks 4–6% above
//! f't·A). The kernel uses
//!   F_s,ij = d_ij·a·S_e,ij + √d_ij·b·Σ_m √d_im·S_e,im,
//! which (i) is (3.8) without damage, (ii) is exactly d·(3.8) when all bonds share one d
//! (as (3.36) is), (iii) vanishes on a broken bond from both ends, and (iv) derives from the
//! energy ¼·Σ_i[a·Σ_k L0·d_k·S_k² + b·(Σ_k √d_k·S_k)(Σ_k L0·√d_k·S_k)], so that the energy
//! balance closes (tests/suite/concrete.rs).
//!
//! The damage law itself (initiation, softening, compressive damage, plasticity) is behind
//! the `model::damage_law::DamageLaw` trait; the two-spring concrete law
//! (`model::two_spring`) is one implementation. This kernel computes the kinematics, asks the
//! law for each bond's damage factor and each particle's new state, and moves the particles.

use super::mechanics::Mechanics;
use super::KernelSet;
use crate::aligned::{copied, filled, Aligned};
use crate::discretise::{Particles, NONE};
pub use crate::model::damage_law::ParticleDamage;
use crate::model::damage_law::{DamageLaw, Kernel};
use crate::model::dimension::{Dim, Dimension, Tensor};
use crate::model::two_spring::TwoSpring;
use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

#[cfg(target_arch = "x86_64")]
mod avx;
mod passes;
mod recovery;
mod stiffness;
#[cfg(test)]
mod tests;

use passes::{slot, slot_cache_len, FIELDS};
pub use passes::{step, SlotCache};
pub use recovery::{internal_energy, particle_strain, particle_stress};
pub use stiffness::{internal_forces, secant_stiffness};

/// Bytes per particle the damage kernel ([`Concrete`]) allocates beside the elastic run's
/// (`discretise::bytes_per_particle`), counted field by field: the strain projector
/// (D(D+1)/2 × K f64), the committed and trial plastic stretch states (2·K f64), the slot
/// cache (2·K f64), the reverse slots (K u8), the committed and trial law states (2 × 32 B)
/// and the length scale (f64). D = 2, K = 6: 414 B; D = 3, K = 18 (FCC): 1530 B.
pub const fn bytes_per_particle(d: usize, k: usize) -> usize {
    (d * (d + 1) / 2 + 2 + FIELDS) * k * 8 + k + 2 * std::mem::size_of::<ParticleDamage>() + 8
}

/// The band of elastic stretch |S_e| ≤ 1e-7 (a thousandth of concrete's cracking strain)
/// within which a held bond keeps its branch at a commit ([`DamageKernel::frozen`]): where an
/// equilibrium puts a damaged bond at S_e = 0 its force is set-valued (the tensile and the
/// compressive damage give different dilatation forces there), and flipping its branch at
/// every commit would never settle (measured on the tension block after its peak: 2–4 flips
/// at every commit for 20,000 iterations).
pub const BRANCH_BAND: f64 = 1e-7;

/// Damage and plasticity of a run: the law, the per-particle geometry the kernel needs, and
/// the committed and trial state.
#[derive(Clone, Debug)]
pub struct DamageKernel<const D: usize, const K: usize, L: DamageLaw<D, K> = TwoSpring<D>>
where
    Dim<D>: Dimension<D>,
{
    pub law: L,
    /// Least-squares strain projector of each particle (reference bond directions).
    pub fit: Vec<<Dim<D> as Dimension<D>>::StrainFit<K>>,
    pub reverse: Vec<[u8; K]>,
    /// Each particle's length scale L0,i (m; the body's `length`).
    pub length: Vec<f64>,
    /// Committed law state (read by both passes of a step).
    pub committed: Aligned<L::State>,
    trial: Aligned<L::State>,
    /// Committed plastic stretch states S_Ps,ij (3.48), per slot.
    pub sps: Aligned<[f64; K]>,
    sps_trial: Aligned<[f64; K]>,
    /// Scratch from pass 1 for pass 2 of the same step, in blocks of [`LANES`] particles
    /// (see [`slot_cache_at`]).
    cache: Aligned<f64>,
    /// Run the full kernel even where the law needs only the tension kernel (for tests that
    /// compare the two).
    pub force_full: bool,
    /// Criteria strain averaged over each particle's neighbourhood (random particles), see
    /// [`Neighbourhood`]; `None`: each particle's own.
    pub neighbourhood: Option<Neighbourhood<D>>,
    /// Let both passes run their SIMD blocks where they can (`true`; `false` for tests that
    /// compare them with the scalar path).
    pub simd: bool,
    /// Keep the committed state through steps (the quasi-static solver's secant iterations:
    /// pass 1 still computes the trial state at the current positions, and
    /// [`DamageKernel::commit`] makes it the committed one between converged states).
    pub frozen: bool,
    /// While [`Self::frozen`]: bit k of particle i set where slot k was shortened
    /// (S_e < 0) at the last commit, so that the held state also holds each bond's branch
    /// (tensile or compressive damage, [`DamageLaw::bond_factor`]). Without it the force of
    /// a damaged bond jumps where its stretch changes sign, the held problem has no smooth
    /// equilibrium, and the iterations chatter about S_e = 0 (measured: the tension block's
    /// peak increment stuck at 0.7–1.7% out of balance for 20,000 iterations).
    shortened: Vec<u64>,
    /// Bits of the slots whose branch flipped at a commit since [`Self::unlock_branches`]:
    /// a second flip is refused (the bond keeps its branch), so that a bond whose equilibrium
    /// stretch changes sign with its branch cannot keep the iterations from settling.
    flipped: Vec<u64>,
    /// The law state at the start of the quasi-static solver's load increment
    /// ([`Self::begin_increment`]; allocated by [`Self::freeze`], empty before).
    start: Aligned<L::State>,
    /// The plastic stretch states at the start of the increment.
    sps_start: Aligned<[f64; K]>,
    /// [`Self::shortened`] at the start of the increment.
    shortened_start: Vec<u64>,
}

/// The criteria (initiation, yield) of a particle read the volume-weighted mean of the damaged
/// elastic strains of the particle and its bonded neighbours that carry no tensile damage
/// (w_t = 0), as they were at the previous step (like every state variable, reading B of
/// docs/model.md §4).
///
/// **Decision (measured, random particles).** A random particle's own strain scatters about
/// the body's (non-affine relaxation, anisotropic particles), so with it the Rankine criterion
/// fired early and off the perpendicular: the tension block peaked at 0.854 × f't·A (10
/// particle sets, CoV 3.9%) with inclined cracks. With the neighbourhood's mean it peaks at
/// 0.991 × f't·A (CoV 2.4%) and the cracks run perpendicular to the load
/// (benchmarks/RESULTS.md, "SPPM in 2D").
///
/// **Decision (measured, lattices).** Lattices keep each particle's own strain by default
/// (`concrete.criteria_strain` chooses). The mean removes the tension an FCC particle's own
/// strain reads at a prism's edges and held platen rows (the compression prism then peaks at
/// 0.90 × f'c·A at 10 and 15 mm, against 0.875 and 0.784), but it raised the FCC tension
/// prism's energy at 15 mm to 1.27 × G_f·A and moved validated 2D results out of their
/// tolerances (benchmarks/RESULTS.md, "Criteria over the neighbourhood on lattices").
///
/// **Decision (measured).** Damaged neighbours are left out of the mean: an unloading cracked
/// particle pulled the mean of the particles at a crack's tip down, so the tip was shielded
/// and cracks started elsewhere instead (two offset cracks in some sets). Without them, over
/// the same 10 sets, the tension block's energy went from 1.29 to 1.18 × G_f·A and the split
/// cylinder's peak from +16.9% to +11.9% over (5.6) (benchmarks/RESULTS.md).
#[derive(Clone, Debug)]
pub struct Neighbourhood<const D: usize> {
    volume: Vec<f64>,
    /// Committed damaged elastic strain of every particle (previous step).
    strain: Vec<Tensor<D>>,
    strain_trial: Vec<Tensor<D>>,
    /// `strain` at the start of a quasi-static increment ([`DamageKernel::undo_increment`]).
    strain_start: Vec<Tensor<D>>,
    /// Where the mean is read (`concrete.criteria_strain = "surface"`: the particles with
    /// fewer bonds than the bulk); `None`: at every particle.
    pub(super) only: Option<Vec<bool>>,
}

impl<const D: usize> Neighbourhood<D> {
    /// The criteria strain of particle i: the volume-weighted mean of the committed strains of
    /// i and of its bonded neighbours (`neighbours`, [`NONE`] in empty slots) that are not
    /// `damaged` (a damaged neighbour no longer stands for the intact material around i).
    #[inline(always)]
    fn mean<const K: usize>(
        &self,
        i: usize,
        neighbours: &[u32; K],
        damaged: impl Fn(usize) -> bool,
    ) -> Tensor<D> {
        let mut sum = self.strain[i] * self.volume[i];
        let mut vol = self.volume[i];
        for &j in neighbours.iter().filter(|&&j| j != NONE) {
            let j = j as usize;
            if damaged(j) {
                continue;
            }
            sum += self.strain[j] * self.volume[j];
            vol += self.volume[j];
        }
        sum / vol
    }
}

impl<const D: usize, const K: usize, L: DamageLaw<D, K>> DamageKernel<D, K, L>
where
    Dim<D>: Dimension<D>,
{
    /// Undamaged, without plastic stretch.
    pub fn new(law: L, p: &Particles<D, K>) -> Self {
        let n = p.len();
        let fit = (0..n)
            .map(|i| {
                let mut dirs = [None; K];
                for (k, d) in dirs.iter_mut().enumerate() {
                    let j = p.neighbours[i][k];
                    if j != NONE {
                        *d = Some((p.x0[j as usize] - p.x0[i]).normalize());
                    }
                }
                Dim::<D>::strain_fit(&dirs)
            })
            .collect();
        DamageKernel {
            law,
            fit,
            reverse: p.reverse.clone(),
            length: p.length.clone(),
            committed: filled(L::State::default(), n),
            trial: filled(L::State::default(), n),
            sps: filled([0.0; K], n),
            sps_trial: filled([0.0; K], n),
            cache: filled(0.0, slot_cache_len(n, K)),
            force_full: false,
            neighbourhood: None,
            simd: true,
            frozen: false,
            shortened: Vec::new(),
            flipped: Vec::new(),
            start: Aligned::new(0),
            sps_start: Aligned::new(0),
            shortened_start: Vec::new(),
        }
    }

    /// The criteria read the neighbourhood's mean strain ([`Neighbourhood`]).
    pub fn with_neighbourhood_criteria(mut self, p: &Particles<D, K>) -> Self {
        let n = p.len();
        self.neighbourhood = Some(Neighbourhood {
            volume: p.volume.clone(),
            strain: vec![Tensor::<D>::zeros(); n],
            strain_trial: vec![Tensor::<D>::zeros(); n],
            strain_start: Vec::new(),
            only: None,
        });
        self
    }

    /// The criteria read the neighbourhood's mean strain at surface particles (fewer bonds
    /// than the most any particle has) and each particle's own strain in the bulk.
    pub fn with_surface_criteria(self, p: &Particles<D, K>) -> Self {
        let bonds = |i: usize| p.neighbours[i].iter().filter(|&&j| j != NONE).count();
        let bulk = (0..p.len()).map(bonds).max().unwrap_or(0);
        let surface = (0..p.len()).map(|i| bonds(i) < bulk).collect();
        let mut c = self.with_neighbourhood_criteria(p);
        if let Some(nb) = c.neighbourhood.as_mut() {
            nb.only = Some(surface);
        }
        c
    }

    /// The step kernel this law needs: the tension kernel unless it needs plastic stretch and
    /// the compressive branch (docs/architecture.md, "skip what the scene does not need").
    pub fn kernel(&self) -> KernelSet {
        if self.force_full || self.law.kernel() == Kernel::Full {
            KernelSet::Full
        } else {
            KernelSet::Tension
        }
    }

    /// Make the trial state the committed one (once per step, after pass 2).
    pub fn commit(&mut self) {
        if let Some(nb) = &mut self.neighbourhood {
            std::mem::swap(&mut nb.strain, &mut nb.strain_trial);
        }
        std::mem::swap(&mut self.committed, &mut self.trial);
        std::mem::swap(&mut self.sps, &mut self.sps_trial);
    }

    /// Hold the committed state, and each bond's branch as it is at positions `x`, through
    /// the steps that follow (`true`); or commit after every step again (`false`).
    pub fn freeze(&mut self, frozen: bool, m: &Mechanics<D, K>, x: &[SVector<f64, D>]) {
        // (the branches are read from S_e, which the held branch does not change; the held
        // bits are read only while frozen, so none are needed to compute the first ones)
        self.frozen = false;
        if frozen {
            self.shortened = self.branches(m, x, None);
            self.flipped = vec![0; m.len()];
            self.start = copied(&self.committed);
            self.sps_start = copied(&self.sps);
        }
        self.frozen = frozen;
    }

    /// Commit the trial state of the last step, and take each bond's branch at `x`
    /// (secant iterations; see [`Self::frozen`]).
    /// Returns how much the state moved: the largest change of w_t or w_c of a particle,
    /// and the number of bond ends whose branch changed.
    pub fn commit_at(&mut self, m: &Mechanics<D, K>, x: &[SVector<f64, D>]) -> (f64, usize) {
        let change = self.largest_change(&self.trial);
        self.commit();
        let mut flips = 0;
        if self.frozen {
            let mut new = self.branches(m, x, Some(&self.shortened));
            for ((n, old), f) in new.iter_mut().zip(&self.shortened).zip(&mut self.flipped) {
                // a bond that flipped before keeps its branch
                let change = (*n ^ old) & !*f;
                *n = old ^ change;
                *f |= change;
                flips += change.count_ones() as usize;
            }
            self.shortened = new;
        }
        (change, flips)
    }

    /// A load increment of a held state ([`Self::freeze`]) starts from the committed state:
    /// keep it, its branches and its criteria strains ([`Self::undo_increment`],
    /// [`Self::growth`]), and let every bond flip its branch again.
    pub fn begin_increment(&mut self) {
        self.flipped.iter_mut().for_each(|f| *f = 0);
        self.start.copy_from_slice(&self.committed);
        self.sps_start.copy_from_slice(&self.sps);
        self.shortened_start.clone_from(&self.shortened);
        if let Some(nb) = &mut self.neighbourhood {
            nb.strain_start.clone_from(&nb.strain);
        }
    }

    /// Undo the increment: the state, branches and criteria strains of its start again
    /// (the quasi-static solver's cut-back of an increment in which damage jumped).
    pub fn undo_increment(&mut self) {
        self.committed.copy_from_slice(&self.start);
        self.sps.copy_from_slice(&self.sps_start);
        self.shortened.clone_from(&self.shortened_start);
        if let Some(nb) = &mut self.neighbourhood {
            nb.strain.clone_from(&nb.strain_start);
        }
    }

    /// The largest change of a particle's w_t or w_c since [`Self::begin_increment`].
    pub fn growth(&self) -> f64 {
        self.largest_change(&self.start)
    }

    /// The largest difference of a particle's w_t or w_c between the committed state and
    /// `other`.
    fn largest_change(&self, other: &[L::State]) -> f64 {
        let law = &self.law;
        self.committed
            .par_iter()
            .zip(other.par_iter())
            .with_min_len(1024)
            .map(|(a, b)| {
                let (a, b) = (law.view(a), law.view(b));
                (a.wt - b.wt).abs().max((a.wc - b.wc).abs())
            })
            .reduce(|| 0.0, f64::max)
    }

    /// The shortened slots of every particle at `x` with the committed plastic stretch. A
    /// slot whose |S_e| is within [`BRANCH_BAND`] keeps its held branch (`old`, if any).
    fn branches(
        &self,
        m: &Mechanics<D, K>,
        x: &[SVector<f64, D>],
        old: Option<&[u64]>,
    ) -> Vec<u64> {
        const { assert!(K <= 64, "the branch bits hold at most 64 slots") };
        (0..m.len())
            .into_par_iter()
            .with_min_len(1024)
            .map(|i| {
                let mut bits = old.map_or(0, |o| o[i]);
                for k in 0..K {
                    if let Some(s) = slot::<D, K, L, true>(m, self, x, i, k) {
                        if s.se < -BRANCH_BAND || (old.is_none() && s.se < 0.0) {
                            bits |= 1 << k;
                        } else if s.se > BRANCH_BAND || old.is_none() {
                            bits &= !(1 << k);
                        }
                    }
                }
                bits
            })
            .collect()
    }

    /// Every particle's state as the outputs show it.
    pub fn damage(&self) -> Vec<ParticleDamage> {
        self.committed.iter().map(|s| self.law.view(s)).collect()
    }
}

/// A material model with state that replaces the elastic kernel for a run (dispatched once
/// per step, never inside the particle loop).
pub trait Inelastic<const D: usize, const K: usize>: Send + Sync {
    /// One step (see [`step`]).
    fn step(
        &mut self,
        m: &Mechanics<D, K>,
        st: &mut super::kernel::State<D>,
        dt: f64,
        lag: bool,
        damp: bool,
    );
    /// Elastic energy at positions x.
    fn internal_energy(&self, m: &Mechanics<D, K>, x: &[nalgebra::SVector<f64, D>]) -> f64;
    /// The step kernel it runs.
    fn kernel(&self) -> KernelSet;
    /// Every particle's damage as the outputs show it.
    fn damage(&self) -> Vec<ParticleDamage>;
    /// Whether some particle has failed (w_t or w_c ≥ 0.99).
    fn has_failed_particle(&self) -> bool;
    /// The mean of max(w_t, w_c) over the particles, weighted by `weights` (their masses:
    /// the damaged share of the failure criteria, docs/failure.md); nothing is allocated.
    fn mean_damage(&self, weights: &[f64]) -> f64;
    /// Hold the committed state through steps (`true`) or commit after every step (`false`,
    /// the explicit run); see [`DamageKernel::frozen`].
    fn set_frozen(&mut self, frozen: bool, m: &Mechanics<D, K>, x: &[nalgebra::SVector<f64, D>]);
    /// Make the trial state of the last step (computed at the positions that step started
    /// from) the committed one; a held state also takes each bond's branch at `x`.
    fn commit(&mut self, m: &Mechanics<D, K>, x: &[nalgebra::SVector<f64, D>]) -> (f64, usize);
    /// A new load increment ([`DamageKernel::begin_increment`]).
    fn begin_increment(&mut self);
    /// The largest change of w_t or w_c in this increment ([`DamageKernel::growth`]).
    fn growth(&self) -> f64;
    /// Back to the increment's start ([`DamageKernel::undo_increment`]).
    fn undo_increment(&mut self);
    /// Internal forces (no dampers) at positions x with the committed state; the trial state
    /// becomes the one computed at x ([`internal_forces`]).
    fn forces(
        &mut self,
        m: &Mechanics<D, K>,
        x: &[nalgebra::SVector<f64, D>],
    ) -> Vec<nalgebra::SVector<f64, D>>;
    /// The secant stiffness at x with the committed state ([`secant_stiffness`]).
    fn stiffness(
        &self,
        m: &Mechanics<D, K>,
        x: &[nalgebra::SVector<f64, D>],
    ) -> Vec<(usize, usize, f64)>;
    /// Particle stresses (3.18) at positions x.
    fn particle_stress(
        &self,
        m: &Mechanics<D, K>,
        x: &[nalgebra::SVector<f64, D>],
        volume: &[f64],
    ) -> Vec<nalgebra::SMatrix<f64, D, D>>;
    /// Each particle's strain from its damaged elastic stretches ([`particle_strain`]).
    fn particle_strain(
        &self,
        m: &Mechanics<D, K>,
        x: &[nalgebra::SVector<f64, D>],
    ) -> Vec<nalgebra::SMatrix<f64, D, D>>;
}

impl<const D: usize, const K: usize, L: DamageLaw<D, K>> Inelastic<D, K> for DamageKernel<D, K, L>
where
    Dim<D>: Dimension<D>,
{
    fn step(
        &mut self,
        m: &Mechanics<D, K>,
        st: &mut super::kernel::State<D>,
        dt: f64,
        lag: bool,
        damp: bool,
    ) {
        let full = self.kernel() == KernelSet::Full;
        match (lag, damp, full) {
            (false, false, false) => step::<D, K, L, false, false, false>(m, self, st, dt),
            (false, true, false) => step::<D, K, L, false, true, false>(m, self, st, dt),
            (true, false, false) => step::<D, K, L, true, false, false>(m, self, st, dt),
            (true, true, false) => step::<D, K, L, true, true, false>(m, self, st, dt),
            (false, false, true) => step::<D, K, L, false, false, true>(m, self, st, dt),
            (false, true, true) => step::<D, K, L, false, true, true>(m, self, st, dt),
            (true, false, true) => step::<D, K, L, true, false, true>(m, self, st, dt),
            (true, true, true) => step::<D, K, L, true, true, true>(m, self, st, dt),
        }
    }
    fn internal_energy(&self, m: &Mechanics<D, K>, x: &[SVector<f64, D>]) -> f64 {
        internal_energy(m, self, x)
    }
    fn kernel(&self) -> KernelSet {
        DamageKernel::kernel(self)
    }
    fn damage(&self) -> Vec<ParticleDamage> {
        DamageKernel::damage(self)
    }
    fn has_failed_particle(&self) -> bool {
        self.committed.iter().any(|s| self.law.view(s).failed())
    }
    fn mean_damage(&self, weights: &[f64]) -> f64 {
        let (mut sum, mut total) = (0.0, 0.0);
        for (s, &w) in self.committed.iter().zip(weights) {
            let d = self.law.view(s);
            sum += w * d.wt.max(d.wc);
            total += w;
        }
        sum / total
    }
    fn set_frozen(&mut self, frozen: bool, m: &Mechanics<D, K>, x: &[SVector<f64, D>]) {
        self.freeze(frozen, m, x)
    }
    fn commit(&mut self, m: &Mechanics<D, K>, x: &[SVector<f64, D>]) -> (f64, usize) {
        self.commit_at(m, x)
    }
    fn begin_increment(&mut self) {
        DamageKernel::begin_increment(self)
    }
    fn growth(&self) -> f64 {
        DamageKernel::growth(self)
    }
    fn undo_increment(&mut self) {
        DamageKernel::undo_increment(self)
    }
    fn forces(&mut self, m: &Mechanics<D, K>, x: &[SVector<f64, D>]) -> Vec<SVector<f64, D>> {
        internal_forces(m, self, x)
    }
    fn stiffness(&self, m: &Mechanics<D, K>, x: &[SVector<f64, D>]) -> Vec<(usize, usize, f64)> {
        secant_stiffness(m, self, x)
    }
    fn particle_stress(
        &self,
        m: &Mechanics<D, K>,
        x: &[SVector<f64, D>],
        volume: &[f64],
    ) -> Vec<SMatrix<f64, D, D>> {
        particle_stress(m, self, x, volume)
    }
    fn particle_strain(
        &self,
        m: &Mechanics<D, K>,
        x: &[SVector<f64, D>],
    ) -> Vec<SMatrix<f64, D, D>> {
        particle_strain(m, self, x)
    }
}
