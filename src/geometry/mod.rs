//! Specimen shapes in 2D and the point-in-shape test used to clip a lattice to the body.
//!
//! Every shape is a closed set: a point on the boundary (within a relative tolerance of
//! 1e-9 of the shape's size) belongs to the body, so a lattice row that lands exactly on an
//! edge is kept. Coordinates are metres.
//!
//! A body may have cutouts (holes, slits, notches, crack lines; [`Cutout`]):
//! [`Shape2::WithCutouts`] is the outer shape less the open interiors of its cutouts.

mod cutout;
pub mod polygon;
pub mod solid;

pub use cutout::Cutout;
pub use polygon::{points_box, polygon_area, Piece};
pub use solid::Shape3;

use nalgebra::Vector2;
use polygon::{clip_by_convex, convex_disc_area, distance_to_polygon, point_in_polygon};
use std::f64::consts::PI;

/// How far (× the body's size) beside an edge [`Shape2::contains`] and [`Shape2::outline`]
/// look for the body's interior, where a point lies on two edges at once (a cutout's and the
/// outline's, or two cutouts'): far above the boundary tolerance (1e-9), far below any
/// feature a spacing resolves.
const PROBE: f64 = 1e-6;

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
    /// The van Vliet & van Mier dog-bone of size `d` (docs/validation.md §D): height 1.5·D, width
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
    /// The outer shape less the open interiors of its cutouts (holes, slits, notches that
    /// cross the outline, crack lines). A point on a cutout's edge belongs to the body, except
    /// where no body lies beside it (the mouth of a notch flush with the outline, an edge two
    /// cutouts share). Made by `Scene::shape` only when the scene has cutouts.
    WithCutouts {
        outer: Box<Shape2>,
        cutouts: Vec<Cutout>,
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
            // the outer's box: cutouts only remove
            Shape2::WithCutouts { outer, .. } => outer.bounding_box(),
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
            // the outer less each cutout's part inside it (exact; see `cutout_area_in`)
            Shape2::WithCutouts { outer, cutouts } => {
                outer.area()
                    - cutouts
                        .iter()
                        .map(|c| cutout_area_in_or_chords(outer, c, None))
                        .sum::<f64>()
            }
        }
    }

    /// The body's polygon for shapes bounded by straight edges (counter-clockwise), `None` for the
    /// disc, the dog-bone and bodies with cutouts.
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
            Shape2::Disc { .. } | Shape2::DogBone { .. } | Shape2::WithCutouts { .. } => {
                return None
            }
        };
        if polygon_area(&v) < 0.0 {
            v.reverse();
        }
        Some(v)
    }

    /// The outline as pieces, counter-clockwise (edges, and the arcs of the disc and the
    /// dog-bone). With cutouts: the body's actual boundary, the body on the pieces' left: the
    /// outer's pieces outside the cutouts (counter-clockwise), then each cutout's pieces
    /// inside the outer (clockwise), split where they meet; a crack line gives its two faces.
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
            Shape2::WithCutouts { .. } => self.tagged_outline().into_iter().map(|t| t.1).collect(),
            _ => {
                let v = self.polygon().expect("straight-edged shape");
                (0..v.len())
                    .map(|i| Piece::Segment(v[i], v[(i + 1) % v.len()]))
                    .collect()
            }
        }
    }

    /// The outline as one polygon, counter-clockwise: the edges' corners, and the arcs in
    /// chords of at most π/128 (a sagitta under 8e-5 of the radius; for drawing). With
    /// cutouts: the outer's outline ([`Self::cutout_outlines`] has the cutouts').
    pub fn outline_polygon(&self) -> Vec<Vector2<f64>> {
        if let Shape2::WithCutouts { outer, .. } = self {
            return outer.outline_polygon();
        }
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
            Shape2::WithCutouts { outer, cutouts } => {
                if !outer.contains(p, tol) {
                    return false;
                }
                let mut edges = 0;
                for c in cutouts {
                    // far from the cutout's box: neither in it nor on its edge
                    let (lo, hi) = c.bounding_box();
                    let m = tol.abs();
                    if p.x < lo.x - m || p.x > hi.x + m || p.y < lo.y - m || p.y > hi.y + m {
                        continue;
                    }
                    let d = c.depth(p);
                    if d > tol {
                        return false;
                    }
                    if c.removes_area() && d >= -tol {
                        edges += 1;
                    }
                }
                if edges == 0 || (edges == 1 && outer.boundary_distance(p) > tol) {
                    return true;
                }
                // on two edges at once: in the body where its interior lies beside p (a
                // notch's corner), not on the mouth of a notch flush with the outline
                let delta = PROBE * self.size();
                (0..8).any(|k| {
                    let th = k as f64 * PI / 4.0;
                    self.interior(&(p + P::new(th.cos(), th.sin()) * delta), 0.25 * delta)
                })
            }
        }
    }

    /// Whether `p` lies in the body at least `margin` from its boundary (crack lines aside).
    fn interior(&self, p: &Vector2<f64>, margin: f64) -> bool {
        match self {
            Shape2::WithCutouts { outer, cutouts } => {
                outer.interior(p, margin)
                    && cutouts
                        .iter()
                        .all(|c| !c.removes_area() || c.depth(p) < -margin)
            }
            _ => self.contains(p, 0.0) && self.boundary_distance(p) > margin,
        }
    }

    /// Distance from `p` to the body's boundary ([`Self::outline`]).
    pub fn boundary_distance(&self, p: &Vector2<f64>) -> f64 {
        self.outline()
            .iter()
            .map(|piece| piece.distance(p))
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether the bond from `a` to `b` stays in the body. The outer shape is tested at
    /// `parts − 1` points along the bond (k/parts, k = 1 … parts − 1: the lattice's quarter
    /// points with 4, seven points for random particles with 8), as a bond is short against
    /// the outline's features; each cutout exactly ([`Cutout::cuts_segment`]), so a bond
    /// cannot step over a hole or a slit, however thin.
    pub fn segment_in_body(
        &self,
        a: &Vector2<f64>,
        b: &Vector2<f64>,
        tol: f64,
        parts: usize,
    ) -> bool {
        let sampled =
            (1..parts).all(|k| self.contains(&(a + (b - a) * (k as f64 / parts as f64)), tol));
        match self {
            Shape2::WithCutouts { cutouts, .. } => {
                let (slo, shi) = (a.inf(b), a.sup(b));
                sampled
                    && !cutouts.iter().any(|c| {
                        let (lo, hi) = c.bounding_box();
                        // boxes apart by more than tol: the bond misses the cutout
                        let apart = slo.x > hi.x + tol
                            || shi.x < lo.x - tol
                            || slo.y > hi.y + tol
                            || shi.y < lo.y - tol;
                        !apart && c.cuts_segment(a, b, tol)
                    })
            }
            _ => sampled,
        }
    }

    /// The cutouts' parts of the body's boundary (the holes, the faces of slits and notches
    /// inside the outer), each piece as a polyline (arcs in chords of at most π/128), for
    /// drawing; empty without cutouts.
    pub fn cutout_outlines(&self) -> Vec<Vec<Vector2<f64>>> {
        if !matches!(self, Shape2::WithCutouts { .. }) {
            return vec![];
        }
        self.tagged_outline()
            .into_iter()
            .filter(|t| t.0.is_some())
            .map(|(_, piece)| {
                let parts = match piece {
                    Piece::Segment(..) => 1,
                    Piece::Arc(_, _, _, sweep) => {
                        ((sweep.abs() / (PI / 128.0)).ceil() as usize).max(1)
                    }
                };
                (0..=parts)
                    .map(|k| piece.at(k as f64 / parts as f64))
                    .collect()
            })
            .collect()
    }

    /// The boundary of a body with cutouts as pieces, each with the cutout it comes from
    /// (`None`: the outer's): every piece of the outer's outline and of the cutouts' edges is
    /// split where it meets the others, and a part is kept where the body lies on its left
    /// (tested a small step beside its midpoint). Crack lines split no other piece.
    fn tagged_outline(&self) -> Vec<(Option<usize>, Piece)> {
        let Shape2::WithCutouts { outer, cutouts } = self else {
            return self.outline().into_iter().map(|p| (None, p)).collect();
        };
        let tol = 1e-9 * self.size();
        let delta = PROBE * self.size();
        let loops: Vec<(Option<usize>, Vec<Piece>)> = std::iter::once((None, outer.outline()))
            .chain(
                cutouts
                    .iter()
                    .enumerate()
                    .map(|(k, c)| (Some(k), c.boundary())),
            )
            .collect();
        let mut out = Vec::new();
        for (li, (tag, pieces)) in loops.iter().enumerate() {
            for piece in pieces {
                let mut ts = vec![0.0, 1.0];
                for (lj, (other, others)) in loops.iter().enumerate() {
                    if lj == li || other.is_some_and(|k| !cutouts[k].removes_area()) {
                        continue;
                    }
                    for q in others {
                        ts.extend(piece.meets(q, tol));
                    }
                }
                ts.sort_by(f64::total_cmp);
                ts.dedup_by(|b, a| *b - *a <= 1e-12);
                if ts.last() != Some(&1.0) {
                    // the last split fell within 1e-12 of the end: end there
                    *ts.last_mut().unwrap() = 1.0;
                }
                for w in ts.windows(2) {
                    let sub = if ts.len() == 2 {
                        piece.clone()
                    } else {
                        piece.sub(w[0], w[1])
                    };
                    let probe = sub.at(0.5) + sub.left_normal(0.5) * delta;
                    if self.interior(&probe, 0.25 * delta) {
                        out.push((*tag, sub));
                    }
                }
            }
        }
        out
    }
}

