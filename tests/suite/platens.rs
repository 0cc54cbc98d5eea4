//! Platens with Coulomb friction (`groups.<name>.friction`, docs/model.md §10): a block pushed
//! along a frictional base slides at μ times the force that presses it down; friction 0 is
//! the sliding platen bit for bit and a large one the gripping platen; a platen of moderate
//! friction carries a compression block between the two; bad settings are refused under the
//! key the scene set.

use sppm::run::{run, RunOptions};
use sppm::scene::Scene;
use std::path::Path;

/// The scene `name` of an elastic block 100 × 50 mm (hexagonal lattice, 5 mm, 50 mm thick)
/// up to its base, the bottom row held in y; the groups that follow are the caller's.
fn block(name: &str) -> String {
    format!(
        r#"
name = "{name}"
[body]
shape = "rectangle"
width = 0.1
height = 0.05
[discretisation]
spacing = 0.005
[material]
E = 30.0e9
nu = 0.2
rho = 2400.0
thickness = 0.05
[[groups]]
name = "base"
select = {{ by = "edge", edge = "bottom", rows = 1 }}
fix = ["y"]"#
    )
}

/// An elastic block 100 × 50 mm (hexagonal lattice, 5 mm) on a base with friction μ, pressed
/// down by a force P on its top row and pushed along x by its left column.
fn sliding_block(mu: f64, press: f64) -> Scene {
    let toml = format!(
        r#"{header}
friction = {mu}
[[groups]]
name = "press"
select = {{ by = "edge", edge = "top", rows = 1 }}
load = {{ component = "y", force = {force:e} }}
[[groups]]
name = "push"
select = {{ by = "box", min = [-0.001, 0.006], max = [0.003, 0.051] }}
load = {{ component = "x", displacement = 2.0e-4 }}
[loading]
end_periods = 400.0
ramp_fraction = 0.8
[damping]
internal = 0.2
external = 0.0
[output]
records = 400
probe_group = "push"
"#,
        header = block("sliding_block"),
        force = -press
    );
    Scene::from_toml_str(&toml, &[]).expect("valid scene")
}

/// Coulomb's law: once the block slides, the push needs μ·P(t), P(t) the pressing force at
/// that time of the ramp. While the push ramps, the whole block moves and its inertia adds
/// m·ü, below 0.1% of μ·P here (400 periods); the block's own elastic shortening is taken up
/// before it slides, so the records from a third to two thirds of the ramp slide. Measured
/// against μ·P·r(t) (r the ramp's fraction): within 1%.
#[test]
fn a_block_slides_when_the_push_reaches_mu_times_the_pressing_force() {
    let (mu, press) = (0.3, 2.0e4);
    let out = run(&sliding_block(mu, press), &RunOptions::default()).unwrap();
    assert_eq!(out.summary.status, "completed");
    let dmax = 2.0e-4;
    let mut checked = 0;
    for r in &out.records {
        let fraction = r.displacement_m / dmax;
        if !(0.33..=0.67).contains(&fraction) {
            continue;
        }
        let coulomb = mu * press * fraction;
        assert!(
            (r.force_n / coulomb - 1.0).abs() < 0.01,
            "at {:.0}% of the push the block needs {:.1} N, Coulomb {:.1} N",
            fraction * 100.0,
            r.force_n,
            coulomb
        );
        checked += 1;
    }
    assert!(checked > 50, "{checked} records checked");
    // the friction's work is dissipated: the balance closes with it among the dampers
    let s = &out.summary;
    assert!(
        s.damping_energy_j > 0.5 * mu * press * 0.5 * dmax,
        "friction and dampers took {:e} J",
        s.damping_energy_j
    );
    assert!(
        s.dissipated_energy_j.abs() < 1e-3 * s.external_work_j.abs(),
        "unbooked energy {:e} J of {:e} J",
        s.dissipated_energy_j,
        s.external_work_j
    );
}

