//! The two passes of a step with damage: the slots (stretches, damage factors, the slot cache),
//! the law's update of each particle's state, and the gather of the bond forces (docs/model.md §6–9).

use super::DamageKernel;
use crate::aligned::Aligned;
use crate::discretise::NONE;
use crate::model::damage_law::{DamageLaw, ParticleBonds};
use crate::model::dimension::{Dim, Dimension, Tensor};
use crate::model::force_state::{damaged_axial, damaged_bond_force, dilatation_term};
use crate::model::stretch::total_stretch;
use crate::solver::kernel::{
    central_difference, chunk_len, lane_cache_at, lane_cache_len, update_in_chunks, use_avx,
    ChunkOut, LANES,
};
use crate::solver::mechanics::{weighted, Mechanics};
use crate::solver::KernelSet;
use nalgebra::SVector;
use rayon::prelude::*;

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
    pub(super) d_a_se: f64,
    pub(super) d: f64,
}

/// The slot cache's fields per slot.
pub(super) const FIELDS: usize = 2;

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
    pub(super) fn read(cache: &[f64], at: usize) -> Self {
        SlotCache {
            d_a_se: cache[at],
            d: cache[at + LANES],
        }
    }

    #[inline(always)]
    pub(super) fn write(self, cache: &mut [f64], at: usize) {
        cache[at] = self.d_a_se;
        cache[at + LANES] = self.d;
    }
}

/// One slot's kinematics: unit vector, total stretch, elastic stretch, damage factor.
#[derive(Clone, Copy)]
pub(super) struct Slot<const D: usize> {
    pub(super) e: SVector<f64, D>,
    pub(super) st: f64,
    pub(super) se: f64,
    pub(super) d: f64,
    /// √d.
    pub(super) sd: f64,
}

/// The slot of particle i in direction k, or `None` if empty. Computed identically from
/// either end of the bond (S_T, S_P and d are symmetric bit for bit), so the two particles
/// of a bond see the same elastic stretch and damage factor.
///
/// With `FULL = false` (the tension kernel: no plasticity, no compressive damage) the plastic
/// stretch is zero, so it is not read.
#[inline(always)]
pub(super) fn slot<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &DamageKernel<D, K, L>,
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
pub(super) fn slots<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &DamageKernel<D, K, L>,
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
    pub(super) st: [f64; K],
    pub(super) se: [f64; K],
    pub(super) dse: [f64; K],
    pub(super) used: [bool; K],
    /// Σ_m w_im·√d_im·S_e,im.
    pub(super) theta: f64,
    /// Σ_m w_im·S_e,im.
    pub(super) theta_e: f64,
    /// The damaged elastic stretches equal the total ones (undamaged bonds, no plastic
    /// stretch): one strain fit serves both.
    pub(super) same: bool,
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
pub(super) fn slot_pass<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &DamageKernel<D, K, L>,
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
pub(super) fn law_pass<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &DamageKernel<D, K, L>,
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
            let here = nb.only.as_ref().is_none_or(|only| only[i]);
            here.then(|| {
                nb.mean(i, &m.neighbours[i], |j| {
                    c.law.view(&c.committed[j]).wt > 0.0
                })
            })
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
pub(super) fn update_state<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &DamageKernel<D, K, L>,
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
pub(super) fn state_chunk<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &DamageKernel<D, K, L>,
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
                    super::avx::slot_block::<D, K, L, FULL, true>(m, c, x, base + o, ca, &mut s)
                } else {
                    super::avx::slot_block::<D, K, L, FULL, false>(m, c, x, base + o, ca, &mut s)
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
pub(super) fn pass_state<const D: usize, const K: usize, L: DamageLaw<D, K>, const FULL: bool>(
    m: &Mechanics<D, K>,
    c: &mut DamageKernel<D, K, L>,
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
/// and √d are recomputed as pass 1 computed them (see [`SlotCache`]). `super::avx::force_block`
/// does four particles at once, bit for bit the same.
#[inline]
pub(super) fn particle_force<const D: usize, const K: usize, L: DamageLaw<D, K>, const DAMP: bool>(
    m: &Mechanics<D, K>,
    c: &DamageKernel<D, K, L>,
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
    c: &mut DamageKernel<D, K, L>,
    st: &mut crate::solver::kernel::State<D>,
    dt: f64,
) where
    Dim<D>: Dimension<D>,
{
    debug_assert!(FULL || c.kernel() == KernelSet::Tension);
    pass_state::<D, K, L, FULL>(m, c, &st.x, &mut st.b_theta);
    #[cfg(target_arch = "x86_64")]
    let avx = c.simd && use_avx();
    #[cfg(not(target_arch = "x86_64"))]
    let avx = false;
    let cr = &*c;
    update_in_chunks(st, m.len(), |base, r, mut out| {
        let len = out.xn.len();
        let done = if avx { len / LANES * LANES } else { 0 };
        #[cfg(target_arch = "x86_64")]
        if done > 0 {
            // SAFETY: AVX is available (checked above); base + len ≤ m.len() and every
            // state array has m.len() entries
            // (update_in_chunks asserts it); pass 1 filled the slot cache of every particle.
            unsafe {
                super::avx::update_chunk::<D, K, L, LAG, DAMP>(m, cr, &r, dt, base, out.head(done))
            }
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
