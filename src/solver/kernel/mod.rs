//! The explicit step kernel (docs/architecture.md, "The step kernel"; docs/model.md §2–5).
//!
//! Two gather passes per step, parallel over chunks of particles, with no scatter, atomics or
//! allocation, so results do not depend on the thread count:
//!
//! 1. `bθ_i = b_i·Σ_m S_im` from the current positions (one number per particle);
//! 2. for each particle, over its own slots: the bond force
//!    F_b,ij = ½(F_s,ij + F_s,ji) = ½((a_i + a_j)·S_ij + bθ_i + bθ_j) (3.7, 3.8) along the
//!    current unit vector e_ij, plus the bond damper (3.55), then central differences
//!    (3.58) with the particle damper (3.56) taken semi-implicitly. In an FCC
//!    second-neighbour slot (`Mechanics::second`, docs/model.md §3 with its erratum) the bond
//!    moduli are a + c: F_b,ij = ½((a_i + c_i) + (a_j + c_j))·S_ij + ½(bθ_i + bθ_j). The
//!    test of whether a model has c is made once per particle (scalar) or per block of four
//!    (AVX), outside the slot loop; without c the code is the one without it.
//!
//! Both passes have an explicit AVX path (`mod avx`, chosen at run time, no FMA) that treats
//! four consecutive particles at once, one per lane, slot by slot; an empty slot is masked to
//! add exactly zero. Per lane it performs the scalar code's IEEE operations in the same order,
//! so its results are bit-identical to the scalar path, which serves chunk tails, CPUs without
//! AVX and other architectures (checked by the test at the end of this file).
//!
//! Writing F_b through bθ uses that S_ji = S_ij, so F_s,ji never needs the neighbour's other
//! bonds. `LAG = true` is the literal reading (A) of docs/model.md §4: the force from the previous
//! step's positions drives this step.

use super::mechanics::{weighted, Mechanics};
use crate::aligned::{copied, filled, Aligned};
use crate::model::force_state::{bond_force, dilatation_term};
use crate::model::stretch::total_stretch;
use nalgebra::SVector;
use rayon::prelude::*;

/// Largest number of particles per parallel work item.
pub const CHUNK: usize = 2048;

/// Particles per parallel work item: about eight items per thread, so that a small scene
/// (a few thousand particles) still keeps every thread busy, at most [`CHUNK`] and a multiple
/// of the SIMD width. Chunking never changes results: each particle's update is independent.
pub fn chunk_len(n: usize) -> usize {
    let per_item = n.div_ceil(8 * rayon::current_num_threads().max(1));
    (per_item.div_ceil(LANES) * LANES).clamp(64, CHUNK)
}

/// Dynamic state, allocated once.
#[derive(Clone, Debug)]
pub struct State<const D: usize> {
    /// Positions x^n.
    pub x: Aligned<SVector<f64, D>>,
    /// Velocities v^{n−½}.
    pub v: Aligned<SVector<f64, D>>,
    pub x_next: Aligned<SVector<f64, D>>,
    pub v_next: Aligned<SVector<f64, D>>,
    /// Internal force (bonds and bond dampers) at x^n.
    pub force: Aligned<SVector<f64, D>>,
    /// Internal force at x^{n−1} (reading A only).
    pub force_prev: Aligned<SVector<f64, D>>,
    /// b_i·θ_i of the current step.
    pub b_theta: Aligned<f64>,
    /// Work done on each particle's dampers so far (J).
    pub damping_work: Aligned<f64>,
}

impl<const D: usize> State<D> {
    /// At rest in the reference configuration.
    pub fn at_rest(x0: &[SVector<f64, D>]) -> Self {
        let n = x0.len();
        // each array built on its own: a clone would not be advised for huge pages
        let z = || filled(SVector::zeros(), n);
        State {
            x: copied(x0),
            v: z(),
            x_next: copied(x0),
            v_next: z(),
            force: z(),
            force_prev: z(),
            b_theta: filled(0.0, n),
            damping_work: filled(0.0, n),
        }
    }
}

/// Particles handled together, one per SIMD lane (see `avx::dilatation_block`).
pub const LANES: usize = 4;

/// Length of a per-slot cache of n particles with k slots and `fields` values a slot, laid
/// out in blocks of [`LANES`] particles: block b (particles 4b..4b+4) holds, for each slot,
/// each field as 4 consecutive values, one per lane, so that an AVX pass loads or stores a
/// field a vector at a time (see [`lane_cache_at`]); the concrete kernels' slot cache.
pub const fn lane_cache_len(n: usize, k: usize, fields: usize) -> usize {
    n.div_ceil(LANES) * LANES * fields * k
}

