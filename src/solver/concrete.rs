//! The step kernel with two-spring damage and plasticity (docs/model.md §2, §6–9) on the slot layout.
//!
//! Same shape as the elastic kernel (`kernel.rs`): two gather passes, parallel over particles,
//! no scatter and no allocation, so results do not depend on the thread count. State variables
//! (w_t, w_c, the plastic stretch states) have a committed value, read by both passes of a
//! step, and a trial value written by pass 1; [`Concrete::commit`] swaps them once per step
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
//!    recomputed as pass 1 computed them. With AVX in 2D, four particles at a time
//!    (`avx::force_block`, for any law: it reads only the slot cache and the positions),
//!    bit-identical to `particle_force` (the same test, three whole steps).
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
//! balance closes (tests/concrete.rs).
//!
//! The damage law itself (initiation, softening, compressive damage, plasticity) is behind
//! the `model::damage_law::DamageLaw` trait; the two-spring concrete law
//! (`model::two_spring`) is one implementation. This kernel computes the kinematics, asks the
//! law for each bond's damage factor and each particle's new state, and moves the particles.

use super::kernel::{
    central_difference, chunk_len, lane_cache_at, lane_cache_len, update_in_chunks, use_avx,
    ChunkOut, LANES,
};
use super::mechanics::{weighted, Mechanics};
use super::KernelSet;
use crate::aligned::{copied, filled, Aligned};
use crate::discretise::{Particles, NONE};
pub use crate::model::damage_law::ParticleDamage;
use crate::model::damage_law::{DamageLaw, Kernel, ParticleBonds};
use crate::model::dimension::{Dim, Dimension, Tensor};
use crate::model::force_state::{
    bond_energy, damaged_axial, damaged_bond_force, damaged_force_state, dilatation_term,
};
use crate::model::stress::StressSum;
use crate::model::stretch::total_stretch;
use crate::model::two_spring::TwoSpring;
use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

#[cfg(target_arch = "x86_64")]
mod avx;

/// Bytes per particle the damage kernel ([`Concrete`]) allocates beside the elastic run's
/// (`discretise::bytes_per_particle`), counted field by field: the strain projector
/// (D(D+1)/2 × K f64), the committed and trial plastic stretch states (2·K f64), the slot
/// cache (2·K f64), the reverse slots (K u8), the committed and trial law states (2 × 32 B)
/// and the length scale (f64). D = 2, K = 6: 414 B; D = 3, K = 18 (FCC): 1530 B.
pub const fn bytes_per_particle(d: usize, k: usize) -> usize {
    (d * (d + 1) / 2 + 2 + FIELDS) * k * 8 + k + 2 * std::mem::size_of::<ParticleDamage>() + 8
}

/// The band of elastic stretch |S_e| ≤ 1e-7 (a thousandth of concrete's cracking strain)
/// within which a held bond keeps its branch at a commit ([`Concrete::frozen`]): where an
/// equilibrium puts a damaged bond at S_e = 0 its force is set-valued (the tensile and the
/// compressive damage give different dilatation forces there), and flipping its branch at
/// every commit would never settle (measured on the tension block after its peak: 2–4 flips
/// at every commit for 20,000 iterations).
pub const BRANCH_BAND: f64 = 1e-7;

/// Damage and plasticity of a run: the law, the per-particle geometry the kernel needs, and
/// the committed and trial state.
#[derive(Clone, Debug)]
pub struct Concrete<const D: usize, const K: usize, L: DamageLaw<D, K> = TwoSpring<D>>
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
    /// [`Concrete::commit`] makes it the committed one between converged states).
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
/// (benchmarks/RESULTS.md, "SPPM in 2D"). Lattices keep the particle's own strain (their
/// golden results are unchanged).
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
    /// `strain` at the start of a quasi-static increment ([`Concrete::undo_increment`]).
    strain_start: Vec<Tensor<D>>,
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

impl<const D: usize, const K: usize, L: DamageLaw<D, K>> Concrete<D, K, L>
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
        Concrete {
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
        });
        self
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

/// What pass 2 needs of one slot, left by pass 1 at the same positions and state:
/// d·(a_i + a_j)·S_e and d (0 in an empty slot).
///
/// **Decision (measured).** Pass 2 recomputes the rest from the same inputs with the same
/// operations as pass 1, so the same bits, rather than reading it: the length
/// |x_j − x_i| and its inverse, the unit vector e = (x_j − x_i)·(1/|x_j − x_i|), and
/// √d = `d.sqrt()` ([`DamageLaw::bond_factor`] returns that square root). 16 bytes a slot
/// instead of 32 (40 with e): the kernel is memory-bound, and two square roots and a
/// division per slot cost less than the 16 bytes written and read again (AVX tension kernel
/// +9 to +22%: benchmarks/RESULTS.md, "Concrete kernels: a two-field slot cache"). The cache
/// is laid out in blocks of [`LANES`] particles, each field of a slot four lanes wide
/// ([`slot_cache_at`]), so that the AVX passes load and store it a vector at a time
/// (benchmarks/RESULTS.md, "Slot cache and pass 2 of the concrete kernels").
#[derive(Clone, Copy, Debug, Default)]
pub struct SlotCache {
    d_a_se: f64,
    d: f64,
}

/// The slot cache's fields per slot.
const FIELDS: usize = 2;

/// Length of the slot cache of n particles with k slots each ([`lane_cache_len`]).
pub(crate) const fn slot_cache_len(n: usize, k: usize) -> usize {
    lane_cache_len(n, k, FIELDS)
}

/// Index in the slot cache of the first field (d·(a_i + a_j)·S_e) of slot k of particle i; the
/// second, d, follows [`LANES`] entries on.
#[inline(always)]
pub(crate) const fn slot_cache_at(i: usize, k: usize, slots: usize) -> usize {
    lane_cache_at(i, k, slots, FIELDS)
}

impl SlotCache {
    #[inline(always)]
    fn read(cache: &[f64], at: usize) -> Self {
        SlotCache {
            d_a_se: cache[at],
            d: cache[at + LANES],
        }
    }

    #[inline(always)]
    fn write(self, cache: &mut [f64], at: usize) {
        cache[at] = self.d_a_se;
        cache[at + LANES] = self.d;
    }
}

/// One slot's kinematics: unit vector, total stretch, elastic stretch, damage factor.
#[derive(Clone, Copy)]
struct Slot<const D: usize> {
    e: SVector<f64, D>,
    st: f64,
    se: f64,
    d: f64,
    /// √d.
    sd: f64,
}

