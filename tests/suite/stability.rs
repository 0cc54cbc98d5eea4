//! Numerical stability and robustness (docs/model.md §5, docs/validation.md §A): time
//! steps of 0.5×, 0.9×, 1.1× and 2× the computed limit, blow-up detection at library level,
//! and extreme but valid parameters (ν = 0, ν = 0.45 in plane strain, a 1000× contrast in E
//! between neighbouring particles).
//!
//! Already covered elsewhere, not repeated here: the undamped energy drift of the default
//! reading over 100 periods and the measured instability threshold against the computed
//! limit (tests/suite/vibration_and_stability.rs), the unstable CLI run (tests/suite/cli.rs), the
//! memory guard for a very small spacing and the "at least 2 particles" guard for a very
//! large one (tests/suite/scene_errors.rs), and generated scenes (tests/suite/proptest_scenes.rs).

use crate::common;
use common::*;
use nalgebra::Vector2;
use sppm::run::{build_simulation, prepare, prepare_model, run, Prepared, RunOptions};
use sppm::solver::time_step::stable_step;
use sppm::solver::{Probe, Simulation, Unstable};
use sppm::Scene;

/// The elastic plate of tests/common (100 × 200 mm, L0 = 5 mm: 924 particles), shortened.
fn plate(overrides: &[&str]) -> Scene {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Scene::from_toml_str(&plate_toml(0.1, 0.2, 0.005, 0.0, "stress", false, 0.2), &o).unwrap()
}

/// The Table 1 tension block (150 × 300 mm) at L0 = 12.5 mm, loaded to 1.5·COD_c.
/// The tension block on the source's lattice surface: with clipped Voronoi cells
/// its peak depends on Δt ten times more (0.9× against 0.5× the limit: −4.9e-3 with
/// `voronoi_fit`, +2.6e-3 with `voronoi`, −4.0e-4 on the source's surface; 0.7× lies
/// between), which is recorded in benchmarks/RESULTS.md ("Surfaces") and left open there;
/// this test keeps checking the integrator on the surface it was written for.
fn block(overrides: &[&str]) -> Scene {
    let mut o: Vec<String> = vec![
        "discretisation.spacing=0.0125".into(),
        "loading.end_periods=20".into(),
        "discretisation.surface=\"lattice\"".into(),
    ];
    o.extend(overrides.iter().map(|s| s.to_string()));
    Scene::from_file(std::path::Path::new("lattices/uniaxial_tension.toml"), &o).unwrap()
}

fn quiet() -> RunOptions {
    RunOptions {
        progress: false,
        threads: Some(1),
    }
}

/// Energy of a finished run: W = K + U + D + dissipated. For an elastic scene nothing
/// dissipates, so `dissipated_energy_J` is the energy error of the scheme. Measured at 0.5×
/// and 0.9× the limit (L0 = 5 mm plate): 6e-11 to 2e-10 W damped, 3e-10 to 9e-10 W
/// undamped. The bound 1e-8 W is ten times the worst: the central-difference balance is exact
/// up to the O((ωΔt)²) oscillation of the discrete energy of the vibrating part, and the
/// slow ramp leaves K/W below 1e-7 here.
const ELASTIC_ENERGY_ERROR: f64 = 1e-8;

