//! Explicit AVX (4 × f64) versions of the block kernels, one particle per lane, bit-identical
//! to the scalar code.

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
pub(crate) unsafe fn load_own<const D: usize>(x: &[SVector<f64, D>], i0: usize) -> [__m256d; D] {
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
pub unsafe fn force_block<const D: usize, const K: usize, const DAMP: bool, const SECOND: bool>(
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
    // g = 1 + dt * c_implicit * inv_mass (S.17)
    let cim = _mm256_loadu_pd(m.c_implicit.as_ptr().add(i0));
    let g = _mm256_add_pd(one, _mm256_mul_pd(_mm256_mul_pd(dtv, cim), im));
    let one_m_h = _mm256_sub_pd(g, h);
    let one_p_h = _mm256_add_pd(g, h);
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
    // dw += dt * (bond_power + c_ex * |½(v_i + v_new)|² + implicit) where DAMP or h ≠ 0,
    // and c_implicit * (v_new − v_i)·½(v_i + v_new)
    let mut vm2 = zero;
    let mut dvm = zero;
    for c in 0..D {
        let vm = _mm256_mul_pd(_mm256_add_pd(vi[c], vnew[c]), half);
        let sq = _mm256_mul_pd(vm, vm);
        let dv = _mm256_mul_pd(_mm256_sub_pd(vnew[c], vi[c]), vm);
        vm2 = if c == 0 { sq } else { _mm256_add_pd(vm2, sq) };
        dvm = if c == 0 { dv } else { _mm256_add_pd(dvm, dv) };
    }
    let pw = dw.as_mut_ptr().add(o0);
    let old = _mm256_loadu_pd(pw);
    let new = _mm256_add_pd(
        old,
        _mm256_mul_pd(
            dtv,
            _mm256_add_pd(
                _mm256_add_pd(power, _mm256_mul_pd(cex, vm2)),
                _mm256_mul_pd(cim, dvm),
            ),
        ),
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
