//! Random particles in 3D (SPPM; Nikravesh Kazeroni (2017) §3.2–3.5, docs/model.md §1): particles on the body's surface
//! first, the interior filled by random sequential Poisson-disc sampling with a minimum
//! distance, each particle weighted by its Voronoi cell clipped to the body
//! ([`voronoi3::clipped_volumes`]) and bonded to its 18 nearest particles (3.50).
//!
//! - **Density.** The body receives as many particles as an FCC lattice of the same spacing
//!   L0 would: volume / ((√2/2)·L0³).
//! - **Surface first.** Every body is a section swept along an axis (the box a rectangle,
//!   the cylinder a disc, a prism its section with notches and cutouts;
//!   [`Shape3::as_sweep`]). Its edges are walked at the spacing (the section's outline at
//!   both ends, piece by piece as in 2D; the straight edges along the axis at the outline's
//!   corners), then each face (the two ends, and each outline piece swept along the axis:
//!   the sides, the faces of notches and holes) receives random points up to a hexagonal
//!   layer's density, 1/((√3/2)·L0²), at the minimum distance. A face the minimum distance
//!   cannot fill (the second face of a slit narrower than it) keeps what it has.
//! - **Interior.** Uniform candidates in the bounding box (turned by the scene's rotation, as
//!   in 2D: the set at a rotation is the set of the same seed turned against the body), kept
//!   when inside the body and at least `min_distance` from every particle so far (a
//!   background grid answers the query), until the count is reached.
//! - **Bonds.** The horizon of i reaches its 18th-nearest particle (3.50); a bond ij exists
//!   where either end lists the other, and only where the segment stays in the body
//!   ([`Shape3::segment_in_body`]). Counts vary; they are stored in [`SLOTS_3D`] slots.
//! - **Reproducible.** One ChaCha20 stream from the scene's seed, consumed in one order on
//!   one thread: the same seed gives the same particles on any machine and thread count.

use super::random::{Generation, DEFAULT_MIN_DISTANCE};
use super::{voronoi3, Particles, NONE};
use crate::geometry::{Piece, Shape3};
use nalgebra::{Matrix3, Vector2, Vector3};
use rand::rngs::ChaCha20Rng;
use rand::{Rng, SeedableRng};

type P = Vector3<f64>;

/// Nearest particles each particle lists (3.50, "the 18th nearest particle").
pub const NEAREST_3D: usize = 18;

/// Bond slots of a random 3D body: the either-end rule gives 18 or more bonds; measured on
/// the test bodies at the default minimum distance, at most 31 (`bonds_fit_the_slots`).
pub const SLOTS_3D: usize = 36;

/// A random 3D particle set's recipe.
#[derive(Clone, Debug)]
pub struct RandomSolid {
    /// Mean spacing L0 (m): the density of an FCC lattice of this spacing.
    pub spacing: f64,
    /// Minimum distance between particles as a fraction of `spacing`.
    pub min_distance: f64,
    pub seed: u64,
    /// Rotation (degrees, about z, y and x as the FCC lattice's) of the interior's random
    /// stream about the centre of the body's box (the objectivity study).
    pub rotation_deg: [f64; 3],
}

impl RandomSolid {
    /// The recipe of a 3D scene's `[discretisation]` (lattice = "random") and its seed.
    pub fn of_scene(scene: &crate::scene::Scene) -> Self {
        let d = &scene.discretisation;
        RandomSolid {
            spacing: d.spacing,
            min_distance: d.min_distance.unwrap_or(DEFAULT_MIN_DISTANCE),
            seed: scene.seed.unwrap_or(crate::scene::DEFAULT_SEED),
            rotation_deg: d.rotation_deg.angles(),
        }
    }

    fn rotation(&self) -> Matrix3<f64> {
        super::fcc::rotation_of(self.rotation_deg)
    }
}

/// Particles a body receives at mean spacing `l0`: as many as an FCC lattice of that
/// spacing, volume / ((√2/2)·L0³).
pub fn target_count(shape: &Shape3, l0: f64) -> usize {
    (shape.volume() / (0.5 * 2f64.sqrt() * l0.powi(3))).round() as usize
}

