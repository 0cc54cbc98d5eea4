//! Dimension-erased arrays of a run's outcome (docs/architecture.md, "Interfaces"): points as
//! 3-vectors, stresses as 6 Voigt components, whatever D.

/// A point of dimension D as a 3-vector (zeros beyond D).
pub fn point3<const D: usize>(p: &nalgebra::SVector<f64, D>) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (o, v) in out.iter_mut().zip(p.iter()) {
        *o = *v;
    }
    out
}

/// A symmetric D×D stress as 6 Voigt components [xx, yy, zz, yz, xz, xy] (zeros beyond D).
pub fn voigt6<const D: usize>(s: &nalgebra::SMatrix<f64, D, D>) -> [f64; 6] {
    let at = |r: usize, c: usize| if r < D && c < D { s[(r, c)] } else { 0.0 };
    [at(0, 0), at(1, 1), at(2, 2), at(1, 2), at(0, 2), at(0, 1)]
}

/// The row-major 3×3 tensor of 6 Voigt components [xx, yy, zz, yz, xz, xy].
pub fn tensor9(s: &[f64; 6]) -> [f64; 9] {
    [s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2]]
}
