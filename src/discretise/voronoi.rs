//! Voronoi cells of a 2D particle set, clipped to the body (Nikravesh Kazeroni 2017, (3.52)–(3.53); docs/model.md §1:
//! "Voronoi cell of the particle, clipped to the body").
//!
//! The Delaunay triangulation (`spade`) gives each particle its Voronoi neighbours; the cell
//! is the body's bounding box cut by the perpendicular bisector of every Delaunay edge
//! (convex, so bounded cells of hull particles come out the same way as interior ones). The
//! clipped area is exact for every shape of [`Shape2`]: straight edges by half-plane
//! clipping, the disc and the dog-bone's arcs by the closed-form area of a convex polygon
//! intersected with a disc. The clipped cells of a body sum to its area to rounding
//! (tests: 1e-9 relative on a rectangle, a disc, the dog-bone and the notched beam).
//!
//! A body with cutouts: the cell's area in the outer less, for each cutout whose box meets
//! the cell's, the exact area of cell ∩ outer ∩ cutout (`geometry::cutout_area_in`: discs
//! in closed form, polygons by convex parts; tests: 1e-9 relative with holes, slits and
//! notches).

pub use crate::geometry::polygon::convex_disc_area;
use crate::geometry::polygon::{clip_by_convex, clip_half_plane, half_planes};
use crate::geometry::{
    cutout_area_in_or_chords, dogbone_area_of_convex, points_box, polygon_area, Shape2,
};
use nalgebra::Vector2;
use spade::{DelaunayTriangulation, Point2, Triangulation};

