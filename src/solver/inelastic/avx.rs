//! Pass 1's slot loop of the concrete kernels for four particles at once, one per AVX lane
//! (4 × f64), as the elastic kernel's blocks (`solver::kernel::avx`). Per lane it performs the
//! scalar path's IEEE operations in the same order (no FMA), so the slot cache, the stretches
//! and the dilatation sums are bit-identical to `slot_pass`: the geometry and the stretches
//! (3.38), the two springs in series (3.37) of a law with [`DamageLaw::SERIES_DAMAGE`], the
//! damaged axial term and the dilatation sums (§6). The law update of each particle stays
//! scalar (`law_pass`).

use super::passes::{slot_cache_at, Stretches, FIELDS};
use super::DamageKernel;
use crate::discretise::NONE;
use crate::model::damage_law::DamageLaw;
use crate::model::dimension::{Dim, Dimension};
use crate::solver::kernel::avx::{
    block_slots, gather, gather_vec, geometry, load_own, slot, update_block, vector_update,
};
use crate::solver::kernel::LANES;
use crate::solver::kernel::{central_difference, ChunkOut, StateReads};
use crate::solver::mechanics::Mechanics;
use core::arch::x86_64::*;
use nalgebra::SVector;

/// A vector's four lanes.
#[target_feature(enable = "avx")]
#[inline]
unsafe fn lanes(v: __m256d) -> [f64; 4] {
    let mut out = [0.0; 4];
    _mm256_storeu_pd(out.as_mut_ptr(), v);
    out
}

/// (w_t, w_c) of particles p[0..4], one per lane.
///
/// # Safety
/// AVX available; every p < c.committed.len().
#[target_feature(enable = "avx")]
#[inline]
unsafe fn series_damage<const D: usize, const K: usize, L: DamageLaw<D, K>>(
    c: &DamageKernel<D, K, L>,
    p: [usize; LANES],
) -> (__m256d, __m256d)
where
    Dim<D>: Dimension<D>,
{
    let w0 = c.law.series_damage(c.committed.get_unchecked(p[0]));
    let w1 = c.law.series_damage(c.committed.get_unchecked(p[1]));
    let w2 = c.law.series_damage(c.committed.get_unchecked(p[2]));
    let w3 = c.law.series_damage(c.committed.get_unchecked(p[3]));
    (
        _mm256_set_pd(w3.0, w2.0, w1.0, w0.0),
        _mm256_set_pd(w3.1, w2.1, w1.1, w0.1),
    )
}

/// The two springs in series (3.37) of damage w_i and w_j per lane, and its square root, as
/// the law's `bond_factor` computes them: (1, 1) where both are 0 (all four lanes at once
/// skip the division and the square root), `damage_factor` otherwise (0 where either is 1).
#[target_feature(enable = "avx")]
#[inline]
unsafe fn series(wi: __m256d, wj: __m256d) -> (__m256d, __m256d) {
    let zero = _mm256_setzero_pd();
    let one = _mm256_set1_pd(1.0);
    let two = _mm256_set1_pd(2.0);
    let undamaged = _mm256_and_pd(
        _mm256_cmp_pd::<_CMP_EQ_OQ>(wi, zero),
        _mm256_cmp_pd::<_CMP_EQ_OQ>(wj, zero),
    );
    if _mm256_movemask_pd(undamaged) == 0b1111 {
        return (one, one);
    }
    let broken = _mm256_or_pd(
        _mm256_cmp_pd::<_CMP_GE_OQ>(wi, one),
        _mm256_cmp_pd::<_CMP_GE_OQ>(wj, one),
    );
    // damage_factor: 2·((1 − w_i)(1 − w_j))/(2 − (w_i + w_j)), 0 where broken
    let d = _mm256_andnot_pd(
        broken,
        _mm256_div_pd(
            _mm256_mul_pd(
                two,
                _mm256_mul_pd(_mm256_sub_pd(one, wi), _mm256_sub_pd(one, wj)),
            ),
            _mm256_sub_pd(two, _mm256_add_pd(wi, wj)),
        ),
    );
    (
        _mm256_blendv_pd(d, one, undamaged),
        _mm256_blendv_pd(_mm256_sqrt_pd(d), one, undamaged),
    )
}

