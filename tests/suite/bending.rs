//! Three-point bending in 2D (lattices/beam_3pb_*.toml) and the gauges that read it
//! (docs/scenes.md, "Gauges"; docs/outputs.md).

use crate::common::says;
use sppm::run::{run, RunOptions};
use sppm::Scene;
use std::path::Path;

/// Tada's LEFM crack-mouth opening of a three-point bending beam per unit load (m/N):
/// CMOD = 4·σN·a·V(α)/E with σN = 3·P·S/(2·b·d²), α = a/d and V(α) = 0.76 − 2.28α + 3.87α²
/// − 2.04α³ + 0.66/(1 − α)² (Tada, Paris & Irwin, The Stress Analysis of Cracks Handbook,
/// 2000, for S/d = 4; Guinea et al. 1998 find the span's effect on V within a few per cent
/// at S/d = 2.5).
fn tada_compliance(a: f64, d: f64, s: f64, b: f64, e: f64) -> f64 {
    let al = a / d;
    let v = 0.76 - 2.28 * al + 3.87 * al * al - 2.04 * al.powi(3) + 0.66 / (1.0 - al).powi(2);
    4.0 * (3.0 * s / (2.0 * b * d * d)) * a * v / e
}

/// The notched beam (notch 0.2·d) with its default loading: quasi-static to the peak; its
/// CMOD gauge recorded, plotted and reported. Before cracking the gauge reads Tada's
/// compliance of the notch (within 10%: the span and the notch's 2 mm width); at the peak
/// the mouth has opened more than the elastic notch would (softening only adds opening)
/// and less than a crack through half the depth would give (LEFM, a = d/2): the
/// elastic-cohesive bracket of the peak's CMOD.
#[test]
fn notched_beam_cmod_lies_between_the_elastic_and_cracked_bounds() {
    let scene = Scene::from_file(Path::new("lattices/beam_3pb_notch02.toml"), &[]).unwrap();
    assert!(scene.loading.end_periods.is_none(), "the default loading");
    let o = run(&scene, &RunOptions::default()).unwrap();
    let s = &o.summary;
    assert!(
        s.max_kinetic_to_internal_energy <= sppm::scene::KINETIC_LIMIT,
        "{}",
        s.max_kinetic_to_internal_energy
    );
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let (d, span, b, e) = (0.05, 0.125, 0.05, 37e9);
    let peak = s.peak_force_n;
    let early = o.records.iter().find(|r| -r.force_n > 0.2 * peak).unwrap();
    let c0 = early.gauges[0] / -early.force_n;
    let tada = tada_compliance(0.01, d, span, b, e);
    assert!((c0 / tada - 1.0).abs() < 0.10, "{c0:e} against {tada:e}");
    let g = &s.gauges[0];
    assert_eq!(g.name, "CMOD");
    let upper = tada_compliance(0.5 * d, d, span, b, e) * peak;
    assert!(
        g.at_peak_m > c0 * peak && g.at_peak_m < upper,
        "CMOD at the peak {:e} m outside [{:e}, {:e}]",
        g.at_peak_m,
        c0 * peak,
        upper
    );
    // the crack grows from the notch: the mouth keeps opening after the peak
    assert!(g.max_m > 2.0 * g.at_peak_m);
    let dir = std::env::temp_dir().join(format!("sppm-bending-{}", std::process::id()));
    sppm::output::write_all(&o, &dir).unwrap();
    let rows = crate::common::csv_rows(&dir.join("force_displacement.csv"));
    assert_eq!(rows.len(), o.records.len());
    assert!(rows.iter().all(|r| r.contains_key("gauge_CMOD_m")));
    let svg = std::fs::read_to_string(dir.join("force_gauge_CMOD.svg")).unwrap();
    assert!(svg.contains("opening of gauge &apos;CMOD&apos; (mm)"));
    std::fs::remove_dir_all(&dir).ok();
}

