//! Specimen shapes in 2D and the point-in-shape test used to clip a lattice to the body.
//!
//! Every shape is a closed set: a point on the boundary (within a relative tolerance of
//! 1e-9 of the shape's size) belongs to the body, so a lattice row that lands exactly on an
//! edge is kept. Coordinates are metres.

use nalgebra::Vector2;

/// A 2D specimen shape.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape2 {
    /// Axis-aligned rectangle `[x0, x0+width] × [y0, y0+height]`.
    Rectangle {
        origin: Vector2<f64>,
        width: f64,
        height: f64,
    },
    /// Simple polygon (vertices in order, either orientation).
    Polygon { vertices: Vec<Vector2<f64>> },
    /// Disc (a cylinder's cross-section).
    Disc { centre: Vector2<f64>, radius: f64 },
    /// The van Vliet & van Mier dog-bone of size `d` (VALIDATION.md §D): height 1.5·D, width
    /// D at the ends narrowing to 0.6·D at mid-height along two arcs of radius 0.725·D.
    /// Spans x ∈ [−D/2, D/2], y ∈ [0, 1.5·D].
    DogBone { size: f64 },
    /// Beam `[0, length] × [0, depth]` with a notch of `notch_width` × `notch_depth` cut
    /// upwards from the bottom at mid-span.
    NotchedBeam {
        length: f64,
        depth: f64,
        notch_depth: f64,
        notch_width: f64,
    },
}

impl Shape2 {
    /// Lower-left and upper-right corners of the bounding box.
    pub fn bounding_box(&self) -> (Vector2<f64>, Vector2<f64>) {
        match self {
            Shape2::Rectangle {
                origin,
                width,
                height,
            } => (*origin, origin + Vector2::new(*width, *height)),
            Shape2::Polygon { vertices } => points_box(vertices),
            Shape2::Disc { centre, radius } => (
                centre - Vector2::repeat(*radius),
                centre + Vector2::repeat(*radius),
            ),
            Shape2::DogBone { size } => (
                Vector2::new(-0.5 * size, 0.0),
                Vector2::new(0.5 * size, 1.5 * size),
            ),
            Shape2::NotchedBeam { length, depth, .. } => {
                (Vector2::zeros(), Vector2::new(*length, *depth))
            }
        }
    }

    /// A length that sets the scale of the boundary tolerance.
    pub fn size(&self) -> f64 {
        let (lo, hi) = self.bounding_box();
        (hi - lo).norm()
    }

    /// Area of the shape (m²).
    pub fn area(&self) -> f64 {
        match self {
            Shape2::Rectangle { width, height, .. } => width * height,
            Shape2::Polygon { vertices } => polygon_area(vertices).abs(),
            Shape2::Disc { radius, .. } => std::f64::consts::PI * radius * radius,
            Shape2::DogBone { size } => {
                // Straight ends plus the middle part whose half-width is
                // 1.025·D − sqrt(R² − y²), R = 0.725·D, integrated in closed form.
                let d = *size;
                let r = 0.725 * d;
                let h = 0.5 * d;
                let integral_sqrt = h * (r * r - h * h).sqrt() + r * r * (h / r).asin(); // ∫_{-h}^{h} sqrt(R²−y²) dy
                2.0 * 0.25 * d * d + 2.0 * (1.025 * d * 2.0 * h - integral_sqrt)
            }
            Shape2::NotchedBeam {
                length,
                depth,
                notch_depth,
                notch_width,
            } => length * depth - notch_depth * notch_width,
        }
    }