/// Index of the first field of slot k of particle i in a [`lane_cache_len`] layout with
/// `slots` slots; field f follows f·LANES entries later.
#[inline(always)]
pub const fn lane_cache_at(i: usize, k: usize, slots: usize, fields: usize) -> usize {
    (i / LANES) * (fields * LANES * slots) + fields * LANES * k + i % LANES
}

/// b_i·θ_i, θ_i = Σ_m w_im·S_im (w = 1 without weights), for particle i (scalar; chunk tails
/// and reference).
#[inline(always)]
fn dilatation_one<const D: usize, const K: usize>(
    m: &Mechanics<D, K>,
    x: &[SVector<f64, D>],
    i: usize,
) -> f64 {
    let xi = x[i];
    let nb = &m.neighbours[i];
    let il = &m.inv_l0[i];
    let w = m.weights(i);
    let mut s = 0.0;
    for k in 0..K {
        let j = nb[k];
        if j == crate::discretise::NONE {
            continue;
        }
        // SAFETY: Mechanics::new checks every occupied slot indexes a particle.
        let xj = unsafe { *x.get_unchecked(j as usize) };
        s += weighted(w, k, total_stretch((xj - xi).norm(), il[k]));
    }
    dilatation_term(m.b[i], s)
}

/// Whether the AVX block kernels can run on this CPU.
#[inline]
pub(crate) fn use_avx() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Pass 1 over one chunk starting at particle `base`.
#[inline(always)]
fn dilatation_chunk<const D: usize, const K: usize>(
    m: &Mechanics<D, K>,
    x: &[SVector<f64, D>],
    base: usize,
    chunk: &mut [f64],
    avx: bool,
) {
    assert!(base + chunk.len() <= m.len() && m.len() == x.len());
    #[cfg(target_arch = "x86_64")]
    let done = if avx {
        let done = chunk.len() / LANES * LANES;
        // SAFETY: AVX is available (`use_avx`); base + done ≤ m.len() = x.len() (asserted
        // above); Mechanics::new checks every occupied slot indexes a particle.
        unsafe { avx::dilatation_chunk::<D, K>(m, x, base, &mut chunk[..done]) };
        done
    } else {
        0
    };
    #[cfg(not(target_arch = "x86_64"))]
    let done = {
        let _ = avx;
        0
    };
    for (o, bt) in chunk.iter_mut().enumerate().skip(done) {
        *bt = dilatation_one(m, x, base + o);
    }
}

/// Pass 1: b_i·Σ_m S_im for every particle.
pub fn pass_dilatation<const D: usize, const K: usize>(
    m: &Mechanics<D, K>,
    x: &[SVector<f64, D>],
    out: &mut [f64],
) {
    assert!(x.len() == m.len() && out.len() == m.len());
    let avx = use_avx();
    let chunk = chunk_len(out.len());
    out.par_chunks_mut(chunk)
        .enumerate()
        .for_each(|(c, items)| dilatation_chunk::<D, K>(m, x, c * chunk, items, avx));
}

/// Internal force on particle i at positions x with velocities v (bond dampers if `DAMP`);
/// returns the force and the power dissipated in its bond dampers (half of each bond's).
/// Second-neighbour slots use the moduli a + c where the model has them
/// ([`Mechanics::bond_moduli`]).
#[inline(always)]
pub fn particle_force<const D: usize, const K: usize, const DAMP: bool>(
    m: &Mechanics<D, K>,
    x: &[SVector<f64, D>],
    v: &[SVector<f64, D>],
    b_theta: &[f64],
    i: usize,
) -> (SVector<f64, D>, f64) {
    match &m.second {
        None => particle_force_impl::<D, K, DAMP, false>(m, &[], 0, x, v, b_theta, i),
        Some(s) => particle_force_impl::<D, K, DAMP, true>(m, &s.c, s.first_slot, x, v, b_theta, i),
    }
}

