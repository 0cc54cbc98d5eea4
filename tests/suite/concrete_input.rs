//! Concrete input (docs/model.md §11, docs/validation.md §B–D): the correlations reproduce the derived
//! values the validation cases quote, a scene value overrides a correlation, and bad
//! material input is refused with one message naming the key, the value and what is allowed.

use sppm::Scene;
use std::path::Path;

const CONCRETE: &str = r#"
name = "c"
[body]
shape = "rectangle"
width = 0.15
height = 0.3
[discretisation]
spacing = 0.01
[material]
nu = 0.2
rho = 2323.0
thickness = 0.15
[concrete]
fc = 27.58e6
max_aggregate = 0.019
[[groups]]
name = "bottom"
select = { by = "edge", edge = "bottom", rows = 2 }
fix = ["y"]
[[groups]]
name = "top"
select = { by = "edge", edge = "top", rows = 2 }
load = { component = "y" }
[loading]
end_periods = 2.0
"#;

fn scene(overrides: &[&str]) -> Result<Scene, String> {
    scene_of(CONCRETE, overrides)
}

/// The shipped 3D tension prism (FCC) with `overrides`.
fn prism(overrides: &[&str]) -> Scene {
    let text = std::fs::read_to_string("lattices/tension_prism_3d.toml").unwrap();
    scene_of(&text, overrides).unwrap()
}

fn scene_of(text: &str, overrides: &[&str]) -> Result<Scene, String> {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Scene::from_toml_str(text, &o).map_err(|e| e.to_string())
}

fn refused(overrides: &[&str], fragments: &[&str]) {
    let msg = match scene(overrides) {
        Ok(_) => panic!("{overrides:?} was accepted"),
        Err(e) => e,
    };
    for f in fragments {
        assert!(msg.contains(f), "message {msg:?} does not name {f:?}");
    }
}

fn close(what: &str, got: f64, want: f64, rel: f64) {
    assert!(
        (got / want - 1.0).abs() <= rel,
        "{what}: {got:e} against {want:e} (tolerance {rel})"
    );
}

/// docs/validation.md §B: E (ACI) ≈ 25.1 GPa, f't = 2.6168 MPa, G_f ≈ 81.4 N/m, COD_c ≈ 0.178 mm;
/// the default Δmax is 1.5·COD_c. Tolerances: half a unit of the last digit quoted (f't:
/// the table's rounding).
#[test]
fn block_values_follow_aci_and_ceb_fip() {
    let s = scene(&[]).unwrap();
    let v = |k: &str| s.derived_value(k).unwrap();
    close("E", v("E"), 25.1e9, 0.05 / 25.1);
    // ACI gives 2.61642 MPa for 27.58 MPa; Table 1 prints 2.6168 MPa (0.015% apart)
    close("ft", v("ft"), 2.6168e6, 2e-4);
    close("Gf", v("Gf"), 81.4, 0.05 / 81.4);
    close("COD_c", v("COD_c"), 0.178e-3, 0.0005 / 0.178);
    close("fy", v("fy"), 27.58e6 * 5.0 / 6.0, 1e-12);
    let top = s.groups.iter().find(|g| g.name == "top").unwrap();
    close(
        "Δmax",
        top.load.as_ref().unwrap().delta(),
        1.5 * v("COD_c"),
        1e-12,
    );
}

/// docs/validation.md §C and §D through the shipped scenes (presets).
#[test]
fn shipped_scenes_derive_the_quoted_values() {
    let load = |f: &str| Scene::from_file(Path::new(f), &[]).unwrap();
    let c = load("lattices/split_cylinder.toml");
    let v = |s: &Scene, k: &str| s.derived_value(k).unwrap();
    close("E", v(&c, "E"), 30.7e9, 0.05 / 30.7);
    close("ft", v(&c, "ft"), 3.20e6, 0.005 / 3.20);
    close("Gf", v(&c, "Gf"), 102.2, 0.05 / 102.2);
    close("COD_c", v(&c, "COD_c"), 0.183e-3, 0.0005 / 0.183);
    for f in ["lattices/dogbone_B.toml", "lattices/dogbone_D.toml"] {
        let d = load(f);
        close("E", v(&d, "E"), 30.8e9, 0.05 / 30.8);
        assert_eq!(v(&d, "ft"), 2.415e6);
        close("Gf", v(&d, "Gf"), 85.6, 0.05 / 85.6);
        close("COD_c", v(&d, "COD_c"), 0.202e-3, 0.0005 / 0.202);
    }
}

