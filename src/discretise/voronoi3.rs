//! Voronoi cells of particles in a 3D body, clipped to the body (issue "Surfaces" carried to
//! 3D): the volume ΔV_i of a boundary particle of the FCC lattice is its cell clipped to the
//! body, so the particles carry the body's volume at any rotation and offset.
//!
//! A cell is the body's convex polyhedron clipped by the bisector planes of the particles
//! near it ([`ConvexPolyhedron::clip`]). Bodies: the ones with a convex polyhedral form
//! ([`Shape3::planes`]: the box). A particle whose 12 nearest neighbours are all present and
//! which lies more than the cell's circumradius (L0/√2) inside the body keeps the full
//! rhombic dodecahedron, (√2/2)·L0³, without clipping.

use super::fcc::{cell_volume, SECOND, SLOTS};
use super::{Particles, NONE};
use crate::geometry::Shape3;
use nalgebra::Vector3;
use rstar::{primitives::GeomWithData, RTree};

type P = Vector3<f64>;

/// A convex polyhedron as its faces, each a convex polygon ordered counter-clockwise seen
/// from outside.
#[derive(Clone, Debug)]
pub struct ConvexPolyhedron {
    pub faces: Vec<Vec<P>>,
}

impl ConvexPolyhedron {
    /// The polyhedron {x : n_k·x ≤ c_k for every k}, built by clipping a box that holds it.
    pub fn from_planes(planes: &[(P, f64)], lo: P, hi: P) -> Self {
        let mut p = Self::cuboid(lo, hi);
        for (n, c) in planes {
            p.clip(n, *c);
        }
        p
    }

    /// The axis-aligned box [lo, hi].
    pub fn cuboid(lo: P, hi: P) -> Self {
        let v = |i: usize| {
            P::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        };
        // faces counter-clockwise seen from outside
        let quads = [
            [0, 2, 3, 1], // z = lo
            [4, 5, 7, 6], // z = hi
            [0, 1, 5, 4], // y = lo
            [2, 6, 7, 3], // y = hi
            [0, 4, 6, 2], // x = lo
            [1, 3, 7, 5], // x = hi
        ];
        ConvexPolyhedron {
            faces: quads
                .iter()
                .map(|q| q.iter().map(|&i| v(i)).collect())
                .collect(),
        }
    }

    /// Keep the part with n·x ≤ c. The faces are clipped one by one; the points where their
    /// edges cross the plane close the cut with a new face.
    pub fn clip(&mut self, n: &P, c: f64) {
        let scale = self
            .faces
            .iter()
            .flatten()
            .map(|p| p.norm())
            .fold(0.0f64, f64::max)
            .max(c.abs() / n.norm());
        let tol = 1e-13 * scale * n.norm();
        if self.faces.iter().flatten().all(|p| n.dot(p) - c <= tol) {
            return;
        }
        let mut faces = Vec::with_capacity(self.faces.len() + 1);
        let mut cut: Vec<P> = Vec::new();
        for f in &self.faces {
            let mut out = Vec::with_capacity(f.len() + 1);
            for k in 0..f.len() {
                let (a, b) = (f[k], f[(k + 1) % f.len()]);
                let (da, db) = (n.dot(&a) - c, n.dot(&b) - c);
                if da <= tol {
                    out.push(a);
                    if da.abs() <= tol {
                        cut.push(a);
                    }
                }
                if (da < -tol && db > tol) || (da > tol && db < -tol) {
                    let q = a + (b - a) * (da / (da - db));
                    out.push(q);
                    cut.push(q);
                }
            }
            if out.len() >= 3 {
                faces.push(out);
            }
        }
        if cut.len() >= 3 {
            let centre = cut.iter().fold(P::zeros(), |s, p| s + p) / cut.len() as f64;
            let nu = n.normalize();
            let u = (cut
                .iter()
                .map(|p| p - centre)
                .max_by(|a, b| a.norm().total_cmp(&b.norm()))
                .expect("points"))
            .normalize();
            let v = nu.cross(&u);
            cut.sort_by(|a, b| {
                let (pa, pb) = (a - centre, b - centre);
                pa.dot(&v)
                    .atan2(pa.dot(&u))
                    .total_cmp(&pb.dot(&v).atan2(pb.dot(&u)))
            });
            cut.dedup_by(|a, b| (*a - *b).norm() <= 1e-12 * scale);
            if cut.len() >= 3 {
                faces.push(cut);
            }
        }
        self.faces = faces;
    }

    /// Volume by the divergence theorem over the faces' fans.
    pub fn volume(&self) -> f64 {
        let mut v = 0.0;
        for f in &self.faces {
            for k in 1..f.len().saturating_sub(1) {
                v += f[0].dot(&f[k].cross(&f[k + 1]));
            }
        }
        v / 6.0
    }
}