/// [`particle_force`]; with `SECOND`, slots `first..K` are second neighbours with the moduli
/// a + c (`c` per particle), otherwise `c` and `first` are unused.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn particle_force_impl<const D: usize, const K: usize, const DAMP: bool, const SECOND: bool>(
    m: &Mechanics<D, K>,
    c: &[f64],
    first: usize,
    x: &[SVector<f64, D>],
    v: &[SVector<f64, D>],
    b_theta: &[f64],
    i: usize,
) -> (SVector<f64, D>, f64) {
    debug_assert!(x.len() == m.len() && v.len() == m.len() && b_theta.len() == m.len());
    debug_assert!(!SECOND || c.len() == m.len());
    let xi = x[i];
    let ai = m.a[i];
    let aci = if SECOND { ai + c[i] } else { ai };
    let bti = b_theta[i];
    let nb = &m.neighbours[i];
    let il = &m.inv_l0[i];
    let mut f = SVector::<f64, D>::zeros();
    let mut power = 0.0;
    for k in 0..K {
        let j = nb[k];
        if j == crate::discretise::NONE {
            continue;
        }
        let j = j as usize;
        // SAFETY: Mechanics::new checks every occupied slot indexes a particle, and the
        // state arrays have one entry per particle (c too, asserted in debug builds).
        let (xj, aj, btj) = unsafe {
            (
                *x.get_unchecked(j),
                *m.a.get_unchecked(j),
                *b_theta.get_unchecked(j),
            )
        };
        let d = xj - xi;
        let len = d.norm();
        let e = d * (1.0 / len);
        let s = total_stretch(len, il[k]);
        let mut fb = if SECOND && k >= first {
            let acj = aj + unsafe { *c.get_unchecked(j) };
            bond_force(aci, acj, s, bti, btj)
        } else {
            bond_force(ai, aj, s, bti, btj)
        };
        if DAMP {
            let (vj, cj) = unsafe { (*v.get_unchecked(j), *m.c_in.get_unchecked(j)) };
            let c = 0.5 * (m.c_in[i] + cj);
            let rate = (vj - v[i]).dot(&e);
            fb += c * rate;
            power += 0.5 * c * rate * rate;
        }
        f += e * fb;
    }
    (f, power)
}

/// What pass 2 reads: the model, the state at step n and the step size.
#[derive(Clone, Copy)]
struct Inputs<'a, const D: usize, const K: usize> {
    m: &'a Mechanics<D, K>,
    x: &'a [SVector<f64, D>],
    v: &'a [SVector<f64, D>],
    b_theta: &'a [f64],
    force_prev: &'a [SVector<f64, D>],
    dt: f64,
}

/// What pass 2 writes for one chunk of particles (the elastic and the inelastic kernels).
pub(crate) struct ChunkOut<'b, const D: usize> {
    pub xn: &'b mut [SVector<f64, D>],
    pub vn: &'b mut [SVector<f64, D>],
    pub fo: &'b mut [SVector<f64, D>],
    pub dw: &'b mut [f64],
}

impl<const D: usize> ChunkOut<'_, D> {
    /// The chunk's first `len` particles (the share of the AVX blocks).
    pub fn head(&mut self, len: usize) -> ChunkOut<'_, D> {
        ChunkOut {
            xn: &mut self.xn[..len],
            vn: &mut self.vn[..len],
            fo: &mut self.fo[..len],
            dw: &mut self.dw[..len],
        }
    }
}

/// The central-difference update of particle i given its internal force.
#[inline(always)]
fn update_one<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>(
    inp: Inputs<'_, D, K>,
    i: usize,
    f: SVector<f64, D>,
    bond_power: f64,
    xn: &mut SVector<f64, D>,
    vn: &mut SVector<f64, D>,
    dw: &mut f64,
) {
    let Inputs {
        m,
        x,
        v,
        force_prev,
        dt,
        ..
    } = inp;
    let drive = if LAG { force_prev[i] } else { f };
    central_difference::<D, K, DAMP>(m, i, x[i], v[i], drive, bond_power, dt, xn, vn, dw);
}

/// Central differences (3.58) for particle i at x_i, v_i^{n−½} driven by `drive`, with the
/// particle damper (3.56) taken semi-implicitly and the implicit share of the bond dampers
/// (S.17); adds the work of its dampers (the bond
/// dampers' `bond_power` and the particle damper's) over the step to `dw`. Shared by the
/// elastic and the concrete kernels.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn central_difference<const D: usize, const K: usize, const DAMP: bool>(
    m: &Mechanics<D, K>,
    i: usize,
    xi: SVector<f64, D>,
    vi: SVector<f64, D>,
    drive: SVector<f64, D>,
    bond_power: f64,
    dt: f64,
    xn: &mut SVector<f64, D>,
    vn: &mut SVector<f64, D>,
    dw: &mut f64,
) {
    let h = 0.5 * dt * m.c_ex[i] * m.inv_mass[i];
    // (S.17): the implicit share d_i of the bond dampers, g = Δt·d_i/m_i (0: exactly (3.58))
    let g = 1.0 + dt * m.c_implicit[i] * m.inv_mass[i];
    let vnew = (vi * (g - h) + drive * (dt * m.inv_mass[i])) / (g + h);
    *vn = vnew;
    *xn = xi + vnew * dt;
    if DAMP || h != 0.0 {
        let vm = (vi + vnew) * 0.5;
        let implicit = m.c_implicit[i] * (vnew - vi).dot(&vm);
        *dw += dt * (bond_power + m.c_ex[i] * vm.norm_squared() + implicit);
    }
}

