//! Voronoi cells of particles in a 3D body, clipped to the body (the 2D treatment of docs/surfaces.md carried to
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
use crate::geometry::solid::Sweep;
use crate::geometry::{Shape2, Shape3};
use nalgebra::{Vector2, Vector3};
use rayon::prelude::*;
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

/// The Voronoi cell volumes of the particles of an FCC body clipped to `shape`: exactly for
/// the box (a convex polyhedron, [`Shape3::planes`]); for a prism and a cylinder, bodies with
/// a section along an axis, by integrating the area of each cell's slices within the section
/// along the axis ([`volume_in_section`]; the sum is within 1e-11 of the body's volume on
/// the test bodies). A particle with its 12 nearest neighbours, farther than the cell's
/// circumradius L0/√2 from the boundary, keeps the full cell without clipping.
pub fn fcc_clipped_volumes(p: &Particles<3, SLOTS>, shape: &Shape3) -> Vec<f64> {
    let l0 = p.spacing;
    let full = FullCell {
        volume: cell_volume(l0),
        circumradius: l0 / 2f64.sqrt() * (1.0 + 1e-9),
        has_nearest: &|i| p.neighbours[i][..SECOND].iter().all(|&j| j != NONE),
    };
    cells(&p.x0, shape, l0, 1e-12 * full.volume, Some(&full))
}

/// The Voronoi cell volumes of any particle set in `shape` (random particles, SPPM in 3D;
/// Nikravesh Kazeroni (2017) (3.53) without its sphere approximation), each cell clipped to the body: exactly by
/// the planes of a box; for a prism or a cylinder by slicing along the axis
/// ([`volume_in_section`]). The cells tile the body, so the volumes sum to its volume (the
/// tests: within 1e-9 on a box, a cylinder and the dog-bone prism). `spacing`: the mean
/// spacing L0, the scale of the cells' first guess of their reach.
pub fn clipped_volumes(x: &[P], shape: &Shape3, spacing: f64) -> Vec<f64> {
    cells(x, shape, spacing, 1e-12 * spacing.powi(3), None)
}

/// The cell a lattice particle has without clipping (the FCC's rhombic dodecahedron), kept by
/// a particle with all its nearest neighbours lying deeper than the circumradius.
struct FullCell<'a> {
    volume: f64,
    circumradius: f64,
    has_nearest: &'a (dyn Fn(usize) -> bool + Sync),
}

/// The clipped cell volumes of particles `x` in `shape` (cells built by
/// [`nearest_first_cell`], reach 2·`spacing`; `tol` for [`volume_in_section`]); particles
/// that keep a `full` cell are not clipped.
fn cells(x: &[P], shape: &Shape3, spacing: f64, tol: f64, full: Option<&FullCell>) -> Vec<f64> {
    let keeps_full = |i: usize, deep: &dyn Fn(f64) -> bool| {
        full.filter(|f| (f.has_nearest)(i) && deep(f.circumradius))
            .map(|f| f.volume)
    };
    match shape.sweep() {
        Some(sweep) => {
            let (section, length) = (&sweep.section, sweep.length);
            let q: Vec<P> = x.iter().map(|x| sweep.local(x)).collect();
            let bounds = sweep_bounds(&sweep);
            let tree = tree_of(&q);
            (0..q.len())
                .into_par_iter()
                .map(|i| {
                    let xy = Vector2::new(q[i].x, q[i].y);
                    let depth = depth_in(section, &xy);
                    let z = q[i].z;
                    if let Some(v) = keeps_full(i, &|rc| z > rc && z < length - rc && depth > rc) {
                        return v;
                    }
                    let cell = nearest_first_cell(&q, i, &tree, &bounds, 2.0 * spacing);
                    volume_within(&cell, xy, depth, section, tol)
                })
                .collect()
        }
        None => {
            let planes = shape.planes().expect("a convex polyhedral body");
            let body = body_polyhedron(shape);
            let tree = tree_of(x);
            (0..x.len())
                .into_par_iter()
                .map(|i| {
                    let inside = |rc: f64| {
                        let d = planes.iter().map(|(n, c)| c - n.dot(&x[i]));
                        d.fold(f64::INFINITY, f64::min) > rc
                    };
                    if let Some(v) = keeps_full(i, &inside) {
                        return v;
                    }
                    nearest_first_cell(x, i, &tree, &body, 2.0 * spacing).volume()
                })
                .collect()
        }
    }
}

