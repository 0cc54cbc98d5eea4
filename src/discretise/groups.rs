//! Named particle groups chosen by region (scene `[[groups]] select = {...}`): rows along
//! an edge, the particles under a loading strip, a box, or all particles.

use super::Particles;
use crate::geometry::Shape2;
use crate::scene::{Edge, Selection};
use nalgebra::{SVector, Vector2};

/// A named set of particle indices (ascending).
#[derive(Clone, Debug)]
pub struct Group {
    pub name: String,
    pub members: Vec<u32>,
}

/// Outward normal and tangent of an edge in the plane; `None` for the faces normal to z
/// (3D only; validation refuses them in 2D).
fn edge_frame(edge: Edge) -> Option<(Vector2<f64>, Vector2<f64>)> {
    match edge {
        Edge::Top => Some((Vector2::new(0.0, 1.0), Vector2::new(1.0, 0.0))),
        Edge::Bottom => Some((Vector2::new(0.0, -1.0), Vector2::new(1.0, 0.0))),
        Edge::Right => Some((Vector2::new(1.0, 0.0), Vector2::new(0.0, 1.0))),
        Edge::Left => Some((Vector2::new(-1.0, 0.0), Vector2::new(0.0, 1.0))),
        Edge::Front | Edge::Back => None,
    }
}

/// Height of the body's boundary above the tangent line at tangent coordinate `s`, found by
/// bisection on the shape (for the default depth of a loading strip).
fn boundary_height(shape: &Shape2, n: Vector2<f64>, t: Vector2<f64>, s: f64) -> Option<f64> {
    let (lo, hi) = shape.bounding_box();
    let reach = (hi - lo).norm();
    let centre = (lo + hi) * 0.5;
    let base = centre + t * (s - centre.dot(&t)) - n * centre.dot(&n);
    // scan from outside inwards for the first point inside
    let steps = 4000;
    let h_out = centre.dot(&n) + reach;
    let mut prev = h_out;
    for k in 1..=steps {
        let h = h_out - 2.0 * reach * k as f64 / steps as f64;
        if shape.contains(&(base + n * h), 0.0) {
            let (mut a, mut b) = (h, prev);
            for _ in 0..60 {
                let m = 0.5 * (a + b);
                if shape.contains(&(base + n * m), 0.0) {
                    a = m
                } else {
                    b = m
                }
            }
            return Some(a);
        }
        prev = h;
    }
    None
}

/// Add to `chosen` the `rows` outermost layers facing `n` (at heights x·n ≥ `floor`): layer 1
/// is the particles that have no neighbour in any lattice direction e with e·n > ½ (the
/// directions that point out through the edge), layer k+1 those whose neighbours in those
/// directions all lie in layers ≤ k.
fn peel_layers<const K: usize>(
    p: &Particles<2, K>,
    n: Vector2<f64>,
    rows: u32,
    floor: f64,
    chosen: &mut [bool],
) {
    // the lattice directions, read off a particle with every bond
    let Some(bulk) = (0..p.len()).find(|&i| p.bond_count(i) == K) else {
        return;
    };
    let outward: Vec<Vector2<f64>> = p.neighbours[bulk]
        .iter()
        .map(|&j| (p.x0[j as usize] - p.x0[bulk]).normalize())
        .filter(|e| e.dot(&n) > 0.5 + 1e-9)
        .collect();
    let mut layer = vec![0u32; p.len()]; // 0: not peeled yet
    for k in 1..=rows {
        let next: Vec<usize> = (0..p.len())
            .filter(|&i| layer[i] == 0 && p.x0[i].dot(&n) >= floor)
            .filter(|&i| {
                outward.iter().all(|e| {
                    p.neighbours[i].iter().all(|&j| {
                        j == super::NONE
                            || layer[j as usize] != 0
                            || (p.x0[j as usize] - p.x0[i]).normalize().dot(e) < 0.99
                    })
                })
            })
            .collect();
        for i in next {
            layer[i] = k;
            chosen[i] = true;
        }
    }
}

/// Members of particles whose index is `f`-selected (ascending).
fn pick<const D: usize>(x0: &[SVector<f64, D>], f: &dyn Fn(&SVector<f64, D>) -> bool) -> Vec<u32> {
    (0..x0.len())
        .filter(|&i| f(&x0[i]))
        .map(|i| i as u32)
        .collect()
}

/// The one particle nearest `q` (none in an empty body).
pub fn nearest<const D: usize>(x0: &[SVector<f64, D>], q: &SVector<f64, D>) -> Vec<u32> {
    (0..x0.len())
        .min_by(|&a, &b| {
            (x0[a] - q)
                .norm_squared()
                .total_cmp(&(x0[b] - q).norm_squared())
        })
        .map(|i| vec![i as u32])
        .unwrap_or_default()
}

