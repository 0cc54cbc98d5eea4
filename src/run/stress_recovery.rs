//! The stress the outputs show (maps, VTK, CSV): the recovered stress σ_i = D_i·ε_i
//! (MODEL.md §7 and §13).
//!
//! **Decision (measured, issue "Surfaces").** ε_i is the least-squares strain of the
//! particle's own (damaged elastic) bond stretches (`model::strain`) and D_i the isotropic
//! elasticity matrix of the scene's (E, ν) and plane, scaled by the particle's own E where a
//! random field varies it. In the bulk of a lattice this is (3.18) exactly (both are M·K·S;
//! `tests/surfaces.rs`); at a free surface (3.18) divides one-sided bonds by the full
//! volume and under-reads the tangential stress by up to a half, while D·ε reads a
//! homogeneous state exactly with any three independent bond directions: zero normal
//! traction and the right tangential stress. It is the same stress the concrete criteria
//! test (`model::two_spring`). (3.18) stays available as `run::particle_stress`.

use super::prepare::Model;
use crate::discretise::NONE;
use crate::material::properties;
use crate::model::dimension::{Dim, Dimension};
use crate::model::micro_modulus::elasticity_matrix;
use crate::model::stretch::total_stretch;
use nalgebra::{Matrix2, Vector2};

/// Each particle's least-squares strain of its total bond stretches at positions x (the
/// elastic model: no damage, no plastic stretch).
pub fn elastic_strain<const K: usize>(model: &Model<K>, x: &[Vector2<f64>]) -> Vec<Matrix2<f64>> {
    let p = &model.particles;
    (0..p.len())
        .map(|i| {
            let mut dirs = [None; K];
            let mut s = [0.0; K];
            for k in 0..K {
                let j = p.neighbours[i][k];
                if j == NONE {
                    continue;
                }
                let j = j as usize;
                dirs[k] = Some((p.x0[j] - p.x0[i]).normalize());
                s[k] = total_stretch((x[j] - x[i]).norm(), 1.0 / p.l0[i][k]);
            }
            Dim::<2>::strain_tensor(&Dim::<2>::strain_fit(&dirs), &s)
        })
        .collect()
}

/// σ_i = D_i·ε_i for the strains `strain` of the particles of `model`.
pub fn recovered_stress<const K: usize>(
    model: &Model<K>,
    strain: &[Matrix2<f64>],
) -> Vec<Matrix2<f64>> {
    let m = &model.scene.material;
    let d = elasticity_matrix(m.youngs_modulus(), m.nu, m.plane);
    let factor = properties::stiffness_factors(&model.fields, m.youngs_modulus());
    strain
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let f = factor.as_ref().map_or(1.0, |f| f[i]);
            Dim::<2>::stress_of_strain(&(d * f), e)
        })
        .collect()
}
