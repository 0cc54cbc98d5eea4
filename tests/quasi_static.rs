//! The quasi-static solver (`solver.method = "quasi_static"`, src/solver/relaxation.rs,
//! docs/quasi_static.md): the relaxation as secant iterations, the damage state held while the
//! positions relax and committed between equilibria. An elastic scene gives the relaxation's
//! answer, and an increment that cannot converge stops the run with a message that names it.
//! (Issue 16 is open: the solver does not yet converge on every softening branch,
//! docs/quasi_static.md.)

mod common;
use common::says;
use common::*;
use sppm::run::RunOptions;
use sppm::Scene;

fn run(s: &Scene, threads: usize) -> sppm::Outcome {
    sppm::run(
        s,
        &RunOptions {
            progress: false,
            threads: Some(threads),
        },
    )
    .unwrap()
}

/// Without damage there is no state to commit: the secant iterations are the relaxation's
/// iterations (with c kept where Kilic & Madenci's quotient is not positive), so the elastic
/// plate converges to the same answer: both within tolerance 1e-5 of equilibrium, whose
/// reaction error is 3–6 × the tolerance (tests/relaxation.rs), so within 1e-4 of each other.
#[test]
fn elastic_plate_quasi_static_equals_relaxation() {
    let mut text = plate_toml(0.1, 0.2, 0.004, 0.0, "stress", false, 0.2);
    text.push_str("[output]\nmap = false\nvtk = false\n");
    let at = |m: &str| {
        let s = Scene::from_toml_str(
            &text,
            &[
                format!("solver.method=\"{m}\""),
                "solver.increments=5".into(),
                "solver.tolerance=1e-5".into(),
                "solver.max_iterations=5000".into(),
            ],
        )
        .unwrap();
        run(&s, 2)
    };
    let (qs, dr) = (at("quasi_static"), at("relaxation"));
    assert_eq!(qs.summary.status, "completed");
    assert_eq!(qs.summary.commits, Some(0), "no state, no commits");
    assert_eq!(qs.summary.unconverged_increments, Some(0));
    let diff = (qs.summary.final_force_n / dr.summary.final_force_n - 1.0).abs();
    println!("quasi-static against relaxation: {diff:.2e}");
    assert!(diff <= 1e-4, "{diff:e}");
}

/// An increment that does not converge in solver.max_iterations stops the run: the status is
/// "unconverged", the message names the increment, its residual and the keys to change, and
/// the curve ends at the last converged increment (no record of the unconverged state).
#[test]
fn unconverged_increment_stops_the_run_and_is_named() {
    let scene = tension_block(
        0.1,
        0.01,
        &[
            "solver.method=\"quasi_static\"",
            "discretisation.surface=\"lattice\"",
            "solver.max_iterations=60",
        ],
    );
    let out = run(&scene, 2);
    let sm = &out.summary;
    assert_eq!(sm.status, "unconverged");
    let last = out.increments.last().unwrap();
    assert!(!last.converged);
    assert!(out.increments[..out.increments.len() - 1]
        .iter()
        .all(|i| i.converged));
    let message = sm.message.clone().unwrap();
    says(
        &message,
        &[
            &format!("load increment {} of 200", last.increment),
            "did not converge",
            "solver.max_iterations = 60",
            "solver.max_iterations",
            "solver.max_residual",
        ],
    );
    // one record per converged increment (taken at the start of the next) and the start
    assert_eq!(out.records.len(), out.increments.len());
    assert!(sm.unconverged_increments == Some(1));
}
