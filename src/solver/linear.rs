//! The linearised SPLM operator about the reference configuration, matrix-free:
//! (K·u)_i = −f_i(u) with S_ij = n_ij·(u_j − u_i)/L0_ij, θ_i = Σ_m S_im and
//! f_i = Σ_j ½((a_i + a_j)·S_ij + b_i·θ_i + b_j·θ_j)·n_ij (docs/model.md §3–4 linearised), with
//! a + c in place of a in FCC second-neighbour slots (docs/model.md §3 erratum,
//! `Mechanics::bond_moduli`).
//! Used for the fundamental period and for the patch test at round-off accuracy.

use super::mechanics::{weighted, Mechanics};
use crate::model::force_state::{bond_force, dilatation_term, force_state};
use nalgebra::SVector;
use rayon::prelude::*;

/// Matrix-free linear stiffness of a model.
pub struct LinearOperator<'a, const D: usize, const K: usize> {
    pub mech: &'a Mechanics<D, K>,
    pub x0: &'a [SVector<f64, D>],
    theta: Vec<f64>,
}

impl<'a, const D: usize, const K: usize> LinearOperator<'a, D, K> {
    pub fn new(mech: &'a Mechanics<D, K>, x0: &'a [SVector<f64, D>]) -> Self {
        LinearOperator {
            mech,
            x0,
            theta: vec![0.0; x0.len()],
        }
    }

    /// Linearised bond stretches of particle i for displacements u.
    #[inline]
    fn stretch(
        &self,
        u: &[SVector<f64, D>],
        i: usize,
        j: usize,
        il: f64,
    ) -> (f64, SVector<f64, D>) {
        let n = (self.x0[j] - self.x0[i]) * il;
        (n.dot(&(u[j] - u[i])) * il, n)
    }

    /// Internal forces f(u) of the linearised model; `theta` holds θ_i = Σ_m w_im·S_im
    /// afterwards.
    pub fn internal_forces(&mut self, u: &[SVector<f64, D>], f: &mut [SVector<f64, D>]) {
        let mech = self.mech;
        let this = &*self;
        let theta: Vec<f64> = (0..u.len())
            .into_par_iter()
            .with_min_len(1024)
            .map(|i| {
                let w = mech.weights(i);
                mech.bonds(i)
                    .map(|(k, j, il)| weighted(w, k, this.stretch(u, i, j, il).0))
                    .sum()
            })
            .collect();
        f.par_iter_mut()
            .with_min_len(1024)
            .enumerate()
            .for_each(|(i, fi)| {
                let mut acc = SVector::<f64, D>::zeros();
                for (k, j, il) in mech.bonds(i) {
                    let (s, n) = this.stretch(u, i, j, il);
                    let (mi, mj) = mech.bond_moduli(i, j, k);
                    let fb = bond_force(
                        mi,
                        mj,
                        s,
                        dilatation_term(mech.b[i], theta[i]),
                        dilatation_term(mech.b[j], theta[j]),
                    );
                    acc += n * fb;
                }
                *fi = acc;
            });
        self.theta = theta;
    }

    /// Force states F_s,ij = a_i S_ij + b_i θ_i (a_i + c_i in a second-neighbour slot) of
    /// particle i (linearised), slot by slot, after [`Self::internal_forces`].
    pub fn force_states(
        &self,
        u: &[SVector<f64, D>],
        i: usize,
    ) -> Vec<(SVector<f64, D>, f64, f64)> {
        self.mech
            .bonds(i)
            .map(|(k, j, il)| {
                let (s, n) = self.stretch(u, i, j, il);
                (
                    n,
                    1.0 / il,
                    force_state(
                        self.mech.slot_modulus(i, k),
                        s,
                        dilatation_term(self.mech.b[i], self.theta[i]),
                    ),
                )
            })
            .collect()
    }
}

/// The bond dampers as a linear operator on velocities: (C·v)_i = Σ_j c_ij·((v_i − v_j)·e_ij)·e_ij,
/// c_ij = ½(C_in,i + C_in,j), e_ij the reference bond direction (3.55).
pub fn apply_bond_dampers<const D: usize, const K: usize>(
    mech: &Mechanics<D, K>,
    x0: &[SVector<f64, D>],
    v: &[SVector<f64, D>],
    out: &mut [SVector<f64, D>],
) {
    out.par_iter_mut()
        .with_min_len(1024)
        .enumerate()
        .for_each(|(i, o)| {
            let mut acc = SVector::<f64, D>::zeros();
            for (_, j, il) in mech.bonds(i) {
                let e = (x0[j] - x0[i]) * il;
                let c = 0.5 * (mech.c_in[i] + mech.c_in[j]);
                acc += e * (c * (v[i] - v[j]).dot(&e));
            }
            *o = acc;
        });
}
