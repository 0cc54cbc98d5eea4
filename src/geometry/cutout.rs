//! Cutouts: regions taken out of a body (scene `[[cutouts]]`): circular holes, polygonal
//! holes and notches (rectangles and slits of width w > 0 are polygons), and crack lines
//! (slits of zero width), which remove no area, only the bonds that cross them.
//!
//! A cutout removes its open interior: a point on its edge stays in the body. The bond test
//! [`Cutout::cuts_segment`] is exact (no sampling), so a bond cannot step over a slit however
//! thin.

use super::polygon::{
    clip_by_convex, convex_disc_area, counter_clockwise, cross, disc_disc_area,
    distance_to_polygon, half_planes, is_convex, point_in_polygon, points_box, polygon_area,
    segment_distance, triangulate, Piece,
};
use nalgebra::Vector2;
use std::f64::consts::PI;

type P = Vector2<f64>;

/// A region cut out of a body. Build polygons with [`Cutout::polygon`], [`Cutout::slit`] or
/// [`Cutout::rectangle`], which orient them and split them into convex parts.
#[derive(Clone, Debug, PartialEq)]
pub enum Cutout {
    /// A circular hole.
    Disc { centre: P, radius: f64 },
    /// A polygonal hole or notch: `vertices` counter-clockwise, `parts` convex
    /// counter-clockwise polygons that cover it exactly (the polygon itself when it is
    /// convex, else its triangles).
    Polygon {
        vertices: Vec<P>,
        parts: Vec<Vec<P>>,
    },
    /// A crack line (a slit of zero width) from `start` to `end`: it removes no area, only
    /// the bonds that cross it.
    Line { start: P, end: P },
}

impl Cutout {
    /// A polygonal cutout from vertices in either orientation.
    pub fn polygon(vertices: &[P]) -> Cutout {
        let vertices = counter_clockwise(vertices);
        let parts = if is_convex(&vertices) {
            vec![vertices.clone()]
        } else {
            triangulate(&vertices)
                .into_iter()
                .map(|t| t.to_vec())
                .collect()
        };
        Cutout::Polygon { vertices, parts }
    }

    /// A slit about the segment start–end: the rectangle of `width` centred on it, or the
    /// crack line itself for width 0.
    pub fn slit(start: P, end: P, width: f64) -> Cutout {
        if width <= 0.0 {
            return Cutout::Line { start, end };
        }
        let d = (end - start).normalize();
        let n = P::new(-d.y, d.x) * (0.5 * width);
        Cutout::polygon(&[start - n, end - n, end + n, start + n])
    }

    /// A rectangle of `width` × `height` with its lower-left corner at `origin`, turned by
    /// `rotation_deg` about the origin.
    pub fn rectangle(origin: P, width: f64, height: f64, rotation_deg: f64) -> Cutout {
        let (s, c) = rotation_deg.to_radians().sin_cos();
        let turn = |x: f64, y: f64| origin + P::new(c * x - s * y, s * x + c * y);
        Cutout::polygon(&[
            turn(0.0, 0.0),
            turn(width, 0.0),
            turn(width, height),
            turn(0.0, height),
        ])
    }

    /// Whether the cutout removes area (all but crack lines).
    pub fn removes_area(&self) -> bool {
        !matches!(self, Cutout::Line { .. })
    }

    /// The cutout's own area (m²; 0 for a crack line).
    pub fn area(&self) -> f64 {
        match self {
            Cutout::Disc { radius, .. } => PI * radius * radius,
            Cutout::Polygon { vertices, .. } => polygon_area(vertices),
            Cutout::Line { .. } => 0.0,
        }
    }

    /// Lower-left and upper-right corners of the cutout's box.
    pub fn bounding_box(&self) -> (P, P) {
        match self {
            Cutout::Disc { centre, radius } => {
                (centre - P::repeat(*radius), centre + P::repeat(*radius))
            }
            Cutout::Polygon { vertices, .. } => points_box(vertices),
            Cutout::Line { start, end } => (start.inf(end), start.sup(end)),
        }
    }

