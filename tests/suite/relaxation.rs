//! The adaptive dynamic-relaxation solver (`solver.method = "relaxation"`,
//! src/solver/relaxation.rs): it reaches the static solution of an elastic plate to within
//! its convergence tolerance, closes the energy balance, does not depend on the thread
//! count, carries a tension block to f't·A like the explicit solver (docs/validation.md §B), and
//! bad keys are refused with the key, the value and what is allowed.

use crate::common;
use common::says;
use common::*;
use sppm::run::prepare_model;
use sppm::Scene;

/// The plate of tests/suite/run_plate.rs (L0 = 4 mm, ε = 1e-4) under relaxation.
fn plate(settings: &[&str]) -> Scene {
    let mut text = plate_toml(0.1, 0.2, 0.004, 0.0, "stress", false, 0.2);
    text.push_str("[output]\nmap = false\nvtk = false\n");
    let mut o = vec!["solver.method=\"relaxation\"".to_string()];
    o.extend(settings.iter().map(|s| s.to_string()));
    Scene::from_toml_str(&text, &o).unwrap()
}

/// The converged state of each increment satisfies ‖F_free‖ ≤ tol·‖R‖. The reaction error
/// this leaves is the residual carried to the loaded rows, δR = K_pf·K_ff⁻¹·r, so it is
/// proportional to tol: measured 2.9–4.5·tol on this plate at tol = 1e-3 (about 6·tol on
/// the 2 mm plate of lattices/elastic_plate.toml). The test asserts |F/F_static − 1| ≤ 10·tol at loose
/// tolerances, and that tightening the tolerance 100× reduces the error at least 10×
/// (down to the floor set by the geometric nonlinearity the kernel keeps and the linear
/// static solve does not, ~ε = 1e-4 relative, which the tight run must reach).
#[test]
fn relaxed_plate_reaches_the_static_solution_within_its_tolerance() {
    let m = prepare_model(&plate(&[]), sppm::run::Hexagonal).unwrap();
    let f_static = reaction_y(&m, &static_solution(&m), "top");
    let mut errors = Vec::new();
    for (increments, tol) in [(1, 1e-3), (1, 1e-5), (10, 1e-3), (10, 1e-5)] {
        let out = run(
            &plate(&[
                &format!("solver.increments={increments}"),
                &format!("solver.tolerance={tol}"),
            ]),
            2,
        );
        let sm = &out.summary;
        assert_eq!(sm.status, "completed");
        assert_eq!(sm.unconverged_increments, Some(0));
        assert_eq!(sm.increments, Some(increments));
        assert_eq!(out.records.len(), increments + 1);
        let err = (sm.final_force_n / f_static - 1.0).abs();
        // an elastic specimen dissipates nothing: W = K + U + (damper work)
        let balance = sm.dissipated_energy_j / sm.external_work_j;
        println!(
            "increments {increments}, tol {tol:e}: {} iterations, F = {:.6e} N, static {f_static:.6e} N, error {err:.2e} = {:.2} tol; energy balance {balance:.2e}",
            sm.iterations.unwrap(),
            sm.final_force_n,
            err / tol
        );
        // From the second increment on, the predictor moves the whole specimen with the
        // grips, so no shock reaches the highest modes and the central-difference energy
        // balance closes as in the explicit run (tests/suite/run_plate.rs). A single increment
        // is a jump of the grips alone: measured 1.8e-4 of W, the leapfrog energy error of
        // the shock it sends through the lattice; not asserted.
        if increments > 1 {
            assert!(balance.abs() < 1e-6, "W − K − U − D = {balance:e} of W");
        }
        if tol >= 1e-3 {
            assert!(err <= 10.0 * tol, "error {err:e} at tolerance {tol:e}");
        } else {
            assert!(err <= 2e-4, "error {err:e} at tolerance {tol:e}");
        }
        errors.push(err);
    }
    assert!(errors[1] <= 0.1 * errors[0] && errors[3] <= 0.1 * errors[2]);
}

#[test]
fn relaxation_does_not_depend_on_the_thread_count() {
    let s = plate(&["solver.increments=5"]);
    let (a, b) = (run(&s, 1), run(&s, 2));
    assert_eq!(
        a.summary.final_force_n.to_bits(),
        b.summary.final_force_n.to_bits()
    );
    assert_eq!(a.summary.iterations, b.summary.iterations);
    assert_eq!(a.displacement, b.displacement);
}