/// The slot of particle i in direction k, or `None` if empty. Computed identically from
/// either end of the bond (S_T, S_P and d are symmetric bit for bit), so the two particles
/// of a bond see the same elastic stretch and damage factor.
///
/// With `FULL = false` (the tension kernel: no plasticity, no compressive damage) the plastic
/// stretch is zero, so it is not read.
#[inline(always)]
fn slot<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &Concrete<D, K, L>,
    x: &[SVector<f64, D>],
    i: usize,
    k: usize,
) -> Option<Slot<D>>
where
    Dim<D>: Dimension<D>,
{
    let j = m.neighbours[i][k];
    if j == NONE {
        return None;
    }
    let j = j as usize;
    let dx = x[j] - x[i];
    let len = dx.norm();
    let st = total_stretch(len, m.inv_l0[i][k]);
    let se = if FULL {
        let r = c.reverse[i][k] as usize;
        st - 0.5 * (c.sps[i][k] + c.sps[j][r])
    } else {
        st
    };
    // the branch: the sign of S_e, or the one held at the last commit
    let branch = if c.frozen && (c.shortened[i] >> k) & 1 == 1 {
        -1.0
    } else if c.frozen {
        1.0
    } else {
        se
    };
    let (d, sd) = c
        .law
        .bond_factor::<FULL>(&c.committed[i], &c.committed[j], branch);
    Some(Slot {
        e: dx * (1.0 / len),
        st,
        se,
        d,
        sd,
    })
}

/// All slots of particle i and its damaged dilatation term bθ_i = b_i·Σ_m √d_im·S_e,im.
#[inline(always)]
fn slots<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &Concrete<D, K, L>,
    x: &[SVector<f64, D>],
    i: usize,
) -> ([Option<Slot<D>>; K], f64)
where
    Dim<D>: Dimension<D>,
{
    let mut out = [None; K];
    let mut theta = 0.0;
    let w = m.weights(i);
    for (k, o) in out.iter_mut().enumerate() {
        *o = slot::<D, K, L, FULL>(m, c, x, i, k);
        if let Some(s) = o {
            theta += weighted(w, k, s.sd * s.se);
        }
    }
    (out, dilatation_term(m.b[i], theta))
}

/// Particle i's stretches slot by slot (0 and `used = false` in empty slots), as pass 1 hands
/// them to the law: total, elastic, damaged elastic, and the two dilatation sums.
#[derive(Clone, Copy)]
pub(super) struct Stretches<const K: usize> {
    st: [f64; K],
    se: [f64; K],
    dse: [f64; K],
    used: [bool; K],
    /// Σ_m w_im·√d_im·S_e,im.
    theta: f64,
    /// Σ_m w_im·S_e,im.
    theta_e: f64,
    /// The damaged elastic stretches equal the total ones (undamaged bonds, no plastic
    /// stretch): one strain fit serves both.
    same: bool,
}

impl<const K: usize> Default for Stretches<K> {
    fn default() -> Self {
        Stretches {
            st: [0.0; K],
            se: [0.0; K],
            dse: [0.0; K],
            used: [false; K],
            theta: 0.0,
            theta_e: 0.0,
            same: true,
        }
    }
}

/// Pass 1's slot loop for particle i: its [`Stretches`] and the slot cache for pass 2 into
/// `cache`, in which i is particle `p` (the scalar path; `avx::slot_block` does four particles
/// at once, bit for bit the same).
#[inline(always)]
fn slot_pass<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &Concrete<D, K, L>,
    x: &[SVector<f64, D>],
    i: usize,
    cache: &mut [f64],
    p: usize,
) -> Stretches<K>
where
    Dim<D>: Dimension<D>,
{
    let mut s = Stretches::<K>::default();
    let w = m.weights(i);
    for k in 0..K {
        let sc = match slot::<D, K, L, FULL>(m, c, x, i, k) {
            Some(b) => {
                let j = m.neighbours[i][k] as usize;
                let (mi, mj) = m.bond_moduli(i, j, k);
                s.st[k] = b.st;
                s.se[k] = b.se;
                s.dse[k] = b.d * b.se;
                s.used[k] = true;
                s.theta += weighted(w, k, b.sd * b.se);
                s.theta_e += weighted(w, k, b.se);
                s.same &= s.dse[k] == s.st[k];
                SlotCache {
                    d_a_se: damaged_axial(b.d, mi, mj, b.se),
                    d: b.d,
                }
            }
            None => SlotCache::default(),
        };
        sc.write(cache, slot_cache_at(p, k, K));
    }
    s
}

/// Pass 1's law update for particle i from its [`Stretches`]: the trial law state and
/// plastic stretch state (from the law, [`DamageLaw::update`]) and, for the neighbourhood
/// criteria, its own strain; returns bθ_i.
#[inline(always)]
fn law_pass<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &Concrete<D, K, L>,
    i: usize,
    s: &Stretches<K>,
    trial: &mut L::State,
    sps_trial: &mut [f64; K],
    own_strain: Option<&mut Tensor<D>>,
) -> f64
where
    Dim<D>: Dimension<D>,
{
    let mut state = c.committed[i];
    if FULL {
        *sps_trial = c.sps[i];
    }
    // the neighbourhood's mean criteria strain (previous step) and this particle's own (trial)
    let mean_strain = match (&c.neighbourhood, own_strain) {
        (Some(nb), Some(own)) => {
            *own = if s.same {
                Dim::<D>::strain_tensor(&c.fit[i], &s.st)
            } else {
                Dim::<D>::strain_tensor(&c.fit[i], &s.dse)
            };
            Some(nb.mean(i, &m.neighbours[i], |j| {
                c.law.view(&c.committed[j]).wt > 0.0
            }))
        }
        _ => None,
    };
    let bonds = ParticleBonds {
        i,
        fit: &c.fit[i],
        total: &s.st,
        elastic: &s.se,
        damaged: &s.dse,
        used: &s.used,
        undamaged: s.same,
        a: m.a[i],
        second: m.second_of(i),
        b_theta_elastic: dilatation_term(m.b[i], s.theta_e),
        lengths: &c.length,
        criteria_strain: mean_strain.as_ref(),
    };
    c.law.update::<FULL>(&bonds, &mut state, sps_trial);
    *trial = state;
    dilatation_term(m.b[i], s.theta)
}

/// Pass 1 for particle i: bθ_i, the slot cache for pass 2 (i is particle `p` of `cache`), and
/// the trial law state and plastic stretch state (from the law, [`DamageLaw::update`]).
///
/// `FULL = false` is the tension kernel: it reads no plastic stretch.
#[inline(always)]
// The arguments are the particle's inputs and its four disjoint outputs (slices' elements).
#[allow(clippy::too_many_arguments)]
fn update_state<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &Concrete<D, K, L>,
    x: &[SVector<f64, D>],
    i: usize,
    trial: &mut L::State,
    sps_trial: &mut [f64; K],
    cache: &mut [f64],
    p: usize,
    own_strain: Option<&mut Tensor<D>>,
) -> f64
where
    Dim<D>: Dimension<D>,
{
    let s = slot_pass::<D, K, L, FULL>(m, c, x, i, cache, p);
    law_pass::<D, K, L, FULL>(m, c, i, &s, trial, sps_trial, own_strain)
}

