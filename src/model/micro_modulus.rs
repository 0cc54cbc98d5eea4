//! Micro-elastic constants a, b (and c in 3D) of the force state (docs/model.md §3; (4.5), (4.6),
//! (4.8)) and the per-particle least-squares fit D ≈ M_i·K_i·N_i (3.20) used for SPPM
//! particles and for the "surface correction" of lattice particles with missing bonds.
//!
//! Voigt notation in 2D: σ = [σxx, σyy, σxy], ε = [εxx, εyy, γxy] (engineering shear).
//! A bond with unit direction n stretches by S = n·ε·n = v·ε with v = [nx², ny², nx·ny],
//! and contributes (L0/(2ΔV))·F_s·v to the stress (3.18). With F_s,ij = a·S_ij + b·Σ_m S_im,
//! the particle's stiffness is D_i = a·A + b·B with
//! A = Σ_j w_j v_j v_jᵀ and B = (Σ_j w_j v_j)(Σ_k v_k)ᵀ, w_j = L0,j/(2ΔV).
//!
//! The 2D functions here are wrappers over `model::dimension`, which gives the same in 3D
//! (Voigt [xx, yy, zz, yz, xz, xy], v = [nx², ny², nz², ny·nz, nx·nz, nx·ny]). For the FCC
//! lattice, F_s,ij = (a + c·[j ∈ N_II])·S_ij + b·Σ_m S_im (docs/model.md §3 with its erratum), so
//! D_i = a·A + b·B + c·C with C = Σ_{j ∈ N_II} w_j v_j v_jᵀ ([`fcc_basis`], [`fit_fcc`]).

use super::dimension::{least_squares, Dim, Dimension};
use crate::scene::Plane;
use nalgebra::{Matrix3, Matrix6, Vector2, Vector3};

pub use super::dimension::{Fit, MicroModuli};

/// Constants of a bulk particle of the hexagonal lattice: (4.5) plane stress, (4.6) plane strain.
pub fn hexagonal(e: f64, nu: f64, l0: f64, t: f64, plane: Plane) -> MicroModuli {
    let s3 = 3f64.sqrt();
    let a = 2.0 * e * l0 * t / (s3 * (1.0 + nu));
    let b = match plane {
        Plane::Stress => e * l0 * t * (1.0 - 3.0 * nu) / (6.0 * s3 * (nu * nu - 1.0)),
        Plane::Strain => e * l0 * t * (1.0 - 4.0 * nu) / (6.0 * s3 * (2.0 * nu - 1.0) * (1.0 + nu)),
    };
    MicroModuli { a, b }
}

/// Isotropic elasticity matrix D (Voigt, engineering shear) for plane stress or strain.
/// 2D wrapper of [`Dimension::elasticity`].
pub fn elasticity_matrix(e: f64, nu: f64, plane: Plane) -> Matrix3<f64> {
    <Dim<2> as Dimension<2>>::elasticity(e, nu, plane)
}

/// v = [nx², ny², nx·ny] of a unit bond direction: S = v·ε. 2D wrapper of
/// [`Dimension::projector`].
#[inline]
pub fn strain_projector(n: &Vector2<f64>) -> Vector3<f64> {
    <Dim<2> as Dimension<2>>::projector(n)
}

/// The matrices A and B of a particle with bonds (unit direction, reference length) and
/// volume ΔV: D_i = a·A + b·B. 2D wrapper of [`Dimension::stiffness_basis`].
pub fn stiffness_basis(bonds: &[(Vector2<f64>, f64)], volume: f64) -> (Matrix3<f64>, Matrix3<f64>) {
    <Dim<2> as Dimension<2>>::stiffness_basis(bonds, volume)
}

/// Least-squares a, b with D ≈ a·A + b·B (3.20). Returns `None` when the bonds cannot carry
/// the fit (fewer than three independent directions, or a non-positive a). 2D wrapper of
/// [`Dimension::fit`].
pub fn fit(bonds: &[(Vector2<f64>, f64)], volume: f64, d: &Matrix3<f64>) -> Option<Fit> {
    <Dim<2> as Dimension<2>>::fit(bonds, volume, d)
}

/// Micro-elastic constants of an FCC particle (N; per unit stretch): F_s,ij =
/// (a + c·[j ∈ N_II])·S_ij + b·Σ_m S_im (docs/model.md §3 with its erratum: c acts on the
/// second-neighbour bond's own stretch, so second neighbours have modulus a + c).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FccModuli {
    pub a: f64,
    pub b: f64,
    pub c: f64,
}