/// The Voronoi cell volumes of the particles of an FCC body clipped to `shape`; `None` when
/// the shape has no convex polyhedral form ([`Shape3::planes`]).
pub fn fcc_clipped_volumes(p: &Particles<3, SLOTS>, shape: &Shape3) -> Option<Vec<f64>> {
    let planes = shape.planes()?;
    let (lo, hi) = shape.bounding_box();
    let pad = P::repeat(1e-3 * shape.size());
    let body = ConvexPolyhedron::from_planes(&planes, lo - pad, hi + pad);
    let l0 = p.spacing;
    let full = cell_volume(l0);
    let inside = |x: &P| {
        planes
            .iter()
            .map(|(n, c)| c - n.dot(x))
            .fold(f64::INFINITY, f64::min)
    };
    let tree = RTree::bulk_load(
        p.x0.iter()
            .enumerate()
            .map(|(i, x)| GeomWithData::new([x.x, x.y, x.z], i))
            .collect(),
    );
    // a point of the body lies within L0 of a particle, so only particles within 2·L0 (and a
    // margin) of particle i bound its cell
    let reach = 2.5 * l0;
    Some(
        (0..p.len())
            .map(|i| {
                let x = p.x0[i];
                let nearest_all = p.neighbours[i][..SECOND].iter().all(|&j| j != NONE);
                if nearest_all && inside(&x) > l0 / 2f64.sqrt() * (1.0 + 1e-9) {
                    return full;
                }
                let mut cell = body.clone();
                for o in tree.locate_within_distance([x.x, x.y, x.z], reach * reach) {
                    if o.data == i {
                        continue;
                    }
                    let d = p.x0[o.data] - x;
                    let mid = x + d * 0.5;
                    cell.clip(&d, d.dot(&mid));
                }
                cell.volume()
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::discretise::fcc::FccLattice;
    use approx::assert_relative_eq;

    #[test]
    fn clipping_a_cube_gives_the_expected_volumes() {
        let c = ConvexPolyhedron::cuboid(P::zeros(), P::new(1.0, 2.0, 3.0));
        assert_relative_eq!(c.volume(), 6.0, max_relative = 1e-14);
        let mut half = c.clone();
        half.clip(&P::new(0.0, 0.0, 1.0), 1.5);
        assert_relative_eq!(half.volume(), 3.0, max_relative = 1e-14);
        // cut off a corner tetrahedron x + y + z ≥ 2.5 … of the unit cube: volume 1/48
        let mut cube = ConvexPolyhedron::cuboid(P::zeros(), P::repeat(1.0));
        cube.clip(&P::new(1.0, 1.0, 1.0), 2.5);
        assert_relative_eq!(cube.volume(), 1.0 - 1.0 / 48.0, max_relative = 1e-13);
        // a plane that misses leaves it alone
        cube.clip(&P::new(1.0, 0.0, 0.0), 2.0);
        assert_relative_eq!(cube.volume(), 1.0 - 1.0 / 48.0, max_relative = 1e-13);
    }

    #[test]
    fn a_bulk_cell_is_the_rhombic_dodecahedron() {
        let l0 = 1e-3;
        let side = 6.0 * 2f64.sqrt() * l0;
        let shape = Shape3::Box {
            origin: P::zeros(),
            size: P::repeat(side),
        };
        let p = FccLattice {
            spacing: l0,
            rotation_deg: [0.0; 3],
            offset: P::zeros(),
        }
        .fill(&shape);
        // clip the centre particle by its neighbours explicitly
        let c = (0..p.len())
            .find(|&i| (p.x0[i] - P::repeat(0.5 * side)).norm() < 1e-9)
            .unwrap();
        let mut cell = ConvexPolyhedron::cuboid(P::repeat(0.0), P::repeat(side));
        for j in 0..p.len() {
            if j != c {
                let d = p.x0[j] - p.x0[c];
                cell.clip(&d, d.dot(&(p.x0[c] + d * 0.5)));
            }
        }
        assert_relative_eq!(cell.volume(), cell_volume(l0), max_relative = 1e-12);
        assert_eq!(cell.faces.len(), 12);
    }

    #[test]
    fn clipped_cells_sum_to_the_box_at_any_rotation_and_offset() {
        let l0 = 1e-3;
        let size = P::new(7.3, 5.1, 9.7) * l0;
        let shape = Shape3::Box {
            origin: P::new(0.2, -0.4, 0.1) * l0,
            size,
        };
        for rot in [
            [0.0, 0.0, 0.0],
            [15.0, 0.0, 0.0],
            [30.0, 20.0, 10.0],
            [45.0, 35.26, 0.0],
        ] {
            for off in [[0.0, 0.0, 0.0], [0.37, 0.61, 0.13]] {
                let p = FccLattice {
                    spacing: l0,
                    rotation_deg: rot,
                    offset: P::from(off) * l0,
                }
                .fill(&shape);
                let v = fcc_clipped_volumes(&p, &shape).unwrap();
                let total: f64 = v.iter().sum();
                assert_relative_eq!(total, shape.volume(), max_relative = 1e-9);
                assert!(v.iter().all(|&x| x > 0.0 && x <= cell_volume(l0) * 2.5));
            }
        }
    }
}
