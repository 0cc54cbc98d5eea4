//! The 2D hexagonal close-packed lattice of SPLM (docs/model.md §1): spacing L0, any rotation
//! and offset, clipped to the body. Each particle has six slots, one per lattice
//! direction at 0°, 60°, …, 300° (before rotation); the reverse of slot k is (k+3) mod 6.
//! ΔV = (√3/2)·t·L0².

use super::{Particles, NONE};
use crate::geometry::Shape2;
use nalgebra::{Rotation2, Vector2};
use std::collections::HashMap;

/// Lattice-index steps of the six slots.
const STEPS: [(i64, i64); 6] = [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)];

/// Parameters of a hexagonal lattice.
#[derive(Clone, Copy, Debug)]
pub struct HexLattice {
    pub spacing: f64,
    pub rotation_deg: f64,
    pub offset: Vector2<f64>,
    pub thickness: f64,
}

impl HexLattice {
    /// Lattice vectors a1, a2 after rotation.
    pub fn vectors(&self) -> (Vector2<f64>, Vector2<f64>) {
        let r = Rotation2::new(self.rotation_deg.to_radians());
        let l = self.spacing;
        (
            r * Vector2::new(l, 0.0),
            r * Vector2::new(0.5 * l, 0.5 * 3f64.sqrt() * l),
        )
    }

    /// Area of one lattice cell (m²).
    pub fn cell_area(&self) -> f64 {
        0.5 * 3f64.sqrt() * self.spacing * self.spacing
    }

    /// Particles inside `shape`. Bonds whose midpoint or quarter points leave the body
    /// (across a notch or a re-entrant corner), or that pass through a cutout (a hole, a slit,
    /// across a crack line; [`Shape2::segment_in_body`]) are not made; particles left with no
    /// bond are dropped.
    pub fn fill(&self, shape: &Shape2) -> Particles<2, 6> {
        self.fill_slots(shape)
    }

    /// [`Self::fill`] into K ≥ 6 slots (the six lattice directions first, the rest empty),
    /// for a pipeline that runs the lattice in the slot count of another discretisation.
    pub fn fill_slots<const K: usize>(&self, shape: &Shape2) -> Particles<2, K> {
        const { assert!(K >= 6, "a hexagonal lattice needs six slots") };
        let (a1, a2) = self.vectors();
        // The same lattice with the offset reduced to within a cell of the origin, so that an
        // offset of many cells does not cost the positions their precision.
        let cells = nalgebra::Matrix2::from_columns(&[a1, a2])
            .try_inverse()
            .expect("lattice vectors are independent")
            * self.offset;
        let lattice = HexLattice {
            offset: self.offset - a1 * cells.x.round() - a2 * cells.y.round(),
            ..*self
        };
        lattice.fill_reduced(shape)
    }

    fn fill_reduced<const K: usize>(&self, shape: &Shape2) -> Particles<2, K> {
        let (a1, a2) = self.vectors();
        let (lo, hi) = shape.bounding_box();
        let tol = 1e-9 * shape.size().max(self.spacing);
        // Lattice coordinates of the bounding box corners give the index range.
        let basis = nalgebra::Matrix2::from_columns(&[a1, a2]);
        let inv = basis
            .try_inverse()
            .expect("lattice vectors are independent");
        let (mut imin, mut imax, mut jmin, mut jmax) = (i64::MAX, i64::MIN, i64::MAX, i64::MIN);
        for c in [lo, hi, Vector2::new(lo.x, hi.y), Vector2::new(hi.x, lo.y)] {
            let q = inv * (c - self.offset);
            imin = imin.min(q.x.floor() as i64 - 2);
            imax = imax.max(q.x.ceil() as i64 + 2);
            jmin = jmin.min(q.y.floor() as i64 - 2);
            jmax = jmax.max(q.y.ceil() as i64 + 2);
        }
        let mut index: HashMap<(i64, i64), u32> = HashMap::new();
        let mut coords = Vec::new();
        let mut x0 = Vec::new();
        for j in jmin..=jmax {
            for i in imin..=imax {
                let p = self.offset + a1 * i as f64 + a2 * j as f64;
                if shape.contains(&p, tol) {
                    index.insert((i, j), x0.len() as u32);
                    coords.push((i, j));
                    x0.push(p);
                }
            }
        }
        let n = x0.len();
        let mut neighbours = vec![[NONE; K]; n];
        let mut reverse = vec![[0u8; K]; n];
        let mut l0 = vec![[0.0; K]; n];
        for (p, &(i, j)) in coords.iter().enumerate() {
            for (k, (di, dj)) in STEPS.iter().enumerate() {
                if let Some(&q) = index.get(&(i + di, j + dj)) {
                    // quarter points against the outline, cutouts exactly
                    if shape.segment_in_body(&x0[p], &x0[q as usize], tol, 4) {
                        neighbours[p][k] = q;
                        reverse[p][k] = ((k + 3) % 6) as u8;
                        l0[p][k] = self.spacing;
                    }
                }
            }
        }
        let mut particles = Particles::new(
            x0,
            vec![self.cell_area() * self.thickness; n],
            neighbours,
            reverse,
            l0,
            self.spacing,
        );
        drop_isolated(&mut particles);
        particles
    }
}