/// Constants (4.8) of a bulk particle of the FCC lattice with nearest spacing L0
/// (ΔV = (√2/2)·L0³): a = E·L0²/(√2·(1+ν)), b = (√2−1)·E·L0²·(1−4ν)/(24·(2ν−1)·(1+ν)),
/// c = (1/(2√2) − 1)·a. They reproduce isotropic D exactly
/// (`tests::fcc_constants_reproduce_isotropic_elasticity`).
pub fn fcc(e: f64, nu: f64, l0: f64) -> FccModuli {
    let s2 = 2f64.sqrt();
    let a = e * l0 * l0 / (s2 * (1.0 + nu));
    let b = (s2 - 1.0) * e * l0 * l0 * (1.0 - 4.0 * nu) / (24.0 * (2.0 * nu - 1.0) * (1.0 + nu));
    let c = (1.0 / (2.0 * s2) - 1.0) * a;
    FccModuli { a, b, c }
}

/// Volume ΔV = (√2/2)·L0³ of a bulk FCC particle with nearest spacing L0.
pub fn fcc_volume(l0: f64) -> f64 {
    0.5 * 2f64.sqrt() * l0 * l0 * l0
}

/// A bond of a 3D particle for the FCC stiffness: unit direction, reference length, and
/// whether it is a second neighbour (N_II, modulus a + c).
pub type FccBond = (Vector3<f64>, f64, bool);

/// The bases A, B (all bonds, see [`Dimension::stiffness_basis`]) and C = Σ_{j ∈ N_II}
/// w_j·v_j·v_jᵀ of an FCC particle: D_i = a·A + b·B + c·C.
pub fn fcc_basis(bonds: &[FccBond], volume: f64) -> (Matrix6<f64>, Matrix6<f64>, Matrix6<f64>) {
    let all: Vec<(Vector3<f64>, f64)> = bonds.iter().map(|&(n, l0, _)| (n, l0)).collect();
    let second: Vec<(Vector3<f64>, f64)> = bonds
        .iter()
        .filter(|b| b.2)
        .map(|&(n, l0, _)| (n, l0))
        .collect();
    let (a_m, b_m) = <Dim<3> as Dimension<3>>::stiffness_basis(&all, volume);
    let (c_m, _) = <Dim<3> as Dimension<3>>::stiffness_basis(&second, volume);
    (a_m, b_m, c_m)
}

/// [`fcc_basis`] with the weighted dilatation θ_i = Σ_m (L0,im/ℓ_i)·S_im (ℓ_i the
/// particle's shortest bond; [`crate::model::dimension::stiffness_basis_weighted`]). The FCC
/// lattice runs with it: with the source's θ = Σ S, bonds of two lengths make the stiffness
/// unsymmetric (docs/fcc.md), as for random particles (docs/sppm.md).
pub fn fcc_basis_weighted(
    bonds: &[FccBond],
    volume: f64,
    ell: f64,
) -> (Matrix6<f64>, Matrix6<f64>, Matrix6<f64>) {
    use crate::model::dimension::{stiffness_basis_weighted, Voigt6};
    let all: Vec<(Vector3<f64>, f64)> = bonds.iter().map(|&(n, l0, _)| (n, l0)).collect();
    let second: Vec<(Vector3<f64>, f64)> = bonds
        .iter()
        .filter(|b| b.2)
        .map(|&(n, l0, _)| (n, l0))
        .collect();
    let (a_m, b_m) = stiffness_basis_weighted::<3, 6, Voigt6>(&all, volume, Some(ell));
    let (c_m, _) = stiffness_basis_weighted::<3, 6, Voigt6>(&second, volume, Some(ell));
    (a_m, b_m, c_m)
}

/// Least-squares (a, b, c) of an FCC particle with the weighted dilatation
/// ([`fcc_basis_weighted`]); `None` as [`fit_fcc`]. For a bulk particle (all 18 bonds) the
/// fit is exact: A, B and C are cubic and span the isotropic D.
pub fn fit_fcc_weighted(
    bonds: &[FccBond],
    volume: f64,
    ell: f64,
    d: &Matrix6<f64>,
) -> Option<FccFit> {
    let (a_m, b_m, c_m) = fcc_basis_weighted(bonds, volume, ell);
    let ([a, b, c], residual) = least_squares(&[a_m, b_m, c_m], d, |x| x[0] + x[2] > 0.0)?;
    Some(FccFit {
        moduli: FccModuli { a, b, c },
        residual,
    })
}