/// The Voronoi cell of particle i within the convex `bounds`, clipped by the bisector planes
/// of its neighbours nearest first until the next one lies farther than twice the cell's
/// radius (it cannot cut the cell then). The cell starts as `bounds` cut to a cube of
/// half-width `reach` about the particle, and is built again with twice the reach where it
/// touches that cube (its radius reaches `reach`), so the cube never shapes a cell. The
/// cells of random particles and of FCC bodies alike (an FCC cell beside particles the fill
/// dropped, `fcc::unbond_flat_particles`, reaches farther than L0 and is built again).
fn nearest_first_cell(
    x: &[P],
    i: usize,
    tree: &RTree<GeomWithData<[f64; 3], usize>>,
    bounds: &ConvexPolyhedron,
    reach: f64,
) -> ConvexPolyhedron {
    let xi = x[i];
    let radius_of = |c: &ConvexPolyhedron| {
        c.faces
            .iter()
            .flatten()
            .map(|v| (v - xi).norm_squared())
            .fold(0.0, f64::max)
            .sqrt()
    };
    let mut reach = reach;
    loop {
        let mut cell = bounds.clone();
        for d in 0..3 {
            let e = P::from_fn(|k, _| if k == d { 1.0 } else { 0.0 });
            cell.clip(&e, xi[d] + reach);
            cell.clip(&-e, -(xi[d] - reach));
        }
        // the radius is recomputed only where the last one would let the search stop: clips
        // only shrink the cell, so a stale radius errs on the side of clipping more
        let mut radius = radius_of(&cell);
        let mut since = 0;
        for (o, d2) in tree.nearest_neighbor_iter_with_distance_2(&[xi.x, xi.y, xi.z]) {
            if o.data == i {
                continue;
            }
            if d2 > 4.0 * radius * radius || since >= 8 {
                radius = radius_of(&cell);
                since = 0;
                if d2 > 4.0 * radius * radius {
                    break;
                }
            }
            let d = x[o.data] - xi;
            cell.clip(&d, d.dot(&(xi + d * 0.5)));
            since += 1;
        }
        if radius_of(&cell) < reach * (1.0 - 1e-9) {
            return cell;
        }
        reach *= 2.0;
    }
}

/// The convex polyhedron of a box-shaped body, padded by 1e-3 of its size (the bounds its
/// cells are clipped from).
fn body_polyhedron(shape: &Shape3) -> ConvexPolyhedron {
    let planes = shape.planes().expect("a convex polyhedral body");
    let (lo, hi) = shape.bounding_box();
    let pad = P::repeat(1e-3 * shape.size());
    ConvexPolyhedron::from_planes(&planes, lo - pad, hi + pad)
}

/// The bounds of a swept body's cells in its local coordinates: the section's box, padded,
/// through w ∈ [0, length].
fn sweep_bounds(sweep: &Sweep) -> ConvexPolyhedron {
    let (lo, hi) = sweep.section.bounding_box();
    let pad = 1e-3 * sweep.section.size().max(sweep.length);
    ConvexPolyhedron::cuboid(
        P::new(lo.x - pad, lo.y - pad, 0.0),
        P::new(hi.x + pad, hi.y + pad, sweep.length),
    )
}

/// The volume of `cell` (local coordinates of a swept body) within the section: the cell's
/// own where its projection lies `depth` inside the section (the particle at `xy`), else
/// [`volume_in_section`] to `tol`.
fn volume_within(
    cell: &ConvexPolyhedron,
    xy: Vector2<f64>,
    depth: f64,
    section: &Shape2,
    tol: f64,
) -> f64 {
    let radius_xy = cell
        .faces
        .iter()
        .flatten()
        .map(|v| (Vector2::new(v.x, v.y) - xy).norm())
        .fold(0.0, f64::max);
    if depth > radius_xy * (1.0 + 1e-9) {
        cell.volume()
    } else {
        volume_in_section(cell, section, tol)
    }
}

/// How deep `xy` lies inside the section (0 outside it).
fn depth_in(section: &Shape2, xy: &Vector2<f64>) -> f64 {
    if section.contains(xy, 0.0) {
        section.boundary_distance(xy)
    } else {
        0.0
    }
}

/// An R-tree of points, each with its index.
fn tree_of(x: &[P]) -> RTree<GeomWithData<[f64; 3], usize>> {
    RTree::bulk_load(
        x.iter()
            .enumerate()
            .map(|(i, x)| GeomWithData::new([x.x, x.y, x.z], i))
            .collect(),
    )
}