/// Pass 1 over one chunk of particles from `base` on (every slice holds the chunk's
/// particles): with `avx`, whole blocks of four through `avx::slot_block` and the rest one by
/// one, bit for bit the same.
// The arguments are the chunk's inputs and its disjoint outputs.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn state_chunk<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &Concrete<D, K, L>,
    x: &[SVector<f64, D>],
    base: usize,
    b_theta: &mut [f64],
    trial: &mut [L::State],
    sps_trial: &mut [[f64; K]],
    cache: &mut [f64],
    mut own: Option<&mut [Tensor<D>]>,
    avx: bool,
) where
    Dim<D>: Dimension<D>,
{
    let n = b_theta.len();
    assert!(base + n <= m.len() && m.len() == x.len());
    assert!(trial.len() == n && sps_trial.len() == n && cache.len() == slot_cache_len(n, K));
    assert!(own.as_ref().is_none_or(|o| o.len() == n));
    #[cfg(target_arch = "x86_64")]
    let done = if avx {
        let done = n / LANES * LANES;
        let mut s = [Stretches::<K>::default(); LANES];
        for o in (0..done).step_by(LANES) {
            // SAFETY: AVX is available (`use_avx`, checked by the caller); base + o + 4 ≤
            // m.len() = x.len() and the block's cache exists (asserted above);
            // Mechanics::new checks every occupied slot indexes a particle.
            let at = slot_cache_at(o, 0, K);
            let ca = &mut cache[at..at + FIELDS * LANES * K];
            unsafe {
                if m.dilatation_weight.is_some() {
                    avx::slot_block::<D, K, L, FULL, true>(m, c, x, base + o, ca, &mut s)
                } else {
                    avx::slot_block::<D, K, L, FULL, false>(m, c, x, base + o, ca, &mut s)
                }
            };
            for (l, s) in s.iter().enumerate() {
                let p = o + l;
                b_theta[p] = law_pass::<D, K, L, FULL>(
                    m,
                    c,
                    base + p,
                    s,
                    &mut trial[p],
                    &mut sps_trial[p],
                    own.as_deref_mut().map(|own| &mut own[p]),
                );
            }
        }
        done
    } else {
        0
    };
    #[cfg(not(target_arch = "x86_64"))]
    let done = {
        let _ = avx;
        0
    };
    for p in done..n {
        b_theta[p] = update_state::<D, K, L, FULL>(
            m,
            c,
            x,
            base + p,
            &mut trial[p],
            &mut sps_trial[p],
            cache,
            p,
            own.as_deref_mut().map(|own| &mut own[p]),
        );
    }
}

/// Pass 1 over all particles, in chunks of [`chunk_len`] (a multiple of the SIMD width); the
/// SIMD blocks run where the law's bond factor is the series one
/// ([`DamageLaw::SERIES_DAMAGE`]) and the CPU has AVX.
fn pass_state<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &mut Concrete<D, K, L>,
    x: &[SVector<f64, D>],
    b_theta: &mut [f64],
) where
    Dim<D>: Dimension<D>,
{
    // the AVX slot loop takes each bond's branch from the sign of S_e
    let avx = L::SERIES_DAMAGE && c.simd && !c.frozen && use_avx();
    let mut trial = std::mem::replace(&mut c.trial, Aligned::new(0));
    let mut sps_trial = std::mem::replace(&mut c.sps_trial, Aligned::new(0));
    let mut cache = std::mem::replace(&mut c.cache, Aligned::new(0));
    let mut strain_trial = c
        .neighbourhood
        .as_mut()
        .map(|nb| std::mem::take(&mut nb.strain_trial));
    {
        let c = &*c;
        let chunk = chunk_len(b_theta.len());
        let zipped = b_theta
            .par_chunks_mut(chunk)
            .zip(trial.par_chunks_mut(chunk))
            .zip(sps_trial.par_chunks_mut(chunk))
            .zip(cache.par_chunks_mut(slot_cache_len(chunk, K)))
            .enumerate();
        match &mut strain_trial {
            Some(own) => zipped.zip(own.par_chunks_mut(chunk)).for_each(
                |((ci, (((bt, tr), sp), ca)), own)| {
                    state_chunk::<D, K, L, FULL>(
                        m,
                        c,
                        x,
                        ci * chunk,
                        bt,
                        tr,
                        sp,
                        ca,
                        Some(own),
                        avx,
                    )
                },
            ),
            None => zipped.for_each(|(ci, (((bt, tr), sp), ca))| {
                state_chunk::<D, K, L, FULL>(m, c, x, ci * chunk, bt, tr, sp, ca, None, avx)
            }),
        }
    }
    if let (Some(nb), Some(s)) = (c.neighbourhood.as_mut(), strain_trial) {
        nb.strain_trial = s;
    }
    c.trial = trial;
    c.sps_trial = sps_trial;
    c.cache = cache;
}

/// Internal force on particle i and the power of its bond dampers (half of each bond's),
/// from the slot cache pass 1 left at positions x and every particle's bθ; the unit vector
/// and √d are recomputed as pass 1 computed them (see [`SlotCache`]). `avx::force_block`
/// does four particles at once, bit for bit the same.
#[inline]
fn particle_force<const D: usize, const K: usize, L: DamageLaw<D, K>, const DAMP: bool>(
    m: &Mechanics<D, K>,
    c: &Concrete<D, K, L>,
    x: &[SVector<f64, D>],
    v: &[SVector<f64, D>],
    b_theta: &[f64],
    i: usize,
) -> (SVector<f64, D>, f64)
where
    Dim<D>: Dimension<D>,
{
    let mut f = SVector::<f64, D>::zeros();
    let mut power = 0.0;
    let xi = x[i];
    for (k, &j) in m.neighbours[i].iter().enumerate() {
        let s = SlotCache::read(&c.cache, slot_cache_at(i, k, K));
        if s.d == 0.0 {
            continue;
        }
        let j = j as usize;
        // as pass 1 (`slot`): the same operations, the same bits
        let dx = x[j] - xi;
        let e = dx * (1.0 / dx.norm());
        let mut fb = damaged_bond_force(s.d_a_se, s.d.sqrt(), b_theta[i], b_theta[j]);
        if DAMP {
            let cb = s.d * 0.5 * (m.c_in[i] + m.c_in[j]);
            let rate = (v[j] - v[i]).dot(&e);
            fb += cb * rate;
            power += 0.5 * cb * rate * rate;
        }
        f += e * fb;
    }
    (f, power)
}

/// One explicit step with damage and plasticity from x^n, v^{n−½} into `x_next`, `v_next`
/// (not yet swapped in), `force` (the internal force at x^n) and the damper work; then the
/// trial state is committed. With `LAG`, the force of the previous step drives this one
/// (reading A of docs/model.md §4; `force_prev` holds it). `FULL = false` is the tension kernel
/// (see [`update_state`]), valid only for a law that needs no more ([`Kernel::Tension`]).
pub fn step<
    const D: usize,
    const K: usize,
    L: DamageLaw<D, K>,
    const LAG: bool,
    const DAMP: bool,
    const FULL: bool,
