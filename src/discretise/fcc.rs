//! The 3D face-centred cubic lattice of SPLM (docs/model.md §1, §3): nearest spacing L0, any
//! rotation (three angles) and offset, clipped to the body. Each particle has 18 slots: the
//! 12 nearest neighbours at L0 (slots 0..12) and the 6 second neighbours at √2·L0 (slots
//! 12..18, [`SECOND`]); the direction of slot k^1 is the opposite of slot k's, so the reverse
//! of slot k is k^1. ΔV = (√2/2)·L0³ ([`cell_volume`]).
//!
//! In the lattice's own frame the sites are (i, j, k)·L0/√2 with i + j + k even (a cube of
//! side √2·L0 with a site at each corner and face centre).

use super::{drop_isolated, Particles, NONE};
use crate::geometry::solid::dyad_voigt;
use crate::geometry::Shape3;
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Slots per FCC particle.
pub const SLOTS: usize = 18;
/// The first second-neighbour slot: slots `SECOND..SLOTS` hold the bonds of modulus a + c.
pub const SECOND: usize = 12;

/// Lattice-frame steps of the 18 slots (units L0/√2), opposite directions in adjacent slots.
pub const STEPS: [[i64; 3]; SLOTS] = [
    [1, 1, 0],
    [-1, -1, 0],
    [1, -1, 0],
    [-1, 1, 0],
    [1, 0, 1],
    [-1, 0, -1],
    [1, 0, -1],
    [-1, 0, 1],
    [0, 1, 1],
    [0, -1, -1],
    [0, 1, -1],
    [0, -1, 1],
    [2, 0, 0],
    [-2, 0, 0],
    [0, 2, 0],
    [0, -2, 0],
    [0, 0, 2],
    [0, 0, -2],
];

/// Volume ΔV = (√2/2)·L0³ of a lattice cell (a rhombic dodecahedron) with nearest spacing
/// L0.
pub fn cell_volume(l0: f64) -> f64 {
    0.5 * 2f64.sqrt() * l0 * l0 * l0
}

/// Parameters of an FCC lattice.
#[derive(Clone, Copy, Debug)]
pub struct FccLattice {
    /// Nearest-neighbour spacing L0 (m).
    pub spacing: f64,
    /// Rotation [α, β, γ] (degrees) about z, y and x: R = Rz(α)·Ry(β)·Rx(γ), applied to the
    /// lattice frame.
    pub rotation_deg: [f64; 3],
    /// Position of the site (0, 0, 0) (m).
    pub offset: Vector3<f64>,
}

/// The rotation of angles [α, β, γ] (degrees) about z, y and x: the FCC lattice's frame, and
/// the frame random 3D particles are drawn in (`random3`).
pub fn rotation_of(deg: [f64; 3]) -> Matrix3<f64> {
    let [a, b, g] = deg.map(f64::to_radians);
    *Rotation3::from_euler_angles(g, b, a).matrix()
}

impl FccLattice {
    /// The rotation R of the lattice frame.
    pub fn rotation(&self) -> Matrix3<f64> {
        rotation_of(self.rotation_deg)
    }

    /// Half the cubic constant: the lattice-frame unit L0/√2 (m).
    fn unit(&self) -> f64 {
        self.spacing / 2f64.sqrt()
    }