    /// How deep `p` lies inside the cutout: its distance to the cutout's edge, positive
    /// inside, negative outside (a crack line: minus the distance to it).
    pub fn depth(&self, p: &P) -> f64 {
        match self {
            Cutout::Disc { centre, radius } => radius - (p - centre).norm(),
            Cutout::Polygon { vertices, .. } => {
                let d = distance_to_polygon(vertices, p);
                if point_in_polygon(vertices, p) {
                    d
                } else {
                    -d
                }
            }
            Cutout::Line { start, end } => -segment_distance(start, end, p),
        }
    }

    /// The cutout's edge as outline pieces, clockwise (the body on their left).
    pub fn boundary(&self) -> Vec<Piece> {
        match self {
            Cutout::Disc { centre, radius } => vec![Piece::Arc(*centre, *radius, 0.0, -2.0 * PI)],
            Cutout::Polygon { vertices: v, .. } => {
                let n = v.len();
                (0..n)
                    .rev()
                    .map(|i| Piece::Segment(v[(i + 1) % n], v[i]))
                    .collect()
            }
            Cutout::Line { start, end } => {
                vec![Piece::Segment(*start, *end), Piece::Segment(*end, *start)]
            }
        }
    }

    /// The cutout as one counter-clockwise polygon (a disc in chords of at most π/128; a crack
    /// line as its two ends), for drawing.
    pub fn drawing_polygon(&self) -> Vec<P> {
        match self {
            Cutout::Disc { centre, radius } => (0..256)
                .map(|k| {
                    let th = 2.0 * PI * k as f64 / 256.0;
                    centre + P::new(th.cos(), th.sin()) * *radius
                })
                .collect(),
            Cutout::Polygon { vertices, .. } => vertices.clone(),
            Cutout::Line { start, end } => vec![*start, *end],
        }
    }

    /// Whether the bond from `a` to `b` passes through the cutout, exactly:
    ///
    /// - a disc: the segment comes closer to the centre than radius − `tol`; except a chord
    ///   no longer than the radius between two particles on the circle (within `tol`), a
    ///   bond along the hole's surface that dips into it by its sagitta only (random
    ///   particles on a hole's outline keep their bonds to their neighbours along it);
    /// - a polygon: the segment meets the open interior deeper than `tol` (separating axes
    ///   for a convex polygon; for a non-convex one, each stretch of the segment between its
    ///   crossings with the edges is tested at its midpoint); a bond along an edge stays;
    /// - a crack line: the bond joins its two sides and crosses it between its ends (by more
    ///   than `tol`). A particle within `tol` of the line counts as on its left side (seen
    ///   from start to end), so the line cuts bonds from there to the right side: a crack
    ///   along a row of particles still separates the rows.
    pub fn cuts_segment(&self, a: &P, b: &P, tol: f64) -> bool {
        match self {
            Cutout::Disc { centre, radius } => {
                if segment_distance(a, b, centre) >= radius - tol {
                    return false;
                }
                let on_circle = |p: &P| ((p - centre).norm() - radius).abs() <= tol;
                !(on_circle(a) && on_circle(b) && (b - a).norm() <= *radius)
            }
            Cutout::Polygon { vertices, parts } => {
                if parts.len() == 1 {
                    segment_meets_convex(a, b, vertices, tol)
                } else {
                    segment_meets_polygon(a, b, vertices, tol)
                }
            }
            Cutout::Line { start, end } => {
                let e = end - start;
                let le = e.norm();
                let side = |p: &P| cross(&e, &(p - start)) / le;
                let (da, db) = (side(a), side(b));
                if (da >= -tol) == (db >= -tol) {
                    return false;
                }
                // where the bond meets the crack's line, measured along the crack
                let t = (da / (da - db)).clamp(0.0, 1.0);
                let q = a + (b - a) * t;
                let u = (q - start).dot(&e) / le;
                u > tol && u < le - tol
            }
        }
    }