#[test]
fn steps_below_the_limit_complete_with_bounded_energy() {
    type SceneOf = fn(&[&str]) -> Scene;
    let cases: [(&str, SceneOf); 3] = [
        ("elastic, damped", |o| plate(o)),
        ("elastic, undamped", |o| {
            let mut all = vec!["damping.internal=0", "damping.external=0"];
            all.extend_from_slice(o);
            plate(&all)
        }),
        ("concrete", |o| block(o)),
    ];
    for (name, scene_of) in cases {
        let mut peaks = vec![];
        for f in [0.5, 0.9] {
            let safety = format!("solver.safety={f}");
            let out = run(&scene_of(&[&safety]), &quiet()).unwrap();
            let s = &out.summary;
            let w = s.external_work_j;
            println!(
                "{name:18} {f}×: {} steps, peak {:.6e} N, W {w:.6e} J, K {:.3e}, U {:.3e}, D {:.3e}, W−K−U−D {:+.3e} W, max damage {:?}",
                s.steps, s.peak_force_n, s.kinetic_energy_j, s.internal_energy_j,
                s.damping_energy_j, s.dissipated_energy_j / w, s.max_damage
            );
            assert_eq!(s.status, "completed", "{name} at {f}×: {:?}", s.message);
            assert!(w > 0.0);
            // passive specimen: what it holds and lost is what was put in (bounded energy)
            let held = s.kinetic_energy_j + s.internal_energy_j + s.damping_energy_j;
            assert!(held <= w * (1.0 + ELASTIC_ENERGY_ERROR), "{name} {f}×");
            match s.max_damage {
                None => assert!(
                    s.dissipated_energy_j.abs() <= ELASTIC_ENERGY_ERROR * w,
                    "{name} {f}×: energy error {:e} W",
                    s.dissipated_energy_j / w
                ),
                Some(d) => {
                    // the block breaks (w_t = 1) and dissipates the rest: damage and
                    // plasticity only take energy out
                    assert_eq!(d, 1.0, "{name} {f}×: the block did not break");
                    assert!(s.dissipated_energy_j > 0.0 && s.dissipated_energy_j < w);
                }
            }
            if name.contains("undamped") {
                assert_eq!(s.damping_energy_j, 0.0);
            } else {
                assert!(s.damping_energy_j > 0.0);
            }
            peaks.push(s.peak_force_n);
        }
        // The quasi-static peak does not depend on Δt: the period error of central differences
        // is O((ω1·Δt)²) ~ 1e-4 at T1/Δt ≈ 300. Measured: 2.9e-6 damped, 5.5e-5 undamped (the
        // residual vibration), 4.0e-4 for the concrete block (the peak is where it cracks).
        let change = peaks[1] / peaks[0] - 1.0;
        println!("{name:18} peak 0.9× / 0.5× − 1 = {change:+.3e}");
        assert!(change.abs() < 2e-3, "{name}: {change:e}");
    }
}

/// The computed limit of a scene.
fn limit(scene: &Scene) -> f64 {
    prepare(scene, sppm::run::Hexagonal)
        .unwrap()
        .stable
        .dt_stable
}

#[test]
fn steps_above_the_limit_are_refused_in_the_scene() {
    for (name, scene) in [("elastic", plate(&[])), ("concrete", block(&[]))] {
        let dt_stable = limit(&scene);
        for f in [1.1, 2.0] {
            let mut s = scene.clone();
            s.solver.dt = Some(f * dt_stable);
            let msg = match prepare(&s, sppm::run::Hexagonal) {
                Ok(_) => panic!("{name}: solver.dt = {f}× the limit was accepted"),
                Err(e) => e.to_string(),
            };
            for part in [
                "solver.dt".to_string(),
                format!("{:e}", f * dt_stable),
                format!("{dt_stable:.6e}"),
                "at most the stable limit".to_string(),
            ] {
                assert!(msg.contains(&part), "{msg:?} does not name {part:?}");
            }
        }
        // and 0.9× is accepted as given
        let mut s = scene.clone();
        s.solver.dt = Some(0.9 * dt_stable);
        assert_eq!(
            prepare(&s, sppm::run::Hexagonal).unwrap().dt,
            0.9 * dt_stable
        );
    }
}

/// Run `p` at `dt` (forced past the scene check) for at most `max_steps`, checking stability
/// at every step as the run loop does (with the probe record's elastic energy).
pub(crate) fn forced(
    p: &mut Prepared,
    dt: f64,
    max_steps: usize,
) -> (Simulation<2, 6>, Option<Unstable>) {
    let mut sim = build_simulation(p);
    sim.integration.dt = dt;
    let probe = Probe {
        members: vec![],
        component: 1,
        amplitude: 0.0,
        force: None,
    };
    for _ in 0..max_steps {
        let rec = sim.advance(Some(&probe)).unwrap();
        if let Err(e) = sim.check_stability(Some(rec.internal_j), true) {
            return (sim, Some(e));
        }
    }
    (sim, None)
}