/// The area per particle of a surface layer: a hexagonal layer of spacing L0 (an FCC
/// lattice's close-packed plane).
fn face_area_per_particle(l0: f64) -> f64 {
    0.5 * 3f64.sqrt() * l0 * l0
}

/// Uniform in [0, 1) from 53 random bits (the same on every platform).
fn uniform(rng: &mut ChaCha20Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A background grid of cell size δ/√3 (at most one particle a cell) for the
/// minimum-distance test.
struct Grid {
    lo: P,
    h: f64,
    n: [usize; 3],
    cells: Vec<u32>,
}

impl Grid {
    fn new(lo: P, hi: P, delta: f64) -> Result<Self, String> {
        let h = delta / 3f64.sqrt();
        let n = [0, 1, 2].map(|d| (((hi[d] - lo[d]) / h).ceil() as usize).max(1) + 1);
        let total = n[0].checked_mul(n[1]).and_then(|v| v.checked_mul(n[2]));
        match total {
            Some(t) if t <= 1 << 31 => Ok(Grid {
                lo,
                h,
                n,
                cells: vec![NONE; t],
            }),
            _ => Err(format!(
                "the body's box holds {}×{}×{} cells of the minimum distance's grid, more than 2^31",
                n[0], n[1], n[2]
            )),
        }
    }
    fn cell(&self, p: &P) -> [usize; 3] {
        [0, 1, 2].map(|d| {
            ((p[d] - self.lo[d]) / self.h)
                .floor()
                .clamp(0.0, (self.n[d] - 1) as f64) as usize
        })
    }
    /// Whether no particle lies closer than δ to p.
    fn free(&self, p: &P, delta: f64, x: &[P]) -> bool {
        let c = self.cell(p);
        let r = 2usize; // δ = √3·h: two cells each way cover the ball of radius δ
        for k in c[2].saturating_sub(r)..=(c[2] + r).min(self.n[2] - 1) {
            for j in c[1].saturating_sub(r)..=(c[1] + r).min(self.n[1] - 1) {
                let row = (k * self.n[1] + j) * self.n[0];
                for i in c[0].saturating_sub(r)..=(c[0] + r).min(self.n[0] - 1) {
                    let q = self.cells[row + i];
                    if q != NONE && (x[q as usize] - p).norm_squared() < delta * delta {
                        return false;
                    }
                }
            }
        }
        true
    }
    fn insert(&mut self, p: &P, index: u32) {
        let c = self.cell(p);
        self.cells[(c[2] * self.n[1] + c[1]) * self.n[0] + c[0]] = index;
    }
}

/// The unit tangent of an outline piece at parameter t.
fn tangent(piece: &Piece, t: f64) -> Vector2<f64> {
    let n = piece.left_normal(t);
    Vector2::new(n.y, -n.x)
}

/// The particles placed so far, in global and in the sweep's local coordinates.
struct Placed {
    x: Vec<P>,
    local: Vec<P>,
    grid: Grid,
    delta: f64,
}

impl Placed {
    /// Keep the point of local coordinates `q` (global `p`) where it is free.
    fn offer(&mut self, p: P, q: P) -> bool {
        if self.grid.free(&p, self.delta, &self.x) {
            self.grid.insert(&p, self.x.len() as u32);
            self.x.push(p);
            self.local.push(q);
            true
        } else {
            false
        }
    }
}

/// The box, about the centre of the box (lo, hi), that holds it turned back by `rotation`:
/// where the interior's candidates are drawn before they are turned into the body.
fn turned_box(lo: P, hi: P, rotation: &nalgebra::Matrix3<f64>) -> (P, P) {
    let centre = (lo + hi) * 0.5;
    let inv = rotation.transpose();
    let corners: Vec<P> = (0..8)
        .map(|c| {
            let v = P::new(
                if c & 1 == 0 { lo.x } else { hi.x },
                if c & 2 == 0 { lo.y } else { hi.y },
                if c & 4 == 0 { lo.z } else { hi.z },
            );
            inv * (v - centre)
        })
        .collect();
    corners
        .iter()
        .fold((corners[0], corners[0]), |(a, b), c| (a.inf(c), b.sup(c)))
}

/// Place the particles: the surface's edges and faces, then the interior; then sort them in
/// rows. Returns the positions and how many lie on the surface. `Err` when the body cannot
/// hold the density at this minimum distance.
pub fn place(shape: &Shape3, recipe: &RandomSolid) -> Result<(Vec<P>, usize), String> {
    let l0 = recipe.spacing;
    let delta = recipe.min_distance * l0;
    let target = target_count(shape, l0);
    let (lo, hi) = shape.bounding_box();
    let sweep = shape.as_sweep();
    let (section, length) = (&sweep.section, sweep.length);
    let pieces = section.outline();
    let tol = 1e-9 * shape.size();
    let mut placed = Placed {
        x: Vec::with_capacity(target + 16),
        local: Vec::with_capacity(target + 16),
        grid: Grid::new(lo - P::repeat(tol), hi + P::repeat(tol), delta)?,
        delta,
    };
    let at = |uv: Vector2<f64>, w: f64| {
        let q = P::new(uv.x, uv.y, w);
        (sweep.global(&q), q)
    };
    // the edges: the outline at both ends, piece by piece as in 2D
    for w in [0.0, length] {
        for piece in &pieces {
            let n = ((piece.length() / l0).round() as usize).max(1);
            for k in 0..n {
                let (p, q) = at(piece.at(k as f64 / n as f64), w);
                placed.offer(p, q);
            }
        }
    }
    // the edges along the axis, at the outline's corners (where no piece ends tangent to
    // the one that starts)
    let steps = ((length / l0).round() as usize).max(1);
    for piece in &pieces {
        let start = piece.at(0.0);
        let smooth = pieces.iter().any(|o| {
            (o.at(1.0) - start).norm() <= tol
                && tangent(o, 1.0).dot(&tangent(piece, 0.0)) > 1.0 - 1e-6
        });
        if !smooth {
            for k in 1..steps {
                let (p, q) = at(start, length * k as f64 / steps as f64);
                placed.offer(p, q);
            }
        }
    }
    let mut rng = ChaCha20Rng::seed_from_u64(recipe.seed);
    let per_face = face_area_per_particle(l0);
    // the faces, each up to a hexagonal layer's density; a face the minimum distance cannot
    // fill (beside another face nearer than it) keeps what it has after this many attempts
    // per particle wanted
    const FACE_ATTEMPTS: usize = 50;
    let (slo, shi) = section.bounding_box();
    for w in [0.0, length] {
        let wanted = (section.area() / per_face).round() as usize;
        let mut have = placed
            .local
            .iter()
            .filter(|q| (q.z - w).abs() <= tol)
            .count();
        let mut attempts = 0;
        while have < wanted && attempts < FACE_ATTEMPTS * wanted {
            attempts += 1;
            let uv = Vector2::new(
                slo.x + (shi.x - slo.x) * uniform(&mut rng),
                slo.y + (shi.y - slo.y) * uniform(&mut rng),
            );
            if section.contains(&uv, -tol) {
                let (p, q) = at(uv, w);
                if placed.offer(p, q) {
                    have += 1;
                }
            }
        }
    }
    for piece in &pieces {
        let wanted = (piece.length() * length / per_face).round() as usize;
        let mut have = placed
            .local
            .iter()
            .filter(|q| piece.distance(&Vector2::new(q.x, q.y)) <= tol)
            .count();
        let mut attempts = 0;
        while have < wanted && attempts < FACE_ATTEMPTS * wanted {
            attempts += 1;
            let uv = piece.at(uniform(&mut rng));
            let (p, q) = at(uv, length * uniform(&mut rng));
            if placed.offer(p, q) {
                have += 1;
            }
        }
    }
    let on_surface = placed.x.len();
    // the interior, in the body's box turned by the rotation
    let rotation = recipe.rotation();
    let turned = recipe.rotation_deg.iter().any(|&a| a != 0.0);
    let centre = (lo + hi) * 0.5;
    let (flo, fhi) = if turned {
        turned_box(lo, hi, &rotation)
    } else {
        (lo, hi)
    };
    let max_attempts = 1000 * target.max(16) as u64;
    let mut attempts = 0u64;
    while placed.x.len() < target {
        attempts += 1;
        if attempts > max_attempts {
            return Err(format!(
                "placed {} of {} particles after {} random attempts: the body cannot hold an FCC lattice's density at discretisation.min_distance = {} × spacing; use a smaller min_distance",
                placed.x.len(),
                target,
                max_attempts,
                recipe.min_distance
            ));
        }
        let c = P::new(
            flo.x + (fhi.x - flo.x) * uniform(&mut rng),
            flo.y + (fhi.y - flo.y) * uniform(&mut rng),
            flo.z + (fhi.z - flo.z) * uniform(&mut rng),
        );
        let p = if turned { centre + rotation * c } else { c };
        if shape.contains(&p, -tol) {
            let q = sweep.local(&p);
            placed.offer(p, q);
        }
    }
    let mut x = placed.x;
    // Rows one spacing high and deep, as the lattice's: a particle's neighbours sit near it
    // in memory (the kernels gather them).
    let row = |p: &P| {
        (
            ((p.z - lo.z) / l0).floor() as i64,
            ((p.y - lo.y) / l0).floor() as i64,
        )
    };
    x.sort_by(|a, b| row(a).cmp(&row(b)).then(a.x.total_cmp(&b.x)));
    Ok((x, on_surface))
}

/// Bond every particle to its [`NEAREST_3D`] nearest (either-end rule, segments inside the
/// body) into `K` slots: neighbours, reverse slots, reference lengths.
#[allow(clippy::type_complexity)]
pub fn bond<const K: usize>(
    x: &[P],
    shape: &Shape3,
) -> Result<(Vec<[u32; K]>, Vec<[u8; K]>, Vec<[f64; K]>), String> {
    let tol = 1e-9 * shape.size();
    super::random::bond_nearest::<3, K>(x, NEAREST_3D, |a, b| shape.segment_in_body(a, b, tol, 8))
}

/// Generate a random 3D body: particles, clipped Voronoi volumes, bonds, each particle's
/// length scale (its mean bond length); and what generation measured. A particle without a
/// bond inside the body is an error.
pub fn fill<const K: usize>(
    shape: &Shape3,
    recipe: &RandomSolid,
) -> Result<(Particles<3, K>, Generation), String> {
    let t0 = std::time::Instant::now();
    let (x, on_surface) = place(shape, recipe)?;
    let t1 = std::time::Instant::now();
    let volume = voronoi3::clipped_volumes(&x, shape, recipe.spacing);
    let t2 = std::time::Instant::now();
    let (neighbours, reverse, l0) = bond::<K>(&x, shape)?;
    let t3 = std::time::Instant::now();
    let mut p = Particles::new(x, volume, neighbours, reverse, l0, recipe.spacing);
    p.weighted_dilatation = true;
    if let Some(i) = (0..p.len()).find(|&i| p.bond_count(i) == 0) {
        return Err(format!(
            "particle {i} at ({:.6}, {:.6}, {:.6}) m has no bond inside the body (a sliver of the body thinner than the spacing); use a smaller discretisation.spacing",
            p.x0[i].x, p.x0[i].y, p.x0[i].z
        ));
    }
    let generation = super::random::measure(
        &mut p,
        recipe.min_distance,
        on_surface,
        target_count(shape, recipe.spacing),
        [t0, t1, t2, t3],
    );
    Ok((p, generation))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Cutout, Shape2};
    use rstar::RTree;

    fn recipe(seed: u64) -> RandomSolid {
        RandomSolid {
            spacing: 0.004,
            min_distance: DEFAULT_MIN_DISTANCE,
            seed,
            rotation_deg: [0.0; 3],
        }
    }

    /// A box, a cylinder along a tilted axis, the dog-bone prism, and a prism with a slit.
    fn shapes() -> Vec<Shape3> {
        vec![
            Shape3::Box {
                origin: P::new(0.01, -0.02, 0.0),
                size: P::new(0.04, 0.03, 0.05),
            },
            Shape3::Cylinder {
                base: P::new(0.0, 0.0, 0.0),
                axis: P::new(1.0, 0.4, -0.3).normalize(),
                radius: 0.015,
                length: 0.04,
            },
            Shape3::Extruded {
                section: Shape2::DogBone { size: 0.05 },
                thickness: 0.02,
            },
            Shape3::Extruded {
                section: Shape2::WithCutouts {
                    outer: Box::new(Shape2::Rectangle {
                        origin: Vector2::zeros(),
                        width: 0.06,
                        height: 0.03,
                    }),
                    cutouts: vec![Cutout::rectangle(
                        Vector2::new(0.029, -0.001),
                        0.002,
                        0.011,
                        0.0,
                    )],
                },
                thickness: 0.02,
            },
        ]
    }

    /// The count is an FCC lattice's, every pair keeps the minimum distance, every particle
    /// is in the body, and the surface carries a layer.
    #[test]
    fn density_minimum_distance_and_surface() {
        for s in shapes() {
            let r = recipe(3);
            let (x, on) = place(&s, &r).unwrap();
            let target = s.volume() / (0.5 * 2f64.sqrt() * r.spacing.powi(3));
            assert!((x.len() as f64 - target).abs() <= 0.5 + 1e-9, "{s:?}");
            let delta = r.min_distance * r.spacing;
            let tree: RTree<[f64; 3]> =
                RTree::bulk_load(x.iter().map(|p| [p.x, p.y, p.z]).collect());
            for p in &x {
                let close = tree
                    .locate_within_distance([p.x, p.y, p.z], (delta * (1.0 - 1e-12)).powi(2))
                    .count();
                assert_eq!(
                    close, 1,
                    "{s:?}: a pair nearer than the minimum distance at {p:?}"
                );
            }
            let tol = 1e-9 * s.size();
            assert!(x.iter().all(|p| s.contains(p, tol)));
            // the surface's particles: at least a hexagonal layer's density at 0.7·L0 falls
            // short of the full layer by the random packing; more than 60% of it is reached
            let sweep = s.as_sweep();
            let area = 2.0 * sweep.section.area()
                + sweep
                    .section
                    .outline()
                    .iter()
                    .map(|p| p.length())
                    .sum::<f64>()
                    * sweep.length;
            let layer = area / face_area_per_particle(r.spacing);
            assert!(
                on as f64 > 0.6 * layer && (on as f64) < 1.05 * layer,
                "{s:?}: {on} of {layer}"
            );
        }
    }

    #[test]
    fn same_seed_same_particles_other_seed_other_particles() {
        let s = &shapes()[1];
        let a = place(s, &recipe(11)).unwrap().0;
        let b = place(s, &recipe(11)).unwrap().0;
        let c = place(s, &recipe(12)).unwrap().0;
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    /// The clipped Voronoi cells sum to the body's volume (1e-9 relative) on a box, a
    /// cylinder, the dog-bone prism and a prism with a slit.
    #[test]
    fn cells_sum_to_the_body_volume() {
        for s in shapes() {
            let r = recipe(5);
            let (x, _) = place(&s, &r).unwrap();
            let v = voronoi3::clipped_volumes(&x, &s, r.spacing);
            let sum: f64 = v.iter().sum();
            let rel = (sum - s.volume()).abs() / s.volume();
            assert!(
                rel < 1e-9,
                "{s:?}: cells sum to {sum}, volume {} ({rel:e})",
                s.volume()
            );
            assert!(v.iter().all(|&c| c > 0.0), "{s:?}: an empty cell");
        }
    }

    /// Bonds are symmetric, every particle lists its 18 nearest where the body allows, none
    /// crosses the slit, and the counts fit the slots.
    #[test]
    fn bonds_are_symmetric_stay_in_the_body_and_fit_the_slots() {
        for (k, s) in shapes().iter().enumerate() {
            let (p, g) = fill::<SLOTS_3D>(s, &recipe(5)).unwrap();
            p.check_topology().unwrap();
            let bulk = (0..p.len())
                .filter(|&i| p.bond_count(i) >= NEAREST_3D)
                .count();
            assert!(bulk as f64 > 0.8 * p.len() as f64, "{s:?}: {g:?}");
            let most = g.bond_histogram.len() - 1;
            assert!(most <= SLOTS_3D - 4, "{s:?}: {most} bonds");
            if k == 3 {
                for i in 0..p.len() {
                    for kk in 0..SLOTS_3D {
                        let j = p.neighbours[i][kk];
                        if j == NONE {
                            continue;
                        }
                        let (a, b) = (p.x0[i], p.x0[j as usize]);
                        let crosses = (a.x - 0.03) * (b.x - 0.03) < 0.0 && a.y.max(b.y) < 0.01;
                        assert!(!crosses, "bond {a:?}-{b:?} crosses the slit");
                    }
                }
            }
        }
    }
}