    /// The body's polygon for shapes bounded by straight edges (counter-clockwise), `None` for the
    /// disc and the dog-bone.
    pub fn polygon(&self) -> Option<Vec<Vector2<f64>>> {
        let mut v = match self {
            Shape2::Rectangle {
                origin,
                width,
                height,
            } => vec![
                *origin,
                origin + Vector2::new(*width, 0.0),
                origin + Vector2::new(*width, *height),
                origin + Vector2::new(0.0, *height),
            ],
            Shape2::Polygon { vertices } => vertices.clone(),
            Shape2::NotchedBeam {
                length,
                depth,
                notch_depth,
                notch_width,
            } => {
                let (l, h, nd, nw) = (*length, *depth, *notch_depth, *notch_width);
                if nd > 0.0 && nw > 0.0 {
                    vec![
                        Vector2::new(0.0, 0.0),
                        Vector2::new(0.5 * (l - nw), 0.0),
                        Vector2::new(0.5 * (l - nw), nd),
                        Vector2::new(0.5 * (l + nw), nd),
                        Vector2::new(0.5 * (l + nw), 0.0),
                        Vector2::new(l, 0.0),
                        Vector2::new(l, h),
                        Vector2::new(0.0, h),
                    ]
                } else {
                    vec![
                        Vector2::new(0.0, 0.0),
                        Vector2::new(l, 0.0),
                        Vector2::new(l, h),
                        Vector2::new(0.0, h),
                    ]
                }
            }
            Shape2::Disc { .. } | Shape2::DogBone { .. } => return None,
        };
        if polygon_area(&v) < 0.0 {
            v.reverse();
        }
        Some(v)
    }

    /// The outline as pieces, counter-clockwise (edges, and the arcs of the disc and the
    /// dog-bone).
    pub fn outline(&self) -> Vec<Piece> {
        use std::f64::consts::PI;
        type P = Vector2<f64>;
        match self {
            Shape2::Disc { centre, radius } => vec![Piece::Arc(*centre, *radius, 0.0, 2.0 * PI)],
            Shape2::DogBone { size } => {
                let d = *size;
                let (r, [cl, cr]) = dogbone_arcs(d);
                let ang = |c: P, p: P| (p.y - c.y).atan2(p.x - c.x);
                let (r0, r1) = (P::new(0.5 * d, 0.25 * d), P::new(0.5 * d, 1.25 * d));
                let (l0, l1) = (P::new(-0.5 * d, 1.25 * d), P::new(-0.5 * d, 0.25 * d));
                // right arc bulges to −x (through angle π about its centre), left to +x (angle 0)
                let (tr0, tr1) = (ang(cr, r0), ang(cr, r1));
                let (tl0, tl1) = (ang(cl, l0), ang(cl, l1));
                vec![
                    Piece::Segment(P::new(-0.5 * d, 0.0), P::new(0.5 * d, 0.0)),
                    Piece::Segment(P::new(0.5 * d, 0.0), r0),
                    Piece::Arc(cr, r, tr0, tr1 - tr0 - 2.0 * PI),
                    Piece::Segment(r1, P::new(0.5 * d, 1.5 * d)),
                    Piece::Segment(P::new(0.5 * d, 1.5 * d), P::new(-0.5 * d, 1.5 * d)),
                    Piece::Segment(P::new(-0.5 * d, 1.5 * d), l0),
                    Piece::Arc(cl, r, tl0, tl1 - tl0),
                    Piece::Segment(l1, P::new(-0.5 * d, 0.0)),
                ]
            }
            _ => {
                let v = self.polygon().expect("straight-edged shape");
                (0..v.len())
                    .map(|i| Piece::Segment(v[i], v[(i + 1) % v.len()]))
                    .collect()
            }
        }
    }

    /// The outline as one polygon, counter-clockwise: the edges' corners, and the arcs in
    /// chords of at most π/128 (a sagitta under 8e-5 of the radius; for drawing).
    pub fn outline_polygon(&self) -> Vec<Vector2<f64>> {
        let mut v = vec![];
        for piece in self.outline() {
            let parts = match piece {
                Piece::Segment(..) => 1,
                Piece::Arc(_, _, _, sweep) => {
                    ((sweep.abs() / (std::f64::consts::PI / 128.0)).ceil() as usize).max(1)
                }
            };
            v.extend((0..parts).map(|k| piece.at(k as f64 / parts as f64)));
        }
        v
    }

