//! Random particles in 2D (SPPM; Nikravesh Kazeroni (2017) chapter 3, docs/model.md §1): particles on the body's outline
//! at the spacing, the interior filled by random sequential Poisson-disc sampling with a
//! minimum distance, each particle weighted by its Voronoi cell clipped to the body
//! ([`super::voronoi`]) and bonded to its k = 6 nearest particles (3.50).
//!
//! - **Density.** The body receives as many particles as a hexagonal lattice of the same
//!   spacing L0 would: area / ((√3/2)·L0²).
//! - **Outline first.** The boundary is walked piece by piece (edges, arcs; with cutouts
//!   also the holes' edges and the faces of slits, notches and crack lines,
//!   `Shape2::outline`), each piece divided into ⌈length/L0⌉ equal parts, so corners,
//!   notches, holes and the supports' edges carry particles; an outline point closer than
//!   the minimum distance to one already placed is skipped (the second face of a notch or
//!   slit narrower than that; the second face of a crack line).
//! - **Interior.** Uniform candidates in the bounding box, kept when inside the body and at
//!   least `min_distance` from every particle so far (a background grid answers the query),
//!   until the count is reached.
//! - **Bonds.** The horizon of i reaches its 6th-nearest particle (3.50); a bond ij exists
//!   where either end lists the other (the force needs both force states), and only where
//!   the segment stays in the body (as for the lattice: no bond across a notch, through a
//!   hole or across a crack line; `Shape2::segment_in_body`). Neighbour
//!   counts therefore vary; they are stored in `K` fixed slots (empty slots hold
//!   [`NONE`]), and a particle with more than `K` bonds is an error.
//! - **Reproducible.** One ChaCha20 stream from the scene's seed, consumed in one order on
//!   one thread: the same seed gives the same particles on any machine and thread count.

use super::voronoi;
use super::{Particles, NONE};
use crate::geometry::Shape2;
use nalgebra::Vector2;
use rand::rngs::ChaCha20Rng;
use rand::{Rng, SeedableRng};
use rstar::primitives::GeomWithData;
use rstar::RTree;

type P = Vector2<f64>;

/// Nearest particles each particle lists (3.50, 2D).
pub const NEAREST_2D: usize = 6;

/// Bond slots of a random 2D body: the either-end rule gives 6 or more bonds, rarely more
/// than 10 (measured histograms in the run summaries).
pub const SLOTS_2D: usize = 12;

/// Default minimum distance between particles, as a fraction of the spacing. Measured
/// (model::sppm_calibration): at 0.7 the fitted moduli need the smallest correction of the
/// range placement reaches quickly (E −20% before calibration, against −30% at 0.6 and −43%
/// at 0.5) and particle sets scatter least (E ±0.8%, ν ±0.008 at W/L0 = 50).
pub const DEFAULT_MIN_DISTANCE: f64 = 0.7;

/// A random particle set's recipe.
#[derive(Clone, Debug)]
pub struct RandomParticles {
    /// Mean spacing L0 (m): the density of a hexagonal lattice of this spacing.
    pub spacing: f64,
    /// Minimum distance between particles as a fraction of `spacing`.
    pub min_distance: f64,
    pub seed: u64,
    /// Rotation (degrees) of the interior's random stream about the centre of the body's
    /// box: the candidates of angle θ are those of angle 0 (drawn in the box of the body
    /// turned by −θ) turned by θ, so a set at θ is the set of the same seed rotated against
    /// the body and its loads (the objectivity study). 0: candidates in the body's own box.
    pub rotation_deg: f64,
    pub thickness: f64,
}

impl RandomParticles {
    /// The recipe of a scene's `[discretisation]` (lattice = "random"), its seed and
    /// thickness.
    pub fn of_scene(scene: &crate::scene::Scene) -> Self {
        let d = &scene.discretisation;
        RandomParticles {
            spacing: d.spacing,
            min_distance: d.min_distance.unwrap_or(DEFAULT_MIN_DISTANCE),
            seed: scene.seed.unwrap_or(crate::scene::DEFAULT_SEED),
            rotation_deg: d.rotation_deg.angle(),
            thickness: scene.material.thickness(),
        }
    }
}

