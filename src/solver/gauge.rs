//! Gauges read during a run (`[[gauges]]`, docs/scenes.md "Gauges"): an opening as a
//! weighted sum of particle displacements, read with every record.

use nalgebra::SVector;

pub use crate::scene::gauge::MAX_GAUGES;

/// One gauge as weights on the particles' displacements: the opening is
/// Σ w_i·(x_i − x0_i) over its terms.
#[derive(Clone, Debug, PartialEq)]
pub struct Gauge<const D: usize> {
    pub name: String,
    pub terms: Vec<(u32, SVector<f64, D>)>,
}

impl<const D: usize> Gauge<D> {
    /// The gauge between two sets of particles (`first`, `second`, each read as the mean of
    /// its members' displacements) along the unit vector `n`: second less first.
    pub fn between(name: &str, first: &[u32], second: &[u32], n: SVector<f64, D>) -> Self {
        let mut terms = Vec::with_capacity(first.len() + second.len());
        for (set, sign) in [(first, -1.0), (second, 1.0)] {
            let w = sign / set.len().max(1) as f64;
            terms.extend(set.iter().map(|&i| (i, n * w)));
        }
        Gauge {
            name: name.to_string(),
            terms,
        }
    }

    /// The opening at positions `x` (m).
    pub fn reading(&self, x: &[SVector<f64, D>], x0: &[SVector<f64, D>]) -> f64 {
        self.terms
            .iter()
            .map(|(i, w)| w.dot(&(x[*i as usize] - x0[*i as usize])))
            .sum()
    }
}

/// The readings of `gauges` at positions `x`, in their order (zeros after the last).
pub fn readings<const D: usize>(
    gauges: &[Gauge<D>],
    x: &[SVector<f64, D>],
    x0: &[SVector<f64, D>],
) -> [f64; MAX_GAUGES] {
    let mut r = [0.0; MAX_GAUGES];
    for (slot, g) in r.iter_mut().zip(gauges) {
        *slot = g.reading(x, x0);
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    /// Two particles pulled apart by 1 and 3 µm along x, a third moving in y only: the
    /// opening along x is the difference of the ends' mean x displacements.
    #[test]
    fn a_gauge_reads_the_difference_of_the_mean_displacements_along_its_direction() {
        let x0 = vec![
            Vector2::zeros(),
            Vector2::new(1.0, 0.0),
            Vector2::new(2.0, 0.0),
        ];
        let u = [
            Vector2::new(-1e-6, 5e-6),
            Vector2::new(3e-6, -2e-6),
            Vector2::new(7e-6, 9e-6),
        ];
        let x: Vec<_> = x0.iter().zip(&u).map(|(a, b)| a + b).collect();
        let g = Gauge::between("g", &[0], &[1, 2], Vector2::new(1.0, 0.0));
        // mean of the second end 5e-6, first end −1e-6; x − x0 carries the round-off of
        // positions up to 2 m, a few 1e-16 m
        let tol = 8.0 * f64::EPSILON * 2.0;
        assert!((g.reading(&x, &x0) - 6e-6).abs() < tol);
        let diag = Vector2::new(1.0, 1.0).normalize();
        let h = Gauge::between("h", &[0], &[2], diag);
        let want = ((7e-6 + 9e-6) - (-1e-6 + 5e-6)) / 2f64.sqrt();
        assert!((h.reading(&x, &x0) - want).abs() < tol);
        let r = readings(&[g, h], &x, &x0);
        assert!(r[1] != 0.0 && r[2..].iter().all(|&v| v == 0.0));
    }
}