    /// Whether `p` lies in the closed shape (boundary included within `tol`).
    pub fn contains(&self, p: &Vector2<f64>, tol: f64) -> bool {
        match self {
            Shape2::Rectangle {
                origin,
                width,
                height,
            } => {
                let q = p - origin;
                q.x >= -tol && q.x <= width + tol && q.y >= -tol && q.y <= height + tol
            }
            Shape2::Polygon { vertices } => {
                point_in_polygon(vertices, p) || distance_to_polygon(vertices, p) <= tol
            }
            Shape2::Disc { centre, radius } => (p - centre).norm() <= radius + tol,
            Shape2::DogBone { size } => {
                let d = *size;
                if p.y < -tol || p.y > 1.5 * d + tol {
                    return false;
                }
                p.x.abs() <= dogbone_half_width(d, p.y) + tol
            }
            Shape2::NotchedBeam {
                length,
                depth,
                notch_depth,
                notch_width,
            } => {
                let inside =
                    p.x >= -tol && p.x <= length + tol && p.y >= -tol && p.y <= depth + tol;
                let in_notch =
                    (p.x - 0.5 * length).abs() < 0.5 * notch_width - tol && p.y < notch_depth - tol;
                inside && !in_notch
            }
        }
    }
}

/// The two arcs that waist the dog-bone of size `d`: their radius 0.725·d and their centres
/// (∓1.025·d, 0.75·d), left then right.
pub fn dogbone_arcs(d: f64) -> (f64, [Vector2<f64>; 2]) {
    (
        0.725 * d,
        [
            Vector2::new(-1.025 * d, 0.75 * d),
            Vector2::new(1.025 * d, 0.75 * d),
        ],
    )
}

/// Half-width of the dog-bone of size `d` at height `y` (0 ≤ y ≤ 1.5·d).
pub fn dogbone_half_width(d: f64, y: f64) -> f64 {
    let (r, [_, c]) = dogbone_arcs(d);
    let dy = y - c.y;
    if dy.abs() >= 0.5 * d {
        0.5 * d
    } else {
        c.x - (r * r - dy * dy).sqrt()
    }
}

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
}

/// Signed area (positive for counter-clockwise vertices).
pub fn polygon_area(v: &[Vector2<f64>]) -> f64 {
    let n = v.len();
    (0..n)
        .map(|i| v[i].x * v[(i + 1) % n].y - v[(i + 1) % n].x * v[i].y)
        .sum::<f64>()
        * 0.5
}

