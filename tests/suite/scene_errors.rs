//! Every scene-validation path: a bad scene stops before any work with one message naming
//! the key, the value and what is allowed (docs/architecture.md, "Interfaces").

use crate::common;
use common::says;

use sppm::run::{prepare, prepare_model};
use sppm::Scene;

const BASE: &str = r#"
name = "base"
[body]
shape = "rectangle"
width = 0.1
height = 0.2
[discretisation]
spacing = 0.01
[material]
E = 30.0e9
nu = 0.2
rho = 2400.0
thickness = 0.05
[[groups]]
name = "bottom"
select = { by = "edge", edge = "bottom", rows = 2 }
fix = ["y"]
[[groups]]
name = "top"
select = { by = "edge", edge = "top", rows = 2 }
load = { component = "y", displacement = 1.0e-5 }
[loading]
end_periods = 2.0
"#;

/// Parse BASE with `--set` overrides; the error text.
fn error_of(overrides: &[&str]) -> String {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    match Scene::from_toml_str(BASE, &o) {
        Ok(_) => panic!("{overrides:?} was accepted"),
        Err(e) => e.to_string(),
    }
}

fn error_of_text(text: &str) -> String {
    match Scene::from_toml_str(text, &[]) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn base_scene_is_valid() {
    let s = Scene::from_toml_str(BASE, &[]).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

/// An elastic scene may be of any solid, so only values no solid has are refused (E below
/// 1e5 Pa), with the likely unit; an unusual one is warned (docs/scenes.md, "Units and
/// plausible values").
#[test]
fn elastic_unit_slips_are_refused_or_warned() {
    says(
        &error_of(&["material.E=30"]),
        &["material.E = 30", "GPa", "3e10 Pa"],
    );
    says(
        &error_of(&["discretisation.spacing=25"]),
        &[
            "discretisation.spacing = 25",
            "at most half",
            "mm",
            "2.5e-2 m",
        ],
    );
    // larger than the body but not a slip to mm: no unit is guessed
    let e = error_of(&["discretisation.spacing=0.2"]);
    says(&e, &["discretisation.spacing = 0.2", "at most half"]);
    assert!(!e.contains("mm"), "{e}");
    let rubber = Scene::from_toml_str(BASE, &["material.E=5e6".to_string()]).unwrap();
    assert!(
        rubber.warnings.len() == 1 && rubber.warnings[0].starts_with("material.E = 5000000"),
        "{:?}",
        rubber.warnings
    );
}

#[test]
fn unknown_keys_and_wrong_types_are_named() {
    says(
        &error_of_text(&format!("{BASE}\ncolour = 3\n")),
        &["unknown field `colour`", "expected one of"],
    );
    says(
        &error_of(&["material.youngs=3"]),
        &["unknown field `youngs`", "`E`"],
    );
    says(
        &error_of(&["discretisation.lattice_spacing=0.01"]),
        &["lattice_spacing", "spacing"],
    );
    says(&error_of(&["groups.top.selct=1"]), &["selct"]);
    says(&error_of(&["groups.top.select.rowz=2"]), &["rowz"]);
    says(&error_of(&["material.E=\"stiff\""]), &["invalid type", "E"]);
    says(
        &error_of(&["body.shape=hexagon"]),
        &["hexagon", "rectangle"],
    );
    says(
        &error_of(&["material.plane=membrane"]),
        &["membrane", "stress", "strain"],
    );
    says(
        &error_of(&["groups.top.select.by=circle"]),
        &["circle", "edge"],
    );
    // z is an axis of 3D scenes only
    says(
        &error_of(&["groups.bottom.fix=[\"z\"]"]),
        &["groups.bottom.fix", "z", "2D", "fcc"],
    );
    says(&error_of(&["groups.bottom.fix=[\"w\"]"]), &["w", "`x`"]);
    says(
        &error_of(&["loading.ramp=linear"]),
        &["linear", "cosine", "smoothstep"],
    );
    says(
        &error_of(&["solver.force_lag=later"]),
        &["later", "current", "previous"],
    );
    says(
        &error_of(&["output.field=colour"]),
        &["colour", "displacement"],
    );
}

#[test]
fn impossible_values_name_key_value_and_what_is_allowed() {
    let cases: &[(&[&str], &[&str])] = &[
        (&["name=\"a/b\""], &["name", "a/b", "path separators"]),
        (
            &["discretisation.lattice=cubic"],
            &["discretisation.lattice", "cubic", "hexagonal", "fcc"],
        ),
        // the FCC lattice fills solids: a 2D shape is told how to become one
        (
            &["discretisation.lattice=fcc"],
            &["body.shape", "rectangle", "fcc", "prism"],
        ),
        (
            &["discretisation.spacing=0.0"],
            &["discretisation.spacing", "= 0", "greater than zero"],
        ),
        (
            &["discretisation.spacing=-1.0"],
            &["discretisation.spacing", "-1", "greater than zero"],
        ),
        (
            &["discretisation.spacing=nan"],
            &["discretisation.spacing", "NaN", "finite"],
        ),
        (
            &["discretisation.spacing=0.06"],
            &["discretisation.spacing", "0.06", "at most half"],
        ),
        (
            &["discretisation.rotation_deg=inf"],
            &["discretisation.rotation_deg", "inf", "finite"],
        ),
        (
            &["discretisation.offset=[0.0, nan]"],
            &["discretisation.offset[1]", "NaN"],
        ),
        (
            &["material.E=-3e10"],
            &["material.E", "-30000000000", "greater than zero"],
        ),
        (
            &["material.nu=0.5"],
            &["material.nu", "0.5", "-1 < nu < 0.5"],
        ),
        (
            &["material.nu=-1.0"],
            &["material.nu", "-1", "-1 < nu < 0.5"],
        ),
        (
            &["material.rho=0"],
            &["material.rho", "0", "greater than zero"],
        ),
        (
            &["material.thickness=-0.1"],
            &["material.thickness", "-0.1"],
        ),
        (&["groups.top.name=\"\""], &["groups[1].name", "non-empty"]),
        (
            &["groups.top.name=\"bottom\""],
            &["groups[1].name", "bottom", "unique"],
        ),
        (
            &["groups.top.select.rows=0"],
            &["groups.top.select.rows", "0", "1 to 20"],
        ),
        (
            &["groups.top.select.rows=21"],
            &["groups.top.select.rows", "21", "1 to 20"],
        ),
        (
            &["groups.bottom.fix=[\"y\", \"y\"]"],
            &["groups.bottom.fix", "at most once"],
        ),
        (
            &["groups.top.fix=[\"y\"]"],
            &["groups.top.load.component", "y", "not also in fix"],
        ),
        (
            &["groups.top.load.displacement=nan"],
            &["groups.top.load.displacement", "NaN"],
        ),
        (
            &["loading.ramp_fraction=0"],
            &["loading.ramp_fraction", "0", "0 < ramp_fraction <= 1"],
        ),
        (
            &["loading.ramp_fraction=1.5"],
            &["loading.ramp_fraction", "1.5"],
        ),
        (
            &["loading.end_s=0.01"],
            &[
                "loading.end_s",
                "either loading.end_periods or loading.end_s",
            ],
        ),
        (
            &["loading.end_periods=0"],
            &["loading.end_periods", "0", "greater than zero"],
        ),
        (
            &["loading.end_periods=1e6"],
            &["loading.end_periods", "1000000", "at most 1e5"],
        ),
        (
            &["damping.internal=-0.1"],
            &["damping.internal", "-0.1", "0 to 10"],
        ),
        (
            &["damping.external=11"],
            &["damping.external", "11", "0 to 10"],
        ),
        (
            &["solver.safety=0"],
            &["solver.safety", "0", "0 < safety <= 1"],
        ),
        (&["solver.safety=1.2"], &["solver.safety", "1.2"]),
        (
            &["solver.dt=-1e-7"],
            &["solver.dt", "-0.0000001", "greater than zero"],
        ),
        (&["solver.threads=0"], &["solver.threads", "0", "1 to 1024"]),
        (
            &["output.records=1"],
            &["output.records", "1", "2 to 1000000"],
        ),
        (
            &["output.probe_group=middle"],
            &["output.probe_group", "middle", "one of the groups"],
        ),
        (
            &["output.deformed_scale=-5"],
            &["output.deformed_scale", "-5", ">= 0"],
        ),
        (&["body.width=0"], &["body.width", "0", "greater than zero"]),
        (&["body.height=inf"], &["body.height", "inf"]),
    ];
    for (overrides, fragments) in cases {
        says(&error_of(overrides), fragments);
    }
}

#[test]
fn a_reactionless_probe_is_refused() {
    let text = format!("{BASE}\n[[groups]]\nname = \"mid\"\nselect = {{ by = \"all\" }}\n[output]\nprobe_group = \"mid\"\n");
    says(
        &error_of_text(&text),
        &["output.probe_group", "mid", "loaded or fixed"],
    );
}

#[test]
fn bad_bodies_are_refused() {
    let shape =
        |body: &str| BASE.replace("shape = \"rectangle\"\nwidth = 0.1\nheight = 0.2\n", body);
    says(
        &error_of_text(&shape(
            "shape = \"polygon\"\nvertices = [[0.0, 0.0], [1.0, 0.0]]\n",
        )),
        &["body.vertices", "2 vertices", "at least 3"],
    );
    says(
        &error_of_text(&shape(
            "shape = \"polygon\"\nvertices = [[0.0, 0.0], [2.0, 2.0], [2.0, 0.0], [0.0, 1.0]]\n",
        )),
        &["body.vertices", "simple polygon"],
    );
    says(
        &error_of_text(&shape(
            "shape = \"polygon\"\nvertices = [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]\n",
        )),
        &["body.vertices", "non-zero area"],
    );
    says(
        &error_of_text(&shape("shape = \"disc\"\ndiameter = -0.15\n")),
        &["body.diameter", "-0.15"],
    );
    says(
        &error_of_text(&shape("shape = \"dogbone\"\nsize = 0\n")),
        &["body.size", "0"],
    );
    says(
        &error_of_text(&shape("shape = \"notched_beam\"\nlength = 0.5\ndepth = 0.1\nnotch_depth = 0.1\nnotch_width = 0.002\n")),
        &["body.notch_depth", "0.1", "notch_depth < depth"],
    );
    says(
        &error_of_text(&shape("shape = \"notched_beam\"\nlength = 0.5\ndepth = 0.1\nnotch_depth = 0.05\nnotch_width = 0.6\n")),
        &["body.notch_width", "0.6", "notch_width < length"],
    );
    says(
        &error_of_text(&shape(
            "shape = \"disc\"\ndiameter = 0.15\nradius = 0.075\n",
        )),
        &["unknown field `radius`"],
    );
}

#[test]
fn override_syntax_errors_are_named() {
    says(
        &error_of(&["material.E"]),
        &["--set material.E", "key=value"],
    );
    says(
        &error_of(&["groups.middle.fix=[\"x\"]"]),
        &["--set groups.middle.fix", "name or index"],
    );
    says(
        &error_of(&["material.E.value=1"]),
        &["--set material.E.value", "`material.E` is a value"],
    );
}

fn prepare_error(overrides: &[&str]) -> String {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let s = Scene::from_toml_str(BASE, &o).expect("valid scene");
    match prepare(&s, sppm::run::Hexagonal) {
        Ok(_) => panic!("{overrides:?} prepared"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn scenes_that_fail_at_discretisation_are_refused_before_running() {
    // a group that selects nothing
    says(
        &prepare_error(&["groups.top.select={ by = \"box\", min = [5.0, 5.0], max = [6.0, 6.0] }"]),
        &["groups.top.select", "at least one particle"],
    );
    // overlapping groups that prescribe different displacements
    says(
        &prepare_error(&["groups.bottom.select={ by = \"all\" }"]),
        &["groups.top", "groups.bottom already prescribes 0"],
    );
    // a time step above the computed limit
    says(
        &prepare_error(&["solver.dt=1.0"]),
        &["solver.dt", "1e0", "at most the stable limit"],
    );
    // a geometry with no bonded particles: a diagonal sliver 0.1 mm wide (its bounding box
    // passes the spacing check, but only one lattice site lies in it)
    let text = BASE
        .replace(
            "shape = \"rectangle\"\nwidth = 0.1\nheight = 0.2\n",
            "shape = \"polygon\"\nvertices = [[0.0, 0.0], [0.02, 0.02], [0.0201, 0.0199]]\n",
        )
        .replace("spacing = 0.01", "spacing = 0.005");
    let mut s = Scene::from_toml_str(&text, &[]).unwrap();
    s.groups.clear();
    let msg = match prepare_model(&s, sppm::run::Hexagonal) {
        Ok(m) => panic!("{} particles", m.particles.len()),
        Err(e) => e.to_string(),
    };
    says(
        &msg,
        &["discretisation.spacing", "0 bonded particles", "at least 2"],
    );
    // a scene too large for this machine's memory
    says(
        &prepare_error(&["discretisation.spacing=1e-7"]),
        &["discretisation.spacing", "more than this machine has"],
    );
}

/// Random particles (SPPM): the minimum distance, the keys a random set does not have, a
/// seed that is not an integer, and a body too small for three particles.
#[test]
fn random_particle_keys() {
    for bad in ["0.8", "0.4", "1", "0", "-0.5"] {
        let msg = error_of(&[
            "discretisation.lattice=\"random\"",
            &format!("discretisation.min_distance={bad}"),
        ]);
        says(&msg, &["discretisation.min_distance", bad, "[0.5, 0.75]"]);
    }
    let msg = error_of(&["discretisation.min_distance=0.7"]);
    says(&msg, &["discretisation.min_distance", "hexagonal"]);
    let msg = error_of(&[
        "discretisation.lattice=\"random\"",
        "discretisation.offset=[0.001, 0.0]",
    ]);
    says(&msg, &["discretisation.offset", "0.001", "random"]);
    let msg = error_of(&[
        "discretisation.lattice=\"random\"",
        "discretisation.surface_correction=true",
    ]);
    says(&msg, &["discretisation.surface_correction", "random"]);
    let msg = error_of(&[
        "discretisation.lattice=\"random\"",
        "discretisation.surface=\"lattice\"",
    ]);
    says(
        &msg,
        &["discretisation.surface", "lattice", "random", "voronoi_fit"],
    );
    let msg = error_of(&[
        "discretisation.surface=\"voronoi\"",
        "discretisation.surface_correction=false",
    ]);
    says(
        &msg,
        &["discretisation.surface_correction", "false", "lattice_fit"],
    );
    let msg = error_of(&["discretisation.surface=\"clipped\""]);
    says(&msg, &["discretisation.surface", "clipped"]);
    let msg = error_of(&["discretisation.lattice=\"random\"", "seed=1.5"]);
    says(&msg, &["seed", "1.5"]);
    let msg = error_of(&["discretisation.lattice=\"voronoi\""]);
    says(&msg, &["discretisation.lattice", "voronoi", "random"]);
}

#[test]
fn a_body_too_small_for_random_particles_is_refused() {
    // a 12 × 12 mm plate at a 7 mm spacing would hold about 3 random particles
    let s = Scene::from_toml_str(
        BASE,
        &[
            "discretisation.lattice=\"random\"".into(),
            "body.width=0.012".into(),
            "body.height=0.012".into(),
            "discretisation.spacing=0.007".into(),
        ],
    );
    let msg = match s {
        Err(e) => e.to_string(),
        Ok(s) => match sppm::run::prepare(&s, sppm::run::RandomPlane::default()) {
            Err(e) => e.to_string(),
            Ok(p) => panic!("{} particles accepted", p.model.particles.len()),
        },
    };
    says(&msg, &["discretisation.spacing"]);
}

/// `[model]`: the bond-based keys only with the bond-based family, their ranges, the cubic
/// grid only with it, and what a bond-based run does not offer, each under the key the scene
/// set.
#[test]
fn model_family_keys() {
    says(
        &error_of(&["model.horizon=3.0"]),
        &["model.horizon = set", "model.family = \"bond_based\""],
    );
    says(
        &error_of(&["discretisation.lattice=cubic"]),
        &["discretisation.lattice = \"cubic\"", "bond_based"],
    );
    let bb = "model.family=bond_based";
    assert!(Scene::from_toml_str(BASE, &[bb.to_string()]).is_ok());
    says(
        &error_of(&[bb, "model.horizon=12"]),
        &["model.horizon = 12", "from 1.5 to 8"],
    );
    says(
        &error_of(&[bb, "model.compressive_stretch=-0.001"]),
        &["model.compressive_stretch = -0.001", "positive"],
    );
    says(
        &error_of(&[bb, "model.softening=trilinear"]),
        &["model.softening = \"trilinear\"", "[concrete]"],
    );
    says(
        &error_of(&[bb, "model.softening=quadratic"]),
        &["unknown variant `quadratic`", "non_linear"],
    );
    says(
        &error_of(&[bb, "solver.method=relaxation"]),
        &[
            "solver.method = \"relaxation\"",
            "\"explicit\"",
            "bond_based",
        ],
    );
    says(
        &error_of(&[bb, "damping.internal=0.1"]),
        &["damping.internal = 0.1", "damping.external"],
    );
    says(
        &error_of(&[bb, "output.snapshots=4"]),
        &["output.snapshots = 4", "absent with model.family"],
    );
}

/// The cubic grid is aligned with the axes: a rotation of it is refused, not ignored.
#[test]
fn a_turned_cubic_grid_is_refused() {
    says(
        &error_of(&[
            "model.family=bond_based",
            "discretisation.lattice=cubic",
            "discretisation.rotation_deg=15",
        ]),
        &["discretisation.rotation_deg = [15.0, 0.0, 0.0]", "cubic"],
    );
}