#[test]
fn a_scene_value_overrides_the_correlation_and_says_so() {
    let s = scene(&["material.E=30e9", "concrete.ft=3.0e6", "concrete.Gf=100.0"]).unwrap();
    for (k, v) in [("E", 30e9), ("ft", 3.0e6), ("Gf", 100.0)] {
        let d = s.derived.iter().find(|d| d.key == k).unwrap();
        assert_eq!((d.value, d.source.as_str()), (v, "scene"));
    }
    assert_eq!(
        s.derived_value("Gf0"),
        None,
        "G_f0 is not needed when G_f is given"
    );
    let law = sppm::model::damage::ConcreteLaw::from_scene(&s).unwrap();
    close("COD_c", law.cod_c, 2.0 * 100.0 / (3.0e6 * 0.35), 1e-12);
}

#[test]
fn bad_material_input_is_refused() {
    refused(
        &["concrete.fc=-27e6"],
        &["concrete.fc", "-27000000", "greater than zero"],
    );
    refused(&["concrete.ft=-1e6"], &["concrete.ft", "greater than zero"]);
    refused(&["material.nu=0.5"], &["material.nu", "0.5", "nu < 0.5"]);
    refused(&["concrete.ft=30e6"], &["concrete.ft", "below f'c"]);
    refused(&["concrete.fy=30e6"], &["concrete.fy", "f_ult"]);
    refused(
        &["concrete.alpha=1.5"],
        &["concrete.alpha", "0 < value < 1"],
    );
    refused(&["concrete.eps_ult=0"], &["concrete.eps_ult"]);
    refused(
        &["concrete.max_aggregate=0.02"],
        &["concrete.max_aggregate", "0.02", "Gf0"],
    );
    // G_f so small that COD_c is below the elastic crack opening crack_band·L0·f't/E of
    // L0 = 50 mm (2.8 × 0.05 m × 2.6164 MPa / 25.13 GPa = 1.4576e-5 m; the least G_f is
    // 1.4576e-5 m × f't × (α+γ)/2 = 6.674 N/m). 5 N/m is below plain concrete's range
    // but not refused by it (see unit_slips_are_refused_in_the_users_key).
    refused(
        &["concrete.Gf=5", "discretisation.spacing=0.05"],
        &[
            "concrete.Gf",
            "5.0000 N/m",
            "elastic crack opening",
            "1.458e-5",
            "6.67",
        ],
    );
    // f'c is needed for the correlations
    let text = CONCRETE.replace("fc = 27.58e6\n", "");
    let e = Scene::from_toml_str(&text, &[]).unwrap_err().to_string();
    assert!(e.contains("concrete.fc") && e.contains("preset"), "{e}");
    // E is needed without [concrete]
    let start = text.find("[concrete]").unwrap();
    let end = text.find("[[groups]]").unwrap();
    let elastic = format!("{}{}", &text[..start], &text[end..]);
    let e = Scene::from_toml_str(&elastic, &[]).unwrap_err().to_string();
    assert!(e.contains("material.E") && e.contains("missing"), "{e}");
}

/// A value outside the range real concrete spans is refused in the key the user wrote,
/// with that range and the unit that would put it inside (docs/scenes.md, "Units and
/// plausible values"): E = 30 (GPa meant), f'c = 40 (MPa), G_f = 0.08 (N/mm), ρ = 2.4
/// (t/m³), a spacing of 10 (mm) on a 150 mm wide block. A value inside the hard bounds but
/// outside plain concrete's range is accepted with a warning.
#[test]
fn unit_slips_are_refused_in_the_users_key() {
    refused(&["material.E=30"], &["material.E = 30", "GPa", "3e10 Pa"]);
    refused(&["concrete.fc=40"], &["concrete.fc = 40", "MPa", "4e7 Pa"]);
    refused(
        &["concrete.Gf=0.08"],
        &["concrete.Gf = 0.08", "N/mm", "80 N/m"],
    );
    refused(
        &["material.rho=2.4"],
        &["material.rho = 2.4", "t/m³", "2400 kg/m³"],
    );
    refused(
        &["concrete.ft=2.6"],
        &["concrete.ft = 2.6", "MPa", "2.6e6 Pa"],
    );
    refused(
        &["discretisation.spacing=10"],
        &["discretisation.spacing = 10", "mm", "1e-2 m"],
    );
    // f'c = 4 looks like ksi (27.6 MPa), not MPa (4 MPa is below the range)
    refused(&["concrete.fc=4"], &["concrete.fc = 4", "ksi"]);
    let s = scene(&["concrete.Gf=2000"]).unwrap();
    assert!(
        s.warnings.len() == 1 && s.warnings[0].starts_with("concrete.Gf = 2000"),
        "{:?}",
        s.warnings
    );
    assert!(scene(&[]).unwrap().warnings.is_empty());
}

/// A strength out of order is blamed on the key the user wrote, not on a derived one.
#[test]
fn strengths_out_of_order_blame_the_written_key() {
    // f_y = (5/6)·f'c = 22.98 MPa is derived; f_ult = 20 MPa is written
    refused(
        &["concrete.fult=20e6"],
        &["concrete.fult = 20000000", "f_y"],
    );
}