>(
    m: &Mechanics<D, K>,
    c: &mut Concrete<D, K, L>,
    st: &mut super::kernel::State<D>,
    dt: f64,
) where
    Dim<D>: Dimension<D>,
{
    debug_assert!(FULL || c.kernel() == KernelSet::Tension);
    pass_state::<D, K, L, FULL>(m, c, &st.x, &mut st.b_theta);
    #[cfg(target_arch = "x86_64")]
    let avx = c.simd && use_avx() && super::kernel::avx::vector_update::<D>();
    #[cfg(not(target_arch = "x86_64"))]
    let avx = false;
    let cr = &*c;
    update_in_chunks(st, m.len(), |base, r, mut out| {
        let len = out.xn.len();
        let done = if avx { len / LANES * LANES } else { 0 };
        #[cfg(target_arch = "x86_64")]
        if done > 0 {
            // SAFETY: AVX is available and D = 2 with 16-byte vectors (checked above);
            // base + len ≤ m.len() and every state array has m.len() entries
            // (update_in_chunks asserts it); pass 1 filled the slot cache of every particle.
            unsafe { avx::update_chunk::<D, K, L, LAG, DAMP>(m, cr, &r, dt, base, out.head(done)) }
        }
        let ChunkOut { xn, vn, fo, dw } = out;
        for o in done..len {
            let i = base + o;
            let (f, bond_power) = particle_force::<D, K, L, DAMP>(m, cr, r.x, r.v, r.b_theta, i);
            fo[o] = f;
            let drive = if LAG { r.force_prev[i] } else { f };
            central_difference::<D, K, DAMP>(
                m, i, r.x[i], r.v[i], drive, bond_power, dt, &mut xn[o], &mut vn[o], &mut dw[o],
            );
        }
    });
    if !c.frozen {
        c.commit();
    }
}

/// Internal forces (bonds only, no dampers) at positions x with the committed state; the
/// trial state is left as the step would compute it. For tests and post-processing.
pub fn internal_forces<const D: usize, const K: usize, L: DamageLaw<D, K>>(
    m: &Mechanics<D, K>,
    c: &mut Concrete<D, K, L>,
    x: &[SVector<f64, D>],
) -> Vec<SVector<f64, D>>
where
    Dim<D>: Dimension<D>,
{
    let mut bt = vec![0.0; x.len()];
    match c.kernel() {
        KernelSet::Tension => pass_state::<D, K, L, false>(m, c, x, &mut bt),
        _ => pass_state::<D, K, L, true>(m, c, x, &mut bt),
    }
    let c = &*c;
    (0..x.len())
        .map(|i| particle_force::<D, K, L, false>(m, c, x, x, &bt, i).0)
        .collect()
}

/// The secant stiffness K = −∂F/∂x of the internal forces at positions x with the
/// committed (held) state, as (row, column, value) triplets over the degrees of freedom
/// D·i + component: the derivative of the damaged bond force
/// F_b,ij = ½(d_ij·(m_i + m_j)·S_e,ij + √d_ij·(bθ_i + bθ_j)) along e_ij (docs/model.md §7 with the
/// kernel's damage decision above), with d, √d and each bond's branch held, the bond
/// directions e taken at x and held (the geometric stiffness, of relative size S ≈ 1e-4, is
/// left out), and dS_e,ij = e_ij·(dx_j − dx_i)/L0,ij. For the quasi-static solver's secant
/// iterations (`solver::secant`): the residual is always the kernel's own force. The
/// triplets' positions depend only on the bonds (zeros included), so that the solver builds
/// the sparse pattern and its symbolic factorisation once.
pub fn secant_stiffness<const D: usize, const K: usize, L: DamageLaw<D, K>>(
    m: &Mechanics<D, K>,
    c: &Concrete<D, K, L>,
    x: &[SVector<f64, D>],
) -> Vec<(usize, usize, f64)>
where
    Dim<D>: Dimension<D>,
{
    match c.kernel() {
        KernelSet::Tension => secant_stiffness_of::<D, K, L, false>(m, c, x),
        _ => secant_stiffness_of::<D, K, L, true>(m, c, x),
    }
}

/// One held slot for the stiffness: neighbour, unit vector, d, √d and √d·w/L0 (the slot's
/// share of ∂θ).
#[derive(Clone, Copy)]
struct HeldSlot<const D: usize> {
    j: usize,
    e: SVector<f64, D>,
    d: f64,
    sd: f64,
    theta: f64,
}

fn secant_stiffness_of<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &Concrete<D, K, L>,
    x: &[SVector<f64, D>],
) -> Vec<(usize, usize, f64)>
where
    Dim<D>: Dimension<D>,
{
    let n = m.len();
    let held: Vec<[Option<HeldSlot<D>>; K]> = (0..n)
        .into_par_iter()
        .with_min_len(1024)
        .map(|i| {
            let w = m.weights(i);
            let mut out = [None; K];
            for (k, o) in out.iter_mut().enumerate() {
                if let Some(s) = slot::<D, K, L, FULL>(m, c, x, i, k) {
                    // a broken bond (d = √d = 0) adds zeros, also where its ends have met
                    // and its direction is not defined (met on the split cylinder after
                    // cracking, with a variant of the solver measured once: NaN
                    // entries, then a failed factorisation); the entries stay, as the
                    // pattern is built once
                    let broken = s.d == 0.0 && s.sd == 0.0;
                    *o = Some(HeldSlot {
                        j: m.neighbours[i][k] as usize,
                        e: if broken { SVector::zeros() } else { s.e },
                        d: s.d,
                        sd: s.sd,
                        theta: weighted(w, k, s.sd * m.inv_l0[i][k]),
                    });
                }
            }
            out
        })
        .collect();
    // Each particle's row: one D×D block per coupled particle (itself, its neighbours and
    // theirs), merged in a small list, so the triplets are a few per block, not one per term.
    let rows: Vec<Vec<(usize, SMatrix<f64, D, D>)>> = (0..n)
        .into_par_iter()
        .with_min_len(256)
        .map(|i| {
            let mut row: Vec<(usize, SMatrix<f64, D, D>)> = Vec::with_capacity(4 * K);
            // row[q] += −g·u·vᵀ (∂F_i/∂x_q = g·u·vᵀ)
            let mut block = |q: usize, g: f64, u: &SVector<f64, D>, v: &SVector<f64, D>| {
                let b = u * v.transpose() * (-g);
                match row.iter_mut().find(|(p, _)| *p == q) {
                    Some((_, m)) => *m += b,
                    None => row.push((q, b)),
                }
            };
            for (k, hs) in held[i].iter().enumerate() {
                let Some(s) = hs else { continue };
                let (mi, mj) = m.bond_moduli(i, s.j, k);
                // axial: ½·d·(m_i + m_j)/L0·e·eᵀ·(dx_j − dx_i)
                let g = 0.5 * s.d * (mi + mj) * m.inv_l0[i][k];
                block(s.j, g, &s.e, &s.e);
                block(i, -g, &s.e, &s.e);
                // dilatation: ½·√d·(b_i·∂θ_i + b_j·∂θ_j) along e
                for (p, bp) in [(i, m.b[i]), (s.j, m.b[s.j])] {
                    let gp = 0.5 * s.sd * bp;
                    for h in held[p].iter().flatten() {
                        block(h.j, gp * h.theta, &s.e, &h.e);
                        block(p, -gp * h.theta, &s.e, &h.e);
                    }
                }
            }
            row
        })
        .collect();
    let mut t = Vec::with_capacity(rows.iter().map(|r| r.len() * D * D).sum());
    for (i, row) in rows.iter().enumerate() {
        for (q, b) in row {
            for r in 0..D {
                for cc in 0..D {
                    t.push((D * i + r, D * q + cc, b[(r, cc)]));
                }
            }
        }
    }
    t
}

