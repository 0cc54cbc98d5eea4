//! Bodies with holes, slits, notches and crack lines (`[[cutouts]]`): exact areas, Voronoi
//! cells that sum to the body's area, no bond through a cutout, a crack line that cuts
//! exactly the bonds crossing it, edge groups on the outer surface, and every validation
//! error naming its key and value. The geometry does not depend on the lattice's rotation
//! and offset, so every check runs at rotations 0, 15, 30 and 45° and several offsets (a
//! seeded ChaCha stream), and on random particles of several seeds and rotations.

use crate::common;
use common::says;

use nalgebra::Vector2;
use rand::rngs::ChaCha20Rng;
use rand::{Rng, SeedableRng};
use sppm::discretise::hex::HexLattice;
use sppm::discretise::random::{self, RandomParticles, DEFAULT_MIN_DISTANCE, SLOTS_2D};
use sppm::discretise::{voronoi, Particles, NONE};
use sppm::geometry::Shape2;
use sppm::Scene;
use std::f64::consts::PI;

type P = Vector2<f64>;

const W: f64 = 0.2;
const H: f64 = 0.1;
const L0: f64 = 0.002;

/// A cutout as the test sees it, to check bonds against independently of the library.
enum Hole {
    Disc(P, f64),
    /// Convex polygons (counter-clockwise) whose open interiors together make the cutout's.
    Convex(Vec<Vec<P>>),
    Crack(P, P),
}

/// Holes inside the plate: a disc, a non-convex L, a second disc, a turned rectangle.
const HOLES: &str = r#"
[[cutouts]]
shape = "disc"
centre = [0.05, 0.05]
diameter = 0.024
[[cutouts]]
shape = "polygon"
vertices = [[0.1, 0.03], [0.124, 0.03], [0.124, 0.042], [0.112, 0.042], [0.112, 0.054], [0.1, 0.054]]
[[cutouts]]
shape = "disc"
centre = [0.16, 0.065]
diameter = 0.016
[[cutouts]]
shape = "rectangle"
origin = [0.14, 0.015]
width = 0.03
height = 0.006
rotation_deg = 20.0
"#;

fn holes_exact() -> (f64, Vec<Hole>) {
    let s = 0.012;
    let area = W * H - PI * (0.012f64.powi(2) + 0.008f64.powi(2)) - 3.0 * s * s - 0.03 * 0.006;
    let rect = |x0: f64, y0: f64, x1: f64, y1: f64| {
        vec![
            P::new(x0, y0),
            P::new(x1, y0),
            P::new(x1, y1),
            P::new(x0, y1),
        ]
    };
    let (sn, cs) = 20f64.to_radians().sin_cos();
    let turn = |x: f64, y: f64| P::new(0.14 + cs * x - sn * y, 0.015 + sn * x + cs * y);
    (
        area,
        vec![
            Hole::Disc(P::new(0.05, 0.05), 0.012),
            // the L as two overlapping rectangles: every point of its interior is inside one
            Hole::Convex(vec![
                rect(0.1, 0.03, 0.124, 0.042),
                rect(0.1, 0.03, 0.112, 0.054),
            ]),
            Hole::Disc(P::new(0.16, 0.065), 0.008),
            Hole::Convex(vec![vec![
                turn(0.0, 0.0),
                turn(0.03, 0.0),
                turn(0.03, 0.006),
                turn(0.0, 0.006),
            ]]),
        ],
    )
}

/// Slits and notches: an inclined slit 2 mm wide, a notch across the bottom edge, a disc
/// across the top edge, an inclined crack line from the right edge.
fn slits_toml() -> String {
    let (s, c) = 30f64.to_radians().sin_cos();
    format!(
        r#"
[[cutouts]]
shape = "slit"
start = [0.03, 0.03]
end = [{}, {}]
width = 0.002
[[cutouts]]
shape = "rectangle"
origin = [0.099, -0.01]
width = 0.003
height = 0.04
[[cutouts]]
shape = "disc"
centre = [0.15, 0.097]
diameter = 0.02
[[cutouts]]
shape = "slit"
start = [0.21, 0.02]
end = [0.17, 0.05]
width = 0.0
"#,
        0.03 + 0.04 * c,
        0.03 + 0.04 * s
    )
}

