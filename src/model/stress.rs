//! Particle stress (MODEL.md §7, (3.18)): σ_i = (1/(2ΔV_i))·Σ_j L0,ij·F_s,ij·(n_ij ⊗ n_ij).

use nalgebra::{Matrix2, Vector2};

/// Accumulates the stress of one particle bond by bond.
#[derive(Clone, Copy, Debug, Default)]
pub struct StressSum(pub Matrix2<f64>);

impl StressSum {
    /// Add a bond of direction `n` (unit), reference length `l0` and force state `fs`.
    #[inline]
    pub fn add(&mut self, n: &Vector2<f64>, l0: f64, fs: f64) {
        self.0 += n * n.transpose() * (l0 * fs);
    }

    /// The stress tensor (Pa) of a particle of volume ΔV.
    pub fn finish(self, volume: f64) -> Matrix2<f64> {
        self.0 / (2.0 * volume)
    }
}

/// Von Mises equivalent stress of a plane stress state (σ3 = 0).
pub fn von_mises(s: &Matrix2<f64>) -> f64 {
    let (sx, sy, txy) = (s[(0, 0)], s[(1, 1)], s[(0, 1)]);
    (sx * sx - sx * sy + sy * sy + 3.0 * txy * txy).sqrt()
}

/// Largest principal stress (nalgebra's symmetric eigen solver).
pub fn max_principal(s: &Matrix2<f64>) -> f64 {
    s.symmetric_eigenvalues().max()
}
