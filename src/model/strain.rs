//! Strain at a particle (docs/model.md §7) from its bond stretches.
//!
//! **Decision (refines §7).** The strain is the one that best fits the particle's own bond
//! stretches in the least-squares sense, ε_i = N_i⁺·S_T,i (N_i's rows v = [nx², ny², nx·ny],
//! see `micro_modulus`), with total stretches as §7 asks. For a bulk particle of the
//! hexagonal lattice this is exactly §7's ε = D⁻¹·M_i·K_i·S_T (both are left inverses of N_i,
//! and both depend only on the sums of opposite stretches, three numbers for three unknowns;
//! `tests::bulk_fit_equals_d_inverse_mk`). For a boundary particle, D⁻¹·M_i·K_i·S_T
//! under-reads every strain by the missing bonds (its M_i uses the full ΔV), so cracks would
//! neither start nor open at free surfaces; the fit reads a homogeneous strain exactly with
//! any three independent bond directions. A particle with fewer independent directions gets
//! the minimum-norm fit (pseudo-inverse).
//!
//! The fit is `Dimension::strain_fit` / `Dimension::strain_tensor` of `model::dimension`,
//! one source for 2D and 3D; the tests below check the decision in 2D.

#[cfg(test)]
mod tests {
    use crate::model::dimension::{Dim, Dimension};
    use crate::model::micro_modulus::{
        elasticity_matrix, hexagonal, stiffness_basis, strain_projector,
    };
    use crate::scene::Plane;
    use nalgebra::Vector3;
    use nalgebra::{Matrix2, Vector2};

    fn hex_dirs(rot: f64, missing: &[usize]) -> [Option<Vector2<f64>>; 6] {
        let mut d = [None; 6];
        for (k, x) in d.iter_mut().enumerate() {
            if !missing.contains(&k) {
                let a = rot + k as f64 * std::f64::consts::PI / 3.0;
                *x = Some(Vector2::new(a.cos(), a.sin()));
            }
        }
        d
    }

    fn stretches(d: &[Option<Vector2<f64>>; 6], eps: &Vector3<f64>) -> [f64; 6] {
        let mut s = [0.0; 6];
        for k in 0..6 {
            if let Some(n) = d[k] {
                s[k] = strain_projector(&n).dot(eps);
            }
        }
        s
    }

    #[test]
    fn homogeneous_strain_is_read_exactly_with_missing_bonds() {
        let eps = Vector3::new(1.3e-4, -0.4e-4, 0.7e-4);
        for missing in [&[][..], &[3], &[3, 4], &[2, 3, 4]] {
            let d = hex_dirs(0.3, missing);
            let e = Dim::<2>::strain_tensor(&Dim::<2>::strain_fit(&d), &stretches(&d, &eps));
            assert!((e[(0, 0)] - eps[0]).abs() < 1e-15);
            assert!((e[(1, 1)] - eps[1]).abs() < 1e-15);
            assert!((2.0 * e[(0, 1)] - eps[2]).abs() < 1e-15);
        }
    }

    /// §7's D⁻¹·M·K·S and the fit agree for a bulk particle, for any stretches.
    #[test]
    fn bulk_fit_equals_d_inverse_mk() {
        let (e, nu, l0, t) = (30e9, 0.2, 0.01, 0.1);
        let m = hexagonal(e, nu, l0, t, Plane::Stress);
        let vol = 0.5 * 3f64.sqrt() * l0 * l0 * t;
        let d = hex_dirs(0.0, &[]);
        let dinv = elasticity_matrix(e, nu, Plane::Stress)
            .try_inverse()
            .unwrap();
        let p = Dim::<2>::strain_fit(&d);
        let s = [1e-4, -3e-5, 2e-5, 7e-5, -1e-5, 4e-5];
        let theta: f64 = s.iter().sum();
        let mut sigma = Vector3::zeros();
        for k in 0..6 {
            let v = strain_projector(&d[k].unwrap());
            sigma += v * (l0 / (2.0 * vol)) * (m.a * s[k] + m.b * theta);
        }
        let via_d = dinv * sigma;
        let fit = Dim::<2>::strain_tensor(&p, &s);
        let _ = stiffness_basis(&[], 1.0);
        assert!((fit[(0, 0)] - via_d[0]).abs() < 1e-12 * 1e-4);
        assert!((fit[(1, 1)] - via_d[1]).abs() < 1e-12 * 1e-4);
        assert!((2.0 * fit[(0, 1)] - via_d[2]).abs() < 1e-12 * 1e-4);
    }

    #[test]
    fn closed_form_principal_values_match_nalgebra() {
        for (a, b, c) in [
            (1e-4, 0.0, -2e-5),
            (-3e6, 1.5e6, 2e6),
            (1.0, 1.0, 1.0),
            (0.0, 0.0, 0.0),
            (-7e-3, 1e-9, -7e-3),
        ] {
            let t = Matrix2::new(a, b, b, c);
            let ev = t.symmetric_eigenvalues();
            let (hi, lo) = (ev.max(), ev.min());
            let [p1, p2] = Dim::<2>::principal_values(&t);
            let scale = t.norm().max(f64::MIN_POSITIVE);
            assert!((p1 - hi).abs() <= 1e-14 * scale && (p2 - lo).abs() <= 1e-14 * scale);
        }
    }

    #[test]
    fn plane_stress_out_of_plane_strain() {
        let e = Matrix2::new(1e-4, 0.0, 0.0, -0.2e-4);
        let (e1, e2, e3) = Dim::<2>::principal_strains(&e, 0.2, Plane::Stress);
        assert!((e1 - 1e-4).abs() < 1e-19 && (e2 + 0.2e-4).abs() < 1e-19);
        assert!((e3 + 0.25 * 0.8e-4).abs() < 1e-18);
    }
}
