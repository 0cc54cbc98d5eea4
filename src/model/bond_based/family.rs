//! The families of a regular cubic grid (docs/bond_based.md, "Families"): each point's
//! neighbours within the horizon δ, with the partial-volume weight of the ones near its edge,
//! the family volumes, and the surface correction of the micromodulus by the volume method
//! (Hobbs 2021, §4.2 and §4.5.1).

/// The part of a neighbour's cell of side Δx inside the horizon: 1 when the neighbour lies
/// within δ − Δx/2, (δ + Δx/2 − ξ)/Δx up to δ, 0 beyond (Hobbs's Eq. 4.2).
pub fn partial_volume(xi: f64, delta: f64, dx: f64) -> f64 {
    if xi <= delta - 0.5 * dx {
        1.0
    } else if xi <= delta {
        (delta + 0.5 * dx - xi) / dx
    } else {
        0.0
    }
}

/// A cubic grid of n[0] × n[1] × n[2] points at spacing Δx, point (i, j, k) at
/// ((i + ½)Δx, (j + ½)Δx, (k + ½)Δx) with index i + n0·(j + n1·k): the centres of the cells
/// of a box of n·Δx.
#[derive(Clone, Copy, Debug)]
pub struct CubicGrid {
    pub n: [usize; 3],
    pub dx: f64,
}

/// The families in compressed rows: point i's neighbours are `neighbour[start[i]..start[i +
/// 1]]`, each with its partial-volume weight.
#[derive(Clone, Debug, Default)]
pub struct Families {
    pub start: Vec<u32>,
    pub neighbour: Vec<u32>,
    pub weight: Vec<f64>,
}

impl CubicGrid {
    pub fn len(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The points' positions, point (i, j, k) at ((i + ½)Δx, (j + ½)Δx, (k + ½)Δx) with
    /// index i + n0·(j + n1·k).
    pub fn points(&self) -> Vec<nalgebra::Vector3<f64>> {
        let [n0, n1, _] = self.n;
        (0..self.len())
            .map(|p| {
                let (i, j, k) = (p % n0, (p / n0) % n1, p / (n0 * n1));
                nalgebra::Vector3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5) * self.dx
            })
            .collect()
    }

    /// The integer offsets within the horizon δ (excluding the point itself), with their
    /// partial-volume weights: the same stencil for every point of the grid.
    pub fn stencil(&self, delta: f64) -> Vec<([i64; 3], f64)> {
        let r = (delta / self.dx).floor() as i64;
        let mut out = Vec::new();
        for c in -r..=r {
            for b in -r..=r {
                for a in -r..=r {
                    if (a, b, c) == (0, 0, 0) {
                        continue;
                    }
                    let xi = self.dx * ((a * a + b * b + c * c) as f64).sqrt();
                    let w = partial_volume(xi, delta, self.dx);
                    if w > 0.0 {
                        out.push(([a, b, c], w));
                    }
                }
            }
        }
        out
    }

    /// The bulk's stiffness under a uniaxial strain against the continuum's, with a
    /// micromodulus calibrated on the sphere (B.2): Σ v_c·n_x⁴·ξ·Δx³ over the stencil against
    /// ∫ n_x⁴·ξ dV = π·δ⁴/5 (docs/bond_based.md, "Families").
    pub fn uniaxial_stiffness_ratio(&self, delta: f64) -> f64 {
        let sum: f64 = self
            .stencil(delta)
            .iter()
            .map(|&([a, b, c], w)| {
                let norm = ((a * a + b * b + c * c) as f64).sqrt();
                let nx = a as f64 / norm;
                w * nx.powi(4) * self.dx * norm
            })
            .sum();
        sum * self.dx.powi(3) / (std::f64::consts::PI * delta.powi(4) / 5.0)
    }