/// Largest amplification |λ| per step of a mode (ω, ζ) of central differences with the bond
/// dampers taken at v^{n−½}: x^{n+1} − 2x^n + x^{n−1} = −w²x^n − 2ζw(x^n − x^{n−1}), w = ωΔt,
/// so λ² + (w² + 2ζw − 2)λ + (1 − 2ζw) = 0 (|λ| = 1 at the limit of time_step.rs).
fn amplification(w: f64, zeta: f64) -> f64 {
    let (b, c) = (w * w + 2.0 * zeta * w - 2.0, 1.0 - 2.0 * zeta * w);
    let disc = b * b - 4.0 * c;
    if disc >= 0.0 {
        ((-b - disc.sqrt()) / 2.0)
            .abs()
            .max(((-b + disc.sqrt()) / 2.0).abs())
    } else {
        c.abs().sqrt()
    }
}

/// The computed limit was measured 1.9–3.6% below the true threshold
/// (tests/suite/vibration_and_stability.rs).
const LIMIT_GAP: f64 = 1.036;

#[test]
fn steps_above_the_limit_forced_through_the_library_are_stopped() {
    for (name, scene) in [("elastic", plate(&[])), ("concrete", block(&[]))] {
        // at and below the limit the guard never fires (no false alarm)
        for f in [0.9, 1.0] {
            let mut p = prepare(&scene, sppm::run::Hexagonal).unwrap();
            let dt = f * p.stable.dt_stable;
            let (_, failure) = forced(&mut p, dt, 3000);
            assert!(failure.is_none(), "{name} {f}×: {failure:?}");
        }
        for f in [1.1, 2.0] {
            let mut p = prepare(&scene, sppm::run::Hexagonal).unwrap();
            let n = p.model.particles.len();
            let x0 = p.model.particles.x0.clone();
            let st = p.stable;
            // Bound on the steps to detection: the highest mode grows by |λ| per step, taken
            // at f/1.036 × the limit (the slowest growth the measured gap allows); from
            // round-off (energy 1e-32 of the work) to 10× the work is a factor 1e33: allow 1e40.
            let g = amplification(st.omega_max * f / LIMIT_GAP * st.dt_stable, st.zeta);
            let bound = (40.0 / (2.0 * g.log10())).ceil() as usize;
            let (sim, failure) = forced(&mut p, f * st.dt_stable, bound);
            let e = failure.unwrap_or_else(|| {
                panic!("{name} {f}×: no blow-up detected in {bound} steps (|λ| = {g:.3})")
            });
            let sppm::solver::Location::Step {
                step,
                particle,
                position,
                ..
            } = &e.at
            else {
                panic!("{name} {f}×: an explicit run stopped at {:?}", e.at)
            };
            let (step, particle) = (*step, *particle);
            println!(
                "{name:8} {f}×: zeta {:.3}, |λ| {g:.3}/step, stopped at step {step} (bound {bound}): {e}",
                st.zeta
            );
            // the step is the one just taken, the particle a real one, named with its position
            assert_eq!(step, sim.step);
            assert!(step >= 1 && step <= bound);
            assert!(particle < n);
            assert_eq!(position, &format!("{:?}", x0[particle].as_slice()));
            let msg = e.to_string();
            assert!(
                msg.contains(&format!("step {step}"))
                    && msg.contains(&format!("particle {particle}"))
            );
            // ... and it is where the motion blew up: not finite, or the fastest particle
            let v = &sim.state.v;
            let vi = v[particle].norm();
            assert!(
                !vi.is_finite() || v.iter().all(|w| w.norm() <= vi),
                "{name} {f}×: particle {particle} is not the fastest",
            );
        }
    }
}

