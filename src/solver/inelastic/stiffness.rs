//! The held state's internal forces and secant stiffness, for the quasi-static solver
//! (docs/quasi_static.md).

use super::passes::*;
use super::DamageKernel;
use crate::model::damage_law::DamageLaw;
use crate::model::dimension::{Dim, Dimension};
use crate::solver::mechanics::{weighted, Mechanics};
use crate::solver::KernelSet;
use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

/// Internal forces (bonds only, no dampers) at positions x with the committed state; the
/// trial state is left as the step would compute it. For tests and post-processing.
pub fn internal_forces<const D: usize, const K: usize, L: DamageLaw<D, K>>(
    m: &Mechanics<D, K>,
    c: &mut DamageKernel<D, K, L>,
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
    c: &DamageKernel<D, K, L>,
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
    c: &DamageKernel<D, K, L>,
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