    /// Area of the overlap of two cutouts (m²; 0 with a crack line).
    pub fn overlap_area(&self, other: &Cutout) -> f64 {
        match (self, other) {
            (Cutout::Line { .. }, _) | (_, Cutout::Line { .. }) => 0.0,
            (
                Cutout::Disc {
                    centre: c1,
                    radius: r1,
                },
                Cutout::Disc {
                    centre: c2,
                    radius: r2,
                },
            ) => disc_disc_area(c1, *r1, c2, *r2),
            (Cutout::Disc { centre, radius }, Cutout::Polygon { vertices, .. })
            | (Cutout::Polygon { vertices, .. }, Cutout::Disc { centre, radius }) => {
                convex_disc_area(vertices, centre, *radius)
            }
            (Cutout::Polygon { parts: pa, .. }, Cutout::Polygon { parts: pb, .. }) => pa
                .iter()
                .flat_map(|a| pb.iter().map(move |b| polygon_area(&clip_by_convex(a, b))))
                .sum(),
        }
    }
}

/// Whether the segment a–b meets the open interior of a convex counter-clockwise polygon
/// deeper than `tol` (separating axes: the polygon's edge normals and the segment's normal).
fn segment_meets_convex(a: &P, b: &P, convex: &[P], tol: f64) -> bool {
    for (n, c) in half_planes(convex) {
        let l = n.norm();
        if n.dot(a) - c >= -tol * l && n.dot(b) - c >= -tol * l {
            return false;
        }
    }
    let d = b - a;
    let m = P::new(-d.y, d.x) / d.norm();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in convex {
        let s = m.dot(&(v - a));
        lo = lo.min(s);
        hi = hi.max(s);
    }
    !(hi <= tol || lo >= -tol)
}