fn point_in_polygon(v: &[Vector2<f64>], p: &Vector2<f64>) -> bool {
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

fn distance_to_polygon(v: &[Vector2<f64>], p: &Vector2<f64>) -> f64 {
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

/// Whether a polygon is not simple: two edges (other than neighbours) cross, touch or
/// overlap, a vertex repeats, or an edge turns straight back along the one before (an
/// outline traversed twice is all of these). Used to refuse such bodies.
pub fn polygon_self_intersects(v: &[Vector2<f64>]) -> bool {
    let n = v.len();
    let size = v
        .iter()
        .flat_map(|p| [p.x.abs(), p.y.abs()])
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    // cross products below this are zero (collinear) to round-off
    let eps = 1e-12 * size * size;
    let cross = |o: Vector2<f64>, a: Vector2<f64>, b: Vector2<f64>| {
        (a - o).x * (b - o).y - (a - o).y * (b - o).x
    };
    let sign = |c: f64| {
        if c > eps {
            1
        } else if c < -eps {
            -1
        } else {
            0
        }
    };
    // q lies on the segment a–b (given that the three are collinear)
    let within = |a: Vector2<f64>, b: Vector2<f64>, q: Vector2<f64>| {
        q.x >= a.x.min(b.x) - eps.sqrt()
            && q.x <= a.x.max(b.x) + eps.sqrt()
            && q.y >= a.y.min(b.y) - eps.sqrt()
            && q.y <= a.y.max(b.y) + eps.sqrt()
    };
    for i in 0..n {
        // a vertex visited twice, or an edge that turns straight back on the one before
        let (a, b, c) = (v[i], v[(i + 1) % n], v[(i + 2) % n]);
        if (b - a).norm() <= eps.sqrt()
            || (sign(cross(a, b, c)) == 0 && (b - a).dot(&(c - b)) < 0.0)
        {
            return true;
        }
        for j in i + 1..n {
            if j == i + 1 || (i == 0 && j == n - 1) {
                continue;
            }
            let (p1, p2, q1, q2) = (v[i], v[(i + 1) % n], v[j], v[(j + 1) % n]);
            let d1 = sign(cross(q1, q2, p1));
            let d2 = sign(cross(q1, q2, p2));
            let d3 = sign(cross(p1, p2, q1));
            let d4 = sign(cross(p1, p2, q2));
            // a proper crossing, or two edges that touch or overlap
            if (d1 * d2 < 0 && d3 * d4 < 0)
                || (d1 == 0 && within(q1, q2, p1))
                || (d2 == 0 && within(q1, q2, p2))
                || (d3 == 0 && within(p1, p2, q1))
                || (d4 == 0 && within(p1, p2, q2))
            {
                return true;
            }
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygons_that_cross_touch_or_retrace_themselves_are_not_simple() {
        let p = |v: &[[f64; 2]]| -> Vec<Vector2<f64>> {
            v.iter().map(|a| Vector2::new(a[0], a[1])).collect()
        };
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert!(!polygon_self_intersects(&p(&square)));
        let l_shape = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ];
        assert!(!polygon_self_intersects(&p(&l_shape)));
        // the square's outline traversed twice
        let twice: Vec<[f64; 2]> = square.iter().chain(square.iter()).copied().collect();
        assert!(polygon_self_intersects(&p(&twice)));
        // a bow tie (proper crossing)
        assert!(polygon_self_intersects(&p(&[
            [0.0, 0.0],
            [1.0, 1.0],
            [1.0, 0.0],
            [0.0, 1.0]
        ])));
        // a vertex on another edge, and an edge that doubles back
        assert!(polygon_self_intersects(&p(&[
            [0.0, 0.0],
            [2.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0]
        ])));
        assert!(polygon_self_intersects(&p(&[
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 2.0],
            [1.0, 0.0],
            [0.0, 2.0]
        ])));
    }

    #[test]
    fn dogbone_widths_match_the_specification() {
        let d = 0.1;
        assert!((dogbone_half_width(d, 0.0) - 0.05).abs() < 1e-12);
        assert!((dogbone_half_width(d, 0.25 * d) - 0.05).abs() < 1e-12);
        assert!((dogbone_half_width(d, 0.75 * d) - 0.03).abs() < 1e-12);
        // the arc meets the straight end without a step
        assert!((dogbone_half_width(d, 0.2500001 * d) - 0.05).abs() < 1e-8);
    }

    #[test]
    fn dogbone_area_matches_numerical_integration() {
        let d = 0.2;
        let n = 200_000;
        let h = 1.5 * d / n as f64;
        let numeric: f64 = (0..n)
            .map(|i| 2.0 * dogbone_half_width(d, (i as f64 + 0.5) * h) * h)
            .sum();
        let exact = Shape2::DogBone { size: d }.area();
        assert!(
            (numeric - exact).abs() / exact < 1e-8,
            "{numeric} vs {exact}"
        );
    }

    #[test]
    fn polygon_containment_and_area() {
        let sq = vec![
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            Vector2::new(1.0, 1.0),
            Vector2::new(0.0, 1.0),
        ];
        let s = Shape2::Polygon {
            vertices: sq.clone(),
        };
        assert!(s.contains(&Vector2::new(0.5, 0.5), 1e-9));
        assert!(s.contains(&Vector2::new(1.0, 0.5), 1e-9));
        assert!(!s.contains(&Vector2::new(1.1, 0.5), 1e-9));
        assert!((s.area() - 1.0).abs() < 1e-15);
        assert!(!polygon_self_intersects(&sq));
        let bow = vec![sq[0], sq[2], sq[1], sq[3]];
        assert!(polygon_self_intersects(&bow));
    }

    #[test]
    fn notch_is_outside_the_beam() {
        let b = Shape2::NotchedBeam {
            length: 1.0,
            depth: 0.2,
            notch_depth: 0.1,
            notch_width: 0.01,
        };
        assert!(!b.contains(&Vector2::new(0.5, 0.05), 1e-9));
        assert!(b.contains(&Vector2::new(0.5, 0.15), 1e-9));
        assert!(b.contains(&Vector2::new(0.2, 0.05), 1e-9));
    }
}