/// Pass 2 over one chunk starting at particle `base`.
#[inline(always)]
fn update_chunk<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>(
    inp: Inputs<'_, D, K>,
    base: usize,
    out: ChunkOut<'_, D>,
    avx: bool,
) {
    let Inputs {
        m,
        x,
        v,
        b_theta,
        force_prev,
        ..
    } = inp;
    let mut out = out;
    let len = out.xn.len();
    let n = m.len();
    assert!(base + len <= n && x.len() == n && v.len() == n && b_theta.len() == n);
    assert!(force_prev.len() == n);
    assert!(out.vn.len() == len && out.fo.len() == len && out.dw.len() == len);
    #[cfg(target_arch = "x86_64")]
    let done = if avx {
        let done = len / LANES * LANES;
        // SAFETY: AVX is available (`use_avx`); base + done ≤ n and every state array has n
        // entries (asserted above); Mechanics::new checks every occupied slot indexes a
        // particle.
        unsafe { avx::update_chunk::<D, K, LAG, DAMP>(inp, base, out.head(done)) };
        done
    } else {
        0
    };
    #[cfg(not(target_arch = "x86_64"))]
    let done = {
        let _ = avx;
        0
    };
    let ChunkOut { xn, vn, fo, dw } = out;
    for o in done..len {
        let i = base + o;
        let (f, bond_power) = particle_force::<D, K, DAMP>(m, x, v, b_theta, i);
        fo[o] = f;
        update_one::<D, K, LAG, DAMP>(inp, i, f, bond_power, &mut xn[o], &mut vn[o], &mut dw[o]);
    }
}

/// Pass 2: forces and the central-difference update of every particle into x_next, v_next.
pub fn pass_update<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>(
    m: &Mechanics<D, K>,
    st: &mut State<D>,
    dt: f64,
) {
    let n = m.len();
    let avx = use_avx();
    update_in_chunks(st, n, |base, r, out| {
        let inp = Inputs {
            m,
            x: r.x,
            v: r.v,
            b_theta: r.b_theta,
            force_prev: r.force_prev,
            dt,
        };
        update_chunk::<D, K, LAG, DAMP>(inp, base, out, avx)
    });
}

/// What pass 2 reads of the state at step n (all particles).
pub(crate) struct StateReads<'a, const D: usize> {
    pub x: &'a [SVector<f64, D>],
    pub v: &'a [SVector<f64, D>],
    pub b_theta: &'a [f64],
    pub force_prev: &'a [SVector<f64, D>],
}

/// Pass 2's parallel frame, shared by the elastic and the inelastic kernels: checks that every
/// per-particle array of the state holds `n` entries, then hands each chunk of
/// [`chunk_len`]`(n)` particles (starting at `base`) its slice of x_next, v_next, force and
/// damper work, with the state it reads, to `update(base, reads, out)`.
pub(crate) fn update_in_chunks<const D: usize>(
    st: &mut State<D>,
    n: usize,
    update: impl Fn(usize, StateReads<'_, D>, ChunkOut<'_, D>) + Sync,
) {
    let State {
        x,
        v,
        x_next,
        v_next,
        force,
        force_prev,
        b_theta,
        damping_work,
    } = st;
    assert!([
        x.len(),
        v.len(),
        x_next.len(),
        v_next.len(),
        force.len(),
        force_prev.len(),
        b_theta.len(),
        damping_work.len()
    ]
    .iter()
    .all(|&l| l == n));
    let (x, v, b_theta, force_prev) = (&x[..], &v[..], &b_theta[..], &force_prev[..]);
    let chunk = chunk_len(n);
    x_next
        .par_chunks_mut(chunk)
        .zip(v_next.par_chunks_mut(chunk))
        .zip(force.par_chunks_mut(chunk))
        .zip(damping_work.par_chunks_mut(chunk))
        .enumerate()
        .for_each(|(c, (((xn, vn), fo), dw))| {
            let reads = StateReads {
                x,
                v,
                b_theta,
                force_prev,
            };
            update(c * chunk, reads, ChunkOut { xn, vn, fo, dw })
        });
}

/// One explicit step from x^n, v^{n−½} to x^{n+1}, v^{n+½} (not yet swapped in): pass 1
/// ([`pass_dilatation`]) and pass 2 ([`pass_update`]). Pass 2 recomputes each bond's length
/// rather than reading it from a per-bond cache written by pass 1: on the 2-core Xeon the
/// cache's 16 B per bond of traffic cost more than the square roots and divisions it saved
/// (benchmarks/RESULTS.md, "Without the bond cache").
pub fn step<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>(
    m: &Mechanics<D, K>,
    st: &mut State<D>,
    dt: f64,
) {
    pass_dilatation(m, &st.x, &mut st.b_theta);
    pass_update::<D, K, LAG, DAMP>(m, st, dt);
}

/// Explicit AVX (4 × f64) versions of the block kernels, one particle per lane. They perform
/// per lane the same IEEE operations in the same order as the scalar code (no FMA), so the
/// results are bit-identical to it.
#[cfg(target_arch = "x86_64")]
pub(crate) mod avx;

#[cfg(test)]
mod tests;