/// Whether the segment a–b meets the open interior of a simple polygon deeper than `tol`:
/// the segment is cut at every crossing with an edge (and wherever a vertex lies on it), and
/// each stretch between cuts, wholly inside or wholly outside, is tested at its midpoint.
fn segment_meets_polygon(a: &P, b: &P, v: &[P], tol: f64) -> bool {
    let d = b - a;
    let l2 = d.norm_squared();
    let mut ts = vec![0.0, 1.0];
    let n = v.len();
    for i in 0..n {
        let (p, q) = (v[i], v[(i + 1) % n]);
        let e = q - p;
        let den = cross(&d, &e);
        if den != 0.0 {
            let t = cross(&(p - a), &e) / den;
            let s = cross(&(p - a), &d) / den;
            if (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&s) {
                ts.push(t);
            }
        }
        let t = ((p - a).dot(&d) / l2).clamp(0.0, 1.0);
        if (a + d * t - p).norm() <= tol {
            ts.push(t);
        }
    }
    ts.sort_by(f64::total_cmp);
    let depth = |x: &P| {
        let dist = distance_to_polygon(v, x);
        if point_in_polygon(v, x) {
            dist
        } else {
            -dist
        }
    };
    ts.windows(2)
        .filter(|w| w[1] > w[0])
        .any(|w| depth(&(a + d * (0.5 * (w[0] + w[1])))) > tol)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slits_and_rectangles_are_counter_clockwise_polygons() {
        let s = Cutout::slit(P::new(0.0, 0.0), P::new(1.0, 1.0), 0.1);
        assert!((s.area() - 0.1 * 2f64.sqrt()).abs() < 1e-15);
        let r = Cutout::rectangle(P::new(1.0, 1.0), 2.0, 0.5, 30.0);
        assert!((r.area() - 1.0).abs() < 1e-14);
        // clockwise input is turned
        let c = Cutout::polygon(&[P::new(0.0, 0.0), P::new(0.0, 1.0), P::new(1.0, 0.0)]);
        assert!((c.area() - 0.5).abs() < 1e-15);
        assert_eq!(Cutout::slit(P::zeros(), P::new(1.0, 0.0), 0.0).area(), 0.0);
    }

    #[test]
    fn bonds_through_a_hole_are_cut_and_bonds_beside_it_are_not() {
        let h = Cutout::Disc {
            centre: P::zeros(),
            radius: 1.0,
        };
        let tol = 1e-9;
        assert!(h.cuts_segment(&P::new(-2.0, 0.5), &P::new(2.0, 0.5), tol));
        assert!(!h.cuts_segment(&P::new(-2.0, 1.0), &P::new(2.0, 1.0), tol));
        assert!(!h.cuts_segment(&P::new(-2.0, 1.5), &P::new(2.0, 1.5), tol));
        // a short chord between two particles on the circle stays; a long one is cut
        let on = |th: f64| P::new(th.cos(), th.sin());
        assert!(!h.cuts_segment(&on(0.0), &on(0.2), tol));
        assert!(h.cuts_segment(&on(0.0), &on(2.0), tol));
        // a bond into the hole from its edge
        assert!(h.cuts_segment(&on(0.0), &P::new(0.5, 0.0), tol));
    }

    #[test]
    fn a_thin_slit_cuts_every_bond_across_it() {
        let s = Cutout::slit(P::new(0.0, 0.0), P::new(1.0, 0.0), 1e-12);
        let tol = 1e-15;
        assert!(s.cuts_segment(&P::new(0.5, -0.1), &P::new(0.6, 0.1), tol));
        assert!(!s.cuts_segment(&P::new(1.5, -0.1), &P::new(1.6, 0.1), tol));
        assert!(!s.cuts_segment(&P::new(0.2, 0.1), &P::new(0.6, 0.1), tol));
        // along a face
        assert!(!s.cuts_segment(&P::new(0.2, 5e-13), &P::new(0.6, 5e-13), tol));
    }

    #[test]
    fn a_crack_line_cuts_the_bonds_that_cross_it() {
        let c = Cutout::Line {
            start: P::new(0.0, 0.0),
            end: P::new(1.0, 1.0),
        };
        let tol = 1e-12;
        assert!(c.cuts_segment(&P::new(0.6, 0.4), &P::new(0.4, 0.6), tol));
        // beyond the tip
        assert!(!c.cuts_segment(&P::new(1.6, 1.4), &P::new(1.4, 1.6), tol));
        // on one side
        assert!(!c.cuts_segment(&P::new(0.6, 0.4), &P::new(0.9, 0.5), tol));
        // from a particle on the line: it belongs to the left side
        assert!(c.cuts_segment(&P::new(0.5, 0.5), &P::new(0.6, 0.4), tol));
        assert!(!c.cuts_segment(&P::new(0.5, 0.5), &P::new(0.4, 0.6), tol));
    }

    #[test]
    fn bonds_through_a_non_convex_hole() {
        // a U-shaped hole: the bond across the gap of the U passes outside it
        let u = Cutout::polygon(&[
            P::new(0.0, 0.0),
            P::new(3.0, 0.0),
            P::new(3.0, 2.0),
            P::new(2.0, 2.0),
            P::new(2.0, 1.0),
            P::new(1.0, 1.0),
            P::new(1.0, 2.0),
            P::new(0.0, 2.0),
        ]);
        let tol = 1e-12;
        assert!(matches!(&u, Cutout::Polygon { parts, .. } if parts.len() == 6));
        assert!(!u.cuts_segment(&P::new(1.1, 1.5), &P::new(1.9, 1.5), tol));
        assert!(u.cuts_segment(&P::new(-0.5, 1.5), &P::new(1.5, 1.5), tol));
        assert!(u.cuts_segment(&P::new(1.5, 1.5), &P::new(1.5, 0.5), tol));
        // along an edge
        assert!(!u.cuts_segment(&P::new(1.0, 1.0), &P::new(2.0, 1.0), tol));
        assert!((u.area() - 5.0).abs() < 1e-14);
    }

    #[test]
    fn overlap_areas() {
        let d = Cutout::Disc {
            centre: P::zeros(),
            radius: 1.0,
        };
        let sq = Cutout::rectangle(P::new(0.0, -2.0), 2.0, 4.0, 0.0);
        assert!((d.overlap_area(&sq) - 0.5 * PI).abs() < 1e-14);
        let far = Cutout::rectangle(P::new(1.0, -2.0), 2.0, 4.0, 0.0);
        assert!(d.overlap_area(&far).abs() < 1e-15);
        let a = Cutout::rectangle(P::new(0.0, 0.0), 2.0, 2.0, 0.0);
        let b = Cutout::rectangle(P::new(1.0, 0.0), 2.0, 2.0, 0.0);
        assert!((a.overlap_area(&b) - 2.0).abs() < 1e-14);
        // touching along an edge: no overlap
        let c = Cutout::rectangle(P::new(2.0, 0.0), 2.0, 2.0, 0.0);
        assert!(a.overlap_area(&c).abs() < 1e-15);
    }
}
