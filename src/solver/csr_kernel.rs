//! The explicit elastic step kernel on the CSR bond layout ([`Csr`]: a varying number of
//! bonds per particle, docs/model.md §1), the counterpart of `solver::kernel` for the slot layout.
//!
//! The same two gather passes per step, parallel over fixed chunks of particles with no
//! scatter, atomics or allocation, so results do not depend on the thread count:
//!
//! 1. `bθ_i = b_i·Σ_m S_im` (3.8) from the current positions;
//! 2. for each particle, over its own bonds: the bond force
//!    F_b,ij = ½((a_i + a_j)·S_ij + bθ_i + bθ_j) (3.7, 3.8) along e_ij, plus the bond damper
//!    (3.55), then central differences (3.58) with the particle damper (3.56) taken
//!    semi-implicitly (`solver::kernel::central_difference`). Each bond's stretch and length
//!    are computed again, as in the slot kernel (`solver::kernel::step`).
//!
//! The scalar path takes the force law from `model::force_state` and `model::stretch`; the
//! AVX path below performs the same operations lane by lane. Per-particle data
//! (a_i, b_i, masses, damper coefficients) are borrowed from a [`Mechanics`]; its slot arrays
//! are not read, so a body of random particles can pass a `Mechanics<D, 0>`.
//!
//! Both passes have an explicit AVX path (`mod avx`, chosen at run time, no FMA) that treats
//! four consecutive particles at once, one per lane, bond k of each lane together up to the
//! largest bond count of the four: the slot kernel's scheme with "slot k" read as "bond k",
//! and its loads and gathers. A lane past its own count keeps its sums (a blend, not an added
//! zero). Per lane it performs the scalar code's IEEE operations in the same order, so its
//! results are bit-identical to the scalar path ([`particle_force`]), which serves chunk
//! tails, CPUs without AVX and other architectures (checked by the test at the end of this
//! file, with bond counts from 0 to 12).
//!
//! Each particle sums over its bonds in flat order. Built with [`Csr::from_slots`], that is
//! slot order, and every bond performs the IEEE operations of the slot kernel's scalar path
//! (`solver::kernel::particle_force`) in the same order, so the results are bit-identical to
//! the slot kernel's (whose AVX path is tested bit-identical to its scalar path):
//! `tests/csr_layout.rs` checks this over 1,000 steps.
//!
//! `LAG = true` is reading (A) of docs/model.md §4: the force from the previous step's positions
//! drives this step.

use super::kernel::{central_difference, chunk_len, update_in_chunks, use_avx, ChunkOut, State};
use super::mechanics::Mechanics;
use crate::discretise::csr::Csr;
use crate::model::force_state::{bond_force, dilatation_term};
use crate::model::stretch::total_stretch;
use nalgebra::SVector;
use rayon::prelude::*;

/// Particles treated together, one per lane. [`chunk_len`] is a multiple of it.
pub const LANES: usize = 4;

/// Bytes per particle-step the elastic CSR [`step`] streams in dimension `d` with bond
/// dampers, for `bonds` directed bonds per particle: each array read or written once per pass
/// that touches it, neighbours' data assumed in cache, write-allocate not counted. Pass 1
/// reads the offset (4), x_i (8d) and b_i (8) and writes bθ_i (8); per bond it reads j (4)
/// and 1/L0 (8). Pass 2 reads the offset (4), x_i and v_i (16d), a_i, bθ_i, c_in,i, c_ex,i
/// and 1/m_i (40), writes x, v and F (24d) and reads and writes the damper work (16); per
/// bond it reads j (4) and 1/L0 (8) again. In 2D with six bonds: 36 + 72 + 140 + 72 = 320 B.
/// The slot kernel, counted alike, reads its 6 neighbour slots in both passes: 296 B on a
/// lattice, whose 1/L0 per slot is one value (`Mechanics::slot_inv_l0`).
pub const fn bytes_per_particle_step(d: usize, bonds: usize) -> usize {
    (4 + 8 * d + 8 + 8) + bonds * (4 + 8) + (4 + 16 * d + 40 + 24 * d + 16) + bonds * (4 + 8)
}

