//! The SPLM force law, written once (docs/model.md §3–4, §6; (3.7), (3.8), (3.36)).
//!
//! Every caller computes bond forces, force states, the dilatation term and the stored
//! energy through these functions: the scalar step kernels (`solver::kernel`,
//! `solver::inelastic`), the linearised operator (`solver::linear`), the
//! eigenvalue bound (`solver::mechanics`), the energy (`solver::Simulation`) and the stress
//! recovery (`run::particle_stress`, `solver::inelastic::particle_stress`). The AVX path of the
//! slot layout (`solver::kernel::avx`) performs the same IEEE operations lane by lane and is
//! tested bit-identical to them; `tests/suite/force_law.rs` evaluates random configurations
//! through every caller and finds them equal.
//!
//! With micro-moduli a_i, b_i (and, for FCC second neighbours, a bond modulus a_i + c_i
//! passed as `a`), a bond of stretch S between particles i and j:
//! - dilatation term bθ_i = b_i·Σ_m S_im (3.8);
//! - force state F_s,ij = a_i·S_ij + bθ_i (3.8);
//! - bond force F_b,ij = ½(F_s,ij + F_s,ji) = ½((a_i + a_j)·S_ij + bθ_i + bθ_j) (3.7), using
//!   S_ji = S_ij;
//! - with damage factor d (3.37) and elastic stretch S_e, the damaged force state
//!   d·a_i·S_e + √d·bθ_i and bond force ½(d·(a_i + a_j)·S_e + √d·(bθ_i + bθ_j)), with
//!   bθ_i = b_i·Σ_m √d_im·S_e,im (the decision of `solver::inelastic`);
//! - stored energy U = ¼·Σ_i Σ_j L0,ij·S_ij·F_s,ij, so that ∂U/∂L_ij = F_b,ij.
//!
//! Without damage (d = 1) the damaged forms equal the elastic ones up to the order of the
//! additions; each caller keeps the form it always had, so results are unchanged bit for bit.

/// The dilatation term bθ_i = b_i·Σ_m S_im (3.8) from the sum of particle i's stretches
/// (damaged: Σ_m √d_im·S_e,im).
#[inline(always)]
pub fn dilatation_term(b: f64, stretch_sum: f64) -> f64 {
    b * stretch_sum
}

/// Particle i's own bond modulus in slot k: a_i, or a_i + c_i in an FCC second-neighbour
/// slot (docs/model.md §3 erratum); `second` is (c_i, the first second-neighbour slot), `None`
/// without second neighbours.
#[inline(always)]
pub fn slot_modulus(a: f64, second: Option<(f64, usize)>, k: usize) -> f64 {
    match second {
        Some((c, first)) if k >= first => a + c,
        _ => a,
    }
}

/// Force state F_s,ij = a_i·S_ij + bθ_i (3.8).
#[inline(always)]
pub fn force_state(a: f64, stretch: f64, b_theta: f64) -> f64 {
    a * stretch + b_theta
}

/// Bond force F_b,ij = ½((a_i + a_j)·S_ij + bθ_i + bθ_j) (3.7), along the bond.
#[inline(always)]
pub fn bond_force(a_i: f64, a_j: f64, stretch: f64, b_theta_i: f64, b_theta_j: f64) -> f64 {
    0.5 * ((a_i + a_j) * stretch + b_theta_i + b_theta_j)
}

/// The axial part of a damaged bond's force, d·((a_i + a_j)·S_e): computed once per bond
/// (pass 1 of the concrete kernel caches it for pass 2).
#[inline(always)]
pub fn damaged_axial(d: f64, a_i: f64, a_j: f64, elastic_stretch: f64) -> f64 {
    d * ((a_i + a_j) * elastic_stretch)
}

/// Damaged bond force ½(d·(a_i + a_j)·S_e + √d·(bθ_i + bθ_j)) from its axial part
/// ([`damaged_axial`]) and √d.
#[inline(always)]
pub fn damaged_bond_force(axial: f64, sqrt_d: f64, b_theta_i: f64, b_theta_j: f64) -> f64 {
    0.5 * (axial + sqrt_d * (b_theta_i + b_theta_j))
}

/// Damaged force state d·a_i·S_e + √d·bθ_i.
#[inline(always)]
pub fn damaged_force_state(d: f64, sqrt_d: f64, a: f64, elastic_stretch: f64, b_theta: f64) -> f64 {
    d * a * elastic_stretch + sqrt_d * b_theta
}

/// The bond's share of its particle's stored energy before the factor ¼: L0·S·F_s
/// (U_i = ¼·Σ_j L0,ij·S_ij·F_s,ij), with 1/L0 as the kernels store it.
#[inline(always)]
pub fn bond_energy(stretch: f64, force_state: f64, inv_l0: f64) -> f64 {
    stretch * force_state / inv_l0
}

/// A particle's stored elastic energy U_i = ¼·Σ_j L0,ij·S_ij·(a_i·S_ij + b_i·θ_i), from the
/// sums Σ_j S_ij (θ_i), Σ_j S_ij²·L0,ij and Σ_j S_ij·L0,ij.
#[inline(always)]
pub fn particle_energy(a: f64, b: f64, theta: f64, sum_s2_l0: f64, sum_s_l0: f64) -> f64 {
    0.25 * (a * sum_s2_l0 + b * theta * sum_s_l0)
}

/// ∂F_b,ij/∂S_ij = ½(a_i + a_j): the axial stiffness of a bond per unit stretch.
#[inline(always)]
pub fn axial_stiffness(a_i: f64, a_j: f64) -> f64 {
    0.5 * (a_i + a_j)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The energy's derivative is the bond force: one bond of length L0 between particles
    /// with only that bond, U(S) = ¼·L0·S·(a_i S + b_i S) + ¼·L0·S·(a_j S + b_j S), so
    /// dU/dL = (1/L0)·dU/dS = ½((a_i + a_j)S + b_i S + b_j S) = F_b.
    #[test]
    fn energy_derivative_is_the_bond_force() {
        let (ai, aj, bi, bj, l0) = (3.0e7, 2.5e7, -4.0e6, 1.0e6, 0.01);
        let u = |s: f64| {
            0.25 * l0 * s * force_state(ai, s, dilatation_term(bi, s))
                + 0.25 * l0 * s * force_state(aj, s, dilatation_term(bj, s))
        };
        let s = 1.3e-4;
        let h = 1e-9;
        let du_dl = (u(s + h) - u(s - h)) / (2.0 * h) / l0;
        let fb = bond_force(ai, aj, s, bi * s, bj * s);
        assert!((du_dl - fb).abs() <= 1e-6 * fb.abs(), "{du_dl} vs {fb}");
    }

    #[test]
    fn damaged_forms_reduce_to_the_elastic_ones_without_damage() {
        let (ai, aj, s, bti, btj) = (3.0e7, 2.5e7, 1.3e-4, -40.0, 25.0);
        let fb = bond_force(ai, aj, s, bti, btj);
        let fd = damaged_bond_force(damaged_axial(1.0, ai, aj, s), 1.0, bti, btj);
        assert!((fb - fd).abs() <= 4.0 * f64::EPSILON * fb.abs());
        assert_eq!(
            damaged_force_state(1.0, 1.0, ai, s, bti),
            force_state(ai, s, bti)
        );
        // a broken bond carries nothing from either end
        assert_eq!(
            damaged_bond_force(damaged_axial(0.0, ai, aj, s), 0.0, bti, btj),
            0.0
        );
    }
}