/// The exact area (m²) of the part of `cutout` inside `outer` and, if given, inside the
/// convex counter-clockwise polygon `cell`; `None` where it has no exact form here: a disc
/// cutout that crosses a curved outline (the disc's or the dog-bone's).
///
/// - Straight-edged outer: a disc wholly inside it is πr² (the cell's part of it,
///   [`convex_disc_area`]), else the outer polygon clipped by the cell, within the disc
///   (the signed triangle sum is exact for any polygon); a polygon cutout, part by convex
///   part: the outer clipped by the part (and then by the cell).
/// - Disc outer: each convex part (clipped by the cell) within the disc.
/// - Dog-bone (its box less two discs): each convex part clipped by the box, less its parts
///   within the two discs.
/// - A disc inside a disc or a dog-bone: πr² (the cell's part of it).
pub fn cutout_area_in(outer: &Shape2, cutout: &Cutout, cell: Option<&[P]>) -> Option<f64> {
    match cutout {
        Cutout::Line { .. } => Some(0.0),
        Cutout::Disc { centre, radius } => {
            let r = *radius;
            let whole = |cell: Option<&[P]>| match cell {
                None => PI * r * r,
                Some(cell) => convex_disc_area(cell, centre, r),
            };
            if let Some(poly) = outer.polygon() {
                let inside =
                    point_in_polygon(&poly, centre) && distance_to_polygon(&poly, centre) >= r;
                return Some(match (inside, cell) {
                    (true, _) => whole(cell),
                    (false, None) => convex_disc_area(&poly, centre, r),
                    (false, Some(cell)) => {
                        convex_disc_area(&clip_by_convex(&poly, cell), centre, r)
                    }
                });
            }
            match outer {
                Shape2::Disc {
                    centre: c0,
                    radius: r0,
                } => ((centre - c0).norm() + r <= *r0).then(|| whole(cell)),
                Shape2::DogBone { size } => {
                    let d = *size;
                    let (ra, arcs) = dogbone_arcs(d);
                    let in_box = centre.x - r >= -0.5 * d
                        && centre.x + r <= 0.5 * d
                        && centre.y - r >= 0.0
                        && centre.y + r <= 1.5 * d;
                    (in_box && arcs.iter().all(|a| (centre - a).norm() >= r + ra))
                        .then(|| whole(cell))
                }
                _ => None,
            }
        }
        Cutout::Polygon { parts, .. } => {
            let outer_poly = outer.polygon();
            let mut sum = 0.0;
            for part in parts {
                if let Some(poly) = &outer_poly {
                    // clipped by the part, then by the cell: each clipper has the edges it
                    // was given (the part clipped by the cell may have vertices that differ
                    // by rounding only, whose edge has no direction to clip by)
                    let mut q = clip_by_convex(poly, part);
                    if let Some(cell) = cell {
                        q = clip_by_convex(&q, cell);
                    }
                    sum += polygon_area(&q);
                    continue;
                }
                let q = match cell {
                    Some(cell) => clip_by_convex(part, cell),
                    None => part.clone(),
                };
                if q.len() < 3 {
                    continue;
                }
                sum += match outer {
                    Shape2::Disc { centre, radius } => convex_disc_area(&q, centre, *radius),
                    Shape2::DogBone { size } => dogbone_area_of_convex(&q, *size),
                    _ => return None,
                };
            }
            Some(sum)
        }
    }
}