/// Check the per-particle arrays against the bonds (the gathers rely on it).
fn check_sizes<const D: usize, const K: usize>(csr: &Csr, m: &Mechanics<D, K>, n: usize) {
    assert!(
        csr.len() == n && m.a.len() == n && m.b.len() == n,
        "CSR kernel: {} particles in the bonds, {} in the state, {} in the model",
        csr.len(),
        n,
        m.len()
    );
    assert!(m.c_in.len() == n && m.c_ex.len() == n && m.inv_mass.len() == n);
    // CSR bonds have no slots, so no second-neighbour slots (docs/model.md §3, FCC)
    m.assert_no_second("the CSR kernel");
}

/// b_i·Σ_m S_im of particle i.
#[inline(always)]
fn dilatation_one<const D: usize, const K: usize>(
    csr: &Csr,
    m: &Mechanics<D, K>,
    x: &[SVector<f64, D>],
    i: usize,
) -> f64 {
    let (nb, il) = (csr.neighbours(), csr.inv_l0());
    let xi = x[i];
    let mut s = 0.0;
    for b in csr.range(i) {
        let len = (x[nb[b] as usize] - xi).norm();
        s += total_stretch(len, il[b]);
    }
    dilatation_term(m.b[i], s)
}

/// Pass 1 over the particles `base..base + out.len()`: whole blocks of [`LANES`] particles on
/// the AVX path where `avx`, the rest one at a time.
fn dilatation_chunk<const D: usize, const K: usize>(
    csr: &Csr,
    m: &Mechanics<D, K>,
    x: &[SVector<f64, D>],
    base: usize,
    out: &mut [f64],
    avx: bool,
) {
    let end = base + out.len();
    assert!(end <= csr.len() && csr.len() == x.len() && m.b.len() == x.len());
    #[cfg(target_arch = "x86_64")]
    let done = if avx {
        let done = out.len() / LANES * LANES;
        // SAFETY: AVX is available (`use_avx`); base + done ≤ csr.len() = x.len() = m.len()
        // (asserted above); a Csr's neighbours index its particles.
        unsafe { avx::dilatation_chunk::<D, K>(csr, m, x, base, &mut out[..done]) };
        done
    } else {
        0
    };
    #[cfg(not(target_arch = "x86_64"))]
    let done = {
        let _ = avx;
        0
    };
    for (o, bt) in out.iter_mut().enumerate().skip(done) {
        *bt = dilatation_one::<D, K>(csr, m, x, base + o);
    }
}

/// Pass 1: b_i·Σ_m S_im for every particle.
pub fn pass_dilatation<const D: usize, const K: usize>(
    csr: &Csr,
    m: &Mechanics<D, K>,
    x: &[SVector<f64, D>],
    out: &mut [f64],
) {
    check_sizes(csr, m, x.len());
    assert!(out.len() == x.len());
    let avx = use_avx();
    let chunk = chunk_len(out.len());
    out.par_chunks_mut(chunk)
        .enumerate()
        .for_each(|(c, items)| dilatation_chunk::<D, K>(csr, m, x, c * chunk, items, avx));
}

/// Internal force on particle i at positions x with velocities v (bond dampers if `DAMP`):
/// the force and the power dissipated in its bond dampers (half of each bond's).
#[inline(always)]
pub fn particle_force<const D: usize, const K: usize, const DAMP: bool>(
    csr: &Csr,
    m: &Mechanics<D, K>,
    x: &[SVector<f64, D>],
    v: &[SVector<f64, D>],
    b_theta: &[f64],
    i: usize,
) -> (SVector<f64, D>, f64) {
    let (nb, il) = (csr.neighbours(), csr.inv_l0());
    let xi = x[i];
    let ai = m.a[i];
    let bti = b_theta[i];
    let mut f = SVector::<f64, D>::zeros();
    let mut power = 0.0;
    for b in csr.range(i) {
        let j = nb[b] as usize;
        let (xj, aj, btj) = (x[j], m.a[j], b_theta[j]);
        let d = xj - xi;
        let len = d.norm();
        let (e, s) = (d * (1.0 / len), total_stretch(len, il[b]));
        let mut fb = bond_force(ai, aj, s, bti, btj);
        if DAMP {
            let c = 0.5 * (m.c_in[i] + m.c_in[j]);
            let rate = (v[j] - v[i]).dot(&e);
            fb += c * rate;
            power += 0.5 * c * rate * rate;
        }
        f += e * fb;
    }
    (f, power)
}