/// Remove particles with no bond, renumbering the neighbour slots.
pub(crate) fn drop_isolated<const D: usize, const K: usize>(p: &mut Particles<D, K>) {
    let keep: Vec<bool> = p
        .neighbours
        .iter()
        .map(|s| s.iter().any(|&j| j != NONE))
        .collect();
    if keep.iter().all(|&k| k) {
        return;
    }
    let mut new_index = vec![NONE; p.len()];
    let mut next = 0u32;
    for (i, &k) in keep.iter().enumerate() {
        if k {
            new_index[i] = next;
            next += 1;
        }
    }
    fn retain<T>(v: &mut Vec<T>, keep: &[bool]) {
        let mut it = keep.iter();
        v.retain(|_| *it.next().unwrap());
    }
    retain(&mut p.x0, &keep);
    retain(&mut p.volume, &keep);
    retain(&mut p.reverse, &keep);
    retain(&mut p.l0, &keep);
    retain(&mut p.neighbours, &keep);
    for v in [&mut p.horizon, &mut p.length, &mut p.a, &mut p.b, &mut p.c] {
        retain(v, &keep);
    }
    for slots in p.neighbours.iter_mut() {
        for j in slots.iter_mut() {
            if *j != NONE {
                *j = new_index[*j as usize];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(rot: f64) -> HexLattice {
        HexLattice {
            spacing: 0.01,
            rotation_deg: rot,
            offset: Vector2::zeros(),
            thickness: 0.1,
        }
    }

    #[test]
    fn rectangle_rows_and_bonds() {
        let s = Shape2::Rectangle {
            origin: Vector2::zeros(),
            width: 0.1,
            height: 0.01 * 3f64.sqrt() / 2.0 * 4.0,
        };
        let p = lattice(0.0).fill(&s);
        p.check_topology().unwrap();
        // five rows, alternating 11 and 10 particles (x = 0..0.1 and 0.005..0.095)
        assert_eq!(p.len(), 11 + 10 + 11 + 10 + 11);
        let bulk = (0..p.len()).filter(|&i| p.bond_count(i) == 6).count();
        assert!(bulk > 0);
    }

    #[test]
    fn rotated_lattices_keep_a_consistent_topology_and_density() {
        let s = Shape2::Disc {
            centre: Vector2::new(0.0, 0.0),
            radius: 0.2,
        };
        for rot in [0.0, 7.5, 15.0, 30.0, 45.0] {
            let l = lattice(rot);
            let p = l.fill(&s);
            p.check_topology().unwrap();
            let expected = s.area() / l.cell_area();
            assert!(
                (p.len() as f64 - expected).abs() / expected < 0.02,
                "{rot}: {} vs {expected}",
                p.len()
            );
        }
    }

    #[test]
    fn bonds_do_not_cross_a_notch() {
        let s = Shape2::NotchedBeam {
            length: 0.2,
            depth: 0.05,
            notch_depth: 0.025,
            notch_width: 0.002,
        };
        let l = HexLattice {
            spacing: 0.005,
            rotation_deg: 0.0,
            offset: Vector2::new(0.0025, 0.0),
            thickness: 0.05,
        };
        let p = l.fill(&s);
        p.check_topology().unwrap();
        for i in 0..p.len() {
            for k in 0..6 {
                let j = p.neighbours[i][k];
                if j == NONE {
                    continue;
                }
                let (a, b) = (p.x0[i], p.x0[j as usize]);
                let crosses = (a.x - 0.1) * (b.x - 0.1) < 0.0 && a.y.max(b.y) < 0.025;
                assert!(!crosses, "bond {a:?}-{b:?} crosses the notch");
            }
        }
    }

    #[test]
    fn bonds_do_not_cross_a_hole_or_a_crack_line() {
        use crate::geometry::Cutout;
        let (c, r) = (Vector2::new(0.05, 0.05), 0.012);
        let (a, b) = (Vector2::new(0.07, 0.02), Vector2::new(0.09, 0.09));
        let s = Shape2::WithCutouts {
            outer: Box::new(Shape2::Rectangle {
                origin: Vector2::zeros(),
                width: 0.1,
                height: 0.1,
            }),
            cutouts: vec![
                Cutout::Disc {
                    centre: c,
                    radius: r,
                },
                Cutout::slit(a, b, 0.0),
            ],
        };
        for rot in [0.0, 15.0, 30.0, 45.0] {
            let p = HexLattice {
                spacing: 0.002,
                rotation_deg: rot,
                offset: Vector2::new(0.0003, 0.0007),
                thickness: 0.05,
            }
            .fill(&s);
            p.check_topology().unwrap();
            let cross = |u: Vector2<f64>, v: Vector2<f64>| u.x * v.y - u.y * v.x;
            let mut cut_by_crack = 0;
            for i in 0..p.len() {
                assert!((p.x0[i] - c).norm() >= r * (1.0 - 1e-9));
                for k in 0..6 {
                    let j = p.neighbours[i][k];
                    if j == NONE {
                        continue;
                    }
                    let (x, y) = (p.x0[i], p.x0[j as usize]);
                    // the bond's closest approach to the hole's centre
                    let d = y - x;
                    let t = ((c - x).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
                    assert!(
                        (x + d * t - c).norm() >= r * (1.0 - 1e-9),
                        "{rot}°: {x:?}-{y:?}"
                    );
                    // the crack's two sides, and the bond's two sides
                    let across = cross(b - a, x - a) * cross(b - a, y - a) < 0.0
                        && cross(d, a - x) * cross(d, b - x) < 0.0;
                    assert!(!across, "{rot}°: bond {x:?}-{y:?} crosses the crack");
                }
                // particles just beside the crack miss the bonds across it
                let side = cross(b - a, p.x0[i] - a) / (b - a).norm();
                let along = (p.x0[i] - a).dot(&(b - a)) / (b - a).norm_squared();
                if side.abs() < 0.5 * 0.002 && (0.1..0.9).contains(&along) {
                    cut_by_crack += 6 - p.bond_count(i);
                }
            }
            assert!(cut_by_crack > 0);
        }
    }
}
