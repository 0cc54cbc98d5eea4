//! Voronoi cells of a 2D particle set, clipped to the body (002 (3.52)–(3.53); MODEL.md §1:
//! "Voronoi cell of the particle, clipped to the body").
//!
//! The Delaunay triangulation (`spade`) gives each particle its Voronoi neighbours; the cell
//! is the body's bounding box cut by the perpendicular bisector of every Delaunay edge
//! (convex, so bounded cells of hull particles come out the same way as interior ones). The
//! clipped area is exact for every shape of [`Shape2`]: straight edges by half-plane
//! clipping, the disc and the dog-bone's arcs by the closed-form area of a convex polygon
//! intersected with a disc. The clipped cells of a body sum to its area to rounding
//! (tests: 1e-9 relative on a rectangle, a disc, the dog-bone and the notched beam).

use crate::geometry::{dogbone_arcs, points_box, polygon_area, Shape2};
use nalgebra::Vector2;
use spade::{DelaunayTriangulation, Point2, Triangulation};

type P = Vector2<f64>;

/// Keep the part of polygon `poly` where n·x ≤ c (Sutherland–Hodgman against one half-plane;
/// `poly` may be non-convex, the clipped area is exact).
fn clip_half_plane(poly: &[P], n: &P, c: f64, out: &mut Vec<P>) {
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
fn half_planes(convex: &[P]) -> Vec<(P, f64)> {
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
fn clip_by_convex(poly: &[P], convex: &[P]) -> Vec<P> {
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

/// Area of the intersection of a convex polygon (counter-clockwise) with a disc: the sum over
/// the polygon's edges of the signed area of the triangle (centre, a, b) within the disc.
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

/// Area of a convex polygon (counter-clockwise) within the body.
pub fn area_in_body(cell: &[P], shape: &Shape2) -> f64 {
    if cell.len() < 3 {
        return 0.0;
    }
    match shape {
        Shape2::Disc { centre, radius } => {
            if cell.iter().all(|v| (v - centre).norm() <= *radius) {
                polygon_area(cell)
            } else {
                convex_disc_area(cell, centre, *radius)
            }
        }
        Shape2::DogBone { size } => {
            // the dog-bone is its bounding rectangle less two discs (geometry::dogbone_half_width)
            let d = *size;
            let rect = [
                P::new(-0.5 * d, 0.0),
                P::new(0.5 * d, 0.0),
                P::new(0.5 * d, 1.5 * d),
                P::new(-0.5 * d, 1.5 * d),
            ];
            let c = clip_by_convex(cell, &rect);
            if c.len() < 3 {
                return 0.0;
            }
            let (r, centres) = dogbone_arcs(d);
            let mut area = polygon_area(&c);
            // only cells whose box meets a disc's box (disjoint cells would add a
            // rounding-size zero)
            let (lo, hi) = points_box(&c);
            for centre in centres {
                if lo.x < centre.x + r
                    && hi.x > centre.x - r
                    && lo.y < centre.y + r
                    && hi.y > centre.y - r
                {
                    area -= convex_disc_area(&c, &centre, r);
                }
            }
            area
        }
        _ => {
            let outline = shape.polygon().expect("straight-edged shape");
            polygon_area(&clip_by_convex(&outline, cell)).abs()
        }
    }
}

/// Each particle's Voronoi cell clipped to the body (the clipped polygon, counter-clockwise,
/// and its area), from the Delaunay triangulation of the particles. The area is exact
/// ([`area_in_body`]); the polygon, for drawing, follows arcs in the chords of
/// [`Shape2::outline_polygon`]. `Err` names what failed
/// (fewer than three particles, coincident or collinear particles).
pub fn clipped_cells(x: &[P], shape: &Shape2) -> Result<Vec<(Vec<P>, f64)>, String> {
    if x.len() < 3 {
        return Err(format!(
            "{} particle(s): a Voronoi tessellation needs at least 3",
            x.len()
        ));
    }
    let pts: Vec<Point2<f64>> = x.iter().map(|p| Point2::new(p.x, p.y)).collect();
    let tri: DelaunayTriangulation<Point2<f64>> = DelaunayTriangulation::bulk_load_stable(pts)
        .map_err(|e| format!("Delaunay triangulation failed: {e:?}"))?;
    if tri.num_vertices() != x.len() {
        return Err(format!(
            "{} of {} particles coincide with others",
            x.len() - tri.num_vertices(),
            x.len()
        ));
    }
    let (lo, hi) = shape.bounding_box();
    let pad = (hi - lo) * 0.5 + P::repeat(1e-9);
    let bbox = [
        P::new(lo.x - pad.x, lo.y - pad.y),
        P::new(hi.x + pad.x, lo.y - pad.y),
        P::new(hi.x + pad.x, hi.y + pad.y),
        P::new(lo.x - pad.x, hi.y + pad.y),
    ];
    let body = shape.outline_polygon();
    let mut cells = Vec::with_capacity(x.len());
    let mut cur = Vec::with_capacity(16);
    let mut next = Vec::with_capacity(16);
    for v in tri.vertices() {
        let i = v.fix().index();
        debug_assert_eq!(i, cells.len(), "bulk_load_stable keeps the order");
        // the cell is cut in coordinates about x_i (for accuracy), then moved back once
        let xi = x[i];
        cur.clear();
        cur.extend(bbox.iter().map(|c| c - xi));
        for e in v.out_edges() {
            // bisector of x_i and x_j: (x_j − x_i)·y ≤ |x_j − x_i|²/2
            let n = x[e.to().fix().index()] - xi;
            clip_half_plane(&cur, &n, 0.5 * n.dot(&n), &mut next);
            std::mem::swap(&mut cur, &mut next);
        }
        let cell: Vec<P> = cur.iter().map(|p| p + xi).collect();
        let area = area_in_body(&cell, shape);
        // cells of particles at the surface reach beyond it (their area in the body is less
        // than their own): cut them to the body
        let drawn = if area >= (1.0 - 1e-12) * polygon_area(&cell) {
            cell
        } else {
            clip_by_convex(&body, &cell)
        };
        cells.push((drawn, area));
    }
    Ok(cells)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn disc_area_of_polygons() {
        let sq = [
            P::new(-1.0, -1.0),
            P::new(1.0, -1.0),
            P::new(1.0, 1.0),
            P::new(-1.0, 1.0),
        ];
        // the unit disc inside a square of side 2
        assert_relative_eq!(
            convex_disc_area(&sq, &P::zeros(), 1.0),
            std::f64::consts::PI,
            max_relative = 1e-14
        );
        // the square inside a disc of radius 2
        assert_relative_eq!(
            convex_disc_area(&sq, &P::zeros(), 2.0),
            4.0,
            max_relative = 1e-14
        );
        // a half disc: the square [0,2]×[-2,2] with the unit disc about 0
        let half = [
            P::new(0.0, -2.0),
            P::new(2.0, -2.0),
            P::new(2.0, 2.0),
            P::new(0.0, 2.0),
        ];
        assert_relative_eq!(
            convex_disc_area(&half, &P::zeros(), 1.0),
            0.5 * std::f64::consts::PI,
            max_relative = 1e-14
        );
        // circular segment cut by the line x = 0.5: r²acos(d/r) − d√(r²−d²)
        let seg = [
            P::new(0.5, -2.0),
            P::new(2.0, -2.0),
            P::new(2.0, 2.0),
            P::new(0.5, 2.0),
        ];
        let want = (0.5f64).acos() - 0.5 * (0.75f64).sqrt();
        assert_relative_eq!(
            convex_disc_area(&seg, &P::zeros(), 1.0),
            want,
            max_relative = 1e-13
        );
    }
}
