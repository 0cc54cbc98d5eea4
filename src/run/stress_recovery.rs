//! The stress the outputs show (maps, VTK, CSV): the recovered stress σ_i = D_i·ε_i
//! (docs/model.md §7 and §13), with D_i the isotropic elasticity matrix of the scene's (E, ν) and
//! plane, scaled by the particle's own E where a random field varies it.
//!
//! **Decision (measured; docs/surfaces.md).**
//!
//! - *Bulk particles* (all six bonds): ε_i is the least-squares strain of the particle's own
//!   (damaged elastic) bond stretches (`model::strain`). In the bulk of a lattice D·ε_i is
//!   (3.18) exactly (both are M·K·S), and it is the stress the concrete criteria test.
//! - *Boundary particles* (missing bonds) whose patch (the particles within two bonds) is
//!   undamaged and has not yielded: ε_i is the strain of the affine displacement field
//!   fitted to the patch by least squares. A particle's own bonds cannot give it: at a
//!   surface across the lattice rows the particles zig-zag, and their positions relax off the
//!   affine field. Measured on a plate in tension (normal / tangential stress error at the
//!   side faces, of the remote stress) and at a hole of R = 10·L0 (hoop stress at the hole's
//!   side, Kirsch 3, Howland 3.03):
//!
//!   | recovery | faces 0° | faces 15° | faces 30° | hole: hoop, max σ_rr |
//!   |---|---|---|---|---|
//!   | own bonds | 23% / 22% | 33% / 43% | 1.9% / 1.3% | 2.00, 1.01 |
//!   | affine, one ring | 19% / 4.9% | 17% / 25% | 2.0% / 1.2% | 2.49, 0.50 |
//!   | affine, two rings (this) | 9.4% / 2.8% | 7.4% / 7.2% | 1.2% / 1.2% | 2.47, 0.32 |
//!   | quadratic, two rings | | | | 2.32, 1.08 |
//!
//!   (3.18) divides one-sided bonds by the particle's volume: 0.78 and 1.23 × the tangential
//!   stress on the faces at 0° and 30°.
//! - Boundary particles with damage or plastic flow in their patch keep their own fit: a
//!   displacement fit across a crack would read the opening as strain.
//!
//! (3.18) stays available as `run::particle_stress`.

use super::model::Model;
use crate::discretise::NONE;
use crate::material::properties;
use crate::model::dimension::{Dim, Dimension};
use crate::model::micro_modulus::elasticity_matrix;
use crate::model::stretch::total_stretch;
use nalgebra::{Matrix2, SMatrix, SVector, Vector2};

/// Each particle's least-squares strain of its total bond stretches at positions x (the
/// elastic model: no damage, no plastic stretch), in 2D or 3D.
pub fn elastic_strain<const K: usize, const D: usize>(
    model: &Model<K, D>,
    x: &[SVector<f64, D>],
) -> Vec<SMatrix<f64, D, D>>
where
    Dim<D>: Dimension<D>,
{
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
            Dim::<D>::strain_tensor(&Dim::<D>::strain_fit(&dirs), &s)
        })
        .collect()
}

/// The particles within two bonds of particle i (i first).
fn patch<const K: usize>(model: &Model<K>, i: usize) -> Vec<usize> {
    let nb = &model.particles.neighbours;
    let mut out = vec![i];
    for &j in nb[i].iter().filter(|&&j| j != NONE) {
        let j = j as usize;
        if !out.contains(&j) {
            out.push(j);
        }
        for &m in nb[j].iter().filter(|&&m| m != NONE) {
            let m = m as usize;
            if !out.contains(&m) {
                out.push(m);
            }
        }
    }
    out
}

/// The small strain of the affine displacement field u ≈ c + G·(x0 − x0_i) fitted by least
/// squares to the displacements of `members` (reference positions about x0_i, in units of
/// the spacing); `None` when the patch cannot carry the fit (collinear).
fn patch_strain<const K: usize>(
    model: &Model<K>,
    x: &[Vector2<f64>],
    i: usize,
    members: &[usize],
) -> Option<Matrix2<f64>> {
    let p = &model.particles;
    let h = p.spacing;
    let mut ata = SMatrix::<f64, 3, 3>::zeros();
    let mut atb = [SVector::<f64, 3>::zeros(), SVector::<f64, 3>::zeros()];
    for &j in members {
        let r = (p.x0[j] - p.x0[i]) / h;
        let phi = SVector::<f64, 3>::from([1.0, r.x, r.y]);
        let u = x[j] - p.x0[j];
        ata += phi * phi.transpose();
        atb[0] += phi * u.x;
        atb[1] += phi * u.y;
    }
    let chol = ata.cholesky()?;
    let (cx, cy) = (chol.solve(&atb[0]), chol.solve(&atb[1]));
    let (exx, eyy) = (cx[1] / h, cy[2] / h);
    let exy = 0.5 * (cx[2] + cy[1]) / h;
    let e = Matrix2::new(exx, exy, exy, eyy);
    e.iter().all(|v| v.is_finite()).then_some(e)
}

/// The strains the recovered stress uses: `own` (each particle's fit of its own bonds) for
/// bulk particles, the patch fit for boundary particles whose patch is `intact` (see the
/// module docs).
pub fn recovered_strain<const K: usize>(
    model: &Model<K>,
    x: &[Vector2<f64>],
    own: Vec<Matrix2<f64>>,
    intact: &dyn Fn(usize) -> bool,
) -> Vec<Matrix2<f64>> {
    let p = &model.particles;
    let mut out = own;
    for (i, e) in out.iter_mut().enumerate() {
        if p.neighbours[i].iter().filter(|&&j| j != NONE).count() >= 6 {
            continue;
        }
        let members = patch(model, i);
        if members.len() < 4 || !members.iter().all(|&j| intact(j)) {
            continue;
        }
        if let Some(fit) = patch_strain(model, x, i, &members) {
            *e = fit;
        }
    }
    out
}

/// σ_i = D_i·ε_i for the strains `strain` of the particles of `model`.
pub fn recovered_stress<const K: usize>(
    model: &Model<K>,
    strain: &[Matrix2<f64>],
) -> Vec<Matrix2<f64>> {
    let m = &model.scene.material;
    let d = elasticity_matrix(m.youngs_modulus(), m.nu, m.plane());
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

/// The recovered stress of an elastic run at positions x.
pub fn elastic_stress<const K: usize>(model: &Model<K>, x: &[Vector2<f64>]) -> Vec<Matrix2<f64>> {
    let strain = recovered_strain(model, x, elastic_strain(model, x), &|_| true);
    recovered_stress(model, &strain)
}

/// The stress D·ε_i of each particle of a 3D model from its strain ε_i (the least-squares
/// strain of its own bond stretches, [`elastic_strain`] or the concrete kernel's damaged
/// elastic one; docs/model.md §7, §13): exact in the bulk of the FCC lattice under a homogeneous
/// strain. The surface recovery of 2D (the affine patch fit) is not carried to 3D yet.
pub fn stress_3d<const K: usize>(
    model: &Model<K, 3>,
    strain: &[nalgebra::Matrix3<f64>],
) -> Vec<nalgebra::Matrix3<f64>> {
    let m = &model.scene.material;
    let d = <Dim<3> as Dimension<3>>::elasticity(m.youngs_modulus(), m.nu, m.plane());
    strain
        .iter()
        .map(|e| Dim::<3>::stress_of_strain(&d, e))
        .collect()
}
