//! The semi-implicit bond dampers, selective mass scaling and the adaptive pace
//! (docs/model.md §5 and §10): the step they allow, what they report, and that they leave the
//! results of the schemes they replace.

use crate::common::*;
use crate::stability::forced;
use sppm::run::{prepare, run, RunOptions};
use sppm::Scene;

fn quiet() -> RunOptions {
    RunOptions {
        progress: false,
        threads: Some(1),
    }
}

/// The Table 1 tension block (150 × 300 mm) at L0 = 12.5 mm on the lattice surface, with the
/// source's dampers (ξ_in = ξ_ex = 0.2).
fn block(overrides: &[&str]) -> Scene {
    let mut o: Vec<String> = vec![
        "discretisation.spacing=0.0125".into(),
        "loading.end_periods=20".into(),
        "discretisation.surface=\"lattice\"".into(),
    ];
    o.extend(overrides.iter().map(|s| s.to_string()));
    Scene::from_file(std::path::Path::new("lattices/uniaxial_tension.toml"), &o).unwrap()
}

/// (S.17): with the implicit share the limit is the undamped one, 2/ω_max, although the bond
/// dampers are stiff (ζ ≈ 1 at ω_max); the run is stable there and the explicit dampers at
/// the same step blow up. (The limit is sufficient, not sharp: the scheme's mass
/// M + Δt·(diag(d) − C/2) exceeds M, and the block still ran 3,000 steps at 1.14 × it.)
#[test]
fn semi_implicit_bond_dampers_are_stable_at_the_undamped_limit() {
    let scene = block(&["damping.bond_scheme=\"semi_implicit\""]);
    let p = prepare(&scene, sppm::run::Hexagonal).unwrap();
    let st = p.stable;
    assert!(st.zeta > 0.5, "ζ = {}", st.zeta);
    assert!(st.implicit_share > 0.0 && st.implicit_share <= 1.0);
    assert!((st.dt_stable * st.omega_max - 2.0).abs() < 1e-12);
    let explicit_limit = 2.0 / st.omega_max * ((1.0 + st.zeta * st.zeta).sqrt() - st.zeta);
    assert!(st.dt_stable > 2.0 * explicit_limit);

    let mut p = prepare(&scene, sppm::run::Hexagonal).unwrap();
    let (_, failure) = forced(&mut p, st.dt_stable, 3000);
    assert!(failure.is_none(), "semi-implicit at its limit: {failure:?}");

    let mut p = prepare(&scene, sppm::run::Hexagonal).unwrap();
    p.model.mech.c_implicit.iter_mut().for_each(|d| *d = 0.0);
    let (_, failure) = forced(&mut p, st.dt_stable, 3000);
    assert!(
        failure.is_some(),
        "the explicit dampers at the undamped limit did not blow up"
    );
}

/// The two schemes integrate the same equations: they differ by Δt·(diag(d) − C/2)·a, first
/// order in Δt (docs/model.md §5), so on the damped elastic plate at one step the dampers'
/// energy and the work differ between the schemes, and at half the step the difference is
/// about half as large (at most 0.6 of it: first order plus the second-order remainder).
#[test]
fn semi_implicit_dampers_converge_to_the_explicit_ones_at_first_order() {
    let toml = plate_toml(0.1, 0.2, 0.005, 0.0, "stress", false, 0.2);
    let base = Scene::from_toml_str(&toml, &[]).unwrap();
    let limit = prepare(&base, sppm::run::Hexagonal)
        .unwrap()
        .stable
        .dt_stable;
    let energies = |scheme: &str, dt: f64| {
        let o = [
            format!("damping.bond_scheme=\"{scheme}\""),
            format!("solver.dt={dt:e}"),
        ];
        let s = run(&Scene::from_toml_str(&toml, &o).unwrap(), &quiet())
            .unwrap()
            .summary;
        (s.damping_energy_j, s.external_work_j)
    };
    let gap = |dt: f64| {
        let (d1, w1) = energies("explicit", dt);
        let (d2, w2) = energies("semi_implicit", dt);
        ((d2 - d1).abs() / d1, (w2 - w1).abs() / w1)
    };
    let (dd1, dw1) = gap(0.5 * limit);
    let (dd2, dw2) = gap(0.25 * limit);
    println!("damper energy: {dd1:.3e} → {dd2:.3e}; work: {dw1:.3e} → {dw2:.3e}");
    assert!(dd1 > 0.0 && dd2 <= 0.6 * dd1, "{dd1:e} → {dd2:e}");
    assert!(dw1 > 0.0 && dw2 <= 0.6 * dw1, "{dw1:e} → {dw2:e}");
}

