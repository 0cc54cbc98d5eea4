//! Plane primitives the shapes are built from: outline pieces (segments and arcs), polygon
//! area and containment, half-plane and convex clipping, and the exact area of a polygon
//! within a disc. Nothing here knows a specimen; `Shape2` and `Cutout` are made of these.

use nalgebra::Vector2;
use std::f64::consts::PI;

type P = Vector2<f64>;

/// Lower-left and upper-right corners of the box of a point set (infinite for no points).
pub fn points_box<'a>(
    points: impl IntoIterator<Item = &'a Vector2<f64>>,
) -> (Vector2<f64>, Vector2<f64>) {
    points.into_iter().fold(
        (
            Vector2::repeat(f64::INFINITY),
            Vector2::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    )
}

/// One piece of a body's outline.
#[derive(Clone, Debug, PartialEq)]
pub enum Piece {
    Segment(Vector2<f64>, Vector2<f64>),
    /// Centre, radius, start angle, signed sweep (radians).
    Arc(Vector2<f64>, f64, f64, f64),
}

impl Piece {
    pub fn length(&self) -> f64 {
        match self {
            Piece::Segment(a, b) => (b - a).norm(),
            Piece::Arc(_, r, _, sweep) => r * sweep.abs(),
        }
    }

    /// The point at parameter t ∈ [0, 1] along the piece.
    pub fn at(&self, t: f64) -> Vector2<f64> {
        match self {
            Piece::Segment(a, b) => a + (b - a) * t,
            Piece::Arc(c, r, t0, sweep) => {
                let th = t0 + sweep * t;
                c + Vector2::new(th.cos(), th.sin()) * *r
            }
        }
    }

    /// The part of the piece from parameter t0 to t1.
    pub fn sub(&self, t0: f64, t1: f64) -> Piece {
        match self {
            Piece::Segment(..) => Piece::Segment(self.at(t0), self.at(t1)),
            Piece::Arc(c, r, a0, sweep) => Piece::Arc(*c, *r, a0 + sweep * t0, sweep * (t1 - t0)),
        }
    }

    /// The unit normal to the left of the direction of travel at parameter t (the side the
    /// body lies on, for an outline traversed with the body on its left).
    pub fn left_normal(&self, t: f64) -> Vector2<f64> {
        match self {
            Piece::Segment(a, b) => {
                let d = (b - a).normalize();
                P::new(-d.y, d.x)
            }
            Piece::Arc(_, _, a0, sweep) => {
                let th = a0 + sweep * t;
                // towards the centre on a counter-clockwise arc, away from it on a clockwise one
                P::new(th.cos(), th.sin()) * -sweep.signum()
            }
        }
    }

    /// The parameter t ∈ [0, 1] of a point on the piece's segment line or circle (its
    /// projection; for an arc its angle), `None` where an arc's angle is outside its sweep
    /// by more than `slack` radians.
    pub fn parameter_of(&self, p: &P, slack: f64) -> Option<f64> {
        match self {
            Piece::Segment(a, b) => {
                let d = b - a;
                Some(((p - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0))
            }
            Piece::Arc(c, _, a0, sweep) => {
                let phi = (p.y - c.y).atan2(p.x - c.x);
                let rel = if *sweep >= 0.0 {
                    (phi - a0).rem_euclid(2.0 * PI)
                } else {
                    (a0 - phi).rem_euclid(2.0 * PI)
                };
                let span = sweep.abs();
                if rel <= span + slack {
                    Some((rel / span).min(1.0))
                } else if 2.0 * PI - rel <= slack {
                    Some(0.0)
                } else {
                    None
                }
            }
        }
    }

    /// Distance from `p` to the piece.
    pub fn distance(&self, p: &P) -> f64 {
        match self {
            Piece::Segment(a, b) => segment_distance(a, b, p),
            Piece::Arc(c, r, ..) => match self.parameter_of(p, 0.0) {
                Some(_) if (p - c).norm() > 0.0 => ((p - c).norm() - r).abs(),
                _ => (self.at(0.0) - p).norm().min((self.at(1.0) - p).norm()),
            },
        }
    }

    /// Parameters t ∈ [0, 1] on this piece where it meets `other` (crossings and touching
    /// points), and where an end of `other` lies within `tol` of it: the places an outline
    /// made of both pieces may change from one to the other.
    pub fn meets(&self, other: &Piece, tol: f64) -> Vec<f64> {
        let mut points: Vec<P> = Vec::new();
        match (self, other) {
            (Piece::Segment(a, b), Piece::Segment(c, d)) => {
                let (u, v) = (b - a, d - c);
                let den = cross(&u, &v);
                if den.abs() > 1e-14 * u.norm() * v.norm() {
                    let s = cross(&(c - a), &u) / den;
                    let t = cross(&(c - a), &v) / den;
                    if (-1e-12..=1.0 + 1e-12).contains(&s) && (-1e-12..=1.0 + 1e-12).contains(&t) {
                        points.push(a + u * t);
                    }
                }
            }
            (Piece::Segment(..), Piece::Arc(c, r, ..)) => {
                points.extend(
                    line_circle(self, c, *r)
                        .into_iter()
                        .filter(|q| other.parameter_of(q, 1e-12).is_some()),
                );
            }
            (Piece::Arc(c, r, ..), Piece::Segment(..)) => {
                points.extend(line_circle(other, c, *r));
            }
            (Piece::Arc(c1, r1, ..), Piece::Arc(c2, r2, ..)) => {
                points.extend(
                    circle_circle(c1, *r1, c2, *r2)
                        .into_iter()
                        .filter(|q| other.parameter_of(q, 1e-12).is_some()),
                );
            }
        }
        for end in [other.at(0.0), other.at(1.0)] {
            if self.distance(&end) <= tol {
                points.push(end);
            }
        }
        points
            .iter()
            .filter_map(|q| match self {
                Piece::Segment(..) => {
                    let t = self.parameter_of(q, 0.0)?;
                    ((self.at(t) - q).norm() <= tol.max(1e-12 * self.length())).then_some(t)
                }
                Piece::Arc(..) => self.parameter_of(q, 1e-12),
            })
            .collect()
    }
}

/// Points where the segment piece `seg` meets the circle of centre c and radius r.
fn line_circle(seg: &Piece, c: &P, r: f64) -> Vec<P> {
    let (a, b) = (seg.at(0.0), seg.at(1.0));
    let d = b - a;
    let qa = d.dot(&d);
    if qa == 0.0 {
        return vec![];
    }
    let f = a - c;
    let qb = 2.0 * f.dot(&d);
    let qc = f.dot(&f) - r * r;
    let disc = qb * qb - 4.0 * qa * qc;
    if disc < 0.0 {
        return vec![];
    }
    let sq = disc.sqrt();
    [(-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)]
        .into_iter()
        .filter(|t| (-1e-12..=1.0 + 1e-12).contains(t))
        .map(|t| a + d * t)
        .collect()
}

/// The points two circles share (none, or two, which coincide for touching circles).
fn circle_circle(c1: &P, r1: f64, c2: &P, r2: f64) -> Vec<P> {
    let d = c2 - c1;
    let l = d.norm();
    if l == 0.0 || l > r1 + r2 || l < (r1 - r2).abs() {
        return vec![];
    }
    let a = (r1 * r1 - r2 * r2 + l * l) / (2.0 * l);
    let h = (r1 * r1 - a * a).max(0.0).sqrt();
    let m = c1 + d * (a / l);
    let n = P::new(-d.y, d.x) / l;
    vec![m + n * h, m - n * h]
}

/// z-component of the cross product.
pub fn cross(u: &P, v: &P) -> f64 {
    u.x * v.y - u.y * v.x
}

/// Distance from `p` to the segment a–b.
pub fn segment_distance(a: &P, b: &P, p: &P) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    if l2 == 0.0 {
        return (p - a).norm();
    }
    let t = ((p - a).dot(&ab) / l2).clamp(0.0, 1.0);
    (a + ab * t - p).norm()
}

/// Signed area (positive for counter-clockwise vertices).
pub fn polygon_area(v: &[Vector2<f64>]) -> f64 {
    let n = v.len();
    (0..n)
        .map(|i| v[i].x * v[(i + 1) % n].y - v[(i + 1) % n].x * v[i].y)
        .sum::<f64>()
        * 0.5
}

/// Whether `p` lies inside the polygon (crossing-number test; a point on an edge may fall
/// either way).
pub fn point_in_polygon(v: &[Vector2<f64>], p: &Vector2<f64>) -> bool {
    let n = v.len();
    let mut inside = false;
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (v[i], v[j]);
        if (a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x {
            inside = !inside;
        }
        j = i;
    }
    inside
}

/// Distance from `p` to the polygon's edges.
pub fn distance_to_polygon(v: &[Vector2<f64>], p: &Vector2<f64>) -> f64 {
    let n = v.len();
    (0..n)
        .map(|i| {
            let (a, b) = (v[i], v[(i + 1) % n]);
            let ab = b - a;
            let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            (a + ab * t - p).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The vertices counter-clockwise (reversed if they run clockwise).
pub fn counter_clockwise(v: &[P]) -> Vec<P> {
    let mut v = v.to_vec();
    if polygon_area(&v) < 0.0 {
        v.reverse();
    }
    v
}

/// Whether a simple counter-clockwise polygon is convex (no right turn beyond round-off;
/// collinear vertices allowed).
pub fn is_convex(v: &[P]) -> bool {
    let n = v.len();
    let (lo, hi) = points_box(v.iter());
    let eps = 1e-12 * (hi - lo).norm_squared();
    (0..n).all(|i| cross(&(v[(i + 1) % n] - v[i]), &(v[(i + 2) % n] - v[(i + 1) % n])) >= -eps)
}

/// A simple counter-clockwise polygon as counter-clockwise triangles (ear clipping); the
/// triangles cover it exactly.
pub fn triangulate(v: &[P]) -> Vec<[P; 3]> {
    let mut idx: Vec<usize> = (0..v.len()).collect();
    let mut out = Vec::with_capacity(v.len().saturating_sub(2));
    let (lo, hi) = points_box(v.iter());
    let eps = 1e-12 * (hi - lo).norm_squared();
    while idx.len() > 3 {
        let n = idx.len();
        let ear = (0..n).find(|&k| {
            let (a, b, c) = (v[idx[(k + n - 1) % n]], v[idx[k]], v[idx[(k + 1) % n]]);
            if cross(&(b - a), &(c - b)) <= eps {
                return false;
            }
            // no other vertex inside or on the triangle
            !idx.iter().any(|&m| {
                let q = v[m];
                if q == a || q == b || q == c {
                    return false;
                }
                cross(&(b - a), &(q - a)) >= -eps
                    && cross(&(c - b), &(q - b)) >= -eps
                    && cross(&(a - c), &(q - c)) >= -eps
            })
        });
        // no ear (round-off on a nearly degenerate polygon): drop the flattest vertex
        let k = ear.unwrap_or_else(|| {
            (0..n)
                .min_by(|&i, &j| {
                    let turn = |k: usize| {
                        let (a, b, c) = (v[idx[(k + n - 1) % n]], v[idx[k]], v[idx[(k + 1) % n]]);
                        cross(&(b - a), &(c - b)).abs()
                    };
                    turn(i).total_cmp(&turn(j))
                })
                .unwrap()
        });
        let (a, b, c) = (v[idx[(k + n - 1) % n]], v[idx[k]], v[idx[(k + 1) % n]]);
        if ear.is_some() {
            out.push([a, b, c]);
        }
        idx.remove(k);
    }
    if idx.len() == 3 {
        out.push([v[idx[0]], v[idx[1]], v[idx[2]]]);
    }
    out
}

/// Keep the part of polygon `poly` where n·x ≤ c (Sutherland–Hodgman against one half-plane;
/// `poly` may be non-convex, the clipped area is exact).
pub fn clip_half_plane(poly: &[P], n: &P, c: f64, out: &mut Vec<P>) {
    out.clear();
    let len = poly.len();
    for i in 0..len {
        let (a, b) = (poly[i], poly[(i + 1) % len]);
        let (fa, fb) = (n.dot(&a) - c, n.dot(&b) - c);
        if fa <= 0.0 {
            out.push(a);
        }
        if (fa < 0.0 && fb > 0.0) || (fa > 0.0 && fb < 0.0) {
            let t = fa / (fa - fb);
            out.push(a + (b - a) * t);
        }
    }
}

/// The half-planes n·x ≤ c of a convex polygon with vertices counter-clockwise.
pub fn half_planes(convex: &[P]) -> Vec<(P, f64)> {
    let len = convex.len();
    (0..len)
        .map(|i| {
            let (a, b) = (convex[i], convex[(i + 1) % len]);
            let e = b - a;
            let n = P::new(e.y, -e.x);
            (n, n.dot(&a))
        })
        .collect()
}

/// `poly` (any simple polygon) clipped by a convex polygon (counter-clockwise).
pub fn clip_by_convex(poly: &[P], convex: &[P]) -> Vec<P> {
    let mut cur = poly.to_vec();
    let mut next = Vec::with_capacity(poly.len() + 4);
    for (n, c) in half_planes(convex) {
        clip_half_plane(&cur, &n, c, &mut next);
        std::mem::swap(&mut cur, &mut next);
        if cur.is_empty() {
            break;
        }
    }
    cur
}

/// Area of the intersection of a counter-clockwise polygon with a disc: the sum over the
/// polygon's edges of the signed area of the triangle (centre, a, b) within the disc. Exact
/// for any simple polygon (and for the bridged polygons half-plane clipping leaves), not only
/// convex ones: the sum integrates the polygon's winding number over the disc.
pub fn convex_disc_area(poly: &[P], centre: &P, r: f64) -> f64 {
    let len = poly.len();
    let mut s = 0.0;
    for i in 0..len {
        s += triangle_disc_area(poly[i] - centre, poly[(i + 1) % len] - centre, r);
    }
    s
}

/// Signed area of the triangle (0, a, b) intersected with the disc of radius r about 0.
fn triangle_disc_area(a: P, b: P, r: f64) -> f64 {
    let cross = a.x * b.y - a.y * b.x;
    let (la, lb) = (a.norm(), b.norm());
    if la <= r && lb <= r {
        return 0.5 * cross;
    }
    let sector = |u: P, v: P| {
        let ang = (u.x * v.y - u.y * v.x).atan2(u.dot(&v));
        0.5 * r * r * ang
    };
    // Points of the segment a + t(b − a), t in (0, 1), on the circle.
    let d = b - a;
    let qa = d.dot(&d);
    if qa == 0.0 {
        return 0.0;
    }
    let qb = 2.0 * a.dot(&d);
    let qc = a.dot(&a) - r * r;
    let disc = qb * qb - 4.0 * qa * qc;
    if disc <= 0.0 {
        return sector(a, b);
    }
    let sq = disc.sqrt();
    let t1 = (-qb - sq) / (2.0 * qa);
    let t2 = (-qb + sq) / (2.0 * qa);
    let p1 = a + d * t1.clamp(0.0, 1.0);
    let p2 = a + d * t2.clamp(0.0, 1.0);
    if la <= r {
        // a inside, b outside: triangle to the exit point, then the sector
        0.5 * (a.x * p2.y - a.y * p2.x) + sector(p2, b)
    } else if lb <= r {
        // a outside, b inside
        sector(a, p1) + 0.5 * (p1.x * b.y - p1.y * b.x)
    } else if t1 >= 1.0 || t2 <= 0.0 || t1 >= t2 {
        sector(a, b)
    } else {
        // both outside, the chord p1–p2 inside
        sector(a, p1) + 0.5 * (p1.x * p2.y - p1.y * p2.x) + sector(p2, b)
    }
}

/// Area of the intersection of two discs (the lens).
pub fn disc_disc_area(c1: &P, r1: f64, c2: &P, r2: f64) -> f64 {
    let d = (c2 - c1).norm();
    if d >= r1 + r2 {
        return 0.0;
    }
    if d <= (r1 - r2).abs() {
        return PI * r1.min(r2).powi(2);
    }
    let a1 = ((d * d + r1 * r1 - r2 * r2) / (2.0 * d * r1))
        .clamp(-1.0, 1.0)
        .acos();
    let a2 = ((d * d + r2 * r2 - r1 * r1) / (2.0 * d * r2))
        .clamp(-1.0, 1.0)
        .acos();
    r1 * r1 * (a1 - a1.sin() * a1.cos()) + r2 * r2 * (a2 - a2.sin() * a2.cos())
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn disc_area_of_a_non_convex_polygon() {
        // an L-shape: [0,2]×[0,1] ∪ [0,1]×[1,2], with the unit disc about (1, 1): three
        // quarters of the disc lie in the L
        let l = [
            P::new(0.0, 0.0),
            P::new(2.0, 0.0),
            P::new(2.0, 1.0),
            P::new(1.0, 1.0),
            P::new(1.0, 2.0),
            P::new(0.0, 2.0),
        ];
        assert_relative_eq!(
            convex_disc_area(&l, &P::new(1.0, 1.0), 1.0),
            0.75 * PI,
            max_relative = 1e-14
        );
    }

    #[test]
    fn lens_area() {
        // two unit discs one radius apart: 2π/3 − √3/2
        let want = 2.0 * PI / 3.0 - 0.5 * 3f64.sqrt();
        assert_relative_eq!(
            disc_disc_area(&P::zeros(), 1.0, &P::new(1.0, 0.0), 1.0),
            want,
            max_relative = 1e-14
        );
        assert_eq!(
            disc_disc_area(&P::zeros(), 1.0, &P::new(3.0, 0.0), 1.0),
            0.0
        );
        assert_relative_eq!(
            disc_disc_area(&P::zeros(), 2.0, &P::new(0.5, 0.0), 1.0),
            PI,
            max_relative = 1e-15
        );
    }

    #[test]
    fn triangles_cover_a_non_convex_polygon() {
        let v = [
            P::new(0.0, 0.0),
            P::new(3.0, 0.0),
            P::new(3.0, 2.0),
            P::new(2.0, 0.5),
            P::new(1.0, 2.0),
            P::new(0.5, 1.0),
            P::new(0.0, 2.0),
        ];
        let tri = triangulate(&v);
        assert_eq!(tri.len(), v.len() - 2);
        let sum: f64 = tri.iter().map(|t| polygon_area(t)).sum();
        assert!(tri.iter().all(|t| polygon_area(t) > 0.0));
        assert_relative_eq!(sum, polygon_area(&v), max_relative = 1e-14);
        assert!(!is_convex(&v));
        assert!(tri.iter().all(|t| is_convex(t)));
    }

    #[test]
    fn pieces_meet_where_they_cross() {
        let s = Piece::Segment(P::new(-2.0, 0.5), P::new(2.0, 0.5));
        let circle = Piece::Arc(P::zeros(), 1.0, 0.0, -2.0 * PI);
        let mut t = s.meets(&circle, 1e-12);
        t.sort_by(f64::total_cmp);
        let x = 0.75f64.sqrt();
        assert_eq!(t.len(), 2);
        assert_relative_eq!(s.at(t[0]).x, -x, max_relative = 1e-14);
        assert_relative_eq!(s.at(t[1]).x, x, max_relative = 1e-14);
        // the same points, seen from the (clockwise) circle
        let on_circle: Vec<P> = circle
            .meets(&s, 1e-12)
            .iter()
            .map(|&t| circle.at(t))
            .collect();
        assert_eq!(on_circle.len(), 2);
        for q in on_circle {
            assert!((q.y - 0.5).abs() < 1e-14 && (q.x.abs() - x).abs() < 1e-14);
        }
        // the body lies left of a clockwise hole's circle: outside it
        assert_relative_eq!(circle.left_normal(0.0).x, 1.0);
    }
}
