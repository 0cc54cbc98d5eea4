//! Named particle groups chosen by region (scene `[[groups]] select = {...}`): rows along
//! an edge, the particles under a loading strip, a box, or all particles.

use super::Particles;
use crate::geometry::Shape2;
use crate::scene::{Edge, Selection};
use nalgebra::Vector2;

/// A named set of particle indices (ascending).
#[derive(Clone, Debug)]
pub struct Group {
    pub name: String,
    pub members: Vec<u32>,
}

/// Outward normal and tangent of an edge.
fn edge_frame(edge: Edge) -> (Vector2<f64>, Vector2<f64>) {
    match edge {
        Edge::Top => (Vector2::new(0.0, 1.0), Vector2::new(1.0, 0.0)),
        Edge::Bottom => (Vector2::new(0.0, -1.0), Vector2::new(1.0, 0.0)),
        Edge::Right => (Vector2::new(1.0, 0.0), Vector2::new(0.0, 1.0)),
        Edge::Left => (Vector2::new(-1.0, 0.0), Vector2::new(0.0, 1.0)),
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

/// Select the members of a group. Empty selections are reported by the caller.
pub fn select<const K: usize>(sel: &Selection, p: &Particles<2, K>, shape: &Shape2) -> Vec<u32> {
    let pitch = 0.5 * 3f64.sqrt() * p.spacing;
    let eps = 1e-9 * p.spacing;
    let pick = |f: &dyn Fn(&Vector2<f64>) -> bool| -> Vec<u32> {
        (0..p.len())
            .filter(|&i| f(&p.x0[i]))
            .map(|i| i as u32)
            .collect()
    };
    match sel {
        Selection::All => (0..p.len() as u32).collect(),
        Selection::Nearest { point } => {
            let q = Vector2::new(point[0], point[1]);
            (0..p.len())
                .min_by(|&a, &b| {
                    (p.x0[a] - q)
                        .norm_squared()
                        .total_cmp(&(p.x0[b] - q).norm_squared())
                })
                .map(|i| vec![i as u32])
                .unwrap_or_default()
        }
        Selection::Box { min, max } => pick(&|x| {
            x.x >= min[0] - eps && x.x <= max[0] + eps && x.y >= min[1] - eps && x.y <= max[1] + eps
        }),
        Selection::Edge { edge, rows } => {
            let (n, _) = edge_frame(*edge);
            let hmax =
                p.x0.iter()
                    .map(|x| x.dot(&n))
                    .fold(f64::NEG_INFINITY, f64::max);
            let cut = hmax - (*rows as f64 - 0.5) * pitch;
            pick(&|x| x.dot(&n) >= cut)
        }
        Selection::Strip {
            edge,
            width,
            centre,
            depth,
        } => {
            // a particle is under the strip when it lies within `depth` of the body's own
            // surface at its tangent position (so a curved surface, a disc's, is followed)
            let (n, t) = edge_frame(*edge);
            let half = 0.5 * width + eps;
            let depth = depth.unwrap_or(2.0 * pitch);
            pick(&|x| {
                let s = x.dot(&t);
                (s - centre).abs() <= half
                    && boundary_height(shape, n, t, s).is_some_and(|h| x.dot(&n) >= h - depth)
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::discretise::hex::HexLattice;

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
                centre: 0.0,
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