/// Elastic energy stored in the damaged bonds at positions x with the committed state,
/// U = ¼·Σ_i Σ_k L0,k·S_e,k·(d_k·a_i·S_e,k + √d_k·bθ_i) (with fixed d and S_P,
/// ∂U/∂L_ij = F_b,ij for equal bond lengths, as in the lattice).
///
/// The particles' energies are computed in parallel and summed in particle order, so the
/// sum does not depend on the thread count or the scheduling (a parallel reduction's tree
/// does: rayon splits work where threads steal it, and the old `par_iter().sum()` gave
/// dissipated energies that differed in the last bits from run to run).
pub fn internal_energy<const D: usize, const K: usize, L: DamageLaw<D, K>>(
    m: &Mechanics<D, K>,
    c: &Concrete<D, K, L>,
    x: &[SVector<f64, D>],
) -> f64
where
    Dim<D>: Dimension<D>,
{
    let per_particle: Vec<f64> = (0..x.len())
        .into_par_iter()
        .with_min_len(256)
        .map(|i| {
            let (sl, bt) = slots::<D, K, L, true>(m, c, x, i);
            let mut u = 0.0;
            for (k, s) in sl.iter().enumerate() {
                if let Some(s) = s {
                    let fs = damaged_force_state(s.d, s.sd, m.slot_modulus(i, k), s.se, bt);
                    u += bond_energy(s.se, fs, m.inv_l0[i][k]);
                }
            }
            0.25 * u
        })
        .collect();
    per_particle.iter().sum()
}

/// Particle stresses (3.18) of particles of volume ΔV with the damaged force states
/// F_s,ij = d_ij·a_i·S_e,ij + √d_ij·bθ_i.
pub fn particle_stress<const D: usize, const K: usize, L: DamageLaw<D, K>>(
    m: &Mechanics<D, K>,
    c: &Concrete<D, K, L>,
    x: &[SVector<f64, D>],
    volume: &[f64],
) -> Vec<SMatrix<f64, D, D>>
where
    Dim<D>: Dimension<D>,
{
    (0..x.len())
        .map(|i| {
            let (sl, bt) = slots::<D, K, L, true>(m, c, x, i);
            let mut acc = StressSum::<D>::default();
            for (k, s) in sl.iter().enumerate() {
                if let Some(s) = s {
                    acc.add(
                        &s.e,
                        1.0 / m.inv_l0[i][k],
                        damaged_force_state(s.d, s.sd, m.slot_modulus(i, k), s.se, bt),
                    );
                }
            }
            acc.finish(volume[i])
        })
        .collect()
}

/// Each particle's least-squares strain of its damaged elastic stretches d_ij·S_e,ij at
/// positions x (docs/model.md §7 and §13: the strain the criteria stress D·ε reads); the stress
/// the outputs show is D_i times it (`model::stress`, "recovered stress").
pub fn particle_strain<const D: usize, const K: usize, L: DamageLaw<D, K>>(
    m: &Mechanics<D, K>,
    c: &Concrete<D, K, L>,
    x: &[SVector<f64, D>],
) -> Vec<SMatrix<f64, D, D>>
where
    Dim<D>: Dimension<D>,
{
    (0..x.len())
        .map(|i| {
            let (sl, _) = slots::<D, K, L, true>(m, c, x, i);
            let mut dse = [0.0; K];
            for (k, s) in sl.iter().enumerate() {
                if let Some(s) = s {
                    dse[k] = s.d * s.se;
                }
            }
            Dim::<D>::strain_tensor(&c.fit[i], &dse)
        })
        .collect()
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
    /// Hold the committed state through steps (`true`) or commit after every step (`false`,
    /// the explicit run); see [`Concrete::frozen`].
    fn set_frozen(&mut self, frozen: bool, m: &Mechanics<D, K>, x: &[nalgebra::SVector<f64, D>]);
    /// Make the trial state of the last step (computed at the positions that step started
    /// from) the committed one; a held state also takes each bond's branch at `x`.
    fn commit(&mut self, m: &Mechanics<D, K>, x: &[nalgebra::SVector<f64, D>]) -> (f64, usize);
    /// A new load increment ([`Concrete::begin_increment`]).
    fn begin_increment(&mut self);
    /// The largest change of w_t or w_c in this increment ([`Concrete::growth`]).
    fn growth(&self) -> f64;
    /// Back to the increment's start ([`Concrete::undo_increment`]).
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
    /// The model itself, for tests that reach into its state (downcast to its type).
    fn as_any(&self) -> &dyn std::any::Any;
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any;
}

impl<const D: usize, const K: usize, L: DamageLaw<D, K>> Inelastic<D, K> for Concrete<D, K, L>
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
        Concrete::kernel(self)
    }
    fn damage(&self) -> Vec<ParticleDamage> {
        Concrete::damage(self)
    }
    fn has_failed_particle(&self) -> bool {
        self.committed.iter().any(|s| self.law.view(s).failed())
    }
    fn set_frozen(&mut self, frozen: bool, m: &Mechanics<D, K>, x: &[SVector<f64, D>]) {
        self.freeze(frozen, m, x)
    }
    fn commit(&mut self, m: &Mechanics<D, K>, x: &[SVector<f64, D>]) -> (f64, usize) {
        self.commit_at(m, x)
    }
    fn begin_increment(&mut self) {
        Concrete::begin_increment(self)
    }
    fn growth(&self) -> f64 {
        Concrete::growth(self)
    }
    fn undo_increment(&mut self) {
        Concrete::undo_increment(self)
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
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
}

