//! Micro-elastic constants a, b (and c in 3D) of the force state (MODEL.md §3; (4.5), (4.6),
//! (4.8)) and the per-particle least-squares fit D ≈ M_i·K_i·N_i (3.20) used for SPPM
//! particles and for the "surface correction" of lattice particles with missing bonds.
//!
//! Voigt notation in 2D: σ = [σxx, σyy, σxy], ε = [εxx, εyy, γxy] (engineering shear).
//! A bond with unit direction n stretches by S = n·ε·n = v·ε with v = [nx², ny², nx·ny],
//! and contributes (L0/(2ΔV))·F_s·v to the stress (3.18). With F_s,ij = a·S_ij + b·Σ_m S_im,
//! the particle's stiffness is D_i = a·A + b·B with
//! A = Σ_j w_j v_j v_jᵀ and B = (Σ_j w_j v_j)(Σ_k v_k)ᵀ, w_j = L0,j/(2ΔV).

use crate::scene::Plane;
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

/// Micro-elastic constants of one particle (N; per unit stretch).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MicroModuli {
    pub a: f64,
    pub b: f64,
}

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
pub fn elasticity_matrix(e: f64, nu: f64, plane: Plane) -> Matrix3<f64> {
    match plane {
        Plane::Stress => {
            let c = e / (1.0 - nu * nu);
            Matrix3::new(
                c,
                c * nu,
                0.0,
                c * nu,
                c,
                0.0,
                0.0,
                0.0,
                c * (1.0 - nu) / 2.0,
            )
        }
        Plane::Strain => {
            let c = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
            Matrix3::new(
                c * (1.0 - nu),
                c * nu,
                0.0,
                c * nu,
                c * (1.0 - nu),
                0.0,
                0.0,
                0.0,
                c * (1.0 - 2.0 * nu) / 2.0,
            )
        }
    }
}

/// v = [nx², ny², nx·ny] of a unit bond direction: S = v·ε.
#[inline]
pub fn strain_projector(n: &Vector2<f64>) -> Vector3<f64> {
    Vector3::new(n.x * n.x, n.y * n.y, n.x * n.y)
}

/// The matrices A and B of a particle with bonds (unit direction, reference length) and
/// volume ΔV: D_i = a·A + b·B.
pub fn stiffness_basis(bonds: &[(Vector2<f64>, f64)], volume: f64) -> (Matrix3<f64>, Matrix3<f64>) {
    let mut a = Matrix3::zeros();
    let mut mv = Vector3::zeros();
    let mut nv = Vector3::zeros();
    for (n, l0) in bonds {
        let v = strain_projector(n);
        let w = l0 / (2.0 * volume);
        a += v * v.transpose() * w;
        mv += v * w;
        nv += v;
    }
    (a, mv * nv.transpose())
}

/// Result of the least-squares fit of one particle.
#[derive(Clone, Copy, Debug)]
pub struct Fit {
    pub moduli: MicroModuli,
    /// ‖a·A + b·B − D‖_F / ‖D‖_F.
    pub residual: f64,
}

/// Least-squares a, b with D ≈ a·A + b·B (3.20). Returns `None` when the bonds cannot carry
/// the fit (fewer than three independent directions, or a non-positive a).
pub fn fit(bonds: &[(Vector2<f64>, f64)], volume: f64, d: &Matrix3<f64>) -> Option<Fit> {
    let (a_m, b_m) = stiffness_basis(bonds, volume);
    let dot = |x: &Matrix3<f64>, y: &Matrix3<f64>| x.component_mul(y).sum();
    let g = Matrix2::new(
        dot(&a_m, &a_m),
        dot(&a_m, &b_m),
        dot(&b_m, &a_m),
        dot(&b_m, &b_m),
    );
    let r = Vector2::new(dot(&a_m, d), dot(&b_m, d));
    // A must have full rank (three independent v_j) for the particle to resist every strain.
    if a_m.determinant().abs() <= 1e-12 * a_m.norm().powi(3) {
        return None;
    }
    let sol = g.try_inverse()? * r;
    let moduli = MicroModuli { a: sol.x, b: sol.y };
    if !(moduli.a > 0.0 && moduli.a.is_finite() && moduli.b.is_finite()) {
        return None;
    }
    let residual = (a_m * moduli.a + b_m * moduli.b - d).norm() / d.norm();
    Some(Fit { moduli, residual })
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
        // MODEL.md §3: D = M·K·N exactly for a bulk hexagonal particle.
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