    /// Particles inside `shape`, with the full cell ΔV = (√2/2)·L0³ each and no moduli.
    /// Bonds that leave the body ([`Shape3::segment_in_body`]: the prism's section at quarter
    /// points, cutouts exactly) are not made; particles left with no bond are dropped.
    pub fn fill(&self, shape: &Shape3) -> Particles<3, SLOTS> {
        let r = self.rotation();
        let h = self.unit();
        // reduce the offset to within a cubic cell (side 2h) so positions keep precision
        let cells = r.transpose() * self.offset / (2.0 * h);
        let offset = self.offset - r * cells.map(f64::round) * (2.0 * h);
        let (lo, hi) = shape.bounding_box();
        let tol = 1e-9 * shape.size().max(self.spacing);
        let (mut qmin, mut qmax) = ([i64::MAX; 3], [i64::MIN; 3]);
        for c in 0..8 {
            let corner = Vector3::new(
                if c & 1 == 0 { lo.x } else { hi.x },
                if c & 2 == 0 { lo.y } else { hi.y },
                if c & 4 == 0 { lo.z } else { hi.z },
            );
            let q = r.transpose() * (corner - offset) / h;
            for d in 0..3 {
                qmin[d] = qmin[d].min(q[d].floor() as i64 - 1);
                qmax[d] = qmax[d].max(q[d].ceil() as i64 + 1);
            }
        }
        let ext: [usize; 3] = std::array::from_fn(|d| (qmax[d] - qmin[d] + 1) as usize);
        let at = |q: [i64; 3]| -> Option<usize> {
            let mut idx = 0usize;
            for d in (0..3).rev() {
                let o = q[d] - qmin[d];
                if o < 0 || o as usize >= ext[d] {
                    return None;
                }
                idx = idx * ext[d] + o as usize;
            }
            Some(idx)
        };
        let mut index = vec![NONE; ext[0] * ext[1] * ext[2]];
        let mut coords = Vec::new();
        let mut x0 = Vec::new();
        for k in qmin[2]..=qmax[2] {
            for j in qmin[1]..=qmax[1] {
                for i in qmin[0]..=qmax[0] {
                    if (i + j + k).rem_euclid(2) != 0 {
                        continue;
                    }
                    let p = offset + r * Vector3::new(i as f64, j as f64, k as f64) * h;
                    if shape.contains(&p, tol) {
                        index[at([i, j, k]).expect("in range")] = x0.len() as u32;
                        coords.push([i, j, k]);
                        x0.push(p);
                    }
                }
            }
        }
        let n = x0.len();
        let second = 2f64.sqrt() * self.spacing;
        let mut neighbours = vec![[NONE; SLOTS]; n];
        let mut reverse = vec![[0u8; SLOTS]; n];
        let mut l0 = vec![[0.0; SLOTS]; n];
        for (p, q) in coords.iter().enumerate() {
            for (k, s) in STEPS.iter().enumerate() {
                let Some(o) = at([q[0] + s[0], q[1] + s[1], q[2] + s[2]]) else {
                    continue;
                };
                let m = index[o];
                if m == NONE || !shape.segment_in_body(&x0[p], &x0[m as usize], tol, 4) {
                    continue;
                }
                neighbours[p][k] = m;
                reverse[p][k] = (k ^ 1) as u8;
                l0[p][k] = if k < SECOND { self.spacing } else { second };
            }
        }
        unbond_flat_particles(&x0, &mut neighbours, &reverse);
        let mut particles = Particles::new(
            x0,
            vec![cell_volume(self.spacing); n],
            neighbours,
            reverse,
            l0,
            self.spacing,
        );
        // θ_i = Σ_m (L0,im/ℓ_i)·S_im: conservative with bonds of two lengths (docs/fcc.md);
        // ℓ_i = L0 for every particle (the lattice's own length scale, also where a surface
        // particle keeps only second neighbours), so the weights are the same in every row
        particles.weighted_dilatation = true;
        particles.length = vec![self.spacing; particles.len()];
        drop_isolated(&mut particles);
        particles
    }
}

