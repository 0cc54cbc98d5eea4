//! Bond-based peridynamics (docs/bond_based.md): the families of a cubic grid, the
//! micromoduli of a body of horizon δ and the softening laws of a bond, for running the concrete models of the literature beside
//! the state-based lattice.

pub mod body;
pub mod bonds;
pub mod family;
pub mod kernel;
pub mod micromodulus;
pub mod softening;

/// What the tests of the bond-based model share.
#[cfg(test)]
pub(crate) mod test_support {
    use nalgebra::Vector3;

    /// A fixed pseudo-random displacement of size `a` of the points `x0` (a linear
    /// congruential sequence from `seed`).
    pub fn jiggle(x0: &[Vector3<f64>], a: f64, seed: u64) -> Vec<Vector3<f64>> {
        let mut r = seed;
        let mut next = || {
            r = r
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (r >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        x0.iter()
            .map(|p| p + Vector3::new(next(), next(), next()) * a)
            .collect()
    }
}