/// The shipped 2D compression block cut to a 150 mm cube, its platens sliding (as shipped),
/// with friction μ, or gripping (x fixed on both platens).
fn compression(platens: &str) -> f64 {
    let path = Path::new("lattices/uniaxial_compression.toml");
    let mut sets: Vec<String> = match platens {
        "sliding" => vec![],
        "gripping" => vec![
            r#"groups.bottom.fix=["x","y"]"#.into(),
            r#"groups.top.fix=["x"]"#.into(),
        ],
        mu => vec![
            format!("groups.bottom.friction={mu}"),
            format!("groups.top.friction={mu}"),
        ],
    };
    sets.push("body.height=0.15".into());
    let scene = Scene::from_file(path, &sets).unwrap();
    let s = run(&scene, &RunOptions::default()).unwrap().summary;
    assert_eq!(s.status, "completed", "{platens}: {:?}", s.message);
    s.peak_force_n
}

/// Friction 0 adds no force (the sliding platens' peak bit for bit). Any friction restrains
/// the block's ends, so the peak rises above the sliding platens', and it does not pass the
/// gripping platens' (no platen holds more than one that grips): at friction 10 the platens'
/// corners still slip (a gripped face's shear traction is singular at its corners). The
/// block is a cube, as in the laboratory's cube test, where the platens' restraint reaches
/// the whole specimen (sliding 505.2 kN, friction 0.1 and 10 507.8 and 514.3 kN, gripping
/// 535.4 kN). In the shipped 2:1 block the restraint dies out before mid-height, where the
/// block fails, and friction moves the peak by less than 1%: with (4.14) softening the
/// effective stress (docs/model.md §8) every friction lands 0.6% below the sliding peak.
#[test]
fn friction_platens_lie_between_sliding_and_gripping() {
    let sliding = compression("sliding");
    let gripping = compression("gripping");
    assert!(
        gripping > sliding,
        "gripping {gripping} N, sliding {sliding} N"
    );
    assert_eq!(
        compression("0"),
        sliding,
        "friction 0 is the sliding platen"
    );
    for mu in ["0.1", "10"] {
        let peak = compression(mu);
        assert!(
            sliding < peak && peak <= gripping,
            "friction {mu}: {peak} N, between sliding {sliding} N and gripping {gripping} N"
        );
    }
}

/// Bad settings are refused under `groups.<name>.friction`, with what is allowed.
#[test]
fn bad_friction_is_refused_under_its_key() {
    let path = Path::new("lattices/uniaxial_compression.toml");
    for (sets, needle) in [
        (vec!["groups.top.friction=-0.1"], "from 0"),
        (
            vec![
                "groups.anchor.friction=0.2",
                r#"groups.anchor.fix=["x","y"]"#,
            ],
            "exactly one fixed axis",
        ),
        (
            vec!["groups.top.friction=0.2", "solver.method=relaxation"],
            "explicit",
        ),
    ] {
        let sets: Vec<String> = sets.into_iter().map(String::from).collect();
        let err = Scene::from_file(path, &sets)
            .err()
            .unwrap_or_else(|| panic!("{sets:?} accepted"))
            .to_string();
        let group = sets[0].split('.').nth(1).unwrap();
        assert!(
            err.contains(&format!("groups.{group}.friction")) && err.contains(needle),
            "{sets:?}: {err}"
        );
    }
}