impl<const D: usize, const K: usize> dyn Inelastic<D, K>
where
    Dim<D>: Dimension<D>,
{
    /// The two-spring concrete model, if this is one (for tests that reach into its state).
    pub fn concrete(&self) -> Option<&Concrete<D, K>> {
        self.as_any().downcast_ref()
    }

    /// [`Self::concrete`], mutable.
    pub fn concrete_mut(&mut self) -> Option<&mut Concrete<D, K>> {
        self.as_any_mut().downcast_mut()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aligned::CollectAligned;
    use crate::discretise::hex::HexLattice;
    use crate::discretise::random::{self, RandomParticles};
    use crate::geometry::Shape2;
    use crate::model::damage::ConcreteLaw;
    use crate::solver::test_rng::Lcg;
    use nalgebra::{Matrix2, Vector2};

    /// The bench's concrete law, with or without the compressive branch and plasticity.
    fn law<const D: usize>(full: bool) -> TwoSpring<D>
    where
        Dim<D>: Dimension<D>,
    {
        TwoSpring::new(ConcreteLaw::table1(full), None)
    }

    /// A block strained by up to ±2·f't/E per bond, with every kind of committed state:
    /// intact, initiated, partly damaged in tension and compression, fully damaged (w = 1,
    /// where the series factor is 0/0), plastic stretch in every bond.
    /// With 18 slots the particles also get FCC second-neighbour moduli c (about −0.65·a, in
    /// slots 12..18).
    fn damaged<const D: usize, const K: usize>(
        p: &Particles<D, K>,
        full: bool,
        seed: u64,
    ) -> (Mechanics<D, K>, Concrete<D, K>, Vec<SVector<f64, D>>)
    where
        Dim<D>: Dimension<D>,
    {
        let n = p.len();
        let mut r = Lcg(seed);
        let mut m = Mechanics::new(p, &vec![2400.0; n]);
        for i in 0..n {
            m.a[i] = 3e6 * (1.0 + 0.1 * r.next());
            m.b[i] = -1e6 * (1.0 + 0.1 * r.next());
            m.c_in[i] = 5.0 * (1.0 + r.next());
            m.c_ex[i] = if i % 3 == 0 { 0.0 } else { 2.0 * r.next() };
        }
        if let Some(first_slot) = crate::solver::mechanics::first_second_slot(K) {
            let c = (0..n)
                .map(|i| -0.65 * m.a[i] * (1.0 + 0.05 * r.next()))
                .collect_aligned();
            m.second = Some(crate::solver::mechanics::SecondNeighbours { c, first_slot });
        }
        let mut c = Concrete::new(law(full), p);
        let mut w = || match (r.next() * 10.0) as u32 {
            0..=4 => 0.0,
            5..=7 => r.next(),
            8 => 1.0,
            _ => 1.0 + r.next(),
        };
        for s in c.committed.iter_mut() {
            s.wt = w();
            s.wc = if full { w() } else { 0.0 };
            s.initiated = s.wt > 0.0;
            s.eps_init = 8e-5;
        }
        let mut r = Lcg(seed + 1);
        for (i, s) in c.sps.iter_mut().enumerate() {
            for (k, s) in s.iter_mut().enumerate() {
                if full && p.neighbours[i][k] != NONE {
                    *s = 2e-4 * (r.next() - 0.5);
                }
            }
        }
        let eps = 2.0 * 2.6168e6 / 30e9;
        let x =
            p.x0.iter()
                .map(|x0| {
                    let shift = SVector::<f64, D>::from_fn(|c, _| r.next() - [0.3, 0.5, 0.4][c]);
                    x0 + shift * eps * 40.0 * p.spacing
                })
                .map(|x| x * (1.0 + 0.5 * eps))
                .collect();
        (m, c, x)
    }

    /// Pass 1 through the SIMD blocks and through the scalar chunks, on 1 and 2 threads,
    /// against `update_state` particle by particle: the same bits in bθ, the trial state, the
    /// plastic stretch states, the slot cache and the neighbourhood's strains.
    fn check_pass_state<const D: usize, const K: usize, const FULL: bool>(
        p: &Particles<D, K>,
        nb: bool,
    ) where
        Dim<D>: Dimension<D>,
    {
        let (m, mut c, x) = damaged(p, FULL, 99);
        if nb {
            c = c.with_neighbourhood_criteria(p);
            let mut r = Lcg(5);
            for e in c.neighbourhood.as_mut().unwrap().strain.iter_mut() {
                let t = Tensor::<D>::from_fn(|_, _| r.next() - 0.5);
                *e = (t + t.transpose()) * 1.5e-3;
            }
        }
        let n = p.len();
        let mut want = c.clone();
        let mut want_bt = vec![0.0; n];
        let mut own = vec![Tensor::<D>::zeros(); n];
        for i in 0..n {
            want_bt[i] = update_state::<D, K, TwoSpring<D>, FULL>(
                &m,
                &c,
                &x,
                i,
                &mut want.trial[i],
                &mut want.sps_trial[i],
                &mut want.cache,
                i,
                nb.then_some(&mut own[i]),
            );
        }
        let bits = |v: &[f64]| v.iter().map(|c| c.to_bits()).collect::<Vec<_>>();
        let state = |c: &Concrete<D, K>| {
            let mut v = Vec::new();
            for s in c.trial.iter() {
                v.extend([
                    s.wt,
                    s.wc,
                    s.eps_init,
                    s.initiated as u8 as f64,
                    s.yielded as u8 as f64,
                ]);
            }
            v.extend(c.sps_trial.iter().flatten());
            v.extend(c.cache.iter());
            if let Some(nb) = &c.neighbourhood {
                v.extend(nb.strain_trial.iter().flat_map(|e| e.iter().copied()));
            }
            bits(&v)
        };
        if let Some(w) = want.neighbourhood.as_mut() {
            w.strain_trial = own;
        }
        let expect = state(&want);
        // damage of every kind reached the kernel
        let d: Vec<f64> = (0..n)
            .flat_map(|i| (0..K).map(move |k| (i, k)))
            .map(|(i, k)| SlotCache::read(&want.cache, slot_cache_at(i, k, K)).d)
            .collect();
        assert!(d.contains(&1.0) && d.iter().any(|&d| d > 0.0 && d < 1.0));
        assert!(d.iter().filter(|&&d| d == 0.0).count() > n);
        // and every branch of the law: initiation, and with FULL plastic flow
        assert!(want
            .trial
            .iter()
            .zip(c.committed.iter())
            .any(|(t, s)| t.initiated && !s.initiated));
        assert!(!FULL || want.trial.iter().filter(|s| s.yielded).count() > n / 20);
        for simd in [true, false] {
            for threads in [1, 2] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let mut got = c.clone();
                got.simd = simd;
                let mut bt = vec![0.0; n];
                pool.install(|| pass_state::<D, K, TwoSpring<D>, FULL>(&m, &mut got, &x, &mut bt));
                assert_eq!(
                    bits(&bt),
                    bits(&want_bt),
                    "bθ, simd {simd}, {threads} threads"
                );
                assert!(
                    state(&got) == expect,
                    "state, simd {simd}, {threads} threads"
                );
            }
        }
        // whole steps (both passes, the law's commits) through the SIMD and the scalar paths
        let mut st = crate::solver::kernel::State::at_rest(&p.x0);
        let mut r = Lcg(17);
        st.x.copy_from_slice(&x);
        for (v, f) in st.v.iter_mut().zip(st.force_prev.iter_mut()) {
            *v = SVector::<f64, D>::from_fn(|_, _| r.next() - 0.5) * 1e-2;
            *f = SVector::<f64, D>::from_fn(|_, _| r.next() - 0.5) * 1e3;
        }
        check_steps::<D, K, FULL, false, true>(&m, &c, &st);
        check_steps::<D, K, FULL, true, false>(&m, &c, &st);
    }

    /// Three steps with and without the SIMD blocks: the same bits in every output.
    fn check_steps<
        const D: usize,
        const K: usize,
        const FULL: bool,
        const LAG: bool,
        const DAMP: bool,
    >(
        m: &Mechanics<D, K>,
        c: &Concrete<D, K>,
        st0: &crate::solver::kernel::State<D>,
    ) where
        Dim<D>: Dimension<D>,
    {
        let run = |simd: bool| {
            let (mut c, mut st) = (c.clone(), st0.clone());
            c.simd = simd;
            for _ in 0..3 {
                step::<D, K, TwoSpring<D>, LAG, DAMP, FULL>(m, &mut c, &mut st, 1e-8);
                std::mem::swap(&mut st.x, &mut st.x_next);
                std::mem::swap(&mut st.v, &mut st.v_next);
            }
            let mut v: Vec<u64> = [&st.x, &st.v, &st.force]
                .iter()
                .flat_map(|a| a.iter().flat_map(|p| p.iter().map(|c| c.to_bits())))
                .collect();
            v.extend(
                st.damping_work
                    .iter()
                    .chain(st.b_theta.iter())
                    .map(|c| c.to_bits()),
            );
            for s in c.committed.iter() {
                v.extend([s.wt, s.wc, s.eps_init].map(f64::to_bits));
            }
            v
        };
        assert!(
            run(true) == run(false),
            "steps, LAG {LAG}, DAMP {DAMP}, FULL {FULL}"
        );
    }

    /// A hexagonal block of 1,843 particles (not a multiple of 4) and a random one.
    fn bodies() -> (Particles<2, 6>, Particles<2, { random::SLOTS_2D }>) {
        let shape = Shape2::Rectangle {
            origin: Vector2::zeros(),
            width: 0.0405,
            height: 0.0405,
        };
        let hex = HexLattice {
            spacing: 1e-3,
            rotation_deg: 10.0,
            offset: Vector2::zeros(),
            thickness: 0.1,
        }
        .fill(&shape);
        let recipe = RandomParticles {
            spacing: 2e-3,
            min_distance: random::DEFAULT_MIN_DISTANCE,
            seed: 3,
            rotation_deg: 0.0,
            thickness: 0.1,
        };
        let (rnd, _, _) = random::fill::<{ random::SLOTS_2D }>(&shape, &recipe).unwrap();
        (hex, rnd)
    }

    /// The memory estimate counts what [`Concrete::new`] allocates per particle.
    #[test]
    fn damage_kernel_bytes_per_particle_count_its_arrays() {
        fn count<const D: usize, const K: usize>() -> usize
        where
            Dim<D>: Dimension<D>,
        {
            std::mem::size_of::<<Dim<D> as Dimension<D>>::StrainFit<K>>()
                + 2 * std::mem::size_of::<[f64; K]>()
                + slot_cache_len(4096, K) * 8 / 4096
                + std::mem::size_of::<[u8; K]>()
                + 2 * std::mem::size_of::<ParticleDamage>()
                + std::mem::size_of::<f64>()
        }
        assert_eq!(bytes_per_particle(2, 6), count::<2, 6>());
        assert_eq!(bytes_per_particle(3, 18), count::<3, 18>());
        assert_eq!(
            (bytes_per_particle(2, 6), bytes_per_particle(3, 18)),
            (414, 1530)
        );
    }

    /// The secant stiffness is the derivative of the kernel's force with the state held:
    /// K·v against the central difference −(F(x + hv) − F(x − hv))/2h, on damaged bodies with
    /// every kind of state (held at x, branches included). The stiffness leaves out only the
    /// geometric term, whose relative size is the bonds' stretch: the positions are scaled to
    /// stretches below 2e-4, and the test allows 1e-3 (measured 2.5e-5–1.2e-4).
    fn check_stiffness<const D: usize, const K: usize>(p: &Particles<D, K>, full: bool)
    where
        Dim<D>: Dimension<D>,
    {
        let (m, mut c, x) = damaged::<D, K>(p, full, 11);
        let x: Vec<SVector<f64, D>> = x
            .iter()
            .zip(&p.x0)
            .map(|(x, x0)| x0 + (x - x0) * 0.01)
            .collect();
        let largest_stretch = (0..p.len())
            .flat_map(|i| m.bonds(i).map(move |(_, j, il)| (i, j, il)))
            .map(|(i, j, il)| total_stretch((x[j] - x[i]).norm(), il).abs())
            .fold(0.0, f64::max);
        assert!(largest_stretch < 2e-4, "{largest_stretch}");
        c.freeze(true, &m, &x);
        let t = secant_stiffness(&m, &c, &x);
        let mut r = Lcg(5);
        let v: Vec<SVector<f64, D>> = (0..p.len())
            .map(|_| SVector::<f64, D>::from_fn(|_, _| r.next() - 0.5))
            .collect();
        let mut kv = vec![0.0; D * p.len()];
        for &(row, col, val) in &t {
            kv[row] += val * v[col / D][col % D];
        }
        let h = 1e-9 * p.spacing;
        let shifted = |sign: f64| -> Vec<SVector<f64, D>> {
            x.iter().zip(&v).map(|(x, v)| x + v * (sign * h)).collect()
        };
        let (fp, fm) = (
            internal_forces(&m, &mut c, &shifted(1.0)),
            internal_forces(&m, &mut c, &shifted(-1.0)),
        );
        let (mut err, mut norm) = (0.0f64, 0.0f64);
        for i in 0..p.len() {
            for d in 0..D {
                let fd = -(fp[i][d] - fm[i][d]) / (2.0 * h);
                err = err.max((kv[D * i + d] - fd).abs());
                norm = norm.max(fd.abs());
            }
        }
        println!(
            "K = {K}, full {full}: |K·v − FD| ≤ {:.2e} of |FD|",
            err / norm
        );
        assert!(err <= 1e-3 * norm, "{err:e} against {norm:e}");
    }

    /// A rotated FCC block with weighted dilatations, not a multiple of 4 particles.
    fn fcc_body() -> Particles<3, 18> {
        crate::discretise::fcc::FccLattice {
            spacing: 2e-3,
            rotation_deg: [20.0, 10.0, 5.0],
            offset: nalgebra::Vector3::zeros(),
        }
        .fill(&crate::geometry::solid::Shape3::Box {
            origin: nalgebra::Vector3::zeros(),
            size: nalgebra::Vector3::new(0.0133, 0.011, 0.015),
        })
    }

    #[test]
    fn secant_stiffness_is_the_held_forces_derivative() {
        let (hex, rnd) = bodies();
        for full in [false, true] {
            check_stiffness::<2, 6>(&hex, full);
            check_stiffness::<2, 12>(&rnd, full);
        }
        let fcc = fcc_body();
        check_stiffness::<3, 18>(&fcc, true);
    }

    /// A broken bond whose two particles have met (a separated piece pushed onto its
    /// neighbour) has no direction: its stiffness entries are zeros, not NaN, and the
    /// triplets are the same ones as before (the quasi-static solver's pattern is built once).
    #[test]
    fn broken_bond_with_coincident_ends_adds_zeros_to_the_stiffness() {
        let (hex, _) = bodies();
        let (m, mut c, mut x) = damaged::<2, 6>(&hex, false, 11);
        c.freeze(true, &m, &x);
        // a bond held on the tensile branch (the tension kernel has no compressive damage)
        let i = hex.len() / 2;
        let (k, j) = (0..6)
            .map(|k| (k, hex.neighbours[i][k]))
            .find(|&(k, j)| j != NONE && (c.shortened[i] >> k) & 1 == 0)
            .expect("an interior particle has a lengthened bond");
        let j = j as usize;
        c.committed[i].wt = 1.0;
        c.committed[j].wt = 1.0;
        let before = secant_stiffness(&m, &c, &x);
        x[j] = x[i];
        let s = slot::<2, 6, TwoSpring<2>, false>(&m, &c, &x, i, k).unwrap();
        assert!(
            s.d == 0.0 && s.sd == 0.0 && !s.e.x.is_finite(),
            "{} {} {}",
            s.d,
            s.sd,
            s.e
        );
        let after = secant_stiffness(&m, &c, &x);
        assert!(after.iter().all(|t| t.2.is_finite()));
        assert!(before
            .iter()
            .zip(&after)
            .all(|(a, b)| (a.0, a.1) == (b.0, b.1)));
        assert_eq!(before.len(), after.len());
    }

    /// An undone increment leaves the committed state, plastic stretch, branches and
    /// criteria strains as they were at its start, and its growth is the largest change of
    /// w_t or w_c since then.
    #[test]
    fn undo_increment_restores_the_start_and_growth_measures_from_it() {
        let (_, rnd) = bodies();
        let (m, c, x) = damaged::<2, 12>(&rnd, true, 7);
        let mut c = c.with_neighbourhood_criteria(&rnd);
        c.freeze(true, &m, &x);
        c.begin_increment();
        let (state, sps) = (c.committed.to_vec(), c.sps.to_vec());
        let shortened = c.shortened.clone();
        let strain = c.neighbourhood.as_ref().unwrap().strain.clone();
        assert_eq!(c.growth(), 0.0);
        // a strained step: the trial state differs from the start
        let far: Vec<_> = x
            .iter()
            .zip(&rnd.x0)
            .map(|(x, x0)| x0 + (x - x0) * 3.0)
            .collect();
        internal_forces(&m, &mut c, &far);
        let (dw, _) = c.commit_at(&m, &far);
        assert!(dw > 0.0);
        let g = c.growth();
        assert!(g >= dw && g > 0.0, "{g} {dw}");
        c.undo_increment();
        assert!(c.committed.iter().zip(&state).all(|(a, b)| a == b));
        assert!(c.sps.iter().zip(&sps).all(|(a, b)| a == b));
        assert_eq!(c.shortened, shortened);
        assert_eq!(c.neighbourhood.as_ref().unwrap().strain, strain);
        assert_eq!(c.growth(), 0.0);
    }

    #[test]
    fn pass_state_simd_matches_scalar_bitwise() {
        if !use_avx() {
            eprintln!("no AVX on this CPU: only the scalar chunks are compared");
        }
        let (hex, rnd) = bodies();
        assert!(hex.len() % LANES != 0, "{}", hex.len());
        check_pass_state::<2, 6, false>(&hex, false);
        check_pass_state::<2, 6, true>(&hex, false);
        check_pass_state::<2, 12, false>(&rnd, true);
        check_pass_state::<2, 12, true>(&rnd, true);
    }

    /// The same in 3D on an FCC block with second-neighbour moduli c and weighted
    /// dilatations (slots 12..18 take a + c, docs/model.md §3 erratum), not a multiple of 4.
    #[test]
    fn fcc_pass_state_with_second_neighbours_simd_matches_scalar_bitwise() {
        let fcc = fcc_body();
        assert!(
            !fcc.len().is_multiple_of(LANES) && fcc.len() > 200,
            "{}",
            fcc.len()
        );
        assert!(fcc.weighted_dilatation);
        check_pass_state::<3, 18, false>(&fcc, false);
        check_pass_state::<3, 18, true>(&fcc, false);
    }

    /// Particle 0 with neighbours 1 and 2 (and an empty slot): the mean weighs each strain by
    /// its volume, and a damaged neighbour drops out of both the sum and the volume.
    #[test]
    fn neighbourhood_mean_weighs_by_volume_and_leaves_out_damaged_neighbours() {
        let nb = Neighbourhood::<2> {
            volume: vec![1.0, 2.0, 3.0],
            strain: vec![
                Matrix2::new(1.0, 0.5, 0.5, -1.0),
                Matrix2::new(4.0, 0.0, 0.0, 2.0),
                Matrix2::new(-8.0, 1.0, 1.0, 6.0),
            ],
            strain_trial: vec![Matrix2::zeros(); 3],
            strain_start: Vec::new(),
        };
        let row = [1, NONE, 2];
        let all = nb.mean(0, &row, |_| false);
        // (1·ε0 + 2·ε1 + 3·ε2)/6
        let expect_all = Matrix2::new(
            (1.0 + 8.0 - 24.0) / 6.0,
            (0.5 + 3.0) / 6.0,
            (0.5 + 3.0) / 6.0,
            (-1.0 + 4.0 + 18.0) / 6.0,
        );
        assert!((all - expect_all).norm() < 1e-15, "{all} vs {expect_all}");
        let intact = nb.mean(0, &row, |j| j == 2);
        // (1·ε0 + 2·ε1)/3
        let expect_intact = Matrix2::new(3.0, 0.5 / 3.0, 0.5 / 3.0, 1.0);
        assert!(
            (intact - expect_intact).norm() < 1e-15,
            "{intact} vs {expect_intact}"
        );
        // a damaged particle's own strain still counts
        let own = nb.mean(0, &row, |j| j != 0);
        assert!((own - nb.strain[0]).norm() < 1e-15);
    }
}
