//! The stable time step of the explicit scheme (MODEL.md §5), from the actual stiffness,
//! masses and damping: ω_max² is bounded by the block Gershgorin (induced row-sum) norm of
//! M⁻¹K ([`Mechanics::max_eigenvalue_bound`]), and the central-difference limit with the
//! explicitly integrated bond dampers is Δt ≤ (2/ω_max)(√(1+ζ²) − ζ), ζ = c/(2ω_max), with c
//! a bound of the spectral radius of M⁻¹C_in. The particle damper is integrated
//! semi-implicitly and does not lower the limit.

use super::mechanics::Mechanics;
use nalgebra::SVector;

/// The computed limit and its ingredients.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct StableStep {
    /// Upper bound of the highest angular frequency (rad/s).
    pub omega_max: f64,
    /// Damping ratio of the bond dampers at ω_max (bound).
    pub zeta: f64,
    /// Largest stable Δt (s).
    pub dt_stable: f64,
}

pub fn stable_step<const D: usize, const K: usize>(
    mech: &Mechanics<D, K>,
    x0: &[SVector<f64, D>],
) -> StableStep {
    let omega_max = mech.max_eigenvalue_bound(x0).sqrt();
    let zeta = mech.max_bond_damping_rate() / (2.0 * omega_max);
    let dt_stable = 2.0 / omega_max * ((1.0 + zeta * zeta).sqrt() - zeta);
    StableStep {
        omega_max,
        zeta,
        dt_stable,
    }
}