/// The crack band defaults by discretisation (2D: lattices 2.8, random particles 3.2; 3D: FCC
/// 3.45, random particles 4.2; all measured: benchmarks/RESULTS.md), is recorded with its
/// source, and a scene's value wins.
#[test]
fn crack_band_defaults_by_discretisation() {
    let band = |s: &Scene| s.concrete.as_ref().unwrap().crack_band.unwrap();
    let lattice = scene(&[]).unwrap();
    assert_eq!(band(&lattice), 2.8);
    assert_eq!(lattice.derived_value("concrete.crack_band"), Some(2.8));
    let random = scene(&["discretisation.lattice=\"random\""]).unwrap();
    assert_eq!(band(&random), 3.2);
    assert_eq!(random.derived_value("concrete.crack_band"), Some(3.2));
    let given = scene(&[
        "discretisation.lattice=\"random\"",
        "concrete.crack_band=2.5",
    ])
    .unwrap();
    assert_eq!(band(&given), 2.5);
    assert!(given
        .derived
        .iter()
        .any(|d| d.key == "concrete.crack_band" && d.source == "scene"));
    assert_eq!(band(&prism(&[])), 3.45);
    let random3 = prism(&["discretisation.lattice=\"random\""]);
    assert_eq!(band(&random3), 4.2);
    assert_eq!(random3.derived_value("concrete.crack_band"), Some(4.2));
}

/// What (4.14) softens and the opening it reads default by dimension (docs/model.md §8): as
/// written in 2D ((4.14) on E·ε_I, the total opening (4.13)), the effective stress at its own
/// opening in 3D ((S.22), (S.23)), on either discretisation; the law the run uses
/// (`ConcreteLaw::from_scene`, reported in summary.json) follows; a scene's value wins; a
/// value that is none of them is refused in its key.
#[test]
fn law_reading_defaults_by_dimension() {
    use sppm::model::damage::ConcreteLaw;
    use sppm::scene::{CrackOpening, SofteningStress};
    let reading = |s: &Scene| {
        let c = s.concrete.as_ref().unwrap();
        let law = ConcreteLaw::from_scene(s).unwrap();
        assert_eq!(law.softening_stress, c.softening_stress.unwrap());
        assert_eq!(law.crack_opening, c.crack_opening.unwrap());
        (law.softening_stress, law.crack_opening)
    };
    let as_written = (SofteningStress::Strain, CrackOpening::Total);
    let effective = (SofteningStress::Stress, CrackOpening::Stress);
    assert_eq!(reading(&scene(&[]).unwrap()), as_written);
    let random = scene(&["discretisation.lattice=\"random\""]).unwrap();
    assert_eq!(reading(&random), as_written);
    assert_eq!(reading(&prism(&[])), effective);
    assert_eq!(
        reading(&prism(&["discretisation.lattice=\"random\""])),
        effective
    );
    assert_eq!(
        reading(&prism(&[
            "concrete.softening_stress=\"strain\"",
            "concrete.crack_opening=\"total\""
        ])),
        as_written
    );
    assert_eq!(
        reading(&scene(&["concrete.crack_opening=\"inelastic\""]).unwrap()),
        (SofteningStress::Strain, CrackOpening::Inelastic)
    );
    refused(
        &["concrete.softening_stress=\"principal\""],
        &["softening_stress", "strain", "stress"],
    );
}

/// The criteria strain defaults by discretisation (docs/model.md §7): each particle's own on
/// the lattices, the neighbourhood mean on random particles; a scene value wins; a value that
/// is neither is refused in its key.
#[test]
fn criteria_strain_defaults_by_discretisation() {
    use sppm::scene::CriteriaStrain::{Neighbourhood, Own};
    let criteria = |s: &Scene| s.concrete.as_ref().unwrap().criteria_strain.unwrap();
    assert_eq!(criteria(&scene(&[]).unwrap()), Own);
    let random = scene(&["discretisation.lattice=\"random\""]).unwrap();
    assert_eq!(criteria(&random), Neighbourhood);
    let given = scene(&["concrete.criteria_strain=\"neighbourhood\""]).unwrap();
    assert_eq!(criteria(&given), Neighbourhood);
    let surface = scene(&["concrete.criteria_strain=\"surface\""]).unwrap();
    assert_eq!(criteria(&surface), sppm::scene::CriteriaStrain::Surface);
    assert_eq!(criteria(&prism(&[])), Own);
    assert_eq!(
        criteria(&prism(&["concrete.criteria_strain=\"neighbourhood\""])),
        Neighbourhood
    );
    assert_eq!(
        criteria(&prism(&["discretisation.lattice=\"random\""])),
        Neighbourhood
    );
    refused(
        &["concrete.criteria_strain=\"mean\""],
        &["criteria_strain", "neighbourhood", "own"],
    );
}