fn slits_exact() -> (f64, Vec<Hole>) {
    let (s, c) = 30f64.to_radians().sin_cos();
    let (a, b) = (P::new(0.03, 0.03), P::new(0.03 + 0.04 * c, 0.03 + 0.04 * s));
    let n = P::new(-s, c) * 0.001;
    let (r, d) = (0.01f64, 0.003f64);
    // the disc's part above the top edge (y = 0.1), d above its centre
    let above = r * r * (d / r).acos() - d * (r * r - d * d).sqrt();
    let area = W * H - 0.002 * 0.04 - 0.003 * 0.03 - (PI * r * r - above);
    (
        area,
        vec![
            Hole::Convex(vec![vec![a - n, b - n, b + n, a + n]]),
            Hole::Convex(vec![vec![
                P::new(0.099, -0.01),
                P::new(0.102, -0.01),
                P::new(0.102, 0.03),
                P::new(0.099, 0.03),
            ]]),
            Hole::Disc(P::new(0.15, 0.097), r),
            Hole::Crack(P::new(0.21, 0.02), P::new(0.17, 0.05)),
        ],
    )
}

/// Cutouts that touch: a notch flush with the bottom edge, a disc touching it from inside,
/// two rectangles that share an edge.
const TOUCHING: &str = r#"
[[cutouts]]
shape = "rectangle"
origin = [0.05, 0.0]
width = 0.01
height = 0.02
[[cutouts]]
shape = "disc"
centre = [0.12, 0.01]
diameter = 0.02
[[cutouts]]
shape = "rectangle"
origin = [0.15, 0.04]
width = 0.02
height = 0.02
[[cutouts]]
shape = "rectangle"
origin = [0.17, 0.04]
width = 0.02
height = 0.02
"#;

fn touching_exact() -> (f64, Vec<Hole>) {
    let rect = |x0: f64, y0: f64, x1: f64, y1: f64| {
        vec![
            P::new(x0, y0),
            P::new(x1, y0),
            P::new(x1, y1),
            P::new(x0, y1),
        ]
    };
    let area = W * H - 0.01 * 0.02 - PI * 1e-4 - 2.0 * 0.02 * 0.02;
    (
        area,
        vec![
            // the notch reaches below the plate here: no bond may run along its mouth
            Hole::Convex(vec![rect(0.05, -1.0, 0.06, 0.02)]),
            Hole::Disc(P::new(0.12, 0.01), 0.01),
            // the two rectangles as one: no bond may run along the edge they share
            Hole::Convex(vec![rect(0.15, 0.04, 0.19, 0.06)]),
        ],
    )
}

fn plate(cutouts: &str, lattice: &str, rotation: f64, offset: [f64; 2]) -> String {
    format!(
        r#"
name = "cutouts"
seed = 3
{cutouts}
[body]
shape = "rectangle"
width = {W}
height = {H}
[discretisation]
lattice = "{lattice}"
spacing = {L0}
rotation_deg = {rotation}
offset = [{}, {}]
[material]
E = 30.0e9
nu = 0.2
rho = 2400.0
thickness = 0.05
[[groups]]
name = "bottom"
select = {{ by = "edge", edge = "bottom", rows = 2 }}
fix = ["y"]
[[groups]]
name = "top"
select = {{ by = "edge", edge = "top", rows = 2 }}
load = {{ component = "y", displacement = 1.0e-5 }}
[loading]
end_periods = 2.0
"#,
        offset[0], offset[1]
    )
}

