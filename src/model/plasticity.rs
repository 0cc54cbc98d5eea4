//! Plasticity of a particle (docs/model.md §9; (3.38)–(3.48), (4.15)).
//!
//! **Erratum applied.** (3.43) divides half the norm of the deviatoric stress by
//! F_eff^(2/3), which is dimensionally inconsistent; the yield ratio is the von Mises form
//! √(3/2)·‖σ_dev‖/F_eff, yielding at 1.

//! The equivalent stress and the out-of-plane stress are `Dimension::equivalent_stress` and
//! `dimension::out_of_plane_stress` (one source for 2D and 3D).

/// Linear hardening (4.15): F_eff = f_y + (f_ult − f_y)·ε_eff/ε_ult.
#[inline]
pub fn effective_yield(fy: f64, fult: f64, eps_ult: f64, eps_eff: f64) -> f64 {
    fy + (fult - fy) * eps_eff / eps_ult
}

/// Plastic stretch increments (3.44)–(3.47) of a particle whose occupied slots (`used`)
/// carry the flow's values `fs` (the force states F_s, or on the FCC lattice the elastic
/// stretches, (S.21)): ΔS_Ps = Δλ·F_dev/‖F_dev‖ with F_dev = F_s − mean(F_s) and
/// Δλ = (f_y/E)·(ratio − 1). Adds them to `sps`; does nothing when F_dev vanishes.
#[inline]
pub fn flow<const K: usize>(
    fs: &[f64; K],
    used: &[bool; K],
    ratio: f64,
    fy_over_e: f64,
    sps: &mut [f64; K],
) {
    let mut n = 0.0;
    let mut sum = 0.0;
    for k in 0..K {
        if used[k] {
            n += 1.0;
            sum += fs[k];
        }
    }
    if n == 0.0 {
        return;
    }
    let mean = sum / n;
    let mut norm2 = 0.0;
    for k in 0..K {
        if used[k] {
            norm2 += (fs[k] - mean).powi(2);
        }
    }
    if norm2 <= 0.0 {
        return;
    }
    let scale = fy_over_e * (ratio - 1.0) / norm2.sqrt();
    for k in 0..K {
        if used[k] {
            sps[k] += scale * (fs[k] - mean);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::dimension::{out_of_plane_stress, Dim, Dimension};
    use crate::scene::Plane;
    use nalgebra::Matrix2;

    #[test]
    fn von_mises_of_uniaxial_and_shear() {
        let s = Matrix2::new(-30e6, 0.0, 0.0, 0.0);
        assert!((Dim::<2>::equivalent_stress(&s, 0.2, Plane::Stress) - 30e6).abs() < 1e-6);
        let t = Matrix2::new(0.0, 10e6, 10e6, 0.0);
        assert!(
            (Dim::<2>::equivalent_stress(&t, 0.2, Plane::Stress) - 3f64.sqrt() * 10e6).abs() < 1e-6
        );
        // hydrostatic (plane strain, ν = 0.5 limit) is not yielding
        let h = Matrix2::new(-1e6, 0.0, 0.0, -1e6);
        assert!(Dim::<2>::equivalent_stress(&h, 0.5, Plane::Strain) < 1e-6);
    }

    /// The 2D form equals √(3/2)·‖σ − tr(σ)/3·I‖ of the full 3×3 tensor.
    #[test]
    fn two_d_equivalent_stress_matches_the_tensor_form() {
        let s = Matrix2::new(-30e6, 4e6, 4e6, 7e6);
        for plane in [Plane::Stress, Plane::Strain] {
            let szz = out_of_plane_stress(s[(0, 0)], s[(1, 1)], 0.2, plane);
            let full = nalgebra::Matrix3::new(
                s[(0, 0)],
                s[(0, 1)],
                0.0,
                s[(1, 0)],
                s[(1, 1)],
                0.0,
                0.0,
                0.0,
                szz,
            );
            let dev = full - nalgebra::Matrix3::identity() * (full.trace() / 3.0);
            let a = (1.5 * dev.norm_squared()).sqrt();
            let b = Dim::<2>::equivalent_stress(&s, 0.2, plane);
            assert!((a - b).abs() <= 1e-9 * a);
        }
    }

    #[test]
    fn flow_is_deviatoric_with_length_dlambda() {
        let fs = [-3.0, -1.0, -1.0, -3.0, -1.0, -1.0];
        let used = [true; 6];
        let mut sps = [0.0; 6];
        flow(&fs, &used, 1.2, 1e-3, &mut sps);
        let sum: f64 = sps.iter().sum();
        let norm: f64 = sps.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!(sum.abs() < 1e-18);
        assert!((norm - 0.2e-3).abs() < 1e-15);
        // the most compressed bonds shorten plastically
        assert!(sps[0] < 0.0 && sps[1] > 0.0);
        assert!((effective_yield(20.0, 30.0, 0.0035, 0.0035) - 30.0).abs() < 1e-12);
    }
}