/// The slot loop of `slot_pass` for particles i0..i0+4: their stretches into `out` (every
/// field written) and their slot caches into `cache` (the block's part of the slot cache).
///
/// `WEIGHTED` is whether the body weighs its dilatations (`m.dilatation_weight`), a test
/// hoisted out of the slot loop.
///
/// # Safety
/// AVX available; `L::SERIES_DAMAGE`; i0 + 4 ≤ m.len() = x.len() = c.committed.len(); every
/// occupied slot indexes a particle; cache.len() = 2·4·K.
#[target_feature(enable = "avx")]
#[inline]
pub(super) unsafe fn slot_block<
    const D: usize,
    const K: usize,
    L: DamageLaw<D, K>,
    const FULL: bool,
    const WEIGHTED: bool,
>(
    m: &Mechanics<D, K>,
    c: &DamageKernel<D, K, L>,
    x: &[SVector<f64, D>],
    i0: usize,
    cache: &mut [f64],
    out: &mut [Stretches<K>; LANES],
) where
    Dim<D>: Dimension<D>,
{
    debug_assert!(L::SERIES_DAMAGE && cache.len() == FIELDS * LANES * K);
    let blk = cache.as_mut_ptr();
    let zero = _mm256_setzero_pd();
    let one = _mm256_set1_pd(1.0);
    let half = _mm256_set1_pd(0.5);
    let xi = load_own(x, i0);
    let ai = _mm256_loadu_pd(m.a.as_ptr().add(i0));
    // second-neighbour moduli (FCC, docs/model.md §3 erratum): c per particle, a_i + c_i and the
    // first second-neighbour slot (K: none)
    let (sc, aci, first): (&[f64], __m256d, usize) = match &m.second {
        Some(s) => (
            &s.c[..],
            _mm256_add_pd(ai, _mm256_loadu_pd(s.c.as_ptr().add(i0))),
            s.first_slot,
        ),
        None => (&[], ai, K),
    };
    // (w_t, w_c) of the block's own particles
    let (wti, wci) = series_damage(c, [i0, i0 + 1, i0 + 2, i0 + 3]);
    let mut theta = zero;
    let mut theta_e = zero;
    let mut same = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
    let ns = block_slots(m, i0);
    for k in 0..ns {
        let (j, occ, il) = slot(m, i0, k);
        // the bond's factor in tension, before the geometry it does not depend on (so that
        // its division and square root overlap the length's)
        let (wtj, wcj) = series_damage(c, j);
        let (dt, sdt) = series(wti, wtj);
        let (_, len) = geometry(&xi, &gather_vec(x, &j));
        // total_stretch: len·(1/L0) − 1
        let st = _mm256_and_pd(_mm256_sub_pd(_mm256_mul_pd(len, il), one), occ);
        // S_e = S_T − ½(S_Ps,ij + S_Ps,ji) (3.38)
        let se = if FULL {
            let mut spi = [0.0; LANES];
            let mut spj = [0.0; LANES];
            for l in 0..LANES {
                let i = i0 + l;
                let jj = *m.neighbours.get_unchecked(i).get_unchecked(k);
                if jj != NONE {
                    let r = *c.reverse.get_unchecked(i).get_unchecked(k) as usize;
                    spi[l] = *c.sps.get_unchecked(i).get_unchecked(k);
                    spj[l] = *c.sps.get_unchecked(jj as usize).get_unchecked(r);
                }
            }
            let spi = _mm256_loadu_pd(spi.as_ptr());
            let spj = _mm256_loadu_pd(spj.as_ptr());
            _mm256_and_pd(
                _mm256_sub_pd(st, _mm256_mul_pd(half, _mm256_add_pd(spi, spj))),
                occ,
            )
        } else {
            st
        };
        // the two springs in series (3.37): w_t where stretched, w_c where shortened (none
        // in the tension kernel, d = 1)
        let stretched = _mm256_cmp_pd::<_CMP_GE_OQ>(se, zero);
        let (d, sd) = if FULL {
            let (dc, sdc) = series(wci, wcj);
            (
                _mm256_blendv_pd(dc, dt, stretched),
                _mm256_blendv_pd(sdc, sdt, stretched),
            )
        } else {
            (
                _mm256_blendv_pd(one, dt, stretched),
                _mm256_blendv_pd(one, sdt, stretched),
            )
        };
        let (d, sd) = (_mm256_and_pd(d, occ), _mm256_and_pd(sd, occ));
        // damaged_axial: d·((m_i + m_j)·S_e) with the bond moduli (a_i, a_j), or
        // (a_i + c_i, a_j + c_j) in a second-neighbour slot (`Mechanics::bond_moduli`)
        let aj = gather(&m.a, &j);
        let (mi, mj) = if k >= first {
            (aci, _mm256_add_pd(aj, gather(sc, &j)))
        } else {
            (ai, aj)
        };
        let d_a_se = _mm256_mul_pd(d, _mm256_mul_pd(_mm256_add_pd(mi, mj), se));
        let dse = _mm256_mul_pd(d, se);
        let sd_se = _mm256_mul_pd(sd, se);
        // the dilatation sums, weighted for random particles as `weighted` does
        let (t, te) = match (WEIGHTED, &m.dilatation_weight) {
            (true, Some(w)) => {
                let w = _mm256_set_pd(
                    *w.get_unchecked(i0 + 3).get_unchecked(k),
                    *w.get_unchecked(i0 + 2).get_unchecked(k),
                    *w.get_unchecked(i0 + 1).get_unchecked(k),
                    *w.get_unchecked(i0).get_unchecked(k),
                );
                (_mm256_mul_pd(w, sd_se), _mm256_mul_pd(w, se))
            }
            _ => (sd_se, se),
        };
        theta = _mm256_add_pd(theta, _mm256_and_pd(t, occ));
        theta_e = _mm256_add_pd(theta_e, _mm256_and_pd(te, occ));
        same = _mm256_and_pd(same, _mm256_cmp_pd::<_CMP_EQ_OQ>(dse, st));
        let (st, se, dse, occ) = (lanes(st), lanes(se), lanes(dse), lanes(occ));
        let p = blk.add(FIELDS * LANES * k);
        _mm256_storeu_pd(p, d_a_se);
        _mm256_storeu_pd(p.add(LANES), d);
        for l in 0..LANES {
            let o = out.get_unchecked_mut(l);
            *o.st.get_unchecked_mut(k) = st[l];
            *o.se.get_unchecked_mut(k) = se[l];
            *o.dse.get_unchecked_mut(k) = dse[l];
            *o.used.get_unchecked_mut(k) = occ[l].to_bits() != 0;
        }
    }
    for k in ns..K {
        let p = blk.add(FIELDS * LANES * k);
        for f in 0..FIELDS {
            _mm256_storeu_pd(p.add(f * LANES), zero);
        }
    }
    for l in 0..LANES {
        let o = out.get_unchecked_mut(l);
        for k in ns..K {
            *o.st.get_unchecked_mut(k) = 0.0;
            *o.se.get_unchecked_mut(k) = 0.0;
            *o.dse.get_unchecked_mut(k) = 0.0;
            *o.used.get_unchecked_mut(k) = false;
        }
    }
    let (theta, theta_e, same) = (lanes(theta), lanes(theta_e), lanes(same));
    for l in 0..LANES {
        let o = out.get_unchecked_mut(l);
        o.theta = theta[l];
        o.theta_e = theta_e[l];
        o.same = same[l].to_bits() != 0;
    }
}

