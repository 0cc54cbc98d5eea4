//! A damped, displacement-controlled run of a plate in tension through the whole pipeline:
//! the energy balance closes, the run is quasi-static and ends at the static solution, the
//! result does not depend on the thread count, and both readings of the force lag agree
//! when damped (docs/model.md §4).

use crate::common;
use common::*;
use sppm::run::prepare_model;

fn plate(lag: &str) -> sppm::Scene {
    let mut text = plate_toml(0.1, 0.2, 0.004, 0.0, "stress", false, 0.2);
    text.push_str(&format!(
        "[solver]\nforce_lag = \"{lag}\"\n[output]\nmap = false\nvtk = false\n"
    ));
    scene(&text)
}

#[test]
fn damped_run_closes_its_energy_balance_and_reaches_the_static_solution() {
    let s = plate("current");
    let out = run(&s, 2);
    let sm = &out.summary;
    assert_eq!(sm.status, "completed");
    let balance = sm.dissipated_energy_j / sm.external_work_j;
    println!(
        "energy balance error {balance:.3e}, max K/U {:.3e}",
        sm.max_kinetic_to_internal_energy
    );
    // an elastic specimen dissipates only in its dampers
    assert!(balance.abs() < 1e-6, "W − K − U − D = {balance:e} of W");
    assert!(sm.max_kinetic_to_internal_energy < 0.05);
    // at the end of the hold the damped run sits at the static solution
    let m = prepare_model(&s, sppm::run::Hexagonal).unwrap();
    let f_static = reaction_y(&m, &static_solution(&m), "top");
    println!(
        "final force {:.6e} N, static {f_static:.6e} N",
        sm.final_force_n
    );
    assert!((sm.final_force_n / f_static - 1.0).abs() < 2e-3);
    // W at full load equals the elastic energy ½FΔ plus the damper losses
    assert!((sm.internal_energy_j / (0.5 * f_static * 2e-5) - 1.0).abs() < 3e-3);
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let s = plate("current");
    let (a, b) = (run(&s, 1), run(&s, 2));
    assert_eq!(
        a.summary.peak_force_n.to_bits(),
        b.summary.peak_force_n.to_bits()
    );
    assert_eq!(a.displacement, b.displacement);
}

#[test]
fn lagged_reading_needs_half_the_time_step_even_when_damped() {
    // Reading (A) at the step that is stable for (B) blows up, and the guard says where;
    // at half of it (ξ_in = 0.2) it runs and agrees with (B).
    let b = run(&plate("current"), 2);
    let a = run(&plate("previous"), 2);
    assert_eq!(a.summary.status, "unstable");
    let msg = a.summary.message.clone().unwrap();
    println!("{msg}");
    assert!(msg.contains("at step") && msg.contains("at particle"));
    let mut half = plate("previous");
    half.solver.safety = 0.45;
    let a = run(&half, 2);
    println!(
        "peak force: current {:.6e} N, previous at half the step {:.6e} N ({:+.3e})",
        b.summary.peak_force_n,
        a.summary.peak_force_n,
        a.summary.peak_force_n / b.summary.peak_force_n - 1.0
    );
    assert_eq!(a.summary.status, "completed");
    assert!((a.summary.peak_force_n / b.summary.peak_force_n - 1.0).abs() < 1e-4);
}
