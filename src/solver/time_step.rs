//! The stable time step of the explicit scheme (docs/model.md §5), from the actual stiffness,
//! masses and damping.
//!
//! For central differences with the bond dampers taken at v^{n−½} (explicitly) the limit of
//! a mode of frequency ω and damping ratio ζ is Δt ≤ (2/ω)(√(1+ζ²) − ζ). The particle damper
//! is integrated semi-implicitly and does not lower it. ω_max² is the largest eigenvalue of
//! M⁻¹K of the linearised model (all components free, which bounds the constrained
//! specimen), and ζ = ρ(M⁻¹C_in)/(2ω_max), both found by 60 Lanczos steps on the
//! M^{-1/2}-scaled operators, then raised by 4% to cover the Lanczos error (Lanczos
//! approaches the largest eigenvalue from below).
//!
//! Why not a Gershgorin bound: on the hexagonal lattice it over-estimates ω_max² by about
//! 1.5× and the bond-damping rate by 2×, and with the source's ξ_in = 0.2 (ζ ≈ 1 at ω_max)
//! it halved the time step. The Gershgorin value is still computed and reported
//! ([`Mechanics::max_eigenvalue_bound`]): the Lanczos value must lie below it. The estimate
//! is checked against the measured instability threshold in tests/suite/stability.rs.

use super::lanczos::{Extreme, Lanczos};
use super::linear::{apply_bond_dampers, LinearOperator};
use super::mechanics::Mechanics;
use nalgebra::SVector;

/// Relative allowance added to the Lanczos eigenvalues.
pub const LANCZOS_MARGIN: f64 = 0.04;
/// Lanczos steps.
pub const LANCZOS_STEPS: usize = 60;

/// The computed limit and its ingredients.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct StableStep {
    /// Highest angular frequency used for the limit (rad/s), Lanczos estimate with margin.
    pub omega_max: f64,
    /// Block-Gershgorin upper bound of the highest angular frequency (rad/s), for reference.
    pub omega_max_bound: f64,
    /// Damping ratio of the bond dampers at ω_max.
    pub zeta: f64,
    /// σ of (S.17), the implicit share of the bond dampers; 0 when they are wholly explicit.
    pub implicit_share: f64,
    /// Largest stable Δt (s).
    pub dt_stable: f64,
}

impl StableStep {
    /// The limit with a diagonal stiffness added (bearing strips, `solver::bearing`) whose
    /// largest k_i/m_i is `rate`: ω_max² grows by at most `rate` (Weyl's inequality), the
    /// bond dampers' ratio falls with the higher ω_max, and (S.7) gives the step again.
    pub fn add_stiffness(&mut self, rate: f64) {
        let damping = 2.0 * self.zeta * self.omega_max;
        self.omega_max = (self.omega_max * self.omega_max + rate).sqrt();
        self.omega_max_bound = (self.omega_max_bound * self.omega_max_bound + rate).sqrt();
        self.zeta = damping / (2.0 * self.omega_max);
        let z = self.zeta;
        self.dt_stable = if self.implicit_share != 0.0 {
            2.0 / self.omega_max
        } else {
            2.0 / self.omega_max * ((1.0 + z * z).sqrt() - z)
        };
    }
}

/// Largest eigenvalue of M^{-1/2}·A·M^{-1/2}, all components free.
fn largest<const D: usize>(
    mass: &[f64],
    apply: impl FnMut(&[SVector<f64, D>], &mut [SVector<f64, D>]),
) -> f64 {
    Lanczos {
        mass,
        constrained: None,
        deflate: &[],
        which: Extreme::Largest,
        tolerance: 0.0,
        max_steps: LANCZOS_STEPS,
    }
    .run(apply)
    .eigenvalue
}

pub fn stable_step<const D: usize, const K: usize>(
    mech: &Mechanics<D, K>,
    x0: &[SVector<f64, D>],
) -> StableStep {
    let mut op = LinearOperator::new(mech, x0);
    let lambda_k = largest::<D>(&mech.mass, |u, out| {
        op.internal_forces(u, out);
        out.iter_mut().for_each(|v| *v = -*v);
    }) * (1.0 + LANCZOS_MARGIN);
    let bound = mech.max_eigenvalue_bound(x0);
    let omega_max = lambda_k.min(bound).sqrt();
    let rate = if mech.has_bond_dampers() {
        let r = largest::<D>(&mech.mass, |v, out| apply_bond_dampers(mech, x0, v, out))
            * (1.0 + LANCZOS_MARGIN);
        r.min(mech.max_bond_damping_rate())
    } else {
        0.0
    };
    let zeta = rate / (2.0 * omega_max);
    // with an implicit share of the bond dampers (S.17) the limit is the undamped one
    let dt_stable = if mech.c_implicit.iter().any(|&d| d != 0.0) {
        2.0 / omega_max
    } else {
        2.0 / omega_max * ((1.0 + zeta * zeta).sqrt() - zeta)
    };
    StableStep {
        omega_max,
        omega_max_bound: bound.sqrt(),
        zeta,
        implicit_share: 0.0,
        dt_stable,
    }
}

/// Take a share of the bond dampers implicitly (docs/model.md §5, (S.17)): d_i = σ·Σ_j c_ij,
/// c_ij = ½(C_in,i + C_in,j), with σ = ½·λ_max(D_Σ^{-1/2}·C·D_Σ^{-1/2})·(1 + margin), the
/// smallest multiple of the damper sums D_Σ = diag(Σ_j c_ij) for which diag(d) ⪰ C/2
/// (Lanczos; at most 1, since C ⪯ 2·D_Σ). Sets `mech.c_implicit` and returns σ (0 without
/// bond dampers).
pub fn split_bond_dampers<const D: usize, const K: usize>(
    mech: &mut Mechanics<D, K>,
    x0: &[SVector<f64, D>],
) -> f64 {
    let sums: Vec<f64> = (0..mech.len())
        .map(|i| {
            mech.bonds(i)
                .map(|(_, j, _)| 0.5 * (mech.c_in[i] + mech.c_in[j]))
                .sum()
        })
        .collect();
    if !sums.iter().any(|&s| s > 0.0) {
        return 0.0;
    }
    // a particle without dampers is not coupled by C: any positive weight will do
    let weight: Vec<f64> = sums.iter().map(|&s| s.max(f64::MIN_POSITIVE)).collect();
    let lambda = largest::<D>(&weight, |v, out| apply_bond_dampers(mech, x0, v, out));
    let sigma = (0.5 * lambda * (1.0 + LANCZOS_MARGIN)).min(1.0);
    for (d, s) in mech.c_implicit.iter_mut().zip(&sums) {
        *d = sigma * s;
    }
    sigma
}