/// What pass 2 reads: the bonds, the model, the state at step n and the step size.
#[derive(Clone, Copy)]
struct Inputs<'a, const D: usize, const K: usize> {
    csr: &'a Csr,
    m: &'a Mechanics<D, K>,
    x: &'a [SVector<f64, D>],
    v: &'a [SVector<f64, D>],
    b_theta: &'a [f64],
    force_prev: &'a [SVector<f64, D>],
    dt: f64,
}

/// Pass 2 over one chunk starting at particle `base`: whole blocks of [`LANES`] particles on
/// the AVX path where `avx`, the rest one at a time.
fn update_chunk<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>(
    inp: Inputs<'_, D, K>,
    base: usize,
    out: ChunkOut<'_, D>,
    avx: bool,
) {
    let Inputs {
        csr,
        m,
        x,
        v,
        b_theta,
        force_prev,
        dt,
    } = inp;
    let mut out = out;
    let len = out.dw.len();
    let n = x.len();
    assert!(base + len <= n && csr.len() == n && v.len() == n && b_theta.len() == n);
    assert!(force_prev.len() == n && out.xn.len() == len);
    assert!(out.vn.len() == len && out.fo.len() == len);
    #[cfg(target_arch = "x86_64")]
    let done = if avx {
        let done = len / LANES * LANES;
        // SAFETY: AVX is available (`use_avx`); base + done ≤ n, every state array has n
        // entries and the model too (`check_sizes`); a Csr's neighbours index its particles.
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
        let (f, power) = particle_force::<D, K, DAMP>(csr, m, x, v, b_theta, i);
        fo[o] = f;
        let drive = if LAG { force_prev[i] } else { f };
        central_difference::<D, K, DAMP>(
            m, i, x[i], v[i], drive, power, dt, &mut xn[o], &mut vn[o], &mut dw[o],
        );
    }
}