/// `super::particle_force` of particles i0..i0+4, one per lane: the internal force per
/// component and the bond dampers' power, from the slot cache and the positions. Slots with
/// d = 0 (empty or broken) leave the sums untouched, as the scalar path skips them.
///
/// # Safety
/// AVX available; i0 + 4 ≤ m.len(); x, v and b_theta have m.len() entries; every occupied
/// slot indexes a particle; pass 1 filled the slot cache at positions x.
#[target_feature(enable = "avx")]
#[inline]
unsafe fn force_block<const D: usize, const K: usize, L: DamageLaw<D, K>, const DAMP: bool>(
    m: &Mechanics<D, K>,
    c: &DamageKernel<D, K, L>,
    r: &StateReads<'_, D>,
    i0: usize,
) -> ([__m256d; D], __m256d)
where
    Dim<D>: Dimension<D>,
{
    let zero = _mm256_setzero_pd();
    let one = _mm256_set1_pd(1.0);
    let half = _mm256_set1_pd(0.5);
    let xi = load_own(r.x, i0);
    let vi = if DAMP { load_own(r.v, i0) } else { [zero; D] };
    let bti = _mm256_loadu_pd(r.b_theta.as_ptr().add(i0));
    let ci = if DAMP {
        _mm256_loadu_pd(m.c_in.as_ptr().add(i0))
    } else {
        zero
    };
    let blk = c.cache.as_ptr().add(slot_cache_at(i0, 0, K));
    let mut f = [zero; D];
    let mut power = zero;
    for k in 0..block_slots(m, i0) {
        let p = blk.add(FIELDS * LANES * k);
        let d = _mm256_loadu_pd(p.add(LANES));
        let live = _mm256_cmp_pd::<_CMP_NEQ_UQ>(d, zero);
        if _mm256_movemask_pd(live) == 0 {
            continue;
        }
        let d_a_se = _mm256_loadu_pd(p);
        // √d, as the law computes it (`super::SlotCache`)
        let sd = _mm256_sqrt_pd(d);
        // the neighbours (the particle itself in an empty slot, where d = 0: its zero
        // length gives e = NaN, which the blends below drop); the slot's 1/L0, which pass 2
        // does not need, is left unused
        let (j, _, _) = slot(m, i0, k);
        let (dx, len) = geometry(&xi, &gather_vec(r.x, &j));
        // e = (x_j − x_i)·(1/len), as pass 1 computes len and as the scalar path
        let rinv = _mm256_div_pd(one, len);
        let mut e = [zero; D];
        for cc in 0..D {
            e[cc] = _mm256_mul_pd(dx[cc], rinv);
        }
        // damaged_bond_force: ½(d·(a_i + a_j)·S_e + √d·(bθ_i + bθ_j))
        let btj = gather(r.b_theta, &j);
        let mut fb = _mm256_mul_pd(
            half,
            _mm256_add_pd(d_a_se, _mm256_mul_pd(sd, _mm256_add_pd(bti, btj))),
        );
        if DAMP {
            // c_b = d·½·(c_i + c_j), rate = (v_j − v_i)·e
            let cj = gather(&m.c_in, &j);
            let cb = _mm256_mul_pd(_mm256_mul_pd(d, half), _mm256_add_pd(ci, cj));
            let vj = gather_vec(r.v, &j);
            let mut rate = _mm256_mul_pd(_mm256_sub_pd(vj[0], vi[0]), e[0]);
            for cc in 1..D {
                rate = _mm256_add_pd(rate, _mm256_mul_pd(_mm256_sub_pd(vj[cc], vi[cc]), e[cc]));
            }
            fb = _mm256_add_pd(fb, _mm256_mul_pd(cb, rate));
            // power += ½·c_b·rate·rate
            let pw = _mm256_add_pd(
                power,
                _mm256_mul_pd(_mm256_mul_pd(_mm256_mul_pd(half, cb), rate), rate),
            );
            power = _mm256_blendv_pd(power, pw, live);
        }
        for cc in 0..D {
            let fc = _mm256_add_pd(f[cc], _mm256_mul_pd(e[cc], fb));
            f[cc] = _mm256_blendv_pd(f[cc], fc, live);
        }
    }
    (f, power)
}