/// (S.18) on the random tension block: the particles raised reach the target, the added mass
/// is reported, the stable step grows, and a fraction out of (0, 1] is refused by its key.
/// Loaded over two periods instead of twenty, the run is no longer quasi-static and the
/// summary warns that the added mass may have changed its result; at the scene's own
/// loading it does not.
#[test]
fn mass_scaling_raises_the_step_and_reports_what_it_added() {
    let file = std::path::Path::new("lattices/uniaxial_tension_random.toml");
    let plain = prepare(
        &Scene::from_file(file, &[]).unwrap(),
        sppm::run::RandomPlane::default(),
    )
    .unwrap();
    let scaled = prepare(
        &Scene::from_file(file, &["solver.mass_scaling=0.9".into()]).unwrap(),
        sppm::run::RandomPlane::default(),
    )
    .unwrap();
    let m = scaled.mass_scaling.expect("reported");
    assert!(plain.mass_scaling.is_none());
    assert!(m.particles > 0 && m.largest_factor > 1.0);
    let added: f64 = scaled.model.mech.mass.iter().sum::<f64>()
        / plain.model.mech.mass.iter().sum::<f64>()
        - 1.0;
    assert!((m.added_mass_fraction - added).abs() < 1e-12 && added <= 0.05);
    assert!(scaled.stable.dt_stable > plain.stable.dt_stable);
    // the dampers keep the true masses' coefficients, T1 the true specimen's
    assert_eq!(scaled.model.mech.c_in[..], plain.model.mech.c_in[..]);
    assert_eq!(scaled.fundamental.period, plain.fundamental.period);
    let warnings = |end: &str| {
        let o = [
            "solver.mass_scaling=0.9".to_string(),
            format!("loading.end_periods={end}"),
            "loading.stop_after_peak=0.8".to_string(),
        ];
        let s = run(&Scene::from_file(file, &o).unwrap(), &quiet())
            .unwrap()
            .summary;
        (s.max_kinetic_to_internal_energy_to_peak, s.warnings)
    };
    let (ratio, w) = warnings("2");
    assert!(
        ratio > 0.01
            && w.iter()
                .filter(|m| m.contains("solver.mass_scaling"))
                .count()
                == 1,
        "{ratio} {w:?}"
    );
    let (ratio, w) = warnings("20");
    assert!(ratio <= 0.01 && w.is_empty(), "{ratio} {w:?}");
    for q in ["0", "1.5", "-0.2"] {
        let e = Scene::from_file(file, &[format!("solver.mass_scaling={q}")])
            .expect_err("refused")
            .to_string();
        assert!(
            e.contains("solver.mass_scaling") && e.contains("0 < mass_scaling <= 1"),
            "{e}"
        );
    }
}

/// The adaptive pace reads the fixed ramp through the peak bit for bit (its records up to
/// there are the fixed ramp's), then runs the tail faster and still ends at Δmax.
#[test]
fn adaptive_pace_reads_the_fixed_ramp_through_the_peak() {
    let fixed = run(&block(&["loading.pace=\"fixed\""]), &quiet()).unwrap();
    let adaptive = run(&block(&["loading.pace=\"adaptive\""]), &quiet()).unwrap();
    let (f, a) = (&fixed.summary, &adaptive.summary);
    assert_eq!(f.peak_force_n, a.peak_force_n);
    assert_eq!(f.peak_step, a.peak_step);
    let upto = fixed
        .records
        .iter()
        .position(|r| r.step == f.peak_step)
        .unwrap();
    for (r, s) in fixed.records[..=upto].iter().zip(&adaptive.records) {
        assert_eq!(
            (r.step, r.force_n, r.displacement_m),
            (s.step, s.force_n, s.displacement_m)
        );
    }
    assert!(a.steps < f.steps, "{} against {}", a.steps, f.steps);
    assert_eq!(a.final_displacement_m, f.final_displacement_m);
    println!(
        "steps {} → {}; dissipated {:.4} → {:.4} J",
        f.steps, a.steps, f.dissipated_energy_j, a.dissipated_energy_j
    );
}
