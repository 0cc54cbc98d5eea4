//! Surfaces: the lattice's boundary particles weighted by their clipped
//! Voronoi cells (`discretisation.surface`), and the recovered stress at free surfaces.
//!
//! Measured tables (all methods, more depths, rotations and offsets):
//! `cargo run --release --example surfaces`, benchmarks/RESULTS.md "Surfaces".

use nalgebra::{Matrix2, Vector2};
use sppm::run::stress_recovery::elastic_stress;
use sppm::run::{particle_stress, prepare_model};
use sppm::solver::modal::static_response;
use sppm::study::elastic_checks::{cantilever_stiffness, plate_modulus, plate_scene, Placement};
use sppm::Scene;

fn placement(rotation_deg: f64, offset: [f64; 2], surface: &'static str) -> Placement {
    Placement {
        spacing: 0.001,
        rotation_deg,
        offset,
        surface,
    }
}

/// Offsets within a cell: the origin and two drawn once (fixed here so the test is
/// reproducible).
const OFFSETS: [[f64; 2]; 3] = [[0.0, 0.0], [0.37, 0.61], [0.83, 0.12]];

/// Every shipped lattice body carries ρ·V of the real body at rotations 0/15/30/45° and three
/// offsets. Asked: 0.5%; the clipped cells are exact, so the test holds them to
/// round-off (1e-9).
#[test]
fn every_shipped_body_carries_its_mass_at_any_rotation_and_offset() {
    let mut checked = 0;
    for entry in std::fs::read_dir("lattices").unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let base = Scene::from_toml_str(&text, &[]).unwrap();
        // random particles and the bond-based grid (whole cells) are not lattice bodies
        if base.discretisation.is_random()
            || base.discretisation.lattice == sppm::scene::Lattice::Cubic
        {
            continue;
        }
        let l0 = base.discretisation.spacing;
        if base.dim() == 3 {
            // a 3D body (FCC): three angles, three offsets
            for rot in [
                [0.0, 0.0, 0.0],
                [15.0, 0.0, 0.0],
                [30.0, 20.0, 10.0],
                [45.0, 35.26, 0.0],
            ] {
                for off in OFFSETS {
                    // at twice the shipped spacing: the same shapes, an eighth of the cells
                    let sets = [
                        format!("discretisation.rotation_deg={rot:?}"),
                        format!(
                            "discretisation.offset=[{}, {}, {}]",
                            off[0] * l0,
                            off[1] * l0,
                            0.5 * off[0] * l0
                        ),
                        format!("discretisation.spacing={}", 2.0 * l0),
                    ];
                    let scene = Scene::from_toml_str(&text, &sets).unwrap();
                    // the body alone: a scene's groups (a beam's single-column supports)
                    // need its own lattice position
                    let (p, _) = sppm::run::generate::fcc_body(&scene).unwrap();
                    let rho = scene.material.rho;
                    let want = rho * scene.solid().unwrap().volume();
                    let got: f64 = p.volume.iter().map(|v| rho * v).sum();
                    assert!(
                        (got / want - 1.0).abs() < 1e-9,
                        "{}: rotation {rot:?}, offset {off:?}: mass {got} against {want}",
                        path.display()
                    );
                    checked += 1;
                }
            }
            continue;
        }
        for rot in [0.0, 15.0, 30.0, 45.0] {
            for off in OFFSETS {
                let sets = [
                    format!("discretisation.rotation_deg={rot}"),
                    format!("discretisation.offset=[{}, {}]", off[0] * l0, off[1] * l0),
                ];
                let scene = Scene::from_toml_str(&text, &sets).unwrap();
                let model = prepare_model(&scene, sppm::run::Hexagonal).unwrap();
                let m = &scene.material;
                let want = m.rho * scene.shape().area() * m.thickness();
                let got: f64 = model.mech.mass.iter().sum();
                assert!(
                    (got / want - 1.0).abs() < 1e-9,
                    "{}: rotation {rot}, offset {off:?}: mass {got} against {want}",
                    path.display()
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 7 * 12, "{checked} bodies checked");
}

/// docs/validation.md §A on plates of 20 and 40 spacings: E and ν within 1% at rotations 0, 15
/// and 30° (faces across the lattice rows, oblique, along them).
#[test]
fn plate_in_tension_modulus_within_one_percent() {
    for w_l0 in [20.0, 40.0] {
        for rot in [0.0, 15.0, 30.0] {
            let w = w_l0 * 0.001;
            let (e, nu) =
                plate_modulus(w, 2.0 * w, &placement(rot, [0.0; 2], "voronoi_fit")).unwrap();
            println!(
                "W/L0 {w_l0}, rotation {rot}: E {:+.3}%, nu {:+.3}%",
                (e - 1.0) * 100.0,
                (nu - 1.0) * 100.0
            );
            assert!(
                (e - 1.0).abs() < 0.01,
                "W/L0 {w_l0}, rotation {rot}: E/E0 = {e}"
            );
            assert!(
                (nu - 1.0).abs() < 0.01,
                "W/L0 {w_l0}, rotation {rot}: nu/nu0 = {nu}"
            );
        }
    }
}

/// A member whose faces lie on lattice rows: with clipped cells the face rows weigh half,
/// so the section's second moment is the trapezoid rule's, exact to 2·(p/h)² (p the row
/// pitch); volume-scaled moduli then give Timoshenko's tip stiffness within that and the
/// clamp's and load's discreteness (0.5%). The source's full cells are a row too deep
/// (+3p/h, 12% at h = 20·L0), which this test also shows.
#[test]
fn faces_on_rows_bend_as_the_trapezoid_rule_predicts() {
    let pitch = 0.5 * 3f64.sqrt() * 0.001;
    for rows in [12.0, 24.0] {
        let h = rows * pitch;
        let tol = 2.0 * (pitch / h).powi(2) + 0.005;
        let (k, _) =
            cantilever_stiffness(h, 10.0 * h, &placement(0.0, [0.0; 2], "voronoi")).unwrap();
        let (k_src, _) =
            cantilever_stiffness(h, 10.0 * h, &placement(0.0, [0.0; 2], "lattice")).unwrap();
        println!(
            "h = {rows} pitches: voronoi {:+.2}%, lattice {:+.2}% (3p/h = {:.2}%)",
            (k - 1.0) * 100.0,
            (k_src - 1.0) * 100.0,
            300.0 * pitch / h
        );
        assert!(
            (k - 1.0).abs() < tol,
            "h = {rows} pitches: stiffness ratio {k}"
        );
        assert!(
            k_src - 1.0 > 0.5 * 3.0 * pitch / h,
            "h = {rows} pitches: the source's ratio {k_src}"
        );
    }
}

/// Oblique faces (rotation 15°) lose stiffness in a surface layer a fraction of L0 deep (the
/// ragged surface relaxes); the error is first order in L0/h: doubling the depth at least
/// nearly halves it.
#[test]
fn oblique_face_bending_error_is_first_order() {
    let l0 = 0.001;
    let err = |h: f64| {
        let (k, _) =
            cantilever_stiffness(h, 10.0 * h, &placement(15.0, [0.0; 2], "voronoi_fit")).unwrap();
        k - 1.0
    };
    let (e10, e20) = (err(10.0 * l0), err(20.0 * l0));
    println!(
        "rotation 15: h = 10 L0 {:+.2}%, 20 L0 {:+.2}%",
        e10 * 100.0,
        e20 * 100.0
    );
    assert!(e20.abs() <= 0.6 * e10.abs(), "{e10} then {e20}");
}

/// The recovered stress at a traction-free face (`run::stress_recovery`): on faces along the
/// lattice rows (rotation 30° of a plate pulled along y) the normal stress below 5% of the
/// far-field stress and the tangential stress within 5% of it, where (3.18) over-reads the
/// tangential stress by 23% (fitted moduli over the clipped volume).
#[test]
fn free_faces_carry_no_normal_traction_and_the_far_field_tangential_stress() {
    for rot in [30.0, 0.0, 15.0] {
        let (w, h) = (0.02, 0.04);
        let model = prepare_model(
            &plate_scene(w, h, &placement(rot, [0.0; 2], "voronoi_fit")).unwrap(),
            sppm::run::Hexagonal,
        )
        .unwrap();
        let n = model.particles.len();
        let mut ubar = vec![Vector2::zeros(); n];
        for pr in &model.prescribed {
            ubar[pr.particle as usize][pr.component as usize] = pr.amplitude;
        }
        let x0 = &model.particles.x0;
        let u = static_response(&model.mech, x0, &model.constrained, &ubar).unwrap();
        let x: Vec<Vector2<f64>> = x0.iter().zip(&u).map(|(a, b)| a + b).collect();
        let sigma = elastic_stress(&model, &x);
        let source = particle_stress(&model.mech, &model.particles.volume, &x);
        // far field: the mean σyy over the middle quarter of the plate
        let mid: Vec<usize> = (0..n)
            .filter(|&i| {
                (x0[i].x - 0.5 * w).abs() < 0.125 * w && (x0[i].y - 0.5 * h).abs() < 0.25 * h
            })
            .collect();
        let far = mid.iter().map(|&i| sigma[i][(1, 1)]).sum::<f64>() / mid.len() as f64;
        // particles on the side faces (missing bonds) over the middle half of the height
        let edge: Vec<usize> = (0..n)
            .filter(|&i| model.particles.bond_count(i) < 6 && (x0[i].y - 0.5 * h).abs() < 0.25 * h)
            .collect();
        assert!(edge.len() >= 10);
        let worst = |s: &[Matrix2<f64>], r: usize, c: usize, minus: f64| {
            edge.iter()
                .map(|&i| (s[i][(r, c)] - minus).abs())
                .fold(0.0, f64::max)
                / far
        };
        let (normal, tangential) = (worst(&sigma, 0, 0, 0.0), worst(&sigma, 1, 1, far));
        let src_tangential = edge
            .iter()
            .map(|&i| source[i][(1, 1)])
            .fold(f64::INFINITY, f64::min)
            / far;
        println!("rotation {rot}: {} face particles, |σxx|/σ ≤ {normal:.4}, |σyy/σ − 1| ≤ {tangential:.4}; (3.18) reads σyy/σ down to {src_tangential:.3}", edge.len());
        if rot == 30.0 {
            assert!(
                normal < 0.05,
                "rotation {rot}: normal stress {normal} of the far field"
            );
            assert!(
                tangential < 0.05,
                "rotation {rot}: tangential stress off by {tangential}"
            );
        }
    }
}

/// Bodies and lattices symmetric about x = 0 (the split cylinder and the dog-bones at 0°)
/// get mirror-image
/// volumes and micro-moduli, bit for bit, so that a symmetric specimen cracks symmetrically
/// (tests/suite/specimens.rs).
#[test]
fn mirror_images_get_the_same_cells_and_moduli() {
    for scene in ["split_cylinder", "dogbone_B", "dogbone_D"] {
        mirror_check(scene);
    }
}

fn mirror_check(scene: &str) {
    let text = std::fs::read_to_string(format!("lattices/{scene}.toml")).unwrap();
    let model = prepare_model(
        &Scene::from_toml_str(&text, &[]).unwrap(),
        sppm::run::Hexagonal,
    )
    .unwrap();
    let p = &model.particles;
    let key = |x: f64, y: f64| ((x * 1e9).round() as i64, (y * 1e9).round() as i64);
    let index: std::collections::HashMap<(i64, i64), usize> = (0..p.len())
        .map(|i| (key(p.x0[i].x, p.x0[i].y), i))
        .collect();
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..p.len() {
        let j = index[&key(-p.x0[i].x, p.x0[i].y)];
        worst.0 = worst.0.max((p.volume[i] - p.volume[j]).abs() / p.volume[i]);
        worst.1 = worst.1.max((p.a[i] - p.a[j]).abs() / p.a[i].abs());
        worst.2 = worst.2.max((p.b[i] - p.b[j]).abs() / p.b[i].abs());
    }
    println!(
        "{scene}: mirror differences: volume {:.1e}, a {:.1e}, b {:.1e}",
        worst.0, worst.1, worst.2
    );
    assert_eq!(worst, (0.0, 0.0, 0.0), "{scene}");
}

/// The 3D prism cantilever (square section h × h, length 10·h) of an FCC lattice whose rows
/// lie along its faces: the error against Timoshenko comes from a surface layer a fraction
/// of L0 deep, so it is first order in L0/h: doubling the depth at least nearly halves it
/// (measured +4.40% at h = 10·L0, +2.27% at 20·L0; docs/surfaces.md, "3D: the prism
/// cantilever").
#[test]
#[cfg_attr(
    not(feature = "validation"),
    ignore = "validation: cargo test --release --features validation"
)]
fn prism_cantilever_bending_error_is_first_order() {
    use nalgebra::Vector3;
    use sppm::discretise::fcc::FccLattice;
    use sppm::study::elastic_checks::fcc_prism_cantilever;
    let l0 = 0.001;
    let lattice = FccLattice {
        spacing: l0,
        rotation_deg: [0.0; 3],
        offset: Vector3::zeros(),
    };
    let err = |h: f64| {
        fcc_prism_cantilever(h, 10.0 * h, &lattice, sppm::scene::Surface::VoronoiFit).unwrap() - 1.0
    };
    let (e10, e20) = (err(10.0 * l0), err(20.0 * l0));
    println!(
        "FCC 0°: h = 10 L0 {:+.2}%, 20 L0 {:+.2}%",
        e10 * 100.0,
        e20 * 100.0
    );
    assert!(e20.abs() <= 0.6 * e10.abs(), "{e10} then {e20}");
}