/// Every shipped beam's supports and load strip select particles where the scene's
/// comments say: x = 25 and 150 mm on the bottom edge, mid-span (87.5 mm, the strip's
/// default centre) on the top.
#[test]
fn beam_groups_sit_where_their_scenes_say() {
    for f in [
        "beam_3pb_notch02",
        "beam_3pb_unnotched",
        "beam_3pb_notch02_random",
        "beam_3pb_unnotched_random",
    ] {
        let path = format!("lattices/{f}.toml");
        let scene = Scene::from_file(Path::new(&path), &[]).unwrap();
        let (groups, x0) = if scene.discretisation.is_random() {
            let m = sppm::run::prepare_model(&scene, sppm::run::RandomPlane::default()).unwrap();
            (m.groups, m.particles.x0)
        } else {
            let m = sppm::run::prepare_model(&scene, sppm::run::Hexagonal).unwrap();
            (m.groups, m.particles.x0)
        };
        for (name, x, y) in [
            ("left_support", 0.025, 0.0),
            ("right_support", 0.15, 0.0),
            ("load", 0.0875, 0.05),
        ] {
            let g = groups.iter().find(|g| g.name == name).unwrap();
            assert!(!g.members.is_empty(), "{f} {name}");
            for &i in &g.members {
                let p = x0[i as usize];
                assert!(
                    (p[0] - x).abs() <= 0.0025 + 1e-9 && (p[1] - y).abs() <= 0.004,
                    "{f} {name}: particle at {p:?}"
                );
            }
        }
    }
}

/// The 3D beams rest on rollers (docs/scenes.md, "Rollers"): each support and the load is
/// the outermost row of particles below or above, on the lattice planes centred on x = 0.5·d
/// and 3·d below and 1.75·d above (d the depth): one plane (3.47 mm) up to d = 100 mm, three
/// (10.4 mm) at 200 mm, where one plane crushed. Each spans the whole width and is pressed by
/// a bearing that pushes only; both supports hold as many particles (the lattice is
/// symmetric about mid-span).
#[test]
fn beams_in_3d_rest_on_rollers_where_their_scenes_say() {
    for (f, d, planes) in [
        ("beam_3pb_unnotched_3d", 0.05, 1),
        ("beam_3pb_notch02_3d", 0.05, 1),
        ("beam_3pb_notch05_3d", 0.05, 1),
        ("beam_3pb_unnotched_d100_3d", 0.1, 1),
        ("beam_3pb_unnotched_d200_3d", 0.2, 3),
    ] {
        let path = format!("lattices/{f}.toml");
        let scene = Scene::from_file(Path::new(&path), &[]).unwrap();
        let m = sppm::run::prepare_model(&scene, sppm::run::Fcc).unwrap();
        let x0 = &m.particles.x0;
        let bottom = x0.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
        let top = x0.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max);
        let l0 = scene.discretisation.spacing;
        // the pitch of the lattice planes normal to x
        let pitch = l0 / 2f64.sqrt();
        let mut counts = Vec::new();
        for (name, x, y) in [
            ("left_support", 0.5 * d, bottom),
            ("right_support", 3.0 * d, bottom),
            ("load", 1.75 * d, top),
        ] {
            let spec = scene.groups.iter().find(|g| g.name == name).unwrap();
            assert!(spec.bearing.is_some(), "{f} {name}: no bearing");
            let g = m.groups.iter().find(|g| g.name == name).unwrap();
            assert!(!g.members.is_empty(), "{f} {name}: no particles");
            let (mut zmin, mut zmax) = (f64::INFINITY, f64::NEG_INFINITY);
            let mut on_plane = vec![0; planes];
            for &i in &g.members {
                let p = x0[i as usize];
                let k = (p[0] - x) / pitch + (planes / 2) as f64;
                assert!(
                    (k - k.round()).abs() * pitch < 1e-6
                        && (0.0..planes as f64).contains(&k.round())
                        && (p[1] - y).abs() < 1e-6,
                    "{f} {name}: particle at {p:?}"
                );
                on_plane[k.round() as usize] += 1;
                zmin = zmin.min(p[2]);
                zmax = zmax.max(p[2]);
            }
            assert!(
                on_plane.iter().all(|&n| n > 0),
                "{f} {name}: particles per plane {on_plane:?}"
            );
            // across the width: within one spacing of both faces (a row of a lattice plane
            // has a particle every √2·L0 along z)
            assert!(
                zmin < l0 && zmax > 0.05 - l0,
                "{f} {name}: z {zmin}..{zmax}"
            );
            counts.push(g.members.len());
        }
        assert_eq!(
            counts[0], counts[1],
            "{f}: supports of {counts:?} particles"
        );
    }
}

