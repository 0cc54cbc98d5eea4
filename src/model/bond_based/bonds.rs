//! The bond forces of a bond-based body (docs/bond_based.md, (B.1)): every bond of every
//! family pulls its two points along the deformed bond with c·λ·s·(1 − d(s_max))·v_c·ΔV,
//! s_max the largest stretch the bond has seen (damage never heals), no damage in
//! compression. The plain scalar form, the reference for faster kernels.

use super::family::{CubicGrid, Families};
use super::softening::Softening;
use nalgebra::Vector3;

/// The bonds of a cubic grid with their stiffnesses and their history.
#[derive(Clone, Debug)]
pub struct Bonds {
    pub families: Families,
    /// Per bond, c·λ·v_c·ΔV: the force density (N/m³) on its point per unit stretch.
    pub stiffness: Vec<f64>,
    pub law: Softening,
    /// Per bond, the largest stretch seen (0 at rest).
    pub s_max: Vec<f64>,
}

impl Bonds {
    /// The bonds of `grid` with horizon δ, micromodulus c and softening `law`; with
    /// `surface_correction`, each bond's micromodulus scaled by the volume method's λ.
    pub fn new(
        grid: &CubicGrid,
        delta: f64,
        c: f64,
        law: Softening,
        surface_correction: bool,
    ) -> Self {
        let families = grid.families(delta);
        let cell = grid.dx.powi(3);
        let lambda = if surface_correction {
            let v = families.volumes(cell);
            let v0 = grid.stencil(delta).iter().map(|(_, w)| w).sum::<f64>() * cell;
            families.surface_factors(&v, v0)
        } else {
            vec![1.0; families.neighbour.len()]
        };
        let stiffness = families
            .weight
            .iter()
            .zip(&lambda)
            .map(|(w, l)| c * l * w * cell)
            .collect();
        let s_max = vec![0.0; families.neighbour.len()];
        Bonds {
            families,
            stiffness,
            law,
            s_max,
        }
    }

    /// The force density on each point (N/m³) at positions `x` (reference `x0`), into `f`;
    /// the bonds' largest stretches are updated.
    pub fn forces(&mut self, x: &[Vector3<f64>], x0: &[Vector3<f64>], f: &mut [Vector3<f64>]) {
        let fam = &self.families;
        for (i, fi) in f.iter_mut().enumerate() {
            let mut sum = Vector3::zeros();
            for b in fam.start[i] as usize..fam.start[i + 1] as usize {
                let j = fam.neighbour[b] as usize;
                let xi = (x0[j] - x0[i]).norm();
                let y = x[j] - x[i];
                let len = y.norm();
                let s = len / xi - 1.0;
                if s > self.s_max[b] {
                    self.s_max[b] = s;
                }
                let d = if s > 0.0 {
                    self.law.damage(self.s_max[b])
                } else {
                    0.0
                };
                sum += y * (self.stiffness[b] * s * (1.0 - d) / len);
            }
            *fi = sum;
        }
    }

    /// The elastic energy (J), ¼·Σ_i Σ_b stiffness·s²·ξ·ΔV over every bond of every point
    /// (each bond counted from both ends): the potential of [`Self::forces`] while no bond
    /// softens (cell = ΔV, the volume of every point).
    pub fn elastic_energy(&self, x: &[Vector3<f64>], x0: &[Vector3<f64>], cell: f64) -> f64 {
        let fam = &self.families;
        let mut e = 0.0;
        for i in 0..x.len() {
            for b in fam.start[i] as usize..fam.start[i + 1] as usize {
                let j = fam.neighbour[b] as usize;
                let xi = (x0[j] - x0[i]).norm();
                let s = (x[j] - x[i]).norm() / xi - 1.0;
                e += 0.25 * self.stiffness[b] * s * s * xi * cell;
            }
        }
        e
    }
}

#[cfg(test)]
mod tests {
    use super::super::micromodulus::{micromodulus, Body, Influence};
    use super::*;
    use std::f64::consts::PI;

    const DX: f64 = 0.005;

    fn body(n: usize, correction: bool) -> (CubicGrid, Bonds, Vec<Vector3<f64>>) {
        let grid = CubicGrid {
            n: [n, n, n],
            dx: DX,
        };
        let delta = PI * DX;
        let c = micromodulus(37e9, delta, Body::Solid, Influence::Constant);
        let law = Softening::Linear { sc: 1e-3 };
        let bonds = Bonds::new(&grid, delta, c, law, correction);
        let x0 = grid.points();
        (grid, bonds, x0)
    }

