//! What a damaged state stores and shows: the internal energy, the particle stress (3.18)
//! and the particles' least-squares strain (docs/model.md §7).

use super::passes::*;
use super::DamageKernel;
use crate::model::damage_law::DamageLaw;
use crate::model::dimension::{Dim, Dimension};
use crate::model::force_state::{bond_energy, damaged_force_state};
use crate::model::stress::StressSum;
use crate::solver::mechanics::Mechanics;
use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

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
    c: &DamageKernel<D, K, L>,
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
    c: &DamageKernel<D, K, L>,
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
    c: &DamageKernel<D, K, L>,
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