/// Remove every bond of a particle whose bonds do not determine a strain (the least-squares
/// strain of docs/model.md §7 needs six independent bond directions: fewer than six bonds, or all
/// in one plane — a corner or edge particle of a rotated lattice), repeatedly, since its
/// neighbours may lose theirs in turn. With bonds in a plane a particle moves across them
/// without resistance (a zero-stiffness mode: T1 and the static solves fail on it); with
/// fewer than six directions its strain, which the concrete criteria read, is not its
/// neighbourhood's (measured: under a homogeneous stress 2% below the interaction
/// criterion, corner particles with 3–6 bonds read ε_I up to 30% high and initiated).
/// [`drop_isolated`] then removes it, and the clipped cells give its volume to the particles
/// around it.
fn unbond_flat_particles(
    x0: &[Vector3<f64>],
    neighbours: &mut [[u32; SLOTS]],
    reverse: &[[u8; SLOTS]],
) {
    let spans = |i: usize, nb: &[[u32; SLOTS]]| {
        let mut m = nalgebra::Matrix6::zeros();
        for &j in nb[i].iter().filter(|&&j| j != NONE) {
            let p = dyad_voigt(&(x0[j as usize] - x0[i]).normalize());
            m += p * p.transpose();
        }
        // the smallest eigenvalue of Σ p·pᵀ (p the bond's strain projector): 0 where the
        // bonds leave a strain undetermined
        m.symmetric_eigenvalues().min() > 1e-6
    };
    let mut todo: Vec<usize> = (0..x0.len()).collect();
    while !todo.is_empty() {
        let mut next = Vec::new();
        for i in todo {
            if neighbours[i].iter().all(|&j| j == NONE) || spans(i, neighbours) {
                continue;
            }
            for k in 0..SLOTS {
                let j = neighbours[i][k];
                if j != NONE {
                    neighbours[j as usize][reverse[i][k] as usize] = NONE;
                    neighbours[i][k] = NONE;
                    next.push(j as usize);
                }
            }
        }
        next.sort_unstable();
        next.dedup();
        todo = next;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn cube(side: f64) -> Shape3 {
        Shape3::Box {
            origin: Vector3::zeros(),
            size: Vector3::repeat(side),
        }
    }

    #[test]
    fn steps_are_the_twelve_nearest_and_six_second_neighbours_in_opposite_pairs() {
        for (k, s) in STEPS.iter().enumerate() {
            let o = STEPS[k ^ 1];
            assert_eq!([s[0] + o[0], s[1] + o[1], s[2] + o[2]], [0, 0, 0]);
            let len2: i64 = s.iter().map(|v| v * v).sum();
            assert_eq!(len2, if k < SECOND { 2 } else { 4 }, "slot {k}");
            assert_eq!(s.iter().sum::<i64>().rem_euclid(2), 0);
        }
        let mut sorted = STEPS.to_vec();
        sorted.sort();
        sorted.dedup();
        assert_eq!(sorted.len(), SLOTS);
    }

    #[test]
    fn unrotated_cube_has_the_lattice_count_and_bonds() {
        // a cube of 4 cubic cells: (2·4+1)³ sites with i+j+k even = 365
        let l0 = 1e-3;
        let side = 4.0 * 2f64.sqrt() * l0;
        let p = FccLattice {
            spacing: l0,
            rotation_deg: [0.0; 3],
            offset: Vector3::zeros(),
        }
        .fill(&cube(side));
        assert_eq!(p.len(), 365);
        p.check_topology().unwrap();
        // the centre site has all 18 bonds at the right lengths
        let c = (0..p.len())
            .find(|&i| (p.x0[i] - Vector3::repeat(0.5 * side)).norm() < 1e-9)
            .unwrap();
        assert_eq!(p.bond_count(c), 18);
        for k in 0..SLOTS {
            let j = p.neighbours[c][k] as usize;
            let want = if k < SECOND { l0 } else { 2f64.sqrt() * l0 };
            assert_relative_eq!((p.x0[j] - p.x0[c]).norm(), want, max_relative = 1e-12);
            assert_relative_eq!(p.l0[c][k], want, max_relative = 1e-12);
        }
        assert_relative_eq!(p.horizon[c], 2f64.sqrt() * l0, max_relative = 1e-12);
        assert_relative_eq!(p.length[c], l0, max_relative = 1e-12);
    }

    #[test]
    fn any_rotation_fills_the_body_at_the_lattice_density() {
        // particles per volume → 1/ΔV as the body grows; the surface error is O(L0/side)
        let l0 = 1e-3;
        let side = 30.0 * l0;
        for rot in [
            [0.0, 0.0, 0.0],
            [15.0, 0.0, 0.0],
            [30.0, 20.0, 10.0],
            [45.0, 35.26, 0.0],
        ] {
            for off in [[0.0, 0.0, 0.0], [0.37, 0.61, 0.13]] {
                let lat = FccLattice {
                    spacing: l0,
                    rotation_deg: rot,
                    offset: Vector3::from(off) * l0,
                };
                let p = lat.fill(&cube(side));
                p.check_topology().unwrap();
                let ratio = p.len() as f64 * cell_volume(l0) / side.powi(3);
                // a surface layer of at most one plane spacing (≤ L0) on each face: ±6·L0/side
                assert!(
                    (ratio - 1.0).abs() < 6.0 * l0 / side,
                    "{rot:?} {off:?}: {ratio}"
                );
                // interior particles keep all 18 bonds
                let inner = (0..p.len())
                    .filter(|&i| {
                        (0..3).all(|d| p.x0[i][d] > 2.0 * l0 && p.x0[i][d] < side - 2.0 * l0)
                    })
                    .collect::<Vec<_>>();
                assert!(inner.iter().all(|&i| p.bond_count(i) == SLOTS));
                // every bond's length matches its slot
                for i in inner {
                    for k in 0..SLOTS {
                        let j = p.neighbours[i][k] as usize;
                        assert_relative_eq!(
                            (p.x0[j] - p.x0[i]).norm(),
                            p.l0[i][k],
                            max_relative = 1e-9
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_notched_prism_makes_no_bond_across_the_notch() {
        let l0 = 1e-3;
        let section = crate::geometry::Shape2::NotchedBeam {
            length: 30.0 * l0,
            depth: 10.0 * l0,
            notch_depth: 5.0 * l0,
            notch_width: 0.5 * l0,
        };
        let p = FccLattice {
            spacing: l0,
            rotation_deg: [10.0, 20.0, 30.0],
            offset: Vector3::new(0.1, 0.2, 0.3) * l0,
        }
        .fill(&Shape3::Extruded {
            section,
            thickness: 5.0 * l0,
        });
        let mid = 15.0 * l0;
        let mut crossing = 0;
        for i in 0..p.len() {
            for &j in p.neighbours[i].iter().filter(|&&j| j != NONE) {
                let (a, b) = (p.x0[i], p.x0[j as usize]);
                if (a.x - mid) * (b.x - mid) < 0.0 {
                    let t = (mid - a.x) / (b.x - a.x);
                    let y = a.y + t * (b.y - a.y);
                    assert!(y > 5.0 * l0 - 1e-12, "a bond crosses the notch at y = {y}");
                    crossing += 1;
                }
            }
        }
        assert!(crossing > 0, "the ligament above the notch is bonded");
    }
}