/// The middle of a strip along its edge's tangent `t`: the scene's `centre`, else the
/// middle of the shape's extent along `t`.
pub fn strip_centre(centre: Option<f64>, t: Vector2<f64>, shape: &Shape2) -> f64 {
    centre.unwrap_or_else(|| {
        let (lo, hi) = shape.bounding_box();
        0.5 * (lo + hi).dot(&t)
    })
}

/// The middle of a strip on `edge` of `shape` (see [`strip_centre`]); `None` for the faces
/// normal to z.
pub fn strip_centre_on(centre: Option<f64>, edge: Edge, shape: &Shape2) -> Option<f64> {
    edge_frame(edge).map(|(_, t)| strip_centre(centre, t, shape))
}

/// Select the members of a group. Empty selections are reported by the caller.
pub fn select<const K: usize>(sel: &Selection, p: &Particles<2, K>, shape: &Shape2) -> Vec<u32> {
    let pitch = 0.5 * 3f64.sqrt() * p.spacing;
    let eps = 1e-9 * p.spacing;
    let pick = |f: &dyn Fn(&Vector2<f64>) -> bool| pick(&p.x0, f);
    match sel {
        Selection::All => (0..p.len() as u32).collect(),
        Selection::Nearest { point } => nearest(&p.x0, &Vector2::new(point[0], point[1])),
        Selection::Box { min, max } => pick(&|x| {
            x.x >= min[0] - eps && x.x <= max[0] + eps && x.y >= min[1] - eps && x.y <= max[1] + eps
        }),
        Selection::Edge { edge, rows } => {
            let Some((n, _)) = edge_frame(*edge) else {
                return Vec::new();
            };
            let hmax =
                p.x0.iter()
                    .map(|x| x.dot(&n))
                    .fold(f64::NEG_INFINITY, f64::max);
            let cut = hmax - (*rows as f64 - 0.5) * pitch;
            let mut chosen: Vec<bool> = p.x0.iter().map(|x| x.dot(&n) >= cut).collect();
            // Rows parallel to the edge exist only where the edge runs along a lattice
            // direction. Elsewhere (a vertical edge of the unrotated lattice: a zigzag of
            // particles L0/2 apart in depth) the depth cut alone takes every other lattice
            // line; peel `rows` layers off the surface as well, so that every lattice line
            // reaching the edge gives its `rows` outermost particles.
            peel_layers(
                p,
                n,
                *rows,
                hmax - (*rows as f64 + 0.5) * p.spacing,
                &mut chosen,
            );
            (0..p.len())
                .filter(|&i| chosen[i])
                .map(|i| i as u32)
                .collect()
        }
        Selection::Strip {
            edge,
            width,
            centre,
            depth,
        } => {
            // a particle is under the strip when it lies within `depth` of the body's own
            // surface at its tangent position (so a curved surface, a disc's, is followed)
            let Some((n, t)) = edge_frame(*edge) else {
                return Vec::new();
            };
            let half = 0.5 * width + eps;
            let depth = depth.unwrap_or(2.0 * pitch);
            let centre = strip_centre(*centre, t, shape);
            pick(&|x| {
                let s = x.dot(&t);
                (s - centre).abs() <= half
                    && boundary_height(shape, n, t, s).is_some_and(|h| x.dot(&n) >= h - depth)
            })
        }
    }
}