/// In plane strain the in-plane pair (E', ν') relates to (E, ν) by E' = E/(1−ν²), ν' = ν/(1−ν).
fn to_3d(e_plane: f64, nu_plane: f64) -> (f64, f64) {
    let nu = nu_plane / (1.0 + nu_plane);
    (e_plane * (1.0 - nu * nu), nu)
}

/// E and ν (3D values) of the static plate test of docs/validation.md §A (100 × 200 mm, tension).
fn plate_e_nu(plane: &str, nu: f64, l0: f64) -> (f64, f64) {
    let (w, h, t) = (0.1, 0.2, 0.05);
    let m = prepare_model(
        &scene(&plate_toml(w, h, l0, 0.0, plane, false, nu)),
        sppm::run::Hexagonal,
    )
    .unwrap();
    let (e, n) = measure_e_nu(&m, w, h, t);
    if plane == "strain" {
        to_3d(e, n)
    } else {
        (e, n)
    }
}

#[test]
fn extreme_poisson_ratios_recover_e_and_nu_and_run_stably() {
    // ν = 0 in plane stress and strain, and ν = 0.45 in plane strain (ν' = 0.82, b > 0 and
    // large), at W/L0 = 80: E and ν within the 1% of docs/validation.md §A (ν = 0: within 0.002,
    // 1% of the default 0.2). Measured: ν = 0: E −0.07%, ν 1e-5; ν = 0.45: E −0.68%, ν +0.09%.
    for (plane, nu) in [("stress", 0.0), ("strain", 0.0), ("strain", 0.45)] {
        let (e, n) = plate_e_nu(plane, nu, 0.00125);
        println!(
            "plane {plane:6} nu {nu:4}: E {:+.3}%, nu {n:.5}",
            (e / 30e9 - 1.0) * 100.0
        );
        assert!((e / 30e9 - 1.0).abs() < 0.01, "{plane} {nu}: E = {e:e}");
        assert!(
            (n - nu).abs() < 0.01 * nu.max(0.2),
            "{plane} {nu}: nu = {n}"
        );
    }
    // The error is the boundary layer, first order in L0/W: halving L0 halves it. ν = 0.45
    // plane strain: −1.22% → −0.68%; and the auxetic ν = −0.9 (shear modulus 5E), where the
    // boundary layer is large: +27.2% → +13.3% (E); the limit is still E.
    for (plane, nu) in [("strain", 0.45), ("stress", -0.9)] {
        let (e1, _) = plate_e_nu(plane, nu, 0.0025);
        let (e2, n2) = plate_e_nu(plane, nu, 0.00125);
        let ratio = (e1 / 30e9 - 1.0) / (e2 / 30e9 - 1.0);
        println!("plane {plane:6} nu {nu:4}: E error ratio L0 = 2.5 / 1.25 mm {ratio:.3}, nu at 1.25 mm {n2:.5}");
        assert!((1.6..2.4).contains(&ratio), "{plane} {nu}: {ratio}");
    }
    // a loaded, damped run at 0.9× the computed limit completes with the energy balance
    let dt_ref = limit(&plate(&[]));
    for (plane, nu) in [
        ("stress", 0.0),
        ("strain", 0.0),
        ("strain", 0.45),
        ("stress", -0.9),
    ] {
        let set_plane = format!("material.plane={plane}");
        let set_nu = format!("material.nu={nu}");
        let out = run(&plate(&[&set_plane, &set_nu]), &quiet()).unwrap();
        let s = &out.summary;
        println!(
            "plane {plane:6} nu {nu:4}: run {} in {} steps, dt / dt(ν = 0.2) {:.4}, W−K−U−D {:+.3e} W",
            s.status, s.steps, s.dt_stable_s / dt_ref,
            s.dissipated_energy_j / s.external_work_j
        );
        assert_eq!(s.status, "completed", "{plane} {nu}: {:?}", s.message);
        assert!(s.dissipated_energy_j.abs() < ELASTIC_ENERGY_ERROR * s.external_work_j);
    }
}