    fn jiggle(x0: &[Vector3<f64>], a: f64) -> Vec<Vector3<f64>> {
        super::super::test_support::jiggle(x0, a, 12345)
    }

    /// At rest nothing pulls; under a homogeneous strain a point whose family is whole feels
    /// no net force (its stencil is symmetric); for any displacement the forces balance
    /// (action and reaction, equal volumes), with and without the surface correction.
    #[test]
    fn forces_vanish_at_rest_and_in_a_homogeneous_strain_and_balance() {
        for correction in [false, true] {
            let (grid, mut bonds, x0) = body(9, correction);
            let mut f = vec![Vector3::zeros(); grid.len()];
            bonds.forces(&x0, &x0, &mut f);
            assert!(f.iter().all(|v| v.norm() == 0.0));
            let strain =
                nalgebra::Matrix3::new(2e-4, 5e-5, 0.0, 5e-5, -1e-4, 3e-5, 0.0, 3e-5, 1e-4);
            let x: Vec<_> = x0.iter().map(|p| p + strain * p).collect();
            bonds.forces(&x, &x0, &mut f);
            // scale: one bond's force density at this strain
            let scale = bonds.stiffness.iter().cloned().fold(0.0, f64::max) * 2e-4;
            let centre = 4 + 9 * (4 + 9 * 4);
            assert!(f[centre].norm() < 1e-9 * scale, "{}", f[centre].norm());
            let y = jiggle(&x0, 1e-7);
            bonds.forces(&y, &x0, &mut f);
            let total: Vector3<f64> = f.iter().sum();
            let largest = f.iter().map(|v| v.norm()).fold(0.0, f64::max);
            assert!(total.norm() < 1e-10 * largest, "{total}");
        }
    }

    /// The force is the gradient of the elastic energy while no bond softens: the energy's
    /// central difference along one coordinate of one point matches −ΔV·f to 1e-6.
    #[test]
    fn the_force_is_the_gradient_of_the_energy() {
        let (grid, mut bonds, x0) = body(7, true);
        let cell = DX.powi(3);
        let y = jiggle(&x0, 2e-7);
        let mut f = vec![Vector3::zeros(); grid.len()];
        bonds.forces(&y, &x0, &mut f);
        for (p, c) in [
            (0usize, 0usize),
            (3 + 7 * (3 + 7 * 3), 1),
            (grid.len() - 1, 2),
        ] {
            let h = 1e-10;
            let (mut plus, mut minus) = (y.clone(), y.clone());
            plus[p][c] += h;
            minus[p][c] -= h;
            let de = (bonds.elastic_energy(&plus, &x0, cell)
                - bonds.elastic_energy(&minus, &x0, cell))
                / (2.0 * h);
            let want = -cell * f[p][c];
            assert!(
                (de - want).abs() < 1e-6 * want.abs().max(1e-30),
                "point {p}: {de} against {want}"
            );
        }
    }

    /// A bond stretched past s_c stays broken: back at rest and pulled again it carries
    /// nothing; a bond only compressed never breaks.
    #[test]
    fn broken_bonds_stay_broken_and_compression_breaks_nothing() {
        let (grid, mut bonds, x0) = body(5, false);
        let mut f = vec![Vector3::zeros(); grid.len()];
        let squeezed: Vec<_> = x0.iter().map(|p| p * (1.0 - 5e-3)).collect();
        bonds.forces(&squeezed, &x0, &mut f);
        assert!(f.iter().any(|v| v.norm() > 0.0));
        assert!(bonds.s_max.iter().all(|&s| s <= 0.0));
        let pulled: Vec<_> = x0.iter().map(|p| p * (1.0 + 2e-3)).collect();
        bonds.forces(&pulled, &x0, &mut f);
        assert!(
            f.iter().all(|v| v.norm() == 0.0),
            "every bond is past s_c = 1e-3"
        );
        let small: Vec<_> = x0.iter().map(|p| p * (1.0 + 1e-4)).collect();
        bonds.forces(&small, &x0, &mut f);
        assert!(f.iter().all(|v| v.norm() == 0.0));
    }
}