/// Pass 2: forces and the central-difference update of every particle into x_next, v_next,
/// from bθ as [`pass_dilatation`] left it.
pub fn pass_update<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>(
    csr: &Csr,
    m: &Mechanics<D, K>,
    st: &mut State<D>,
    dt: f64,
) {
    let n = st.x.len();
    check_sizes(csr, m, n);
    let avx = use_avx();
    update_in_chunks(st, n, |base, r, out| {
        let inp = Inputs {
            csr,
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

/// One explicit step from x^n, v^{n−½} to x^{n+1}, v^{n+½} (not yet swapped in): pass 1
/// ([`pass_dilatation`]), then pass 2 ([`pass_update`]).
pub fn step<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>(
    csr: &Csr,
    m: &Mechanics<D, K>,
    st: &mut State<D>,
    dt: f64,
) {
    pass_dilatation(csr, m, &st.x, &mut st.b_theta);
    pass_update::<D, K, LAG, DAMP>(csr, m, st, dt);
}

/// Explicit AVX (4 × f64) versions of the block code, one particle per lane, bond k of the
/// four particles at once up to the largest of their bond counts; a lane past its count
/// keeps its sums (a blend). Per lane the same IEEE operations in the same order as the
/// one-particle code (no FMA), so the results are bit-identical to it. The loads and
/// gathers are those of the slot kernel (`solver::kernel::avx`).
#[cfg(target_arch = "x86_64")]
mod avx {
    use super::{ChunkOut, Csr, Inputs, Mechanics, LANES};
    use crate::solver::kernel::avx::{gather, gather_vec, geometry, load_own};
    use crate::solver::kernel::central_difference;
    use core::arch::x86_64::*;
    use nalgebra::SVector;

    const _: () = assert!(LANES == 4);

    /// Bond ranges of particles i0..i0 + LANES: first bond, bond count, largest count.
    #[inline(always)]
    fn lane_bonds(csr: &Csr, i0: usize) -> ([usize; LANES], [usize; LANES], usize) {
        let off = &csr.offsets()[i0..i0 + LANES + 1];
        let start: [usize; LANES] = std::array::from_fn(|l| off[l] as usize);
        let count: [usize; LANES] = std::array::from_fn(|l| (off[l + 1] - off[l]) as usize);
        let most = count.iter().copied().max().unwrap_or(0);
        (start, count, most)
    }

    /// Bond k of particles i0..i0+4: its flat position (bond 0 past a lane's count, valid as
    /// some lane has a bond k), its neighbour (the particle itself past the count) and the
    /// mask of lanes that have a bond k.
    ///
    /// # Safety
    /// AVX available; i0 + 4 ≤ csr.len(); some lane has a bond k.
    #[target_feature(enable = "avx")]
    #[inline]
    unsafe fn bond_k(
        csr: &Csr,
        start: &[usize; 4],
        count: &[usize; 4],
        i0: usize,
        k: usize,
    ) -> ([usize; 4], [usize; 4], __m256d) {
        let nb = csr.neighbours();
        let mut b = [0usize; 4];
        let mut j = [0usize; 4];
        let mut occ = [0i64; 4];
        for l in 0..4 {
            let o = k < count[l];
            occ[l] = -(o as i64);
            b[l] = if o { start[l] + k } else { 0 };
            j[l] = if o {
                *nb.get_unchecked(b[l]) as usize
            } else {
                i0 + l
            };
        }
        let mask = _mm256_castsi256_pd(_mm256_set_epi64x(occ[3], occ[2], occ[1], occ[0]));
        (b, j, mask)
    }

    /// 1/L0 of bonds b[0..4], one per lane.
    ///
    /// # Safety
    /// AVX available; every b < the number of bonds.
    #[target_feature(enable = "avx")]
    #[inline]
    unsafe fn inv_l0(csr: &Csr, b: &[usize; 4]) -> __m256d {
        gather(csr.inv_l0(), b)
    }

    /// b_i·Σ_m S_im of particles i0..i0+4 (`super::dilatation_one` per lane).
    ///
    /// # Safety
    /// AVX available; i0 + 4 ≤ csr.len() = x.len() = m.b.len().
    #[target_feature(enable = "avx")]
    #[inline]
    unsafe fn dilatation_block<const D: usize, const K: usize>(
        csr: &Csr,
        m: &Mechanics<D, K>,
        x: &[SVector<f64, D>],
        i0: usize,
    ) -> __m256d {
        let one = _mm256_set1_pd(1.0);
        let (start, count, most) = lane_bonds(csr, i0);
        let xi = load_own(x, i0);
        let mut s = _mm256_setzero_pd();
        for k in 0..most {
            let (b, j, occ) = bond_k(csr, &start, &count, i0, k);
            let (_, len) = geometry(&xi, &gather_vec(x, &j));
            // total_stretch: len·(1/L0) − 1
            let st = _mm256_sub_pd(_mm256_mul_pd(len, inv_l0(csr, &b)), one);
            s = _mm256_blendv_pd(s, _mm256_add_pd(s, st), occ);
        }
        // dilatation_term: b·Σ S
        _mm256_mul_pd(_mm256_loadu_pd(m.b.as_ptr().add(i0)), s)
    }

    /// Pass 1 over whole blocks: `out` holds particles base.., a multiple of 4 of them.
    ///
    /// # Safety
    /// AVX available; base + out.len() ≤ csr.len() = x.len() = m.b.len().
    #[target_feature(enable = "avx")]
    pub unsafe fn dilatation_chunk<const D: usize, const K: usize>(
        csr: &Csr,
        m: &Mechanics<D, K>,
        x: &[SVector<f64, D>],
        base: usize,
        out: &mut [f64],
    ) {
        for o in (0..out.len()).step_by(4) {
            let r = dilatation_block::<D, K>(csr, m, x, base + o);
            _mm256_storeu_pd(out.as_mut_ptr().add(o), r);
        }
    }

    /// `super::particle_force` of particles i0..i0+4, one per lane, as SoA: the force per
    /// component and the bond-damper power.
    ///
    /// # Safety
    /// AVX available; i0 + 4 ≤ csr.len(); x, v, b_theta and the model have csr.len()
    /// entries.
    #[target_feature(enable = "avx")]
    #[inline]
    unsafe fn force_block<const D: usize, const K: usize, const DAMP: bool>(
        csr: &Csr,
        m: &Mechanics<D, K>,
        x: &[SVector<f64, D>],
        v: &[SVector<f64, D>],
        b_theta: &[f64],
        i0: usize,
    ) -> ([__m256d; D], __m256d) {
        let one = _mm256_set1_pd(1.0);
        let half = _mm256_set1_pd(0.5);
        let (start, count, most) = lane_bonds(csr, i0);
        let xi = load_own(x, i0);
        let vi = if DAMP {
            load_own(v, i0)
        } else {
            [_mm256_setzero_pd(); D]
        };
        let ai = _mm256_loadu_pd(m.a.as_ptr().add(i0));
        let bti = _mm256_loadu_pd(b_theta.as_ptr().add(i0));
        let ci = if DAMP {
            _mm256_loadu_pd(m.c_in.as_ptr().add(i0))
        } else {
            _mm256_setzero_pd()
        };
        let mut f = [_mm256_setzero_pd(); D];
        let mut power = _mm256_setzero_pd();
        for k in 0..most {
            let (b, j, occ) = bond_k(csr, &start, &count, i0, k);
            let xj = gather_vec(x, &j);
            let (d, len) = geometry(&xi, &xj);
            let st = _mm256_sub_pd(_mm256_mul_pd(len, inv_l0(csr, &b)), one);
            let rinv = _mm256_div_pd(one, len);
            let aj = gather(&m.a, &j);
            let btj = gather(b_theta, &j);
            // bond_force: 0.5 * ((ai + aj) * s + bti + btj)
            let mut fb = _mm256_mul_pd(
                half,
                _mm256_add_pd(
                    _mm256_add_pd(_mm256_mul_pd(_mm256_add_pd(ai, aj), st), bti),
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
                let p = _mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(half, c), rate), rate);
                power = _mm256_blendv_pd(power, _mm256_add_pd(power, p), occ);
            }
            for c in 0..D {
                let g = _mm256_add_pd(f[c], _mm256_mul_pd(e[c], fb));
                f[c] = _mm256_blendv_pd(f[c], g, occ);
            }
        }
        (f, power)
    }

    /// Pass 2 over whole blocks: the slices hold particles base.., a multiple of 4 of them;
    /// the central differences lane by lane (`solver::kernel::central_difference`).
    ///
    /// # Safety
    /// AVX available; base + xn.len() ≤ csr.len(); x, v, b_theta, force_prev and the model
    /// have csr.len() entries, vn, fo and dw xn.len().
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
            csr,
            m,
            x,
            v,
            b_theta,
            force_prev,
            dt,
        } = inp;
        let ChunkOut { xn, vn, fo, dw } = out;
        for o0 in (0..xn.len()).step_by(4) {
            let i0 = base + o0;
            let (f, power) = force_block::<D, K, DAMP>(csr, m, x, v, b_theta, i0);
            let mut fa = [[0.0; 4]; D];
            for c in 0..D {
                _mm256_storeu_pd(fa[c].as_mut_ptr(), f[c]);
            }
            let mut pa = [0.0; 4];
            _mm256_storeu_pd(pa.as_mut_ptr(), power);
            for l in 0..4 {
                let (o, i) = (o0 + l, i0 + l);
                let fl = SVector::<f64, D>::from_fn(|c, _| fa[c][l]);
                *fo.get_unchecked_mut(o) = fl;
                let drive = if LAG {
                    *force_prev.get_unchecked(i)
                } else {
                    fl
                };
                central_difference::<D, K, DAMP>(
                    m,
                    i,
                    *x.get_unchecked(i),
                    *v.get_unchecked(i),
                    drive,
                    pa[l],
                    dt,
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
    use crate::aligned::{filled, CollectAligned};
    use crate::solver::kernel::CHUNK;

    use crate::solver::test_rng::Lcg;

    /// Random bonds (0 to about 12 per particle, none for every 17th particle), a random
    /// model without slots (`Mechanics<D, 0>`) and a random state; n not a multiple of the
    /// chunk or block size.
    fn model<const D: usize>(n: usize) -> (Csr, Mechanics<D, 0>, State<D>) {
        let mut r = Lcg(4321);
        let x0: Vec<SVector<f64, D>> = (0..n)
            .map(|i| SVector::from_fn(|c, _| i as f64 * 1e-3 * (c + 1) as f64 + 1e-4 * r.next()))
            .collect();
        let mut pairs = Vec::new();
        for i in (0..n).filter(|i| !i.is_multiple_of(17)) {
            for _ in 0..(r.next() * 7.0) as usize {
                let j = (i + 1 + (r.next() * 40.0) as usize) % n;
                if j != i && !j.is_multiple_of(17) {
                    pairs.push((i as u32, j as u32));
                }
            }
        }
        let csr = Csr::from_pairs(&x0, &pairs).unwrap();
        let most = (0..n).map(|i| csr.bond_count(i)).max().unwrap();
        assert!(most >= 10 && csr.bond_count(0) == 0, "{most}");
        let mut v = |s: f64| (0..n).map(|_| s * (1.0 + r.next())).collect_aligned();
        let (a, b, mass, c_in, mut c_ex) = (v(3e6), v(-1e5), v(1e-3), v(10.0), v(1.0));
        for c in c_ex.iter_mut().step_by(3) {
            *c = 0.0;
        }
        let mech = Mechanics {
            neighbours: filled([], n),
            inv_l0: filled([], n),
            slot_inv_l0: None,
            a,
            b,
            second: None,
            inv_mass: mass.iter().map(|m| 1.0 / m).collect_aligned(),
            mass,
            c_in,
            c_ex,
            dilatation_weight: None,
            slot_weight: None,
            slot_end: filled(0, n),
        };
        let mut st = State::at_rest(&x0);
        for i in 0..n {
            st.x[i] += SVector::from_fn(|_, _| 1e-6 * (r.next() - 0.5));
            st.v[i] = SVector::from_fn(|_, _| r.next() - 0.5);
            st.force_prev[i] = SVector::from_fn(|_, _| r.next() - 0.5);
            st.damping_work[i] = r.next();
        }
        (csr, mech, st)
    }

    /// The kernel (AVX blocks where the CPU has AVX, chunk tails one at a time) against the
    /// plain per-particle code, bit for bit, on 1 and 2 threads.
    fn check<const D: usize, const LAG: bool, const DAMP: bool>() {
        let n = 2 * CHUNK + 4 * 37 + 3;
        let (csr, m, st0) = model::<D>(n);
        let dt = 1e-7;
        let mut want = st0.clone();
        for i in 0..n {
            want.b_theta[i] = dilatation_one::<D, 0>(&csr, &m, &st0.x, i);
        }
        for i in 0..n {
            let (f, p) = particle_force::<D, 0, DAMP>(&csr, &m, &st0.x, &st0.v, &want.b_theta, i);
            want.force[i] = f;
            let drive = if LAG { st0.force_prev[i] } else { f };
            central_difference::<D, 0, DAMP>(
                &m,
                i,
                st0.x[i],
                st0.v[i],
                drive,
                p,
                dt,
                &mut want.x_next[i],
                &mut want.v_next[i],
                &mut want.damping_work[i],
            );
        }
        let bits = |v: &[SVector<f64, D>]| {
            v.iter()
                .flat_map(|p| p.iter().map(|c| c.to_bits()).collect::<Vec<_>>())
                .collect::<Vec<_>>()
        };
        let sbits = |v: &[f64]| v.iter().map(|c| c.to_bits()).collect::<Vec<_>>();
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut st = st0.clone();
            pool.install(|| step::<D, 0, LAG, DAMP>(&csr, &m, &mut st, dt));
            assert_eq!(sbits(&st.b_theta), sbits(&want.b_theta));
            assert_eq!(bits(&st.force), bits(&want.force));
            assert_eq!(bits(&st.x_next), bits(&want.x_next));
            assert_eq!(bits(&st.v_next), bits(&want.v_next));
            assert_eq!(sbits(&st.damping_work), sbits(&want.damping_work));
        }
    }

    #[test]
    fn bytes_per_particle_step_in_2d() {
        assert_eq!(bytes_per_particle_step(2, 6), 320);
    }

    #[test]
    fn step_matches_scalar_reference_bitwise() {
        check::<2, false, true>();
        check::<2, false, false>();
        check::<2, true, true>();
        check::<3, false, true>();
        check::<3, true, false>();
    }
}