/// The bodies under test: (name, cutouts, exact area, holes).
fn bodies() -> Vec<(&'static str, String, f64, Vec<Hole>)> {
    let (a, h) = holes_exact();
    let (b, s) = slits_exact();
    let (c, t) = touching_exact();
    vec![
        ("holes", HOLES.to_string(), a, h),
        ("slits", slits_toml(), b, s),
        ("touching", TOUCHING.to_string(), c, t),
    ]
}

/// Rotations 0, 15, 30, 45° with three offsets each (the first 0), from a seeded stream.
fn placements() -> Vec<(f64, [f64; 2])> {
    let mut rng = ChaCha20Rng::seed_from_u64(20240401);
    let mut unit = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    let mut out = vec![];
    for rot in [0.0, 15.0, 30.0, 45.0] {
        out.push((rot, [0.0, 0.0]));
        for _ in 0..2 {
            out.push((rot, [unit() * L0, unit() * L0]));
        }
    }
    out
}

fn shape_of(cutouts: &str) -> Shape2 {
    Scene::from_toml_str(&plate(cutouts, "hexagonal", 0.0, [0.0, 0.0]), &[])
        .expect("test scene is valid")
        .shape()
}

fn lattice(rotation: f64, offset: [f64; 2]) -> HexLattice {
    HexLattice {
        spacing: L0,
        rotation_deg: rotation,
        offset: P::new(offset[0], offset[1]),
        thickness: 0.05,
    }
}

