//! docs/validation.md §A: the patch test (homogeneous strain → interior particles carry no net
//! force, particle stress = D·ε) and Newton's third law.

use crate::common;
use common::scene;
use nalgebra::{Matrix2, Vector2, Vector3};
use sppm::model::micro_modulus::elasticity_matrix;
use sppm::run::{particle_stress, prepare_model};
use sppm::scene::Plane;
use sppm::solver::kernel::{self, State};
use sppm::solver::linear::LinearOperator;

fn disc(rotation: f64, plane: &str, nu: f64) -> String {
    format!(
        r#"
[body]
shape = "disc"
diameter = 0.1
[discretisation]
spacing = 0.004
rotation_deg = {rotation}
offset = [0.0013, -0.0007]
[material]
E = 30.0e9
nu = {nu}
rho = 2400.0
thickness = 0.1
plane = "{plane}"
"#
    )
}

/// Interior: the particle and all its neighbours have every bond (their θ is that of the
/// homogeneous field).
fn interior(p: &sppm::run::Model, i: usize) -> bool {
    p.particles.bond_count(i) == 6
        && p.mech
            .bonds(i)
            .all(|(_, j, _)| p.particles.bond_count(j) == 6)
}

const STRAIN: [[f64; 2]; 2] = [[1.0e-3, 3.0e-4], [3.0e-4, -5.0e-4]];

fn voigt_stress(d: &nalgebra::Matrix3<f64>) -> Matrix2<f64> {
    let e = Vector3::new(STRAIN[0][0], STRAIN[1][1], 2.0 * STRAIN[0][1]);
    let s = d * e;
    Matrix2::new(s[0], s[2], s[2], s[1])
}

#[test]
fn patch_test_linearised_is_exact_to_round_off() {
    for (rot, plane, nu) in [
        (0.0, "stress", 0.2),
        (17.0, "stress", 0.2),
        (33.0, "strain", 0.3),
        (5.0, "stress", 0.0),
    ] {
        let p = prepare_model(&scene(&disc(rot, plane, nu)), sppm::run::Hexagonal).unwrap();
        let eps = Matrix2::new(STRAIN[0][0], STRAIN[0][1], STRAIN[1][0], STRAIN[1][1]);
        let u: Vec<Vector2<f64>> = p.particles.x0.iter().map(|x| eps * x).collect();
        let mut op = LinearOperator::new(&p.mech, &p.particles.x0);
        let mut f = vec![Vector2::zeros(); u.len()];
        op.internal_forces(&u, &mut f);
        let d = elasticity_matrix(
            30e9,
            nu,
            if plane == "stress" {
                Plane::Stress
            } else {
                Plane::Strain
            },
        );
        let expected = voigt_stress(&d);
        let bond_force = p.mech.a[0] * 1e-3;
        let mut checked = 0;
        for i in (0..u.len()).filter(|&i| interior(&p, i)) {
            assert!(
                f[i].norm() <= 1e-9 * bond_force,
                "rot {rot}: particle {i} net force {:e}",
                f[i].norm()
            );
            let mut s = Matrix2::zeros();
            for (n, l0, fs) in op.force_states(&u, i) {
                s += n * n.transpose() * (l0 * fs);
            }
            let s = s / (2.0 * p.particles.volume[i]);
            assert!(
                (s - expected).norm() <= 1e-9 * expected.norm(),
                "rot {rot}: stress {s} vs {expected}"
            );
            checked += 1;
        }
        assert!(checked > 100, "{checked} interior particles");
    }
}

#[test]
fn patch_test_of_the_step_kernel() {
    // Finite homogeneous strain through the nonlinear kernel: net interior forces vanish to
    // round-off (opposite bonds cancel), and the stress equals D·ε to first order in ε
    // (the stretch (L−L0)/L0 = n·ε·n + O(ε²)).
    let p = prepare_model(&scene(&disc(12.0, "stress", 0.2)), sppm::run::Hexagonal).unwrap();
    let eps = Matrix2::new(STRAIN[0][0], STRAIN[0][1], STRAIN[1][0], STRAIN[1][1]);
    let mut st = State::at_rest(&p.particles.x0);
    for (x, x0) in st.x.iter_mut().zip(&p.particles.x0) {
        *x = x0 + eps * x0;
    }
    kernel::pass_dilatation(&p.mech, &st.x, &mut st.b_theta);
    let bond_force = p.mech.a[0] * 1e-3;
    let stress = particle_stress(&p.mech, &p.particles.volume, &st.x);
    let expected = voigt_stress(&elasticity_matrix(30e9, 0.2, Plane::Stress));
    let emax = 1e-3;
    for i in (0..p.particles.len()).filter(|&i| interior(&p, i)) {
        let (f, _) = kernel::particle_force::<2, 6, false>(&p.mech, &st.x, &st.v, &st.b_theta, i);
        assert!(
            f.norm() <= 1e-10 * bond_force,
            "particle {i}: {:e}",
            f.norm()
        );
        assert!(
            (stress[i] - expected).norm() <= 3.0 * emax * expected.norm(),
            "{} vs {expected}",
            stress[i]
        );
    }
}

#[test]
fn newtons_third_law_holds_to_round_off() {
    let mut p = prepare_model(&scene(&disc(21.0, "stress", 0.2)), sppm::run::Hexagonal).unwrap();
    let n = p.particles.len();
    for i in 0..n {
        p.mech.c_in[i] = 1e3 * (1.0 + (i % 7) as f64); // unequal dampers
        p.mech.a[i] *= 1.0 + 0.3 * ((i * 13 % 11) as f64 / 11.0); // unequal moduli
    }
    let mut st = State::at_rest(&p.particles.x0);
    let mut seed = 12345u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
    };
    for i in 0..n {
        st.x[i] += Vector2::new(rnd(), rnd()) * 2e-5;
        st.v[i] = Vector2::new(rnd(), rnd());
    }
    kernel::pass_dilatation(&p.mech, &st.x, &mut st.b_theta);
    let mut total = Vector2::zeros();
    let mut scale = 0.0;
    for i in 0..n {
        let (f, _) = kernel::particle_force::<2, 6, true>(&p.mech, &st.x, &st.v, &st.b_theta, i);
        total += f;
        scale += f.norm();
    }
    assert!(
        total.norm() <= 1e-13 * scale,
        "Σf = {total:?}, Σ|f| = {scale:e}"
    );
}