/// An elastic block 100 × 50 mm (hexagonal lattice, 5 mm) on a sliding base, its top row
/// pushed down by 10 µm (`push` > 0 presses, < 0 pulls away) through a strip across the
/// whole top, rigid or a bearing strip of E/thickness = `stiffness` (Pa/m).
fn pressed_block(stiffness: Option<f64>, push: f64) -> sppm::run::Summary {
    let bearing = stiffness.map_or(String::new(), |k| {
        format!("bearing = {{ E = {:e}, thickness = 0.01 }}", k * 0.01)
    });
    let toml = format!(
        r#"{header}
[[groups]]
name = "anchor"
select = {{ by = "nearest", point = [0.05, 0.0] }}
fix = ["x"]
[[groups]]
name = "platen"
select = {{ by = "strip", edge = "top", width = 0.1, depth = 0.004 }}
load = {{ component = "y", displacement = {d:e} }}
{bearing}
[loading]
end_periods = 40.0
ramp_fraction = 0.5
[damping]
internal = 0.2
external = 0.5
"#,
        header = block("pressed_block"),
        d = -push
    );
    let scene = Scene::from_toml_str(&toml, &[]).expect("valid scene");
    let s = run(&scene, &RunOptions::default()).unwrap().summary;
    assert_eq!(s.status, "completed");
    s
}

/// A bearing strip is a spring in series with the block: with the block's stiffness K_b
/// (rigid platen, F = K_b·Δ) and the strip's K_s = (E/t)·A, the platen's displacement Δ
/// presses with F = Δ/(1/K_b + 1/K_s). Uniaxial compression on a sliding base is homogeneous
/// under either platen (a uniform displacement or a uniform pressure), so the two agree up
/// to the lattice's rows at the block's corners: within 1% for strips as stiff as the block
/// and ten times stiffer. The strip pushes and never pulls: a platen drawn away carries
/// nothing. The energy balance closes with the strip's work.
#[test]
fn a_bearing_strip_presses_in_series_with_the_block_and_never_pulls() {
    let push = 1e-5;
    let rigid = pressed_block(None, push).final_force_n;
    let k_block = rigid / push;
    let area = 0.1 * 0.05;
    for factor in [1.0, 10.0] {
        let k_strip = factor * k_block;
        let s = pressed_block(Some(k_strip / area), push);
        let series = push / (1.0 / k_block + 1.0 / k_strip);
        assert!(
            (s.final_force_n / series - 1.0).abs() < 0.01,
            "strip {factor} × the block's stiffness: {} N, in series {series} N (rigid {rigid} N)",
            s.final_force_n
        );
        assert!(
            s.dissipated_energy_j.abs() < 1e-3 * s.external_work_j.abs(),
            "unbooked energy {:e} J of {:e} J",
            s.dissipated_energy_j,
            s.external_work_j
        );
    }
    let pulled = pressed_block(Some(k_block / area), -push);
    assert!(
        pulled.final_force_n.abs() < 1e-9 * rigid.abs(),
        "a strip drawn away carries {} N",
        pulled.final_force_n
    );
}

/// Bad bearing strips are refused under `groups.<name>.bearing`, with what is allowed.
#[test]
fn bad_bearing_strips_are_refused_under_their_key() {
    let path = Path::new("lattices/split_cylinder.toml");
    for (sets, key, needle) in [
        (
            vec!["groups.top_strip.bearing={ E = -1e9, thickness = 0.003 }"],
            "groups.top_strip.bearing.E",
            "",
        ),
        (
            vec![
                "groups.top_strip.bearing={ E = 1e9, thickness = 0.003 }",
                "groups.top_strip.friction=0.2",
            ],
            "groups.top_strip.bearing",
            "either friction or a bearing strip",
        ),
    ] {
        let sets: Vec<String> = sets.into_iter().map(String::from).collect();
        let err = Scene::from_file(path, &sets)
            .err()
            .unwrap_or_else(|| panic!("{sets:?} accepted"))
            .to_string();
        assert!(err.contains(key) && err.contains(needle), "{sets:?}: {err}");
    }
    let path = Path::new("lattices/uniaxial_compression.toml");
    let sets = vec!["groups.top.bearing={ E = 1e9, thickness = 0.003 }".to_string()];
    let err = Scene::from_file(path, &sets)
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("groups.top.bearing") && err.contains("strip"),
        "{err}"
    );
}