    /// Every point's family: the stencil's offsets that stay inside the grid.
    pub fn families(&self, delta: f64) -> Families {
        let stencil = self.stencil(delta);
        let [n0, n1, n2] = self.n.map(|v| v as i64);
        let mut f = Families {
            start: Vec::with_capacity(self.len() + 1),
            neighbour: Vec::with_capacity(self.len() * stencil.len()),
            weight: Vec::with_capacity(self.len() * stencil.len()),
        };
        f.start.push(0);
        for k in 0..n2 {
            for j in 0..n1 {
                for i in 0..n0 {
                    for &([a, b, c], w) in &stencil {
                        let (p, q, r) = (i + a, j + b, k + c);
                        if (0..n0).contains(&p) && (0..n1).contains(&q) && (0..n2).contains(&r) {
                            f.neighbour.push((p + n0 * (q + n1 * r)) as u32);
                            f.weight.push(w);
                        }
                    }
                    f.start.push(f.neighbour.len() as u32);
                }
            }
        }
        f
    }
}

impl Families {
    /// Each point's family volume Σ_j w_ij·ΔV (ΔV = Δx³ the cell of every point).
    pub fn volumes(&self, cell: f64) -> Vec<f64> {
        self.start
            .windows(2)
            .map(|r| {
                self.weight[r[0] as usize..r[1] as usize]
                    .iter()
                    .sum::<f64>()
                    * cell
            })
            .collect()
    }