/// The block of tests/suite/concrete.rs (150 × 100 mm, L0 = 10 mm, Table 1 concrete), pulled by
/// 1.5·COD_c under relaxation with the default increments and tolerance: the peak within 5%
/// of f't·A and the dissipated energy within 10% of G_f·A, as the explicit validation test
/// asserts (tests/suite/concrete.rs).
#[test]
fn relaxed_tension_block_reaches_ft() {
    // After the peak 50 of the 200 increments stop at max_iterations with at most 0.58% of
    // the reactions out of balance (still 0.67% with 10× the iterations: the softening
    // branch is where dynamic relaxation stalls); the scene accepts 1%.
    // On the source's lattice surface. With clipped Voronoi cells the same run
    // leaves 71 of 200 increments unconverged above 1% and dissipates 1.61 × G_f·A (peak
    // 0.956 × f't·A): the relaxation does not converge on this softening branch, which the
    // quasi-static solver addresses (benchmarks/RESULTS.md, "Surfaces").
    let scene = tension_block(
        0.1,
        0.01,
        &[
            "solver.method=relaxation",
            "solver.max_residual=0.01",
            "discretisation.surface=\"lattice\"",
        ],
    );
    let law = sppm::model::damage::ConcreteLaw::from_scene(&scene).unwrap();
    let area = 0.15 * 0.15;
    let out = run(&scene, 2);
    let sm = &out.summary;
    let (fta, gfa) = (law.ft * area, law.gf * area);
    println!(
        "peak {:.1} N = {:.4} f't·A; dissipated {:.4} J = {:.4} G_f·A; {} iterations, {} increments unconverged",
        sm.peak_force_n,
        sm.peak_force_n / fta,
        sm.dissipated_energy_j,
        sm.dissipated_energy_j / gfa,
        sm.iterations.unwrap(),
        sm.unconverged_increments.unwrap()
    );
    assert_eq!(sm.status, "completed");
    assert!(sm.max_final_residual.unwrap() <= 0.01);
    assert!(
        (sm.peak_force_n / fta - 1.0).abs() <= 0.05,
        "peak {} N against f't·A = {fta} N",
        sm.peak_force_n
    );
    assert!(sm.max_damage.unwrap() >= 0.99, "the block did not crack");
    // The 100 mm block separates without snap-back, so the relaxation follows the softening
    // branch and the energy booked as dissipated (external work less elastic, kinetic and
    // damper energy, with the predictor's work booked exactly) is G_f per unit crack area,
    // within the 10% of docs/validation.md §B. Measured 1.035 G_f·A.
    assert!(
        (sm.dissipated_energy_j / gfa - 1.0).abs() <= 0.10,
        "dissipated {} J against G_f·A = {gfa} J",
        sm.dissipated_energy_j
    );
}

fn error_of(overrides: &[&str]) -> String {
    let text = plate_toml(0.1, 0.2, 0.01, 0.0, "stress", false, 0.2);
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    match Scene::from_toml_str(&text, &o) {
        Ok(_) => panic!("{overrides:?} was accepted"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_relaxation_keys_are_named() {
    says(
        &error_of(&["solver.method=\"newton\""]),
        &["newton", "explicit", "relaxation"],
    );
    says(
        &error_of(&["solver.increments=0"]),
        &["solver.increments = 0", "from 1 to"],
    );
    says(
        &error_of(&["solver.tolerance=0"]),
        &["solver.tolerance = 0", "0 < tolerance < 1"],
    );
    says(
        &error_of(&["solver.tolerance=1.5"]),
        &["solver.tolerance = 1.5", "0 < tolerance < 1"],
    );
    says(
        &error_of(&["solver.max_iterations=0"]),
        &["solver.max_iterations = 0", "from 1 to"],
    );
    says(&error_of(&["solver.increments=-3"]), &["increments"]);
    says(
        &error_of(&[
            "solver.method=\"relaxation\"",
            "solver.force_lag=\"previous\"",
        ]),
        &["solver.force_lag", "previous", "relaxation"],
    );
}