/// The polygon where the plane at height z cuts a convex polyhedron, projected on (x, y),
/// counter-clockwise (empty where the plane misses it).
pub fn slice(cell: &ConvexPolyhedron, z: f64) -> Vec<Vector2<f64>> {
    let mut pts: Vec<Vector2<f64>> = Vec::new();
    let mut scale: f64 = 0.0;
    for f in &cell.faces {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            scale = scale.max(a.x.abs()).max(a.y.abs());
            if a.z == z {
                pts.push(Vector2::new(a.x, a.y));
            } else if (a.z - z) * (b.z - z) < 0.0 {
                let t = (z - a.z) / (b.z - a.z);
                let q = a + (b - a) * t;
                pts.push(Vector2::new(q.x, q.y));
            }
        }
    }
    if pts.len() < 3 {
        return Vec::new();
    }
    let c = pts.iter().fold(Vector2::zeros(), |s, p| s + p) / pts.len() as f64;
    pts.sort_by(|a, b| {
        (a.y - c.y)
            .atan2(a.x - c.x)
            .total_cmp(&(b.y - c.y).atan2(b.x - c.x))
    });
    let tol = 1e-12 * scale.max(f64::MIN_POSITIVE);
    pts.dedup_by(|a, b| (*a - *b).norm() <= tol);
    while pts.len() > 1 && (pts[0] - pts[pts.len() - 1]).norm() <= tol {
        pts.pop();
    }
    pts
}

/// The volume of a convex polyhedron within the prism `section` × ℝ: ∫ A(z) dz with A(z) the
/// area of its slice within the section (`voronoi::area_in_body`, exact), integrated between
/// consecutive heights of its vertices (where A changes form) by adaptive five-point
/// Gauss–Legendre quadrature to the absolute tolerance `tol`.
pub fn volume_in_section(cell: &ConvexPolyhedron, section: &Shape2, tol: f64) -> f64 {
    let mut zs: Vec<f64> = cell.faces.iter().flatten().map(|v| v.z).collect();
    zs.sort_by(f64::total_cmp);
    let span = zs.last().copied().unwrap_or(0.0) - zs.first().copied().unwrap_or(0.0);
    zs.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * span);
    let area = |z: f64| {
        let s = slice(cell, z);
        if s.len() < 3 {
            0.0
        } else {
            super::voronoi::area_in_body(&s, section)
        }
    };
    let parts = (zs.len().max(2) - 1) as f64;
    zs.windows(2)
        .map(|w| {
            let whole = gauss5(&area, w[0], w[1]);
            adaptive(
                &area,
                (w[0], w[1]),
                whole,
                tol / parts,
                MAX_DEPTH,
                f64::INFINITY,
            )
        })
        .sum()
}

/// Five-point Gauss–Legendre quadrature of f over [a, b] (exact for degree ≤ 9).
fn gauss5(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let s = (10.0f64 / 7.0).sqrt();
    let x1 = (5.0 - 2.0 * s).sqrt() / 3.0;
    let x2 = (5.0 + 2.0 * s).sqrt() / 3.0;
    let r70 = 70.0f64.sqrt();
    let (w0, w1, w2) = (
        128.0 / 225.0,
        (322.0 + 13.0 * r70) / 900.0,
        (322.0 - 13.0 * r70) / 900.0,
    );
    let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
    h * (w0 * f(m) + w1 * (f(m - h * x1) + f(m + h * x1)) + w2 * (f(m - h * x2) + f(m + h * x2)))
}

/// The depth [`adaptive`] starts from: it splits an interval at most this many times.
const MAX_DEPTH: u32 = 40;

/// [`adaptive`] accepts no level before it has split each interval twice (the depth falls
/// from [`MAX_DEPTH`]): the halves of an interval with a kink inside (where a slice's corner
/// crosses the section's outline) can agree with the whole by chance. Measured on the test
/// bodies (`clipped_cells_sum_to_cylinders_and_prisms`), the volumes' sum missed the body's
/// by up to 1.9e-9 accepting any level, 1.3e-9 after one split, 8e-12 after two (2.7 s for
/// the eight bodies), 2e-13 after four (13 s).
const MIN_SPLIT: u32 = MAX_DEPTH - 2;

/// Below this depth (ten splits) [`adaptive`] also accepts a level whose disagreement fell by
/// less than a quarter from its parent's: the error of a smooth integrand falls by about 2^10
/// a split, and of a kink by 4, but rounding in a slice's area (about 1e-7 of it on intervals
/// 1e-13 m wide by a cell's vertex, in a random particle set of the half-notched beam) falls
/// only as the interval, as the tolerance does, and kept every branch splitting to the depth
/// limit: that set's volumes never finished, and now take 4 s.
const STALL_DEPTH: u32 = MAX_DEPTH - 10;