type P = Vector2<f64>;

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
        Shape2::DogBone { size } => dogbone_area_of_convex(cell, *size),
        Shape2::WithCutouts { outer, cutouts } => {
            let cell = &without_near_duplicates(cell);
            let mut area = area_in_body(cell, outer);
            if area <= 0.0 {
                return area;
            }
            let (lo, hi) = points_box(cell);
            for c in cutouts.iter().filter(|c| c.removes_area()) {
                let (clo, chi) = c.bounding_box();
                if lo.x < chi.x && hi.x > clo.x && lo.y < chi.y && hi.y > clo.y {
                    area -= cutout_area_in_or_chords(outer, c, Some(cell));
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

/// The cell without vertices within 1e-9 of its size of the one before. Where several
/// bisectors meet in one point (particles on a circle about it: the edge of a hole, a
/// lattice around a hole), the cell has vertices that differ by rounding only, and the
/// half-plane of the edge between them points anywhere; dropped, its neighbours' half-planes
/// bound the cell as before (to the area of a triangle 1e-9 of the size on a side).
fn without_near_duplicates(cell: &[P]) -> Vec<P> {
    let (lo, hi) = points_box(cell);
    let eps = 1e-9 * (hi - lo).norm();
    let mut out: Vec<P> = Vec::with_capacity(cell.len());
    for v in cell {
        if out.last().is_none_or(|u| (v - u).norm() > eps) {
            out.push(*v);
        }
    }
    while out.len() > 1 && (out[0] - out[out.len() - 1]).norm() <= eps {
        out.pop();
    }
    out
}

/// The drawn polygon of a cell that reaches beyond the body: the cell clipped to the
/// outline (with cutouts: to the outer's), and for each cutout whose box meets the cell, cut
/// along the cutout's edge that faces the particle (the drawing polygon's edge with the
/// particle farthest outside it; for a non-convex cutout the nearest edge). Exact for cells
/// that meet one straight edge of a cutout; where a cell wraps a cutout's corner or spans a
/// hole the drawing loses the part beyond the corner, and at a disc it follows the chord
/// (its sagitta, under 8e-5 of the radius, lies in the hole). The cell's area is exact
/// regardless ([`area_in_body`]).
fn drawn_cell(body: &[P], cell: &[P], cutouts: &[(Vec<P>, bool, (P, P))], xi: &P) -> Vec<P> {
    let mut q = clip_by_convex(body, cell);
    if cutouts.is_empty() {
        return q;
    }
    let (lo, hi) = points_box(cell);
    let mut next = Vec::with_capacity(q.len() + 4);
    for (poly, convex, (clo, chi)) in cutouts {
        if !(lo.x < chi.x && hi.x > clo.x && lo.y < chi.y && hi.y > clo.y) {
            continue;
        }
        let planes = half_planes(poly);
        let outside = |(n, c): &(P, f64)| (n.dot(xi) - c) / n.norm();
        let facing = if *convex {
            planes
                .iter()
                .max_by(|a, b| outside(a).total_cmp(&outside(b)))
        } else {
            let m = poly.len();
            (0..m)
                .min_by(|&i, &j| {
                    let d = |k: usize| {
                        crate::geometry::polygon::segment_distance(&poly[k], &poly[(k + 1) % m], xi)
                    };
                    d(i).total_cmp(&d(j))
                })
                .map(|k| &planes[k])
        };
        if let Some((n, c)) = facing {
            // keep n·y ≥ c: outside the facing edge
            clip_half_plane(&q, &-n, -c, &mut next);
            if next.len() >= 3 {
                std::mem::swap(&mut q, &mut next);
            }
        }
    }
    q
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
    // the cutouts as drawn: polygon, convex, box
    let cutouts: Vec<(Vec<P>, bool, (P, P))> = match shape {
        Shape2::WithCutouts { cutouts, .. } => cutouts
            .iter()
            .filter(|c| c.removes_area())
            .map(|c| {
                let poly = c.drawing_polygon();
                let convex = crate::geometry::polygon::is_convex(&poly);
                (poly, convex, c.bounding_box())
            })
            .collect(),
        _ => vec![],
    };
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
        let mut cell: Vec<P> = cur.iter().map(|p| p + xi).collect();
        if !cutouts.is_empty() {
            cell = without_near_duplicates(&cell);
        }
        let area = area_in_body(&cell, shape);
        // cells of particles at the surface reach beyond it (their area in the body is less
        // than their own): cut them to the body
        let drawn = if area >= (1.0 - 1e-12) * polygon_area(&cell) {
            cell
        } else {
            drawn_cell(&body, &cell, &cutouts, &xi)
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

    /// Lattice particles around a hole are cocircular about points inside it, where many
    /// bisectors meet: the cells still sum to the body's area.
    #[test]
    fn lattice_cells_around_a_hole_sum_to_the_area() {
        use crate::discretise::hex::HexLattice;
        use crate::geometry::Cutout;
        let s = Shape2::WithCutouts {
            outer: Box::new(Shape2::Rectangle {
                origin: P::zeros(),
                width: 0.1,
                height: 0.1,
            }),
            cutouts: vec![
                Cutout::Disc {
                    centre: P::new(0.03, 0.05),
                    radius: 0.008,
                },
                Cutout::slit(P::new(0.06, 0.02), P::new(0.08, 0.08), 0.003),
            ],
        };
        for rot in [0.0, 30.0] {
            let lat = HexLattice {
                spacing: 0.002,
                rotation_deg: rot,
                offset: P::zeros(),
                thickness: 0.05,
            };
            let x = lat.fill(&s).x0;
            let cells = clipped_cells(&x, &s).unwrap();
            let sum: f64 = cells.iter().map(|c| c.1).sum();
            assert_relative_eq!(sum, s.area(), max_relative = 1e-12);
            assert!(cells.iter().all(|c| c.1 > 0.0));
            // the drawn cells keep to the outer and out of the cutouts (to a disc chord's
            // sagitta)
            let tol = 1e-9 * s.size();
            for (poly, _) in &cells {
                for v in poly {
                    assert!(v.x >= -tol && v.x <= 0.1 + tol && v.y >= -tol && v.y <= 0.1 + tol);
                    if let Shape2::WithCutouts { cutouts, .. } = &s {
                        assert!(cutouts.iter().all(|c| c.depth(v) <= 8e-5 * 0.008 + tol));
                    }
                }
            }
        }
    }
}
