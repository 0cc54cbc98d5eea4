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

/// What pass 2 writes for one chunk of particles (the slot and the CSR kernels).
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
/// particle damper (3.56) taken semi-implicitly; adds the work of its dampers (the bond
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
    let vnew = (vi * (1.0 - h) + drive * (dt * m.inv_mass[i])) / (1.0 + h);
    *vn = vnew;
    *xn = xi + vnew * dt;
    if DAMP || h != 0.0 {
        let vm = (vi + vnew) * 0.5;
        *dw += dt * (bond_power + m.c_ex[i] * vm.norm_squared());
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

/// Pass 2's parallel frame, shared by the slot and the CSR kernels: checks that every
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
pub(crate) mod avx {
    use super::{ChunkOut, Inputs, Mechanics, LANES};
    use crate::discretise::NONE;
    use core::arch::x86_64::*;
    use nalgebra::SVector;

    const _: () = assert!(LANES == 4);

    /// Component c of 4 vectors at rows i0..i0+4, one per lane.
    ///
    /// # Safety
    /// AVX available; i0 + 4 ≤ x.len().
    #[target_feature(enable = "avx")]
    #[inline]
    pub(crate) unsafe fn load_own<const D: usize>(
        x: &[SVector<f64, D>],
        i0: usize,
    ) -> [__m256d; D] {
        let mut out = [_mm256_setzero_pd(); D];
        if D == 2 && std::mem::size_of::<SVector<f64, D>>() == 16 {
            let p = x.as_ptr().add(i0) as *const f64;
            let a = _mm256_loadu_pd(p); // x0 y0 x1 y1
            let b = _mm256_loadu_pd(p.add(4)); // x2 y2 x3 y3
            let lo = _mm256_permute2f128_pd(a, b, 0x20); // x0 y0 x2 y2
            let hi = _mm256_permute2f128_pd(a, b, 0x31); // x1 y1 x3 y3
            out[0] = _mm256_unpacklo_pd(lo, hi);
            out[1] = _mm256_unpackhi_pd(lo, hi);
        } else {
            for (c, o) in out.iter_mut().enumerate() {
                *o = _mm256_set_pd(
                    x.get_unchecked(i0 + 3)[c],
                    x.get_unchecked(i0 + 2)[c],
                    x.get_unchecked(i0 + 1)[c],
                    x.get_unchecked(i0)[c],
                );
            }
        }
        out
    }

    /// Component c of the vectors at rows j[0..4], one per lane.
    ///
    /// # Safety
    /// AVX available; every j < x.len().
    #[target_feature(enable = "avx")]
    #[inline]
    pub(crate) unsafe fn gather_vec<const D: usize>(
        x: &[SVector<f64, D>],
        j: &[usize; 4],
    ) -> [__m256d; D] {
        let mut out = [_mm256_setzero_pd(); D];
        if D == 2 && std::mem::size_of::<SVector<f64, D>>() == 16 {
            let p = x.as_ptr() as *const f64;
            let r = |l: usize| _mm_loadu_pd(p.add(2 * j[l]));
            let a = _mm256_insertf128_pd(_mm256_castpd128_pd256(r(0)), r(2), 1); // x0 y0 x2 y2
            let b = _mm256_insertf128_pd(_mm256_castpd128_pd256(r(1)), r(3), 1); // x1 y1 x3 y3
            out[0] = _mm256_unpacklo_pd(a, b);
            out[1] = _mm256_unpackhi_pd(a, b);
        } else if D == 3 && std::mem::size_of::<SVector<f64, D>>() == 24 {
            // x, y as in 2D (one 16-byte load per row, two shuffles), z one by one
            let p = x.as_ptr() as *const f64;
            let r = |l: usize| _mm_loadu_pd(p.add(3 * j[l]));
            let a = _mm256_insertf128_pd(_mm256_castpd128_pd256(r(0)), r(2), 1); // x0 y0 x2 y2
            let b = _mm256_insertf128_pd(_mm256_castpd128_pd256(r(1)), r(3), 1); // x1 y1 x3 y3
            out[0] = _mm256_unpacklo_pd(a, b);
            out[1] = _mm256_unpackhi_pd(a, b);
            let z = |l: usize| *p.add(3 * j[l] + 2);
            out[2] = _mm256_set_pd(z(3), z(2), z(1), z(0));
        } else {
            for (c, o) in out.iter_mut().enumerate() {
                *o = _mm256_set_pd(
                    x.get_unchecked(j[3])[c],
                    x.get_unchecked(j[2])[c],
                    x.get_unchecked(j[1])[c],
                    x.get_unchecked(j[0])[c],
                );
            }
        }
        out
    }

    /// s[j[l]] per lane.
    #[target_feature(enable = "avx")]
    #[inline]
    pub(crate) unsafe fn gather(s: &[f64], j: &[usize; 4]) -> __m256d {
        _mm256_set_pd(
            *s.get_unchecked(j[3]),
            *s.get_unchecked(j[2]),
            *s.get_unchecked(j[1]),
            *s.get_unchecked(j[0]),
        )
    }

    /// The slots a block of particles i0..i0+4 needs: one past the last occupied slot of any
    /// of them (the slots after it are empty in every lane and add nothing).
    ///
    /// # Safety
    /// i0 + 4 ≤ m.len().
    #[inline(always)]
    pub(crate) unsafe fn block_slots<const D: usize, const K: usize>(
        m: &Mechanics<D, K>,
        i0: usize,
    ) -> usize {
        let e = |l: usize| *m.slot_end.get_unchecked(i0 + l) as usize;
        e(0).max(e(1)).max(e(2)).max(e(3))
    }

    /// Neighbours in slot k of particles i0..i0+4 (the particle itself where the slot is
    /// empty) and the occupancy mask (all ones where occupied).
    #[target_feature(enable = "avx")]
    #[inline]
    pub(crate) unsafe fn slot<const D: usize, const K: usize>(
        m: &Mechanics<D, K>,
        i0: usize,
        k: usize,
    ) -> ([usize; 4], __m256d, __m256d) {
        let mut j = [0usize; 4];
        let mut occ = [0i64; 4];
        for l in 0..4 {
            let jj = *m.neighbours.get_unchecked(i0 + l).get_unchecked(k);
            let o = jj != NONE;
            occ[l] = -(o as i64);
            j[l] = if o { jj as usize } else { i0 + l };
        }
        let mask = _mm256_castsi256_pd(_mm256_set_epi64x(occ[3], occ[2], occ[1], occ[0]));
        // 1/L0: the slot's one value on a lattice (an empty lane's value is masked by the
        // caller), else each particle's own
        let il = match &m.slot_inv_l0 {
            Some(u) => _mm256_set1_pd(*u.get_unchecked(k)),
            None => {
                let r = |l: usize| *m.inv_l0.get_unchecked(i0 + l).get_unchecked(k);
                _mm256_set_pd(r(3), r(2), r(1), r(0))
            }
        };
        (j, mask, il)
    }

    /// d = x_j − x_i per component and |d| (components summed in order, as nalgebra does).
    #[target_feature(enable = "avx")]
    #[inline]
    pub(crate) unsafe fn geometry<const D: usize>(
        xi: &[__m256d; D],
        xj: &[__m256d; D],
    ) -> ([__m256d; D], __m256d) {
        let mut d = [_mm256_setzero_pd(); D];
        for c in 0..D {
            d[c] = _mm256_sub_pd(xj[c], xi[c]);
        }
        let mut l2 = _mm256_mul_pd(d[0], d[0]);
        for dc in d.iter().skip(1) {
            l2 = _mm256_add_pd(l2, _mm256_mul_pd(*dc, *dc));
        }
        (d, _mm256_sqrt_pd(l2))
    }

    /// b_i·θ_i (θ_i = Σ_m w_im·S_im, w = 1 without weights) for particles i0..i0+4 into
    /// out[0..4]. `WEIGHTED` is whether the body weighs its dilatations
    /// (`m.dilatation_weight`), a test hoisted out of the slot loop.
    ///
    /// # Safety
    /// AVX available; i0 + 4 ≤ m.len() = x.len(); every occupied slot indexes a particle.
    #[target_feature(enable = "avx")]
    #[inline]
    pub unsafe fn dilatation_block<const D: usize, const K: usize, const WEIGHTED: bool>(
        m: &Mechanics<D, K>,
        x: &[SVector<f64, D>],
        i0: usize,
        out: *mut f64,
    ) {
        let one = _mm256_set1_pd(1.0);
        let xi = load_own(x, i0);
        let mut s = _mm256_setzero_pd();
        for k in 0..block_slots(m, i0) {
            let (j, occ, il) = slot(m, i0, k);
            let (_, len) = geometry(&xi, &gather_vec(x, &j));
            // total_stretch: len·(1/L0) − 1
            let st = _mm256_and_pd(_mm256_sub_pd(_mm256_mul_pd(len, il), one), occ);
            // weighted dilatation (random particles): w·S, as the scalar path
            let term = match (WEIGHTED, &m.slot_weight, &m.dilatation_weight) {
                // the same weight in every row (the FCC lattice): broadcast it
                (true, Some(u), _) => _mm256_mul_pd(_mm256_set1_pd(*u.get_unchecked(k)), st),
                (true, None, Some(w)) => {
                    let wk = |l: usize| *w.get_unchecked(i0 + l).get_unchecked(k);
                    _mm256_mul_pd(_mm256_set_pd(wk(3), wk(2), wk(1), wk(0)), st)
                }
                _ => st,
            };
            s = _mm256_add_pd(s, term);
        }
        let b = _mm256_loadu_pd(m.b.as_ptr().add(i0));
        _mm256_storeu_pd(out, _mm256_mul_pd(b, s));
    }

    /// `super::particle_force` of particles i0..i0+4, one per lane, as SoA: the force per
    /// component and the bond-damper power. With
    /// `SECOND`, the model has second-neighbour moduli (`m.second`) and their slots take
    /// the moduli a + c, added in the scalar code's order.
    ///
    /// # Safety
    /// AVX available; i0 + 4 ≤ m.len(); x, v and b_theta have m.len() entries; every
    /// occupied slot indexes a particle; with `SECOND`, `m.second` is `Some` with m.len() entries.
    #[target_feature(enable = "avx")]
    #[inline]
    pub unsafe fn force_block<
        const D: usize,
        const K: usize,
        const DAMP: bool,
        const SECOND: bool,
    >(
        m: &Mechanics<D, K>,
        x: &[SVector<f64, D>],
        v: &[SVector<f64, D>],
        b_theta: &[f64],
        i0: usize,
    ) -> ([__m256d; D], __m256d) {
        let one = _mm256_set1_pd(1.0);
        let half = _mm256_set1_pd(0.5);
        let xi = load_own(x, i0);
        let vi = if DAMP {
            load_own(v, i0)
        } else {
            [_mm256_setzero_pd(); D]
        };
        let ai = _mm256_loadu_pd(m.a.as_ptr().add(i0));
        // second-neighbour moduli: c per particle, a_i + c_i, the first slot (unused
        // without SECOND)
        let (sc, aci, first): (&[f64], __m256d, usize) = match (SECOND, &m.second) {
            (true, Some(s)) => (
                &s.c[..],
                _mm256_add_pd(ai, _mm256_loadu_pd(s.c.as_ptr().add(i0))),
                s.first_slot,
            ),
            _ => (&[], ai, usize::MAX),
        };
        let bti = _mm256_loadu_pd(b_theta.as_ptr().add(i0));
        let ci = if DAMP {
            _mm256_loadu_pd(m.c_in.as_ptr().add(i0))
        } else {
            _mm256_setzero_pd()
        };
        let mut f = [_mm256_setzero_pd(); D];
        let mut power = _mm256_setzero_pd();
        for k in 0..block_slots(m, i0) {
            let (j, occ, il) = slot(m, i0, k);
            let xj = gather_vec(x, &j);
            let (d, len) = geometry(&xi, &xj);
            let rinv = _mm256_and_pd(_mm256_div_pd(one, len), occ);
            let st = _mm256_and_pd(_mm256_sub_pd(_mm256_mul_pd(len, il), one), occ);
            let aj = gather(&m.a, &j);
            let btj = gather(b_theta, &j);
            // the bond moduli: (a_i + c_i, a_j + c_j) in a second-neighbour slot
            let (mi, mj) = if SECOND && k >= first {
                (aci, _mm256_add_pd(aj, gather(sc, &j)))
            } else {
                (ai, aj)
            };
            // 0.5 * ((mi + mj) * s + bti + btj)
            let mut fb = _mm256_mul_pd(
                half,
                _mm256_add_pd(
                    _mm256_add_pd(_mm256_mul_pd(_mm256_add_pd(mi, mj), st), bti),
                    btj,
                ),
            );
            let mut e = [_mm256_setzero_pd(); D];
            for c in 0..D {
                e[c] = _mm256_mul_pd(d[c], rinv);
            }
            if DAMP {
                let cj = gather(&m.c_in, &j);
                let c = _mm256_mul_pd(half, _mm256_add_pd(ci, cj));
                let vj = gather_vec(v, &j);
                let mut rate = _mm256_mul_pd(_mm256_sub_pd(vj[0], vi[0]), e[0]);
                for cc in 1..D {
                    rate = _mm256_add_pd(rate, _mm256_mul_pd(_mm256_sub_pd(vj[cc], vi[cc]), e[cc]));
                }
                fb = _mm256_add_pd(fb, _mm256_mul_pd(c, rate));
                // 0.5 * c * rate * rate
                power = _mm256_add_pd(
                    power,
                    _mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(half, c), rate), rate),
                );
            }
            for c in 0..D {
                f[c] = _mm256_add_pd(f[c], _mm256_mul_pd(e[c], fb));
            }
        }
        (f, power)
    }

    /// Pass 1 over whole blocks: `out` holds particles base.., a multiple of 4 of them.
    ///
    /// # Safety
    /// AVX available; base + out.len() ≤ m.len() = x.len(); every occupied slot indexes a
    /// particle.
    #[target_feature(enable = "avx")]
    pub unsafe fn dilatation_chunk<const D: usize, const K: usize>(
        m: &Mechanics<D, K>,
        x: &[SVector<f64, D>],
        base: usize,
        out: &mut [f64],
    ) {
        for o in (0..out.len()).step_by(4) {
            // the weights' test hoisted out of the slot loop (one loop per case)
            if m.dilatation_weight.is_some() {
                dilatation_block::<D, K, true>(m, x, base + o, out.as_mut_ptr().add(o));
            } else {
                dilatation_block::<D, K, false>(m, x, base + o, out.as_mut_ptr().add(o));
            }
        }
    }

    /// Stores 4 vectors given per component (one per lane) at rows i0..i0+4 (D = 2 only).
    ///
    /// # Safety
    /// AVX available; D = 2 with 16-byte vectors; i0 + 4 ≤ x.len().
    #[target_feature(enable = "avx")]
    #[inline]
    unsafe fn store_own2<const D: usize>(x: &mut [SVector<f64, D>], i0: usize, c: &[__m256d; D]) {
        let a = _mm256_unpacklo_pd(c[0], c[1]); // x0 y0 x2 y2
        let b = _mm256_unpackhi_pd(c[0], c[1]); // x1 y1 x3 y3
        let p = x.as_mut_ptr().add(i0) as *mut f64;
        _mm256_storeu_pd(p, _mm256_permute2f128_pd(a, b, 0x20));
        _mm256_storeu_pd(p.add(4), _mm256_permute2f128_pd(a, b, 0x31));
    }

    /// Whether [`update_block`] applies: D = 2 with 16-byte vectors.
    #[inline(always)]
    pub(crate) fn vector_update<const D: usize>() -> bool {
        D == 2 && std::mem::size_of::<SVector<f64, D>>() == 16
    }

    /// The central-difference update (`super::update_one`) of particles i0..i0+4 (chunk
    /// positions o0..o0+4 of xn, vn, fo, dw) from their internal forces `f` (per component,
    /// one per lane) and bond-damper power, the same operations in the same order per lane.
    /// Shared by the elastic and the concrete kernels.
    ///
    /// # Safety
    /// AVX available; [`vector_update`]; i0 + 4 ≤ x.len() = v.len() = force_prev.len() =
    /// m.len(); o0 + 4 ≤ the length of xn, vn, fo and dw.
    #[target_feature(enable = "avx")]
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub(crate) unsafe fn update_block<
        const D: usize,
        const K: usize,
        const LAG: bool,
        const DAMP: bool,
    >(
        m: &Mechanics<D, K>,
        x: &[SVector<f64, D>],
        v: &[SVector<f64, D>],
        force_prev: &[SVector<f64, D>],
        dt: f64,
        i0: usize,
        o0: usize,
        f: &[__m256d; D],
        power: __m256d,
        xn: &mut [SVector<f64, D>],
        vn: &mut [SVector<f64, D>],
        fo: &mut [SVector<f64, D>],
        dw: &mut [f64],
    ) {
        let one = _mm256_set1_pd(1.0);
        let half = _mm256_set1_pd(0.5);
        let zero = _mm256_setzero_pd();
        let dtv = _mm256_set1_pd(dt);
        let half_dt = _mm256_set1_pd(0.5 * dt);
        // super::update_one per lane, the same operations in the same order.
        store_own2(fo, o0, f);
        let drive = if LAG { load_own(force_prev, i0) } else { *f };
        let cex = _mm256_loadu_pd(m.c_ex.as_ptr().add(i0));
        let im = _mm256_loadu_pd(m.inv_mass.as_ptr().add(i0));
        // h = 0.5 * dt * c_ex * inv_mass
        let h = _mm256_mul_pd(_mm256_mul_pd(half_dt, cex), im);
        let one_m_h = _mm256_sub_pd(one, h);
        let one_p_h = _mm256_add_pd(one, h);
        let dt_im = _mm256_mul_pd(dtv, im);
        let vi = load_own(v, i0);
        let xi = load_own(x, i0);
        let mut vnew = [zero; D];
        let mut xnew = [zero; D];
        for c in 0..D {
            vnew[c] = _mm256_div_pd(
                _mm256_add_pd(
                    _mm256_mul_pd(vi[c], one_m_h),
                    _mm256_mul_pd(drive[c], dt_im),
                ),
                one_p_h,
            );
            xnew[c] = _mm256_add_pd(xi[c], _mm256_mul_pd(vnew[c], dtv));
        }
        store_own2(vn, o0, &vnew);
        store_own2(xn, o0, &xnew);
        // dw += dt * (bond_power + c_ex * |½(v_i + v_new)|²) where DAMP or h ≠ 0
        let mut vm2 = zero;
        for c in 0..D {
            let vm = _mm256_mul_pd(_mm256_add_pd(vi[c], vnew[c]), half);
            let sq = _mm256_mul_pd(vm, vm);
            vm2 = if c == 0 { sq } else { _mm256_add_pd(vm2, sq) };
        }
        let pw = dw.as_mut_ptr().add(o0);
        let old = _mm256_loadu_pd(pw);
        let new = _mm256_add_pd(
            old,
            _mm256_mul_pd(dtv, _mm256_add_pd(power, _mm256_mul_pd(cex, vm2))),
        );
        let new = if DAMP {
            new
        } else {
            _mm256_blendv_pd(old, new, _mm256_cmp_pd::<_CMP_NEQ_UQ>(h, zero))
        };
        _mm256_storeu_pd(pw, new);
    }

    /// Pass 2 over whole blocks: the slices hold particles base.., a multiple of 4 of them.
    ///
    /// # Safety
    /// AVX available; base + xn.len() ≤ m.len(); x, v, b_theta and force_prev have m.len()
    /// entries, vn, fo and dw xn.len(); every occupied slot indexes a particle.
    #[target_feature(enable = "avx")]
    pub(super) unsafe fn update_chunk<
        const D: usize,
        const K: usize,
        const LAG: bool,
        const DAMP: bool,
    >(
        inp: Inputs<'_, D, K>,
        base: usize,
        out: ChunkOut<'_, D>,
    ) {
        let Inputs {
            m,
            x,
            v,
            b_theta,
            force_prev,
            dt,
        } = inp;
        let ChunkOut { xn, vn, fo, dw } = out;
        let vector_update = vector_update::<D>();
        let second = m.second.is_some();
        for o0 in (0..xn.len()).step_by(4) {
            let i0 = base + o0;
            let (f, power) = if second {
                force_block::<D, K, DAMP, true>(m, x, v, b_theta, i0)
            } else {
                force_block::<D, K, DAMP, false>(m, x, v, b_theta, i0)
            };
            if vector_update {
                update_block::<D, K, LAG, DAMP>(
                    m, x, v, force_prev, dt, i0, o0, &f, power, xn, vn, fo, dw,
                );
                continue;
            }
            let mut fa = [[0.0; 4]; D];
            for c in 0..D {
                _mm256_storeu_pd(fa[c].as_mut_ptr(), f[c]);
            }
            let mut pa = [0.0; 4];
            _mm256_storeu_pd(pa.as_mut_ptr(), power);
            for l in 0..4 {
                let o = o0 + l;
                let fl = SVector::<f64, D>::from_fn(|c, _| fa[c][l]);
                *fo.get_unchecked_mut(o) = fl;
                super::update_one::<D, K, LAG, DAMP>(
                    inp,
                    i0 + l,
                    fl,
                    pa[l],
                    xn.get_unchecked_mut(o),
                    vn.get_unchecked_mut(o),
                    dw.get_unchecked_mut(o),
                );
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aligned::CollectAligned;
    use crate::discretise::NONE;
    use crate::solver::mechanics::uniform_inv_l0;

    use crate::solver::test_rng::Lcg;

    /// A random model with some empty slots and a random state, n not a multiple of the
    /// chunk or block size.
    fn model<const D: usize, const K: usize>(n: usize) -> (Mechanics<D, K>, State<D>) {
        let mut r = Lcg(12345);
        let x0: Vec<SVector<f64, D>> = (0..n)
            .map(|i| SVector::from_fn(|c, _| i as f64 * 1e-3 * (c + 1) as f64 + 1e-4 * r.next()))
            .collect();
        let mut neighbours = vec![[NONE; K]; n];
        let mut inv_l0 = vec![[0.0; K]; n];
        for i in 0..n {
            for k in 0..K {
                if r.next() < 0.8 {
                    let mut j = (i + 1 + (r.next() * 40.0) as usize) % n;
                    if j == i {
                        j = (i + 1) % n;
                    }
                    neighbours[i][k] = j as u32;
                    inv_l0[i][k] = 1.0 / ((x0[j] - x0[i]).norm() * (1.0 + 0.01 * r.next()));
                }
            }
        }
        let mut v = |s: f64| (0..n).map(|_| s * (1.0 + r.next())).collect_aligned();
        let (a, b, mass, c_in, mut c_ex) = (v(3e6), v(-1e5), v(1e-3), v(10.0), v(1.0));
        // some particles without a particle damper (h = 0)
        for c in c_ex.iter_mut().step_by(3) {
            *c = 0.0;
        }
        let slot_end = crate::solver::mechanics::slot_end(&neighbours);
        let mech = Mechanics {
            neighbours: copied(&neighbours),
            slot_inv_l0: uniform_inv_l0(&neighbours, &inv_l0),
            inv_l0: copied(&inv_l0),
            a,
            b,
            second: None,
            inv_mass: mass.iter().map(|m| 1.0 / m).collect_aligned(),
            mass,
            c_in,
            c_ex,
            dilatation_weight: None,
            slot_weight: None,
            slot_end,
        };
        let mut st = State::at_rest(&x0);
        for i in 0..n {
            st.v[i] = SVector::from_fn(|_, _| r.next() - 0.5);
            st.force_prev[i] = SVector::from_fn(|_, _| r.next() - 0.5);
            st.damping_work[i] = r.next();
        }
        (mech, st)
    }

    /// The kernel against the plain per-particle code, bit for bit, on 1 and 2 threads, with
    /// a reference length per bond and with one per slot (a lattice: the AVX blocks
    /// broadcast [`Mechanics::slot_inv_l0`]); with 18 slots also with FCC second-neighbour
    /// moduli c in slots 12..18.
    fn check<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>() {
        check_weighted::<D, K, LAG, DAMP>(false, false);
        check_weighted::<D, K, LAG, DAMP>(false, true);
        if K == 18 {
            let n = 2 * CHUNK + 4 * 37 + 3;
            let (mut m, st0) = model::<D, K>(n);
            with_second(&mut m);
            check_model::<D, K, LAG, DAMP>(&m, &st0);
        }
    }

    /// Random second-neighbour moduli c (about −0.65·a, as FCC's) in slots 12..K.
    fn with_second<const D: usize, const K: usize>(m: &mut Mechanics<D, K>) {
        let mut r = Lcg(99);
        let c =
            m.a.iter()
                .map(|a| -0.65 * a * (1.0 + 0.1 * r.next()))
                .collect_aligned();
        m.second = Some(crate::solver::mechanics::SecondNeighbours { c, first_slot: 12 });
    }

    /// [`check`]; with `weighted`, the body weighs its dilatations (random particles); with
    /// `per_slot`, every bond in slot k has the same reference length.
    fn check_weighted<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>(
        weighted: bool,
        per_slot: bool,
    ) {
        let n = 2 * CHUNK + 4 * 37 + 3;
        let (mut m, st0) = model::<D, K>(n);
        assert!(m.slot_inv_l0.is_none());
        if per_slot {
            let u: [f64; K] = std::array::from_fn(|k| 1.0 / (3e-3 * (1.0 + 0.1 * k as f64)));
            for (s, l) in m.neighbours.iter().zip(m.inv_l0.iter_mut()) {
                for k in 0..K {
                    if s[k] != NONE {
                        l[k] = u[k];
                    }
                }
            }
            m.slot_inv_l0 = uniform_inv_l0(&m.neighbours, &m.inv_l0);
            assert_eq!(m.slot_inv_l0, Some(u));
        }
        if weighted {
            // L0,ik/ℓ_i of random particles lies about 0.6–1.6
            let mut r = Lcg(7);
            m.dilatation_weight = Some(
                (0..n)
                    .map(|i| {
                        std::array::from_fn(|k| {
                            let w = 0.6 + r.next();
                            if m.neighbours[i][k] == NONE {
                                0.0
                            } else {
                                w
                            }
                        })
                    })
                    .collect_aligned(),
            );
        }
        check_model::<D, K, LAG, DAMP>(&m, &st0);
    }

    /// The kernel's step of model `m` from state `st0` against the plain per-particle code.
    fn check_model<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>(
        m: &Mechanics<D, K>,
        st0: &State<D>,
    ) {
        let n = m.len();
        let dt = 1e-7;
        let mut want = st0.clone();
        for i in 0..n {
            want.b_theta[i] = dilatation_one(m, &st0.x, i);
        }
        for i in 0..n {
            let (f, p) = particle_force::<D, K, DAMP>(m, &st0.x, &st0.v, &want.b_theta, i);
            want.force[i] = f;
            let (mut xn, mut vn, mut dw) = (st0.x_next[i], st0.v_next[i], st0.damping_work[i]);
            let inp = Inputs {
                m,
                x: &st0.x,
                v: &st0.v,
                b_theta: &want.b_theta,
                force_prev: &st0.force_prev,
                dt,
            };
            update_one::<D, K, LAG, DAMP>(inp, i, f, p, &mut xn, &mut vn, &mut dw);
            (want.x_next[i], want.v_next[i], want.damping_work[i]) = (xn, vn, dw);
        }
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut st = st0.clone();
            pool.install(|| step::<D, K, LAG, DAMP>(m, &mut st, dt));
            let bits = |v: &[SVector<f64, D>]| {
                v.iter()
                    .flat_map(|p| p.iter().map(|c| c.to_bits()).collect::<Vec<_>>())
                    .collect::<Vec<_>>()
            };
            let sbits = |v: &[f64]| v.iter().map(|c| c.to_bits()).collect::<Vec<_>>();
            assert_eq!(sbits(&st.b_theta), sbits(&want.b_theta));
            assert_eq!(bits(&st.force), bits(&want.force));
            assert_eq!(bits(&st.x_next), bits(&want.x_next));
            assert_eq!(bits(&st.v_next), bits(&want.v_next));
            assert_eq!(sbits(&st.damping_work), sbits(&want.damping_work));
        }
    }

    /// (a) of the FCC kernel: on a randomly perturbed FCC block (`bench::fcc_block`: 18
    /// slots, second neighbours in 12..18) with per-particle a, b and c ≠ 0, moving, the AVX
    /// blocks and the scalar code agree bit for bit, and c changes the forces.
    #[test]
    fn fcc_block_with_second_neighbours_matches_scalar_reference_bitwise() {
        let l0 = 1e-3;
        let p = crate::bench::fcc_block(6, l0);
        p.check_topology().unwrap();
        let n = p.len();
        assert!(
            !n.is_multiple_of(LANES) && n > 1000,
            "{n}: tails on the scalar path"
        );
        let mut m = Mechanics::new(&p, &vec![2400.0; n]);
        let mut r = Lcg(2026);
        for i in 0..n {
            m.a[i] *= 1.0 + 0.1 * r.next();
            m.b[i] *= 1.0 + 0.1 * r.next();
            m.c_in[i] = 2.0 * m.mass[i] * 0.2 * 1e6 * r.next();
            m.c_ex[i] = if i % 3 == 0 { 0.0 } else { m.mass[i] * 1e3 };
        }
        let sec = m.second.as_mut().expect("FCC moduli have c ≠ 0");
        assert_eq!(sec.first_slot, 12);
        for c in sec.c.iter_mut() {
            *c *= 1.0 + 0.1 * r.next();
        }
        let mut st = State::at_rest(&p.x0);
        for i in 0..n {
            st.x[i] += SVector::from_fn(|_, _| 1e-3 * l0 * (r.next() - 0.5));
            st.v[i] = SVector::from_fn(|_, _| r.next() - 0.5);
            st.force_prev[i] = SVector::from_fn(|_, _| r.next() - 0.5);
        }
        check_model::<3, 18, false, true>(&m, &st);
        check_model::<3, 18, true, false>(&m, &st);
        check_model::<3, 18, false, false>(&m, &st);
        // c is used: the same step without it gives other forces
        let mut with = st.clone();
        step::<3, 18, false, false>(&m, &mut with, 1e-9);
        let mut without = st.clone();
        m.second = None;
        step::<3, 18, false, false>(&m, &mut without, 1e-9);
        let differ = (0..n)
            .filter(|&i| with.force[i] != without.force[i])
            .count();
        assert_eq!(differ, n);
    }

    #[test]
    fn step_matches_scalar_reference_bitwise() {
        check::<2, 6, false, true>();
        check::<2, 6, false, false>();
        check::<2, 6, true, true>();
        check::<2, 6, true, false>();
        check::<3, 18, false, true>();
        check::<3, 18, true, false>();
        // weighted dilatation (random particles) on the AVX and scalar paths
        check_weighted::<2, 12, false, true>(true, false);
        check_weighted::<2, 12, true, false>(true, false);
    }
}