/// A run loaded too fast warns, in summary.json and on stderr, with a loading time that
/// would be quasi-static; a scene without a loading time takes the default.
#[test]
fn a_fast_load_warns_with_the_fix_and_the_default_is_used() {
    let fast = Scene::from_file(
        Path::new("lattices/uniaxial_tension.toml"),
        &[
            "discretisation.spacing=0.02".into(),
            "loading.end_periods=1".into(),
        ],
    )
    .unwrap();
    let s = run(&fast, &RunOptions::default()).unwrap().summary;
    assert!(s.max_kinetic_to_internal_energy > sppm::scene::KINETIC_LIMIT);
    let w: Vec<_> = s
        .warnings
        .iter()
        .filter(|w| w.contains("loading.end_periods ="))
        .collect();
    assert_eq!(w.len(), 1, "{:?}", s.warnings);
    let text = std::fs::read_to_string("lattices/uniaxial_tension.toml").unwrap();
    let start = text.find("end_periods").unwrap();
    let end = start + text[start..].find('\n').unwrap();
    let default = Scene::from_toml_str(
        &text.replace(&text[start..end], ""),
        &["discretisation.spacing=0.02".into()],
    )
    .unwrap();
    let p = sppm::run::prepare(&default, sppm::run::Hexagonal).unwrap();
    let periods = p.t_end / p.fundamental.period;
    assert!(
        (periods - sppm::scene::DEFAULT_END_PERIODS).abs() < 1e-9,
        "{periods}"
    );
}

#[test]
fn bad_gauges_are_refused_in_their_keys() {
    let text = std::fs::read_to_string("lattices/beam_3pb_notch02.toml").unwrap();
    let gauge =
        "[[gauges]]\nname = \"CMOD\"\npoints = [[0.0865, 0.0], [0.0885, 0.0]]\ncomponent = \"x\"\n";
    assert!(text.contains(gauge));
    let with = |g: &str| {
        Scene::from_toml_str(&text.replace(gauge, g), &[])
            .unwrap_err()
            .to_string()
    };
    says(
        &with("[[gauges]]\nname = \"a b\"\npoints = [[0.0, 0.0], [0.1, 0.0]]\ncomponent = \"x\"\n"),
        &["gauges[0].name", "letters"],
    );
    says(
        &with("[[gauges]]\nname = \"g\"\npoints = [[0.0, 0.0]]\ncomponent = \"x\"\n"),
        &["gauges[0].points", "two points"],
    );
    says(
        &with("[[gauges]]\nname = \"g\"\ngroups = [\"load\", \"nowhere\"]\ncomponent = \"y\"\n"),
        &["gauges[0].groups", "nowhere", "one of the groups"],
    );
    says(
        &with("[[gauges]]\nname = \"g\"\ngroups = [\"load\", \"left_support\"]\n"),
        &["gauges[0]", "component", "direction"],
    );
    says(
        &with(
            "[[gauges]]\nname = \"g\"\npoints = [[0.0, 0.0], [0.1, 0.0]]\ndirection = [0.0, 0.0]\n",
        ),
        &["gauges[0].direction", "non-zero"],
    );
    says(
        &with("[[gauges]]\nname = \"g\"\npoints = [[0.0, 0.0], [0.1, 0.0]]\ncomponent = \"z\"\n"),
        &["gauges[0].component", "2D"],
    );
}