/// What generation measured (`sppm check`, summary.json).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Generation {
    /// The minimum distance used (fraction of the spacing).
    pub min_distance: f64,
    pub particles: usize,
    pub outline_particles: usize,
    /// Target count (the hexagonal lattice's density).
    pub target: usize,
    /// Nearest-neighbour distance of each particle / spacing: min, mean, max.
    pub nearest_min: f64,
    pub nearest_mean: f64,
    pub nearest_max: f64,
    /// Bond count histogram: `bond_histogram[n]` particles have n bonds.
    pub bond_histogram: Vec<usize>,
    /// Seconds spent placing particles, tessellating and bonding.
    pub seconds_placing: f64,
    pub seconds_voronoi: f64,
    pub seconds_bonding: f64,
}

/// A background grid of cell size δ/√2 (at most one particle a cell) for the
/// minimum-distance test.
struct Grid {
    lo: P,
    h: f64,
    nx: usize,
    ny: usize,
    cells: Vec<u32>,
}

impl Grid {
    fn new(lo: P, hi: P, delta: f64) -> Self {
        let h = delta / 2f64.sqrt();
        let nx = (((hi.x - lo.x) / h).ceil() as usize).max(1) + 1;
        let ny = (((hi.y - lo.y) / h).ceil() as usize).max(1) + 1;
        Grid {
            lo,
            h,
            nx,
            ny,
            cells: vec![NONE; nx * ny],
        }
    }
    fn cell(&self, p: &P) -> (usize, usize) {
        let cx = ((p.x - self.lo.x) / self.h)
            .floor()
            .clamp(0.0, (self.nx - 1) as f64);
        let cy = ((p.y - self.lo.y) / self.h)
            .floor()
            .clamp(0.0, (self.ny - 1) as f64);
        (cx as usize, cy as usize)
    }
    /// Whether no particle lies closer than δ to p.
    fn free(&self, p: &P, delta: f64, x: &[P]) -> bool {
        let (cx, cy) = self.cell(p);
        let r = 2usize; // δ = √2·h: two cells each way cover the disc of radius δ
        for j in cy.saturating_sub(r)..=(cy + r).min(self.ny - 1) {
            for i in cx.saturating_sub(r)..=(cx + r).min(self.nx - 1) {
                let q = self.cells[j * self.nx + i];
                if q != NONE && (x[q as usize] - p).norm_squared() < delta * delta {
                    return false;
                }
            }
        }
        true
    }
    fn insert(&mut self, p: &P, index: u32) {
        let (cx, cy) = self.cell(p);
        self.cells[cy * self.nx + cx] = index;
    }
}

/// Particles a body of `shape` receives at mean spacing `l0`: as many as a hexagonal lattice
/// of that spacing, area / ((√3/2)·L0²).
pub fn target_count(shape: &Shape2, l0: f64) -> usize {
    (shape.area() / (0.5 * 3f64.sqrt() * l0 * l0)).round() as usize
}