/// [`cutout_area_in`], or where it has no exact form (scenes refuse such cutouts) the area
/// of the cutout's chord polygon in the outer's chord polygon (to 1e-4).
pub(crate) fn cutout_area_in_or_chords(
    outer: &Shape2,
    cutout: &Cutout,
    cell: Option<&[Vector2<f64>]>,
) -> f64 {
    cutout_area_in(outer, cutout, cell).unwrap_or_else(|| {
        let chords = Shape2::Polygon {
            vertices: outer.outline_polygon(),
        };
        cutout_area_in(&chords, &Cutout::polygon(&cutout.drawing_polygon()), cell).unwrap_or(0.0)
    })
}

type P = Vector2<f64>;

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

/// Area of a convex polygon (counter-clockwise) within the dog-bone of size `d`: its part in
/// the bounding rectangle less its parts in the two discs of [`dogbone_arcs`] (a disc whose
/// box misses the part's is skipped, so that it adds no rounding-size zero).
pub fn dogbone_area_of_convex(poly: &[Vector2<f64>], d: f64) -> f64 {
    let rect = [
        Vector2::new(-0.5 * d, 0.0),
        Vector2::new(0.5 * d, 0.0),
        Vector2::new(0.5 * d, 1.5 * d),
        Vector2::new(-0.5 * d, 1.5 * d),
    ];
    let c = clip_by_convex(poly, &rect);
    if c.len() < 3 {
        return 0.0;
    }
    let (r, centres) = dogbone_arcs(d);
    let mut area = polygon_area(&c);
    let (lo, hi) = points_box(&c);
    for centre in centres {
        if lo.x < centre.x + r && hi.x > centre.x - r && lo.y < centre.y + r && hi.y > centre.y - r
        {
            area -= convex_disc_area(&c, &centre, r);
        }
    }
    area
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

    fn plate(cutouts: Vec<Cutout>) -> Shape2 {
        Shape2::WithCutouts {
            outer: Box::new(Shape2::Rectangle {
                origin: P::zeros(),
                width: 0.2,
                height: 0.1,
            }),
            cutouts,
        }
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    /// Areas of plates with cutouts against their closed forms.
    #[test]
    fn areas_with_cutouts_are_exact() {
        let plate_area = 0.2 * 0.1;
        let r: f64 = 0.01;
        // a disc hole, two holes
        let hole = |x: f64, y: f64, r: f64| Cutout::Disc {
            centre: P::new(x, y),
            radius: r,
        };
        let a = plate(vec![hole(0.1, 0.05, r)]).area();
        assert!(rel(a, plate_area - PI * r * r) < 1e-14, "{a}");
        let a = plate(vec![hole(0.05, 0.05, r), hole(0.15, 0.04, 0.5 * r)]).area();
        assert!(rel(a, plate_area - 1.25 * PI * r * r) < 1e-14, "{a}");
        // a polygon hole (non-convex: an L of area 3·s²)
        let s = 0.01;
        let l = Cutout::polygon(&[
            P::new(0.05, 0.03),
            P::new(0.05 + 2.0 * s, 0.03),
            P::new(0.05 + 2.0 * s, 0.03 + s),
            P::new(0.05 + s, 0.03 + s),
            P::new(0.05 + s, 0.03 + 2.0 * s),
            P::new(0.05, 0.03 + 2.0 * s),
        ]);
        let a = plate(vec![l]).area();
        assert!(rel(a, plate_area - 3.0 * s * s) < 1e-13, "{a}");
        // an inclined slit of width w and length L: w·L
        let (w, len) = (0.001, 0.05);
        let th = 0.4f64;
        let start = P::new(0.08, 0.04);
        let slit = Cutout::slit(start, start + P::new(th.cos(), th.sin()) * len, w);
        let a = plate(vec![slit]).area();
        assert!(rel(a, plate_area - w * len) < 1e-13, "{a}");
        // a crack line removes nothing
        let crack = Cutout::slit(P::new(0.1, -0.01), P::new(0.1, 0.03), 0.0);
        assert_eq!(plate(vec![crack]).area(), plate_area);
        // a notch across the bottom edge: only its part in the plate counts
        let notch = Cutout::rectangle(P::new(0.099, -0.01), 0.002, 0.03, 0.0);
        let a = plate(vec![notch]).area();
        assert!(rel(a, plate_area - 0.002 * 0.02) < 1e-13, "{a}");
        // a disc across the bottom edge, its centre 4 mm above it: the disc less the
        // circular segment below the edge, r²·acos(d/r) − d·√(r² − d²)
        let d = 0.004;
        let segment = r * r * (d / r).acos() - d * (r * r - d * d).sqrt();
        let a = plate(vec![hole(0.1, d, r)]).area();
        assert!(rel(a, plate_area - (PI * r * r - segment)) < 1e-13, "{a}");
        // a disc across the corner, centred on it: a quarter of it is in the plate
        let a = plate(vec![hole(0.0, 0.0, r)]).area();
        assert!(rel(a, plate_area - 0.25 * PI * r * r) < 1e-13, "{a}");
        // polygon cutouts of a disc body (a notch of the split cylinder's kind) and a hole in
        // the dog-bone
        let disc = Shape2::Disc {
            centre: P::zeros(),
            radius: 0.05,
        };
        let with = Shape2::WithCutouts {
            outer: Box::new(disc.clone()),
            cutouts: vec![Cutout::rectangle(P::new(0.0, -0.1), 0.2, 0.2, 0.0)],
        };
        assert!(rel(with.area(), 0.5 * disc.area()) < 1e-13);
        let bone = Shape2::DogBone { size: 0.1 };
        let with = Shape2::WithCutouts {
            outer: Box::new(bone.clone()),
            cutouts: vec![hole(0.0, 0.02, 0.01)],
        };
        assert!(rel(with.area(), bone.area() - PI * 1e-4) < 1e-13);
        // a slit across the dog-bone's neck: its part between the two arcs
        let with = Shape2::WithCutouts {
            outer: Box::new(bone.clone()),
            cutouts: vec![Cutout::slit(P::new(-0.1, 0.075), P::new(0.1, 0.075), 0.001)],
        };
        // the neck between y = 0.75·D ± h: 2·∫(1.025·D − √(R² − y²)) dy, R = 0.725·D
        let (d, h) = (0.1f64, 0.0005f64);
        let rr = 0.725 * d;
        let removed = 2.0
            * (1.025 * d * 2.0 * h - (h * (rr * rr - h * h).sqrt() + rr * rr * (h / rr).asin()));
        assert!(rel(bone.area() - with.area(), removed) < 1e-9);
    }

    #[test]
    fn a_point_on_a_cutouts_edge_belongs_to_the_body() {
        let s = plate(vec![Cutout::Disc {
            centre: P::new(0.1, 0.05),
            radius: 0.01,
        }]);
        let tol = 1e-9 * s.size();
        assert!(s.contains(&P::new(0.11, 0.05), tol));
        assert!(!s.contains(&P::new(0.109, 0.05), tol));
        assert!(s.contains(&P::new(0.111, 0.05), tol));
        // the mouth of a notch flush with the outline is not in the body; its corners are
        let s = plate(vec![Cutout::rectangle(P::new(0.09, 0.0), 0.02, 0.03, 0.0)]);
        assert!(!s.contains(&P::new(0.1, 0.0), tol));
        assert!(!s.contains(&P::new(0.1, 0.01), tol));
        assert!(s.contains(&P::new(0.09, 0.0), tol));
        assert!(s.contains(&P::new(0.11, 0.0), tol));
        assert!(s.contains(&P::new(0.09, 0.01), tol));
        assert!(s.contains(&P::new(0.1, 0.03), tol));
        // a bond across the flush notch's mouth is not in the body
        assert!(!s.segment_in_body(&P::new(0.09, 0.0), &P::new(0.11, 0.0), tol, 4));
        assert!(s.segment_in_body(&P::new(0.09, 0.0), &P::new(0.09, 0.02), tol, 4));
    }

    #[test]
    fn outlines_with_cutouts_are_the_body_boundary() {
        let length = |s: &Shape2| s.outline().iter().map(Piece::length).sum::<f64>();
        let perimeter = 2.0 * (0.2 + 0.1);
        // a hole adds its circumference
        let s = plate(vec![Cutout::Disc {
            centre: P::new(0.1, 0.05),
            radius: 0.01,
        }]);
        assert!(rel(length(&s), perimeter + 2.0 * PI * 0.01) < 1e-14);
        assert_eq!(s.cutout_outlines().len(), 1);
        // a notch across the bottom edge, or flush with it: less its mouth, plus its faces
        for y0 in [-0.01, 0.0] {
            let s = plate(vec![Cutout::rectangle(
                P::new(0.09, y0),
                0.02,
                0.03 - y0,
                0.0,
            )]);
            assert!(
                rel(length(&s), perimeter - 0.02 + 2.0 * 0.03 + 0.02) < 1e-13,
                "{y0}: {}",
                length(&s)
            );
            // the pieces join up: every piece starts where another ends
            let pieces = s.outline();
            for p in &pieces {
                let start = p.at(0.0);
                assert!(pieces.iter().any(|q| (q.at(1.0) - start).norm() < 1e-12));
            }
        }
        // a crack line from the bottom edge gives its two faces inside the plate
        let s = plate(vec![Cutout::slit(
            P::new(0.1, -0.01),
            P::new(0.1, 0.03),
            0.0,
        )]);
        assert!(rel(length(&s), perimeter + 2.0 * 0.03) < 1e-13);
        // a disc across the bottom edge: the arc above it replaces the chord
        let (r, d) = (0.01f64, 0.004f64);
        let s = plate(vec![Cutout::Disc {
            centre: P::new(0.1, d),
            radius: r,
        }]);
        let half = (d / r).acos(); // half the angle of the arc below the edge
        let chord = 2.0 * (r * r - d * d).sqrt();
        let arc = r * (2.0 * PI - 2.0 * half);
        assert!(
            rel(length(&s), perimeter - chord + arc) < 1e-12,
            "{}",
            length(&s)
        );
    }

    #[test]
    fn bodies_without_cutouts_test_bonds_at_sample_points() {
        let s = Shape2::NotchedBeam {
            length: 1.0,
            depth: 0.2,
            notch_depth: 0.1,
            notch_width: 0.01,
        };
        let (a, b) = (P::new(0.49, 0.05), P::new(0.51, 0.05));
        assert!(!s.segment_in_body(&a, &b, 1e-9, 4));
        assert!(s.segment_in_body(&a, &P::new(0.49, 0.15), 1e-9, 4));
        // a notch narrower than the samples' step is stepped over (as before cutouts)
        let (a, b) = (P::new(0.3, 0.05), P::new(0.66, 0.05));
        assert!(s.segment_in_body(&a, &b, 1e-9, 4));
    }
}