    /// The volume method's correction of each bond's micromodulus, λ_ij = 2·V0/(V_i + V_j),
    /// V0 the family volume of a point far from every surface (Hobbs's §4.5.1): a point near
    /// a surface lacks part of its family, so its bonds are stiffened to restore its energy.
    pub fn surface_factors(&self, volumes: &[f64], v0: f64) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.neighbour.len());
        for (i, r) in self.start.windows(2).enumerate() {
            for &j in &self.neighbour[r[0] as usize..r[1] as usize] {
                out.push(2.0 * v0 / (volumes[i] + volumes[j as usize]));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The number of offsets within a radius m of the integer lattice, counted directly.
    fn lattice_points_in_ball(m: f64) -> usize {
        let r = m.floor() as i64;
        let mut count = 0;
        for c in -r..=r {
            for b in -r..=r {
                for a in -r..=r {
                    let d2 = (a * a + b * b + c * c) as f64;
                    if d2 > 0.0 && d2.sqrt() <= m {
                        count += 1;
                    }
                }
            }
        }
        count
    }

    /// The stencil holds every lattice point within δ = m·Δx (122 at m = π). The thesis's
    /// partial volumes count no neighbour beyond δ and only half a cell at δ, so the family
    /// volume falls short of the sphere's 4/3·πδ³ by about the half-cell shell left out,
    /// 4πδ²·(Δx/2)·¼ / (4/3·πδ³) = 3Δx/(8δ): within a factor of two of it at m = π … 2π
    /// (the lattice's own scatter on top).
    #[test]
    fn the_stencil_is_the_ball_and_its_volume_lacks_a_half_cell_shell() {
        let dx = 0.005;
        let grid = CubicGrid { n: [1, 1, 1], dx };
        assert_eq!(grid.stencil(PI * dx).len(), lattice_points_in_ball(PI));
        assert_eq!(grid.stencil(PI * dx).len(), 122);
        for m in [PI, 4.0, 5.0, 6.0, 2.0 * PI] {
            let delta = m * dx;
            let s = grid.stencil(delta);
            assert_eq!(s.len(), lattice_points_in_ball(m));
            let volume: f64 = s.iter().map(|(_, w)| w).sum::<f64>() * dx.powi(3);
            let deficit = 1.0 - volume / (4.0 / 3.0 * PI * delta.powi(3));
            let shell = 3.0 / (8.0 * m);
            assert!(
                deficit > 0.5 * shell && deficit < 2.0 * shell,
                "m = {m}: {deficit} against {shell}"
            );
        }
        // the weight: whole cells to δ − Δx/2, half a cell at δ, nothing beyond
        let (delta, dx) = (0.0157, 0.005);
        assert_eq!(partial_volume(delta - 0.5 * dx, delta, dx), 1.0);
        assert!((partial_volume(delta, delta, dx) - 0.5).abs() < 1e-12);
        assert_eq!(partial_volume(delta * (1.0 + 1e-12), delta, dx), 0.0);
    }

    /// The bond stress at the centre of a box under a homogeneous uniaxial strain ε,
    /// σ = ½·Σ_j c·s_ij·(ξ⊗ξ/|ξ|)·v_c·Δx³ with the exact (nonlinear) stretch of the displaced
    /// points, is the ratio × the continuum's 1.2·E·ε (ν = 1/4) to the strain's own order
    /// (1e-5 at ε = 1e-5). The ratio is the figure docs/bond_based.md quotes: 0.77 at
    /// m = π, 0.93 at m = 6.
    #[test]
    fn the_bond_stress_of_a_uniaxial_strain_is_the_stiffness_ratio() {
        let (dx, e, eps) = (0.005, 37e9, 1e-5);
        for (m, quoted) in [(PI, 0.77), (6.0, 0.93)] {
            let delta = m * dx;
            let grid = CubicGrid { n: [1, 1, 1], dx };
            let c = super::super::micromodulus::micromodulus(
                e,
                delta,
                super::super::micromodulus::Body::Solid,
                super::super::micromodulus::Influence::Constant,
            );
            let mut sxx = 0.0;
            for ([a, b, cc], w) in grid.stencil(delta) {
                let xi = [a as f64 * dx, b as f64 * dx, cc as f64 * dx];
                let len = (xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]).sqrt();
                let y = [xi[0] * (1.0 + eps), xi[1], xi[2]];
                let s = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2]).sqrt() / len - 1.0;
                let f = c * s * w * dx.powi(3) / len;
                sxx += 0.5 * f * xi[0] * xi[0];
            }
            let ratio = grid.uniaxial_stiffness_ratio(delta);
            assert!((ratio - quoted).abs() < 0.005, "m = {m}: {ratio}");
            let want = ratio * 1.2 * e * eps;
            assert!(
                (sxx / want - 1.0).abs() < 2.0 * eps,
                "m = {m}: {sxx} against {want}"
            );
        }
    }

    /// Families of a 13³ box at m = π (a family reaches 3 points each way): symmetric (j in
    /// i's family iff i in j's, with the same weight), full in the interior, smaller at faces,
    /// edges and corners; the surface factors 1 at the centre, whose neighbours all have full
    /// families, above 1 towards the surface and largest at a corner.
    #[test]
    fn families_are_symmetric_and_surface_points_are_stiffened() {
        let dx = 0.005;
        let delta = PI * dx;
        let grid = CubicGrid {
            n: [13, 13, 13],
            dx,
        };
        let f = grid.families(delta);
        let full = grid.stencil(delta).len();
        let of = |i: usize| {
            let r = f.start[i] as usize..f.start[i + 1] as usize;
            f.neighbour[r.clone()]
                .iter()
                .copied()
                .zip(f.weight[r].iter().copied())
        };
        for i in 0..grid.len() {
            for (j, w) in of(i) {
                assert!(of(j as usize).any(|(k, v)| k as usize == i && v == w));
            }
        }
        let index = |i: usize, j: usize, k: usize| i + 13 * (j + 13 * k);
        let centre = index(6, 6, 6);
        assert_eq!(f.start[centre + 1] - f.start[centre], full as u32);
        let v = f.volumes(dx.powi(3));
        let v0 = v[centre];
        let (face, edge, corner) = (v[index(0, 6, 6)], v[index(0, 0, 6)], v[index(0, 0, 0)]);
        assert!(v0 > face && face > edge && edge > corner);
        // a face point has a little more than half its family, a corner a little more than
        // an eighth: the half-space and the octant, plus the layer of points on the planes
        assert!(face / v0 > 0.5 && face / v0 < 0.75, "{}", face / v0);
        assert!(corner / v0 > 0.125 && corner / v0 < 0.35, "{}", corner / v0);
        let lambda = f.surface_factors(&v, v0);
        let at = |i: usize| &lambda[f.start[i] as usize..f.start[i + 1] as usize];
        assert!(at(centre).iter().all(|&l| (l - 1.0).abs() < 1e-12));
        let max_corner = at(index(0, 0, 0)).iter().cloned().fold(0.0, f64::max);
        let max_face = at(index(0, 6, 6)).iter().cloned().fold(0.0, f64::max);
        assert!(max_corner > max_face && max_face > 1.0);
    }
}