fn seg_distance(a: &P, b: &P, p: &P) -> f64 {
    let d = b - a;
    let t = ((p - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
    (a + d * t - p).norm()
}

fn cross(u: &P, v: &P) -> f64 {
    u.x * v.y - u.y * v.x
}

/// Whether the segment a–b passes through the open interior of the hole, deeper than `tol`
/// (Cyrus–Beck against each convex part shrunk by `tol`; the disc's distance; the crack's
/// proper crossing). A chord no longer than the radius between two points on a hole's
/// circle stays (a bond along the hole's surface, `Cutout::cuts_segment`).
fn crosses(hole: &Hole, a: &P, b: &P, tol: f64) -> bool {
    match hole {
        Hole::Disc(c, r) => {
            let on = |p: &P| ((p - c).norm() - r).abs() <= tol;
            seg_distance(a, b, c) < r - tol && !(on(a) && on(b) && (b - a).norm() <= *r)
        }
        Hole::Convex(parts) => parts.iter().any(|poly| {
            let (mut t0, mut t1) = (0.0f64, 1.0f64);
            let d = b - a;
            for i in 0..poly.len() {
                let e = poly[(i + 1) % poly.len()] - poly[i];
                let n = P::new(e.y, -e.x) / e.norm(); // outward
                let c = n.dot(&poly[i]) - tol;
                // n·(a + t d) ≤ c
                let (num, den) = (c - n.dot(a), n.dot(&d));
                if den == 0.0 {
                    if num < 0.0 {
                        return false;
                    }
                } else if den > 0.0 {
                    t1 = t1.min(num / den);
                } else {
                    t0 = t0.max(num / den);
                }
            }
            t1 > t0
        }),
        Hole::Crack(s, e) => {
            let side = |p: &P| cross(&(e - s), &(p - s)) / (e - s).norm();
            let tip = |p: &P| cross(&(b - a), &(p - a)) / (b - a).norm();
            side(a) * side(b) < 0.0
                && side(a).abs() > tol
                && side(b).abs() > tol
                && tip(s) * tip(e) < 0.0
                && tip(s).abs() > tol
                && tip(e).abs() > tol
        }
    }
}

fn bonds<const K: usize>(p: &Particles<2, K>) -> Vec<(usize, usize)> {
    let mut out = vec![];
    for i in 0..p.len() {
        for &j in &p.neighbours[i] {
            if j != NONE && (j as usize) > i {
                out.push((i, j as usize));
            }
        }
    }
    out
}

#[test]
fn scene_areas_are_exact() {
    for (name, cutouts, exact, _) in bodies() {
        let a = shape_of(&cutouts).area();
        assert!((a - exact).abs() / exact < 1e-12, "{name}: {a} vs {exact}");
    }
}

/// The clipped Voronoi cells of lattice positions sum to the body's area (1e-9 relative),
/// every bond avoids every cutout, and the particle count × cell area is within 3% of it.
#[test]
fn lattices_cells_bonds_and_density() {
    for (name, cutouts, exact, holes) in bodies() {
        let shape = shape_of(&cutouts);
        let tol = 1e-9 * shape.size();
        for (rot, offset) in placements() {
            let lat = lattice(rot, offset);
            let p = lat.fill(&shape);
            p.check_topology().unwrap();
            let cells = voronoi::clipped_cells(&p.x0, &shape).unwrap();
            let sum: f64 = cells.iter().map(|c| c.1).sum();
            assert!(
                (sum - exact).abs() / exact < 1e-9,
                "{name} at {rot}°, {offset:?}: cells sum to {sum}, area {exact}"
            );
            let count = p.len() as f64 * lat.cell_area();
            assert!(
                (count - exact).abs() / exact < 0.03,
                "{name} at {rot}°, {offset:?}: {} particles × cell = {count}, area {exact}",
                p.len()
            );
            for (i, j) in bonds(&p) {
                let (a, b) = (p.x0[i], p.x0[j]);
                for (k, h) in holes.iter().enumerate() {
                    assert!(
                        !crosses(h, &a, &b, tol),
                        "{name} at {rot}°, {offset:?}: bond {a:?}–{b:?} crosses cutout {k}"
                    );
                }
            }
            // no particle inside a cutout
            for x in &p.x0 {
                assert!(
                    shape.contains(x, tol),
                    "{name}: particle {x:?} outside the body"
                );
            }
        }
    }
}

/// The same for random particles of several seeds and rotations: cells sum to the area,
/// every particle has a positive cell, no bond through a cutout, and the holes' edges carry
/// particles.
#[test]
fn random_particles_cells_and_bonds() {
    for (name, cutouts, exact, holes) in bodies() {
        let shape = shape_of(&cutouts);
        let tol = 1e-9 * shape.size();
        for (seed, rot) in [(1u64, 0.0), (2, 15.0), (3, 30.0), (4, 45.0)] {
            let recipe = RandomParticles {
                spacing: L0,
                min_distance: DEFAULT_MIN_DISTANCE,
                seed,
                rotation_deg: rot,
                thickness: 0.05,
            };
            let (p, _, generation) = random::fill::<SLOTS_2D>(&shape, &recipe).unwrap();
            p.check_topology().unwrap();
            let cells = voronoi::clipped_cells(&p.x0, &shape).unwrap();
            let sum: f64 = cells.iter().map(|c| c.1).sum();
            assert!(
                (sum - exact).abs() / exact < 1e-9,
                "{name}, seed {seed}: cells sum to {sum}, area {exact}"
            );
            assert!(cells.iter().all(|c| c.1 > 0.0), "{name}: an empty cell");
            let volume: f64 = p.volume.iter().sum::<f64>() / 0.05;
            assert!((volume - exact).abs() / exact < 1e-9);
            for (i, j) in bonds(&p) {
                let (a, b) = (p.x0[i], p.x0[j]);
                for (k, h) in holes.iter().enumerate() {
                    assert!(
                        !crosses(h, &a, &b, tol),
                        "{name}, seed {seed}: bond {a:?}–{b:?} crosses cutout {k}"
                    );
                }
            }
            // the outline includes the holes: about circumference / L0 particles on each disc
            for h in &holes {
                if let Hole::Disc(c, r) = h {
                    let on =
                        p.x0.iter()
                            .filter(|x| ((*x - c).norm() - r).abs() <= tol)
                            .count();
                    assert!(on > 0, "{name}: no particle on the hole at {c:?}");
                }
            }
            assert!(generation.outline_particles > 0);
        }
    }
}

/// A crack line (a slit of width 0) removes no particle and cuts exactly the lattice bonds
/// that cross it.
#[test]
fn a_crack_line_cuts_exactly_the_bonds_that_cross_it() {
    let (a, b) = (P::new(0.05, 0.02), P::new(0.15, 0.075));
    let crack = format!(
        "[[cutouts]]\nshape = \"slit\"\nstart = [{}, {}]\nend = [{}, {}]\nwidth = 0.0\n",
        a.x, a.y, b.x, b.y
    );
    let cracked = shape_of(&crack);
    let whole = Shape2::Rectangle {
        origin: P::zeros(),
        width: W,
        height: H,
    };
    assert_eq!(cracked.area(), whole.area());
    let tol = 1e-9 * whole.size();
    for (rot, offset) in placements() {
        let lat = lattice(rot, offset);
        let (p0, p1) = (lat.fill(&whole), lat.fill(&cracked));
        assert_eq!(
            p0.x0, p1.x0,
            "{rot}°, {offset:?}: the crack moved particles"
        );
        let kept: std::collections::HashSet<(usize, usize)> = bonds(&p1).into_iter().collect();
        let mut cut = 0;
        for (i, j) in bonds(&p0) {
            let across = crosses(&Hole::Crack(a, b), &p0.x0[i], &p0.x0[j], tol);
            assert_eq!(
                !kept.contains(&(i, j)),
                across,
                "{rot}°, {offset:?}: bond {:?}–{:?}",
                p0.x0[i],
                p0.x0[j]
            );
            cut += across as usize;
        }
        // about two bonds per lattice spacing along the crack (more when it runs across
        // the lattice's rows)
        let per_spacing = cut as f64 / ((b - a).norm() / L0);
        assert!((1.0..4.0).contains(&per_spacing), "{rot}°: {cut} bonds cut");
    }
}

/// Edge and strip groups select on the outer surface: a hole in the middle changes none
/// of them.
#[test]
fn groups_select_on_the_outer_surface() {
    let hole = "[[cutouts]]\nshape = \"disc\"\ncentre = [0.1, 0.05]\ndiameter = 0.03\n";
    let groups = r#"
[[groups]]
name = "left"
select = { by = "edge", edge = "left", rows = 2 }
fix = ["x"]
[[groups]]
name = "strip"
select = { by = "strip", edge = "top", width = 0.02, centre = 0.1 }
"#;
    for (rot, offset) in placements().into_iter().step_by(2) {
        let with = common::scene(&(plate(hole, "hexagonal", rot, offset) + groups));
        let without = common::scene(&(plate("", "hexagonal", rot, offset) + groups));
        let (a, b) = (
            sppm::run::prepare_model(&with, sppm::run::Hexagonal).unwrap(),
            sppm::run::prepare_model(&without, sppm::run::Hexagonal).unwrap(),
        );
        assert!(a.particles.len() < b.particles.len());
        for (ga, gb) in a.groups.iter().zip(&b.groups) {
            let pos = |m: &sppm::run::Model, g: &sppm::discretise::groups::Group| {
                let mut v: Vec<[u64; 2]> = g
                    .members
                    .iter()
                    .map(|&i| {
                        let x = m.particles.x0[i as usize];
                        [x.x.to_bits(), x.y.to_bits()]
                    })
                    .collect();
                v.sort();
                v
            };
            assert!(!ga.members.is_empty(), "{}", ga.name);
            assert_eq!(pos(&a, ga), pos(&b, gb), "{} at {rot}°", ga.name);
        }
    }
}

/// A scene with cutouts runs: the shipped plate with a hole, coarsened.
#[test]
fn a_plate_with_a_hole_prepares_and_its_overrides_reach_the_cutouts() {
    let text = std::fs::read_to_string("lattices/plate_with_hole.toml").unwrap();
    let s = Scene::from_toml_str(
        &text,
        &[
            "discretisation.spacing=0.002".into(),
            "cutouts.0.diameter=0.02".into(),
        ],
    )
    .unwrap();
    let area = 0.1 * 0.1 - PI * 0.01 * 0.01;
    assert!((s.shape().area() - area).abs() / area < 1e-14);
    let m = sppm::run::prepare_model(&s, sppm::run::Hexagonal).unwrap();
    let c = P::new(0.05, 0.05);
    assert!(m
        .particles
        .x0
        .iter()
        .all(|x| (x - c).norm() >= 0.01 - 1e-12));
    let e = Scene::from_toml_str(&text, &["cutouts.0.diameter=-1".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("cutouts[0].diameter = -1"), "{e}");
}

fn error_of(cutouts: &str) -> String {
    error_in(&plate(cutouts, "hexagonal", 0.0, [0.0, 0.0]))
}

fn error_in(text: &str) -> String {
    match Scene::from_toml_str(text, &[]) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn every_cutout_error_names_its_key_and_value() {
    let disc =
        |c: &str, d: &str| format!("[[cutouts]]\nshape = \"disc\"\ncentre = {c}\ndiameter = {d}\n");
    says(
        &error_of(&disc("[0.1, 0.05]", "-1")),
        &["cutouts[0].diameter = -1", "greater than zero"],
    );
    says(
        &error_of(&disc("[nan, 0.05]", "0.01")),
        &["cutouts[0].centre[0] = NaN", "finite"],
    );
    says(
        &error_of("[[cutouts]]\nshape = \"polygon\"\nvertices = [[0.1, 0.05], [0.12, 0.05]]\n"),
        &["cutouts[0].vertices = 2 vertices", "at least 3"],
    );
    says(
        &error_of(
            "[[cutouts]]\nshape = \"polygon\"\nvertices = [[0.1, 0.04], [0.14, 0.07], [0.14, 0.04], [0.1, 0.06]]\n",
        ),
        &["cutouts[0].vertices = [[0.1, 0.04]", "simple polygon"],
    );
    says(
        &error_of("[[cutouts]]\nshape = \"slit\"\nstart = [0.1, 0.05]\nend = [0.1, 0.05]\nwidth = 0.001\n"),
        &["cutouts[0].end = [0.1, 0.05]", "non-zero length"],
    );
    says(
        &error_of("[[cutouts]]\nshape = \"slit\"\nstart = [0.1, 0.05]\nend = [0.12, 0.05]\nwidth = -0.001\n"),
        &["cutouts[0].width = -0.001", "a width from 0"],
    );
    says(
        &error_of("[[cutouts]]\nshape = \"rectangle\"\norigin = [0.1, 0.05]\nwidth = 0.0\nheight = 0.01\n"),
        &["cutouts[0].width = 0", "greater than zero"],
    );
    says(
        &error_of(&disc("[0.5, 0.05]", "0.01")),
        &[
            "cutouts[0] = { shape = \"disc\", centre = [0.5, 0.05], diameter = 0.01 }",
            "lies outside the body",
        ],
    );
    says(
        &error_of(
            "[[cutouts]]\nshape = \"slit\"\nstart = [0.3, 0.05]\nend = [0.4, 0.05]\nwidth = 0.0\n",
        ),
        &["cutouts[0] = { shape = \"slit\"", "lies outside the body"],
    );
    says(
        &error_of(&format!(
            "{}{}",
            disc("[0.1, 0.05]", "0.02"),
            disc("[0.115, 0.05]", "0.02")
        )),
        &[
            "cutouts[1] = { shape = \"disc\", centre = [0.115, 0.05]",
            "cutouts must not overlap",
            "cutouts[0] = { shape = \"disc\", centre = [0.1, 0.05]",
        ],
    );
    // a crack line may cross a hole
    Scene::from_toml_str(
        &plate(
            &format!(
                "{}[[cutouts]]\nshape = \"slit\"\nstart = [0.1, 0.05]\nend = [0.13, 0.05]\nwidth = 0.0\n",
                disc("[0.1, 0.05]", "0.02")
            ),
            "hexagonal",
            0.0,
            [0.0, 0.0],
        ),
        &[],
    )
    .unwrap();
    says(
        &error_of("[[cutouts]]\nshape = \"rectangle\"\norigin = [-0.1, -0.1]\nwidth = 1.0\nheight = 1.0\n"),
        &["cutouts[0] = { shape = \"rectangle\"", "removes the whole body"],
    );
    says(
        &error_of(
            "[[cutouts]]\nshape = \"rectangle\"\norigin = [-0.1, -0.1]\nwidth = 0.2\nheight = 1.0\n[[cutouts]]\nshape = \"rectangle\"\norigin = [0.1, -0.1]\nwidth = 0.2\nheight = 1.0\n",
        ),
        &["cutouts = 2 cutouts", "remove all of it"],
    );
    // a disc across a disc body's outline has no exact area: refused
    let cylinder = r#"
[body]
shape = "disc"
diameter = 0.15
[[cutouts]]
shape = "disc"
centre = [0.075, 0.0]
diameter = 0.02
[discretisation]
spacing = 0.005
[material]
E = 30.0e9
nu = 0.2
rho = 2400.0
thickness = 0.05
"#;
    says(
        &error_in(cylinder),
        &[
            "cutouts[0] = { shape = \"disc\", centre = [0.075, 0.0]",
            "no exact area",
        ],
    );
    // a polygon notch in a disc body is exact, and accepted
    Scene::from_toml_str(
        &cylinder.replace(
            "shape = \"disc\"\ncentre = [0.075, 0.0]\ndiameter = 0.02",
            "shape = \"rectangle\"\norigin = [0.07, -0.001]\nwidth = 0.02\nheight = 0.002",
        ),
        &[],
    )
    .unwrap();
    // parse errors name the key
    says(
        &error_of("[[cutouts]]\nshape = \"disc\"\ncentre = [0.1, 0.05]\nradius = 0.01\n"),
        &["unknown field `radius`", "diameter"],
    );
    says(
        &error_of("[[cutouts]]\nshape = \"ellipse\"\ncentre = [0.1, 0.05]\n"),
        &["ellipse", "disc"],
    );
}

mod generated {
    use super::*;
    use proptest::prelude::*;

    /// Mostly coordinates about the plate (0.2 × 0.1) from `lo` to `hi`, sometimes its edges
    /// or any float.
    fn coordinate(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
        prop_oneof![
            16 => lo..hi,
            1 => Just(0.0),
            1 => Just(0.1),
            1 => prop::num::f64::ANY,
        ]
    }

    /// Mostly lengths up to 40% of the plate's height, sometimes 0, negative or any float.
    fn length() -> impl Strategy<Value = f64> {
        prop_oneof![
            16 => 0.0..0.04f64,
            1 => Just(0.0),
            1 => -0.01..0.0f64,
            1 => prop::num::f64::ANY,
        ]
    }

    fn point() -> impl Strategy<Value = [f64; 2]> {
        [coordinate(-0.03, 0.23), coordinate(-0.03, 0.13)]
    }

    /// Star-shaped (simple) polygons mostly, sometimes any vertices.
    fn vertices() -> impl Strategy<Value = Vec<[f64; 2]>> {
        prop_oneof![
            4 => (point(), prop::collection::vec((0.0..1.0f64, 0.002..0.03f64), 3..9)).prop_map(
                |(c, mut v)| {
                    v.sort_by(|a, b| a.0.total_cmp(&b.0));
                    v.iter()
                        .map(|(t, r)| {
                            let th = 2.0 * PI * t;
                            [c[0] + r * th.cos(), c[1] + r * th.sin()]
                        })
                        .collect()
                }
            ),
            1 => prop::collection::vec(point(), 0..7),
        ]
    }

    fn cutout() -> impl Strategy<Value = String> {
        // TOML spells the special floats inf, -inf and nan
        let t = |v: f64| format!("{v:?}").replace("NaN", "nan");
        let p = move |a: [f64; 2]| format!("[{}, {}]", t(a[0]), t(a[1]));
        prop_oneof![
            (point(), length()).prop_map(move |(c, d)| format!(
                "[[cutouts]]\nshape = \"disc\"\ncentre = {}\ndiameter = {}\n",
                p(c),
                t(d)
            )),
            vertices().prop_map(move |v| format!(
                "[[cutouts]]\nshape = \"polygon\"\nvertices = [{}]\n",
                v.iter().map(|a| p(*a)).collect::<Vec<_>>().join(", ")
            )),
            (point(), point(), length()).prop_map(move |(a, b, w)| format!(
                "[[cutouts]]\nshape = \"slit\"\nstart = {}\nend = {}\nwidth = {}\n",
                p(a),
                p(b),
                t(0.1 * w)
            )),
            (point(), length(), length(), -90.0..90.0f64).prop_map(move |(o, w, h, r)| format!(
                "[[cutouts]]\nshape = \"rectangle\"\norigin = {}\nwidth = {}\nheight = {}\nrotation_deg = {}\n",
                p(o),
                t(w),
                t(h),
                t(r)
            )),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 400, failure_persistence: None, ..ProptestConfig::default() })]

        /// Random cutouts on a plate: the scene is refused with a message naming a cutout,
        /// or it discretises (lattice or random particles) with no bond through a cutout
        /// and cells that sum to its area.
        #[test]
        fn random_cutouts_are_refused_by_name_or_discretise(
            cuts in prop::collection::vec(cutout(), 1..4),
            random in prop::bool::ANY,
            rot in 0.0..60.0f64,
        ) {
            let text = plate(&cuts.concat(), if random { "random" } else { "hexagonal" }, rot, [0.0, 0.0])
                .replace(&format!("spacing = {L0}"), "spacing = 0.005");
            let scene = match Scene::from_toml_str(&text, &[]) {
                Ok(s) => s,
                Err(e) => {
                    let m = e.to_string();
                    prop_assert!(m.contains("cutouts"), "{m}\n{text}");
                    return Ok(());
                }
            };
            let shape = scene.shape();
            let tol = 1e-9 * shape.size();
            let x: Vec<P> = if random {
                match sppm::run::prepare::prepare_model(&scene, sppm::run::RandomPlane::default()) {
                    Ok(m) => {
                        let cutouts = match &shape { Shape2::WithCutouts { cutouts, .. } => cutouts.clone(), _ => vec![] };
                        for (i, j) in bonds(&m.particles) {
                            let (a, b) = (m.particles.x0[i], m.particles.x0[j]);
                            prop_assert!(!cutouts.iter().any(|c| c.cuts_segment(&a, &b, tol)));
                        }
                        m.particles.x0.clone()
                    }
                    // a sliver thinner than the spacing, a group the cutouts emptied
                    Err(e) => { prop_assert!(!e.to_string().is_empty()); return Ok(()); }
                }
            } else {
                let p = lattice(rot, [0.0, 0.0]).fill(&shape);
                p.check_topology().unwrap();
                p.x0.clone()
            };
            if x.len() >= 3 {
                if let Ok(cells) = voronoi::clipped_cells(&x, &shape) {
                    let sum: f64 = cells.iter().map(|c| c.1).sum();
                    let area = shape.area();
                    prop_assert!((sum - area).abs() <= 1e-9 * W * H, "cells {sum} area {area}\n{text}");
                }
            }
        }
    }
}