/// [`gauss5`] on halves of [a, b] until the halves agree with the whole to `tol`, or (below
/// [`STALL_DEPTH`]) their disagreement stalls against `parent`'s, the disagreement one level
/// up (∞ at the top).
fn adaptive(
    f: &dyn Fn(f64) -> f64,
    (a, b): (f64, f64),
    whole: f64,
    tol: f64,
    depth: u32,
    parent: f64,
) -> f64 {
    let m = 0.5 * (a + b);
    let (l, r) = (gauss5(f, a, m), gauss5(f, m, b));
    let err = (l + r - whole).abs();
    let stalled = depth < STALL_DEPTH && err > 0.25 * parent;
    if depth == 0 || (depth < MIN_SPLIT && (err <= tol || stalled)) {
        l + r
    } else {
        let half = |x: (f64, f64), w: f64| adaptive(f, x, w, 0.5 * tol, depth - 1, err);
        half((a, m), l) + half((m, b), r)
    }
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
                let v = fcc_clipped_volumes(&p, &shape);
                let total: f64 = v.iter().sum();
                assert_relative_eq!(total, shape.volume(), max_relative = 1e-9);
                // a boundary particle takes the cells of the under-determined particles the
                // fill dropped beside it (`fcc::unbond_flat_particles`): up to 2.76 × the
                // full cell measured on these small rotated bodies
                assert!(v.iter().all(|&x| x > 0.0 && x <= cell_volume(l0) * 4.0));
            }
        }
    }

    /// A cylinder (along z and along a tilted axis) and two prisms (the dog-bone, with arcs;
    /// a notched beam, with a cutout): the clipped cells sum to the body's volume.
    #[test]
    fn clipped_cells_sum_to_cylinders_and_prisms() {
        use crate::geometry::Cutout;
        let l0 = 2e-3;
        let dogbone = Shape2::DogBone { size: 0.02 };
        let beam = Shape2::WithCutouts {
            outer: Box::new(Shape2::Rectangle {
                origin: Vector2::zeros(),
                width: 0.035,
                height: 0.012,
            }),
            cutouts: vec![Cutout::rectangle(
                Vector2::new(0.0165, -0.001),
                0.002,
                0.005,
                0.0,
            )],
        };
        let shapes = [
            Shape3::Cylinder {
                base: P::new(0.001, -0.002, 0.0),
                axis: P::z(),
                radius: 0.009,
                length: 0.013,
            },
            Shape3::Cylinder {
                base: P::zeros(),
                axis: P::new(1.0, 0.4, -0.3).normalize(),
                radius: 0.007,
                length: 0.016,
            },
            Shape3::Extruded {
                section: dogbone,
                thickness: 0.011,
            },
            Shape3::Extruded {
                section: beam,
                thickness: 0.01,
            },
        ];
        for shape in &shapes {
            for (rot, off) in [
                ([0.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
                ([30.0, 20.0, 10.0], [0.37, 0.61, 0.13]),
            ] {
                let p = FccLattice {
                    spacing: l0,
                    rotation_deg: rot,
                    offset: P::from(off) * l0,
                }
                .fill(shape);
                let v = fcc_clipped_volumes(&p, shape);
                let total: f64 = v.iter().sum();
                assert_relative_eq!(total, shape.volume(), max_relative = 1e-9);
                // a boundary particle takes the cells of the under-determined particles the
                // fill dropped beside it (`fcc::unbond_flat_particles`): up to 2.76 × the
                // full cell measured on these small rotated bodies
                assert!(v.iter().all(|&x| x > 0.0 && x <= cell_volume(l0) * 4.0));
            }
        }
    }

    /// The slice of a unit cube at any height is the unit square; of a corner tetrahedron, a
    /// triangle whose area falls as (1 − z)²/2.
    #[test]
    fn slices_of_convex_polyhedra() {
        let cube = ConvexPolyhedron::cuboid(P::zeros(), P::repeat(1.0));
        let s = slice(&cube, 0.3);
        assert_eq!(s.len(), 4);
        assert_relative_eq!(crate::geometry::polygon_area(&s), 1.0, max_relative = 1e-14);
        let mut tet = cube.clone();
        tet.clip(&P::new(1.0, 1.0, 1.0), 1.0);
        for z in [0.1, 0.5, 0.9] {
            let s = slice(&tet, z);
            assert_eq!(s.len(), 3);
            let a = crate::geometry::polygon_area(&s);
            assert_relative_eq!(a, (1.0 - z) * (1.0 - z) / 2.0, max_relative = 1e-12);
        }
        assert!(slice(&tet, 1.5).is_empty());
        // an integrand with rounding of 1e-7 of itself: accurate to that, and finished (the
        // tolerance alone would split every branch to 2^40 intervals)
        let noisy = |z: f64| 1.0 + 1e-7 * ((z * 1e9).sin() * 1e4).fract();
        let whole = gauss5(&noisy, 0.0, 1.0);
        let v = adaptive(&noisy, (0.0, 1.0), whole, 1e-15, MAX_DEPTH, f64::INFINITY);
        assert!((v - 1.0).abs() <= 2e-7, "{v}");
        // the volume within a section that cuts the cube in half along x + y = 1
        let half = Shape2::Polygon {
            vertices: vec![
                Vector2::new(-1.0, -1.0),
                Vector2::new(2.0, -1.0),
                Vector2::new(-1.0, 2.0),
            ],
        };
        assert_relative_eq!(
            volume_in_section(&cube, &half, 1e-14),
            0.5,
            max_relative = 1e-12
        );
    }
}
