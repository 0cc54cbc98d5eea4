//! Particle stress (docs/model.md §7, (3.18)): σ_i = (1/(2ΔV_i))·Σ_j L0,ij·F_s,ij·(n_ij ⊗ n_ij),
//! in any dimension D (2 by default).

use nalgebra::{SMatrix, SVector};

/// Accumulates the stress (3.18) of one particle bond by bond, in D dimensions.
#[derive(Clone, Copy, Debug)]
pub struct StressSum<const D: usize = 2>(pub SMatrix<f64, D, D>);

impl<const D: usize> Default for StressSum<D> {
    fn default() -> Self {
        StressSum(SMatrix::zeros())
    }
}

impl<const D: usize> StressSum<D> {
    /// Add a bond of direction `n` (unit), reference length `l0` and force state `fs`.
    #[inline]
    pub fn add(&mut self, n: &SVector<f64, D>, l0: f64, fs: f64) {
        self.0 += n * n.transpose() * (l0 * fs);
    }

    /// The stress tensor (Pa) of a particle of volume ΔV.
    pub fn finish(self, volume: f64) -> SMatrix<f64, D, D> {
        self.0 / (2.0 * volume)
    }
}