/// Pass 2 over whole blocks of four: the forces (`force_block`) and the central-difference
/// update of particles base.. into `out`, a multiple of four of them: four lanes at once
/// (`kernel::avx::update_block`) where [`vector_update`] holds (2D), otherwise lane by lane
/// through the scalar `kernel::central_difference` (3D, as the elastic kernel does).
///
/// # Safety
/// AVX available; base + out.xn.len() ≤ m.len() and every array of `r` has m.len() entries;
/// every occupied slot indexes a particle; pass 1 filled the slot cache at positions r.x.
#[target_feature(enable = "avx")]
pub(super) unsafe fn update_chunk<
    const D: usize,
    const K: usize,
    L: DamageLaw<D, K>,
    const LAG: bool,
    const DAMP: bool,
>(
    m: &Mechanics<D, K>,
    c: &DamageKernel<D, K, L>,
    r: &StateReads<'_, D>,
    dt: f64,
    base: usize,
    out: ChunkOut<'_, D>,
) where
    Dim<D>: Dimension<D>,
{
    let ChunkOut { xn, vn, fo, dw } = out;
    let vector = vector_update::<D>();
    for o0 in (0..xn.len()).step_by(LANES) {
        let i0 = base + o0;
        let (f, power) = force_block::<D, K, L, DAMP>(m, c, r, i0);
        if vector {
            update_block::<D, K, LAG, DAMP>(
                m,
                r.x,
                r.v,
                r.force_prev,
                dt,
                i0,
                o0,
                &f,
                power,
                xn,
                vn,
                fo,
                dw,
            );
            continue;
        }
        let fa = f.map(|fc| lanes(fc));
        let pa = lanes(power);
        for l in 0..LANES {
            let (i, o) = (i0 + l, o0 + l);
            let fl = SVector::<f64, D>::from_fn(|cc, _| fa[cc][l]);
            *fo.get_unchecked_mut(o) = fl;
            let drive = if LAG {
                *r.force_prev.get_unchecked(i)
            } else {
                fl
            };
            central_difference::<D, K, DAMP>(
                m,
                i,
                *r.x.get_unchecked(i),
                *r.v.get_unchecked(i),
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