#[test]
fn contrast_of_1000_in_e_between_neighbours() {
    // Undamped (ζ = 0): Δt_stable = 2/ω_max exactly. Scaling E by 1000 on a region scales its
    // a and b (4.5) by 1000 at the same masses, so its highest frequency rises by √1000; a
    // bond between a stiff and a soft particle carries ½(a_i + a_j) ≈ 500·a.
    // - upper half stiff: the stiff half is a uniform lattice 1000× stiffer and sets ω_max:
    //   Δt shrinks by 1/√1000 = 0.03162 (measured 0.03165);
    // - alternate rows stiff: bonds along a stiff row at 1000·a, across rows at ≈ 500·a, so
    //   the factor lies between 1/√1000 and 1/√500.5 = 0.04470 (measured 0.03562).
    let scene = plate(&["damping.internal=0", "damping.external=0"]);
    type Layout = fn(&Vector2<f64>) -> bool;
    let layouts: [(&str, Layout, f64, f64); 2] = [
        ("upper half", |x| x.y > 0.1, 0.03162 * 0.98, 0.03162 * 1.02),
        (
            "alternate rows",
            |x| (x.y / (0.5 * 3f64.sqrt() * 0.005)).round() as i64 % 2 == 0,
            0.03162,
            0.04470,
        ),
    ];
    for (layout, stiff, lo, hi) in layouts {
        let mut p = prepare(&scene, sppm::run::Hexagonal).unwrap();
        let dt_uniform = p.stable.dt_stable;
        let x0 = p.model.particles.x0.clone();
        let mut count = 0;
        for (i, x) in x0.iter().enumerate() {
            if stiff(x) {
                p.model.mech.a[i] *= 1000.0;
                p.model.mech.b[i] *= 1000.0;
                count += 1;
            }
        }
        let st = stable_step(&p.model.mech, &x0);
        let ratio = st.dt_stable / dt_uniform;
        println!(
            "{layout:14}: {count} of {} particles stiff, Δt {dt_uniform:.4e} → {:.4e} s, ratio {ratio:.5}",
            x0.len(),
            st.dt_stable
        );
        assert!((lo..=hi).contains(&ratio), "{layout}: {ratio}");
        // the run is stable at 0.9× the new step (4000 steps, ramp to full load within them)
        // with the energy balance; 1.1× is caught by the guard
        for (f, stable) in [(0.9, true), (1.1, false)] {
            let mut q = prepare(&scene, sppm::run::Hexagonal).unwrap();
            q.model.mech = p.model.mech.clone();
            let dt = f * st.dt_stable;
            let mut sim = build_simulation(&mut q);
            sim.integration.dt = dt;
            sim.integration.t_ramp = 0.8 * 4000.0 * dt;
            let probe = Probe {
                members: vec![],
                component: 1,
                amplitude: 0.0,
                force: None,
            };
            let mut last = None;
            let mut failure = None;
            for _ in 0..4000 {
                let r = sim.advance(Some(&probe)).unwrap();
                if let Err(e) = sim.check_stability(Some(r.internal_j), true) {
                    failure = Some(e);
                    break;
                }
                last = Some(r);
            }
            let r = last.unwrap();
            if stable {
                let err = (r.external_work_j - r.kinetic_j - r.internal_j) / r.external_work_j;
                println!("  {f}×: stable over 4000 steps, W−K−U {err:+.3e} W");
                assert!(failure.is_none(), "{layout} {f}×: {failure:?}");
                // undamped and loaded in 4000 steps, K/W ≈ 4e-3 here: measured 6e-8
                assert!(err.abs() < 1e-6, "{layout}: energy error {err:e}");
            } else {
                let e = failure.unwrap_or_else(|| panic!("{layout} {f}×: not detected"));
                println!("  {f}×: stopped at step {}", e.step());
                assert!(e.step() < 200);
            }
        }
    }
}