/// Select the members of a group of a 3D body (`solid`; `section`: its 2D section where it
/// has one, a prism's or a cylinder's along z). Empty selections are reported by the caller.
///
/// - `edge` takes the faces of the body's bounding box (left/right: x, bottom/top: y,
///   front/back: z): the particles within `rows` lattice-plane pitches L0/√2 of the face
///   (exactly `rows` planes of the unrotated lattice at any offset);
/// - `strip` follows the section as in 2D (a platen of `width` at `centre` along the edge,
///   `depth` below the section's own surface), through the whole length along z: the
///   bearing strips of a split cylinder; a body without a section along z selects nothing;
/// - `box` and `nearest` take three components.
pub fn select_3d<const K: usize>(
    sel: &Selection,
    p: &Particles<3, K>,
    solid: &crate::geometry::Shape3,
    section: Option<&Shape2>,
) -> Vec<u32> {
    use nalgebra::Vector3;
    let pitch = p.spacing / 2f64.sqrt();
    let eps = 1e-9 * p.spacing;
    let pick = |f: &dyn Fn(&Vector3<f64>) -> bool| pick(&p.x0, f);
    let coords = |v: &[f64]| Vector3::new(v[0], v[1], v.get(2).copied().unwrap_or(0.0));
    match sel {
        Selection::All => (0..p.len() as u32).collect(),
        Selection::Nearest { point } => nearest(&p.x0, &coords(point)),
        Selection::Box { min, max } => {
            let (lo, hi) = (coords(min), coords(max));
            pick(&|x| (0..3).all(|d| x[d] >= lo[d] - eps && x[d] <= hi[d] + eps))
        }
        Selection::Edge { edge, rows } => {
            let (lo, hi) = solid.bounding_box();
            let (axis, sign, face) = match edge {
                Edge::Left => (0, -1.0, lo.x),
                Edge::Right => (0, 1.0, hi.x),
                Edge::Bottom => (1, -1.0, lo.y),
                Edge::Top => (1, 1.0, hi.y),
                Edge::Front => (2, -1.0, lo.z),
                Edge::Back => (2, 1.0, hi.z),
            };
            let reach = *rows as f64 * pitch - eps;
            pick(&|x| sign * (face - x[axis]) < reach)
        }
        Selection::Strip {
            edge,
            width,
            centre,
            depth,
        } => {
            let (Some((n, t)), Some(section)) = (edge_frame(*edge), section) else {
                return Vec::new();
            };
            let half = 0.5 * width + eps;
            let depth = depth.unwrap_or(2.0 * pitch);
            let centre = strip_centre(*centre, t, section);
            pick(&|x| {
                let q = Vector2::new(x.x, x.y);
                let s = q.dot(&t);
                (s - centre).abs() <= half
                    && boundary_height(section, n, t, s).is_some_and(|h| q.dot(&n) >= h - depth)
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::discretise::hex::HexLattice;

    #[test]
    fn edge_rows_on_a_vertical_edge_take_one_particle_of_every_lattice_row() {
        // the unrotated lattice's rows are horizontal: along the left and right edges the
        // outermost particles zigzag L0/2 apart; `rows = r` takes r of every row
        let s = Shape2::Rectangle {
            origin: Vector2::zeros(),
            width: 0.1,
            height: 0.05,
        };
        for width in [0.1, 0.1037] {
            let s = match s {
                Shape2::Rectangle { origin, height, .. } => Shape2::Rectangle {
                    origin,
                    width,
                    height,
                },
                _ => unreachable!(),
            };
            let lat = HexLattice {
                spacing: 0.005,
                rotation_deg: 0.0,
                offset: Vector2::zeros(),
                thickness: 0.05,
            };
            let p = lat.fill(&s);
            let mut ys: Vec<i64> = p.x0.iter().map(|x| (x.y / 1e-6).round() as i64).collect();
            ys.sort();
            ys.dedup();
            for edge in [Edge::Left, Edge::Right] {
                for rows in [1u32, 2] {
                    let m = select(&Selection::Edge { edge, rows }, &p, &s);
                    assert_eq!(
                        m.len(),
                        rows as usize * ys.len(),
                        "{edge:?} rows = {rows}, width {width}"
                    );
                    for y in &ys {
                        let in_row = m
                            .iter()
                            .filter(|&&i| (p.x0[i as usize].y / 1e-6).round() as i64 == *y)
                            .count();
                        assert_eq!(
                            in_row, rows as usize,
                            "{edge:?} rows = {rows}, row y = {y} µm"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn edge_rows_pick_whole_rows() {
        let s = Shape2::Rectangle {
            origin: Vector2::zeros(),
            width: 0.1,
            height: 0.1,
        };
        let l = HexLattice {
            spacing: 0.01,
            rotation_deg: 0.0,
            offset: Vector2::zeros(),
            thickness: 0.1,
        };
        let p = l.fill(&s);
        let bottom = select(
            &Selection::Edge {
                edge: Edge::Bottom,
                rows: 2,
            },
            &p,
            &s,
        );
        assert_eq!(bottom.len(), 11 + 10);
        let top = select(
            &Selection::Edge {
                edge: Edge::Top,
                rows: 1,
            },
            &p,
            &s,
        );
        let ymax = p.x0.iter().map(|x| x.y).fold(0.0, f64::max);
        assert!(top
            .iter()
            .all(|&i| (p.x0[i as usize].y - ymax).abs() < 1e-12));
    }

    #[test]
    fn strip_on_a_disc_takes_the_particles_under_the_platen() {
        let s = Shape2::Disc {
            centre: Vector2::zeros(),
            radius: 0.075,
        };
        let l = HexLattice {
            spacing: 0.005,
            rotation_deg: 0.0,
            offset: Vector2::zeros(),
            thickness: 0.3,
        };
        let p = l.fill(&s);
        let g = select(
            &Selection::Strip {
                edge: Edge::Top,
                width: 0.02,
                centre: Some(0.0),
                depth: None,
            },
            &p,
            &s,
        );
        assert!(!g.is_empty());
        for &i in &g {
            let x = p.x0[i as usize];
            assert!(x.x.abs() <= 0.01 + 1e-12 && x.y > 0.06);
        }
        // every column of the strip is represented
        let cols: std::collections::BTreeSet<i64> = g
            .iter()
            .map(|&i| (p.x0[i as usize].x / 0.0025).round() as i64)
            .collect();
        assert!(cols.len() >= 7, "{cols:?}");
    }
}