/// Least-squares (a, b) with c = 0 of a 3D particle with the weighted dilatation (an FCC
/// particle whose (a, b, c) fit fails).
pub fn fit_weighted_3d(
    bonds: &[(Vector3<f64>, f64)],
    volume: f64,
    ell: f64,
    d: &Matrix6<f64>,
) -> Option<crate::model::dimension::Fit> {
    use crate::model::dimension::{stiffness_basis_weighted, Voigt6};
    let (a_m, b_m) = stiffness_basis_weighted::<3, 6, Voigt6>(bonds, volume, Some(ell));
    let ([a, b], residual) = least_squares(&[a_m, b_m], d, |_| true)?;
    Some(crate::model::dimension::Fit {
        moduli: crate::model::dimension::MicroModuli { a, b },
        residual,
    })
}

/// Result of the least-squares (a, b, c) fit of an FCC particle.
#[derive(Clone, Copy, Debug)]
pub struct FccFit {
    pub moduli: FccModuli,
    /// ‖a·A + b·B + c·C − D‖_F / ‖D‖_F.
    pub residual: f64,
}

/// Least-squares a, b, c with D ≈ a·A + b·B + c·C (3.20) for an FCC particle (e.g. the
/// surface correction of one with missing bonds). `None` when A is rank deficient, the
/// Gram matrix singular (e.g. no second neighbours: fit (a, b) with [`Dimension::fit`]),
/// a ≤ 0 or, with second neighbours, a + c ≤ 0.
pub fn fit_fcc(bonds: &[FccBond], volume: f64, d: &Matrix6<f64>) -> Option<FccFit> {
    let (a_m, b_m, c_m) = fcc_basis(bonds, volume);
    let ([a, b, c], residual) = least_squares(&[a_m, b_m, c_m], d, |x| x[0] + x[2] > 0.0)?;
    Some(FccFit {
        moduli: FccModuli { a, b, c },
        residual,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn hex_bonds(l0: f64) -> Vec<(Vector2<f64>, f64)> {
        (0..6)
            .map(|k| {
                let th = (60.0 * k as f64).to_radians();
                (Vector2::new(th.cos(), th.sin()), l0)
            })
            .collect()
    }

    #[test]
    fn closed_form_constants_reproduce_isotropic_elasticity() {
        // docs/model.md §3: D = M·K·N exactly for a bulk hexagonal particle.
        for plane in [Plane::Stress, Plane::Strain] {
            for nu in [0.0, 0.2, 1.0 / 3.0, 0.45] {
                let (e, l0, t) = (30e9, 0.01, 0.1);
                let m = hexagonal(e, nu, l0, t, plane);
                let vol = 0.5 * 3f64.sqrt() * l0 * l0 * t;
                let (a_m, b_m) = stiffness_basis(&hex_bonds(l0), vol);
                let d = elasticity_matrix(e, nu, plane);
                let model = a_m * m.a + b_m * m.b;
                assert!((model - d).norm() / d.norm() < 1e-13, "{plane:?} nu={nu}");
                let f = fit(&hex_bonds(l0), vol, &d).unwrap();
                assert_relative_eq!(f.moduli.a, m.a, max_relative = 1e-12);
                assert_relative_eq!(f.moduli.b, m.b, max_relative = 1e-10, epsilon = 1e-9 * m.a);
                assert!(f.residual < 1e-12);
            }
        }
    }

    #[test]
    fn b_is_negative_for_common_concrete() {
        let m = hexagonal(30e9, 0.2, 0.01, 0.1, Plane::Stress);
        assert!(m.a > 0.0 && m.b < 0.0);
    }

    #[test]
    fn edge_particle_fit_is_stiffer_than_bulk_and_degenerate_sets_are_refused() {
        let (e, nu, l0, t) = (30e9, 0.2, 0.01, 0.1);
        let d = elasticity_matrix(e, nu, Plane::Stress);
        let vol = 0.5 * 3f64.sqrt() * l0 * l0 * t;
        // a particle on a straight edge: bonds at 0°, 60°, 120°, 180°
        let bonds: Vec<_> = hex_bonds(l0).into_iter().take(4).collect();
        let f = fit(&bonds, vol, &d).unwrap();
        assert!(f.moduli.a > hexagonal(e, nu, l0, t, Plane::Stress).a);
        // two collinear bonds cannot resist shear
        let line = vec![hex_bonds(l0)[0], hex_bonds(l0)[3]];
        assert!(fit(&line, vol, &d).is_none());
    }
}
