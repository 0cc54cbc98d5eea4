//! What the README says about the command line holds: its two set-up commands, the
//! validation command, the command list, `--help` and `--set`.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).unwrap()
}

fn sppm(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_sppm"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap()
}

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The README's set-up block: exactly the two commands, the first running a shipped scene
/// (whose output folder is output/<its name>/, as the README says) and the second the tests.
#[test]
fn the_two_set_up_commands_run_a_shipped_scene_and_the_tests() {
    let text = readme();
    let block: Vec<&str> = text
        .split("```sh\n")
        .nth(1)
        .and_then(|b| b.split("```").next())
        .expect("the README opens a sh block for the set-up")
        .lines()
        .filter(|l| !l.trim().is_empty())
        .collect();
    assert_eq!(
        block,
        [
            "cargo run --release -- run lattices/split_cylinder.toml",
            "cargo test --release"
        ]
    );
    assert!(text.contains("`output/split_cylinder/`"));
    let scene = sppm::Scene::from_file(&root().join("lattices/split_cylinder.toml"), &[]).unwrap();
    assert_eq!(scene.name(), "split_cylinder");
    // the run itself, into a folder of its own (the default folder is the repository's)
    let out = std::env::temp_dir().join(format!("sppm-readme-{}", std::process::id()));
    let o = sppm(&[
        "run",
        "lattices/split_cylinder.toml",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--set",
        "loading.stop_after_peak=0.9",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("summary.json").exists() && out.join("crack_map.svg").exists());
    std::fs::remove_dir_all(&out).ok();
}

/// The validation command the README names switches on a feature the package declares, that
/// feature gates long tests, and CI runs it after the fast suite.
#[test]
fn the_validation_command_names_a_feature_ci_runs() {
    assert!(readme().contains("`cargo test --release --features validation`"));
    let cargo = std::fs::read_to_string(root().join("Cargo.toml")).unwrap();
    assert!(
        cargo.contains("\nvalidation = []"),
        "Cargo.toml declares the feature"
    );
    let gated = std::fs::read_dir(root().join("tests/suite"))
        .unwrap()
        .map(|e| std::fs::read_to_string(e.unwrap().path()).unwrap())
        .map(|t| t.matches("not(feature = \"validation\")").count())
        .sum::<usize>();
    assert!(gated >= 10, "{gated} tests gated");
    let ci: String = std::fs::read_to_string(root().join(".ci/run"))
        .unwrap()
        .lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .collect::<Vec<_>>()
        .join("\n");
    let fast = ci
        .find("cargo test --release 2>&1")
        .expect("CI runs the fast suite");
    let long = ci
        .find("cargo test --release --features validation")
        .expect("CI runs the validations");
    assert!(fast < long);
}

/// The command list: `sppm --help` names the four commands, `sppm study --help` the four
/// studies, and each command has its own `--help`.
#[test]
fn the_commands_the_readme_lists_exist_with_their_help() {
    let text = readme();
    let help = stdout(&sppm(&["--help"]));
    for cmd in ["run", "check", "study", "bench"] {
        assert!(text.contains(&format!("sppm {cmd}")), "README lists {cmd}");
        assert!(help.contains(cmd), "sppm --help lists {cmd}: {help}");
        let o = sppm(&[cmd, "--help"]);
        assert!(o.status.success(), "sppm {cmd} --help");
    }
    assert!(text.contains("objectivity | convergence | montecarlo | merge"));
    let study = stdout(&sppm(&["study", "--help"]));
    for s in ["objectivity", "convergence", "montecarlo", "merge"] {
        assert!(study.contains(s), "sppm study --help lists {s}: {study}");
    }
}

/// `--set` changes one scene value without editing the file: `sppm check` shows the value
/// and that it came from the scene.
#[test]
fn set_changes_one_value_without_editing_the_file() {
    assert!(readme().contains("`--set`"));
    let scene = Path::new("lattices/split_cylinder.toml");
    let before = std::fs::read_to_string(root().join(scene)).unwrap();
    let o = sppm(&[
        "check",
        scene.to_str().unwrap(),
        "--set",
        "concrete.ft=3.1e6",
    ]);
    assert!(o.status.success());
    let line = stdout(&o)
        .lines()
        .find(|l| l.starts_with("ft "))
        .map(str::to_string)
        .expect("check lists f't");
    assert!(
        line.contains("3.100000e6") && line.contains("scene"),
        "{line}"
    );
    assert_eq!(std::fs::read_to_string(root().join(scene)).unwrap(), before);
}

/// The size variant's rule is one text in the code (`SPACING_RULE`, its displacement part
/// `DISPLACEMENT_RULE`), and the code applies it: dog-bone D (D0 = 0.4 m, 0.5 mm) at
/// D = 1.6 m is pulled 0.5 mm × √4 = 1 mm. The README, docs/studies.md and `sppm study
/// montecarlo --help` state that rule in those words, and none says the displacement scales
/// as D/D0.
#[test]
fn the_size_variant_rule_is_stated_as_the_code_applies_it() {
    use sppm::study::monte_carlo::{size_overrides, DISPLACEMENT_RULE, SPACING_RULE};
    let base = sppm::Scene::from_file(&root().join("lattices/dogbone_D.toml"), &[]).unwrap();
    let o = size_overrides(&base, 1.6);
    let delta: f64 = o[2]
        .strip_prefix("groups.2.load.displacement=")
        .unwrap()
        .parse()
        .unwrap();
    assert!((delta - 0.5e-3 * 4f64.sqrt()).abs() < 1e-15, "{o:?}");
    assert!(DISPLACEMENT_RULE.contains("√(D/D0)") && SPACING_RULE.contains(DISPLACEMENT_RULE));
    let words = |t: &str| t.split_whitespace().collect::<Vec<_>>().join(" ");
    let docs = words(&std::fs::read_to_string(root().join("docs/studies.md")).unwrap());
    let help = words(&stdout(&sppm(&["study", "montecarlo", "--help"])));
    let readme = words(&readme());
    assert!(docs.contains(SPACING_RULE), "docs/studies.md");
    assert!(help.contains(SPACING_RULE), "--help: {help}");
    assert!(readme.contains(DISPLACEMENT_RULE), "README.md");
    for (name, text) in [
        ("README.md", &readme),
        ("docs/studies.md", &docs),
        ("--help", &help),
    ] {
        for wrong in [
            "displacement × D/D0",
            "displacement multiplied by D/D0",
            "displacement scaled by D/D0",
            "displacement *= D/D0",
            "displacement proportional to D",
        ] {
            assert!(!text.contains(wrong), "{name} says `{wrong}`");
        }
    }
}

/// The README's "Your own scene": the frames it gives are the bodies' bounding boxes, the
/// default loading time and the warning's limit are the code's, and a strip without a
/// centre sits at the middle of its edge.
#[test]
fn your_own_scene_states_what_the_code_does() {
    let text = readme();
    assert!(text.contains(&format!(
        "loaded over {} fundamental periods",
        sppm::scene::DEFAULT_END_PERIODS
    )));
    assert!(text.contains(&format!(
        "kinetic energy exceeds {} of its internal",
        sppm::scene::KINETIC_LIMIT
    )));
    for (row, body, lo, hi) in [
        (
            "| `notched_beam` | x in [0, length], y in [0, depth]",
            "shape = \"notched_beam\"\nlength = 0.175\ndepth = 0.05\nnotch_depth = 0.01\nnotch_width = 0.002",
            [0.0, 0.0],
            [0.175, 0.05],
        ),
        (
            "| `dogbone` | x in [−D/2, D/2], y in [0, 1.5·D]",
            "shape = \"dogbone\"\nsize = 0.1",
            [-0.05, 0.0],
            [0.05, 0.15],
        ),
        (
            "| `rectangle` | x in [origin.x, origin.x + width], y in [origin.y, origin.y + height]; origin default [0, 0]",
            "shape = \"rectangle\"\nwidth = 0.2\nheight = 0.1",
            [0.0, 0.0],
            [0.2, 0.1],
        ),
    ] {
        assert!(text.contains(row), "{row}");
        let scene = sppm::Scene::from_toml_str(
            &format!("[body]\n{body}\n[discretisation]\nspacing = 0.01\n[material]\nE = 30e9\nnu = 0.2\nrho = 2400.0\nthickness = 0.05\n"),
            &[],
        )
        .unwrap();
        let (a, b) = scene.shape().bounding_box();
        for k in 0..2 {
            assert!((a[k] - lo[k]).abs() < 1e-12 && (b[k] - hi[k]).abs() < 1e-12, "{row}: {a:?} {b:?}");
        }
    }
}