/// Uniform in [0, 1) from 53 random bits (the same on every platform).
fn uniform(rng: &mut ChaCha20Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Place the particles: the outline, then the interior; then sort them in rows. Returns the
/// positions and how many lie on the outline. `Err` when the body cannot hold the density
/// at this minimum distance.
pub fn place(shape: &Shape2, recipe: &RandomParticles) -> Result<(Vec<P>, usize), String> {
    let l0 = recipe.spacing;
    let delta = recipe.min_distance * l0;
    let target = target_count(shape, l0);
    let (lo, hi) = shape.bounding_box();
    let mut grid = Grid::new(lo, hi, delta);
    let mut x: Vec<P> = Vec::with_capacity(target + 16);
    for piece in shape.outline() {
        let n = ((piece.length() / l0).round() as usize).max(1);
        for k in 0..n {
            let p = piece.at(k as f64 / n as f64);
            if grid.free(&p, delta, &x) {
                grid.insert(&p, x.len() as u32);
                x.push(p);
            }
        }
    }
    let on_outline = x.len();
    let mut rng = ChaCha20Rng::seed_from_u64(recipe.seed);
    // the frame of the candidates: the body's box (θ = 0), or the box of the body turned by −θ
    let centre = (lo + hi) * 0.5;
    let (sin, cos) = recipe.rotation_deg.to_radians().sin_cos();
    let turn = |v: P, s: f64| P::new(cos * v.x - s * v.y, s * v.x + cos * v.y);
    let corners = [lo, hi, P::new(lo.x, hi.y), P::new(hi.x, lo.y)].map(|c| turn(c - centre, -sin));
    let (flo, fhi) = crate::geometry::points_box(&corners);
    let tol = 1e-9 * shape.size();
    let max_attempts = 1000 * target.max(16) as u64;
    let mut attempts = 0u64;
    while x.len() < target {
        attempts += 1;
        if attempts > max_attempts {
            return Err(format!(
                "placed {} of {} particles after {} random attempts: the body cannot hold a hexagonal lattice's density at discretisation.min_distance = {} × spacing; use a smaller min_distance",
                x.len(),
                target,
                max_attempts,
                recipe.min_distance
            ));
        }
        // θ = 0 draws in the body's own box directly (the same candidates as the turned
        // frame up to rounding; the recorded particle sets of the shipped scenes keep their bits)
        let p = if recipe.rotation_deg == 0.0 {
            P::new(
                lo.x + (hi.x - lo.x) * uniform(&mut rng),
                lo.y + (hi.y - lo.y) * uniform(&mut rng),
            )
        } else {
            let q = P::new(
                flo.x + (fhi.x - flo.x) * uniform(&mut rng),
                flo.y + (fhi.y - flo.y) * uniform(&mut rng),
            );
            centre + turn(q, sin)
        };
        if shape.contains(&p, -tol) && grid.free(&p, delta, &x) {
            grid.insert(&p, x.len() as u32);
            x.push(p);
        }
    }
    // Row-major order in rows one spacing high, as the lattice's: the neighbours of a particle
    // sit next to it in memory or one row away, not anywhere (the kernels gather them).
    let row = |p: &P| ((p.y - lo.y) / l0).floor() as i64;
    x.sort_by(|a, b| row(a).cmp(&row(b)).then(a.x.total_cmp(&b.x)));
    Ok((x, on_outline))
}

/// Bond every particle to its [`NEAREST_2D`] nearest (either-end rule, segments inside the
/// body) into `K` slots: neighbours, reverse slots, reference lengths.
#[allow(clippy::type_complexity)]
pub fn bond<const K: usize>(
    x: &[P],
    shape: &Shape2,
) -> Result<(Vec<[u32; K]>, Vec<[u8; K]>, Vec<[f64; K]>), String> {
    let tol = 1e-9 * shape.size();
    // seven points along the bond: a bond of up to twice the spacing cannot step over a
    // notch of the outline wider than a quarter of the spacing; cutouts are tested exactly
    bond_nearest::<2, K>(x, NEAREST_2D, |a, b| shape.segment_in_body(a, b, tol, 8))
}

/// Bond every particle of `x` to its `nearest` nearest particles where `inside` accepts the
/// segment, a bond existing where either end lists the other (3.50), into `K` slots:
/// neighbours, reverse slots, reference lengths (2D and 3D random bodies). A particle with
/// more than `K` bonds is an error.
#[allow(clippy::type_complexity)]
pub fn bond_nearest<const D: usize, const K: usize>(
    x: &[nalgebra::SVector<f64, D>],
    nearest: usize,
    inside: impl Fn(&nalgebra::SVector<f64, D>, &nalgebra::SVector<f64, D>) -> bool,
) -> Result<(Vec<[u32; K]>, Vec<[u8; K]>, Vec<[f64; K]>), String> {
    let tree: RTree<GeomWithData<[f64; D], u32>> = RTree::bulk_load(
        x.iter()
            .enumerate()
            .map(|(i, p)| GeomWithData::new(p.data.0[0], i as u32))
            .collect(),
    );
    let mut lists: Vec<Vec<u32>> = vec![Vec::with_capacity(2 * nearest); x.len()];
    for (i, p) in x.iter().enumerate() {
        for q in tree
            .nearest_neighbor_iter(&p.data.0[0])
            .filter(|q| q.data as usize != i)
            .take(nearest)
        {
            let j = q.data;
            if inside(p, &x[j as usize]) {
                lists[i].push(j);
                lists[j as usize].push(i as u32);
            }
        }
    }
    let n = x.len();
    let mut neighbours = vec![[NONE; K]; n];
    let mut l0 = vec![[0.0; K]; n];
    for (i, l) in lists.iter_mut().enumerate() {
        l.sort_unstable();
        l.dedup();
        if l.len() > K {
            return Err(format!(
                "particle {i} at {:?} m has {} bonds, more than the {K} slots of a random body",
                x[i].as_slice(),
                l.len()
            ));
        }
        for (k, &j) in l.iter().enumerate() {
            neighbours[i][k] = j;
            // (x_j − x_i) is exactly −(x_i − x_j): both ends hold the same length bits
            l0[i][k] = (x[j as usize] - x[i]).norm();
        }
    }
    let mut reverse = vec![[0u8; K]; n];
    for i in 0..n {
        for k in 0..K {
            let j = neighbours[i][k];
            if j == NONE {
                continue;
            }
            let r = neighbours[j as usize]
                .iter()
                .position(|&q| q == i as u32)
                .expect("bond lists are symmetric");
            reverse[i][k] = r as u8;
        }
    }
    Ok((neighbours, reverse, l0))
}

/// Generate a random body: particles, Voronoi volumes (× thickness), bonds, each particle's
/// length scale (its mean bond length); the cells; and what generation measured. A particle
/// without a bond inside the body is an error.
pub fn fill<const K: usize>(
    shape: &Shape2,
    recipe: &RandomParticles,
) -> Result<(Particles<2, K>, Vec<Vec<P>>, Generation), String> {
    let t0 = std::time::Instant::now();
    let (x, on_outline) = place(shape, recipe)?;
    let t1 = std::time::Instant::now();
    let cells = voronoi::clipped_cells(&x, shape)?;
    let t2 = std::time::Instant::now();
    let (neighbours, reverse, l0) = bond::<K>(&x, shape)?;
    let t3 = std::time::Instant::now();
    let volume: Vec<f64> = cells.iter().map(|c| c.1 * recipe.thickness).collect();
    let polygons: Vec<Vec<P>> = cells.into_iter().map(|c| c.0).collect();
    let mut p = Particles::new(x, volume, neighbours, reverse, l0, recipe.spacing);
    p.weighted_dilatation = true;
    if let Some(i) = (0..p.len()).find(|&i| p.bond_count(i) == 0) {
        return Err(format!(
            "particle {i} at ({:.6}, {:.6}) m has no bond inside the body (a sliver of the body thinner than the spacing); use a smaller discretisation.spacing",
            p.x0[i].x, p.x0[i].y
        ));
    }
    let generation = measure(
        &mut p,
        recipe.min_distance,
        on_outline,
        target_count(shape, recipe.spacing),
        [t0, t1, t2, t3],
    );
    Ok((p, polygons, generation))
}

/// What generation measured of a random body (2D or 3D) whose `length` still holds each
/// particle's shortest bond: the bond histogram and nearest distances; then each particle's
/// length scale becomes its mean bond length (the lattice's shortest bond is its only one:
/// ω_i and the crack band read it). `times`: the instants before placing, after placing,
/// after the cells and after bonding.
pub fn measure<const D: usize, const K: usize>(
    p: &mut Particles<D, K>,
    min_distance: f64,
    on_outline: usize,
    target: usize,
    times: [std::time::Instant; 4],
) -> Generation {
    let mut hist = vec![0usize; K + 1];
    let (mut nmin, mut nsum, mut nmax) = (f64::INFINITY, 0.0, 0.0f64);
    for i in 0..p.len() {
        hist[p.bond_count(i)] += 1;
        let near = p.length[i] / p.spacing;
        nmin = nmin.min(near);
        nmax = nmax.max(near);
        nsum += near;
    }
    while hist.last() == Some(&0) {
        hist.pop();
    }
    for i in 0..p.len() {
        let (mut sum, mut count) = (0.0, 0);
        for k in 0..K {
            if p.neighbours[i][k] != NONE {
                sum += p.l0[i][k];
                count += 1;
            }
        }
        p.length[i] = sum / count as f64;
    }
    let [t0, t1, t2, t3] = times;
    Generation {
        min_distance,
        particles: p.len(),
        outline_particles: on_outline,
        target,
        nearest_min: nmin,
        nearest_mean: nsum / p.len() as f64,
        nearest_max: nmax,
        bond_histogram: hist,
        seconds_placing: (t1 - t0).as_secs_f64(),
        seconds_voronoi: (t2 - t1).as_secs_f64(),
        seconds_bonding: (t3 - t2).as_secs_f64(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recipe(seed: u64) -> RandomParticles {
        RandomParticles {
            spacing: 0.005,
            min_distance: DEFAULT_MIN_DISTANCE,
            seed,
            rotation_deg: 0.0,
            thickness: 0.1,
        }
    }

    fn shapes() -> Vec<Shape2> {
        vec![
            Shape2::Rectangle {
                origin: P::new(0.0, 0.0),
                width: 0.1,
                height: 0.06,
            },
            Shape2::Disc {
                centre: P::new(0.0, 0.0),
                radius: 0.05,
            },
            Shape2::DogBone { size: 0.05 },
            Shape2::NotchedBeam {
                length: 0.2,
                depth: 0.05,
                notch_depth: 0.01,
                notch_width: 0.002,
            },
        ]
    }

    /// The clipped Voronoi cells sum to the body's area (1e-9 relative).
    #[test]
    fn cells_sum_to_the_body_area() {
        for s in shapes() {
            let (x, _) = place(&s, &recipe(7)).unwrap();
            let cells = voronoi::clipped_cells(&x, &s).unwrap();
            let sum: f64 = cells.iter().map(|c| c.1).sum();
            let rel = (sum - s.area()).abs() / s.area();
            assert!(rel < 1e-9, "{s:?}: cells sum to {sum}, area {}", s.area());
            assert!(cells.iter().all(|c| c.1 > 0.0), "{s:?}: an empty cell");
            // the drawn cells stay in the body; on straight-edged bodies they are the exact
            // clipped cells (their areas are the volumes' areas)
            // (arcs are drawn in chords of π/128: a sagitta of r·(1 − cos(π/256)) < 8e-5·r)
            let tol = if s.polygon().is_some() { 1e-9 } else { 8e-5 } * s.size();
            for (poly, area) in &cells {
                assert!(
                    poly.iter().all(|v| s.contains(v, tol)),
                    "{s:?}: a drawn cell leaves the body"
                );
                if s.polygon().is_some() {
                    let a = crate::geometry::polygon_area(poly);
                    assert!((a - area).abs() <= 1e-12 * s.area(), "{s:?}: {a} vs {area}");
                }
            }
        }
    }

    #[test]
    fn density_minimum_distance_and_outline() {
        for s in shapes() {
            let r = recipe(3);
            let (x, on) = place(&s, &r).unwrap();
            let target = s.area() / (0.5 * 3f64.sqrt() * r.spacing * r.spacing);
            assert!((x.len() as f64 - target).abs() <= 0.5 + 1e-9, "{s:?}");
            let delta = r.min_distance * r.spacing;
            for i in 0..x.len() {
                for j in 0..i {
                    assert!((x[i] - x[j]).norm() >= delta * (1.0 - 1e-12));
                }
            }
            let tol = 1e-9 * s.size();
            assert!(x.iter().all(|p| s.contains(p, tol)));
            assert!(on > 0);
        }
    }

    #[test]
    fn same_seed_same_particles_other_seed_other_particles() {
        let s = &shapes()[0];
        let a = place(s, &recipe(11)).unwrap().0;
        let b = place(s, &recipe(11)).unwrap().0;
        let c = place(s, &recipe(12)).unwrap().0;
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn bonds_are_symmetric_and_stay_in_the_body() {
        for s in shapes() {
            let (p, _, g) = fill::<SLOTS_2D>(&s, &recipe(5)).unwrap();
            p.check_topology().unwrap();
            // every particle lists its 6 nearest, so it has at least 6 bonds unless the body
            // cuts some off (outline, notch)
            let bulk = (0..p.len()).filter(|&i| p.bond_count(i) >= 6).count();
            assert!(bulk as f64 > 0.7 * p.len() as f64, "{s:?}: {g:?}");
            if let Shape2::NotchedBeam { length, .. } = s {
                for i in 0..p.len() {
                    for k in 0..SLOTS_2D {
                        let j = p.neighbours[i][k];
                        if j == NONE {
                            continue;
                        }
                        let (a, b) = (p.x0[i], p.x0[j as usize]);
                        let crosses = (a.x - 0.5 * length) * (b.x - 0.5 * length) < 0.0
                            && a.y.max(b.y) < 0.01;
                        assert!(!crosses, "bond {a:?}-{b:?} crosses the notch");
                    }
                }
            }
        }
    }

    /// A plate with a hole and a slit: the hole's edge and the slit's faces carry particles at
    /// the spacing, no bond passes through either, and the cells sum to the area.
    #[test]
    fn holes_and_slits_carry_outline_particles_and_no_bonds() {
        use crate::geometry::Cutout;
        let (c, r) = (P::new(0.03, 0.03), 0.01);
        let slit = Cutout::slit(P::new(0.07, 0.01), P::new(0.09, 0.05), 0.004);
        let s = Shape2::WithCutouts {
            outer: Box::new(shapes()[0].clone()),
            cutouts: vec![
                Cutout::Disc {
                    centre: c,
                    radius: r,
                },
                slit.clone(),
            ],
        };
        let rec = recipe(9);
        let (p, _, g) = fill::<SLOTS_2D>(&s, &rec).unwrap();
        p.check_topology().unwrap();
        let tol = 1e-9 * s.size();
        let on_hole =
            p.x0.iter()
                .filter(|x| ((*x - c).norm() - r).abs() <= tol)
                .count();
        let expected = (2.0 * std::f64::consts::PI * r / rec.spacing).round() as usize;
        assert_eq!(on_hole, expected);
        // both faces of the slit (4 mm wide, more than the minimum distance) carry particles
        let on_faces = p.x0.iter().filter(|x| slit.depth(x).abs() <= tol).count();
        let faces = 2.0 * (0.02f64.powi(2) + 0.04f64.powi(2)).sqrt() / rec.spacing;
        assert!(on_faces as f64 >= faces, "{on_faces}");
        for i in 0..p.len() {
            for k in 0..SLOTS_2D {
                let j = p.neighbours[i][k];
                if j == NONE {
                    continue;
                }
                let (a, b) = (p.x0[i], p.x0[j as usize]);
                assert!(
                    !slit.cuts_segment(&a, &b, tol),
                    "{a:?}-{b:?} through the slit"
                );
                // through the hole: only the short chords between its outline particles
                let d = b - a;
                let t = ((c - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
                if (a + d * t - c).norm() < r - tol {
                    assert!(((a - c).norm() - r).abs() <= tol && ((b - c).norm() - r).abs() <= tol);
                    assert!(d.norm() <= r);
                }
            }
        }
        let cells = voronoi::clipped_cells(&p.x0, &s).unwrap();
        let sum: f64 = cells.iter().map(|c| c.1).sum();
        assert!((sum - s.area()).abs() / s.area() < 1e-9);
        assert!(g.outline_particles >= on_hole + on_faces);
    }
}
