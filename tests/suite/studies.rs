//! `sppm study objectivity|convergence` as a user meets it: one CSV row per run written as the
//! run finishes, the overlay and convergence plots, the per-run outputs, resuming an
//! interrupted study, clear errors for bad arguments, and the objectivity of the tension block
//! against docs/validation.md §B.

use crate::common;
use common::sppm;
use std::path::{Path, PathBuf};
use std::process::Output;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sppm-study-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// The shipped tension block at L0 = 30 mm (66 particles, a few tenths of a second a run):
/// for the mechanics of the study, not for physics.
const TINY: [&str; 2] = ["--set", "discretisation.spacing=0.03"];

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// The rows of a study CSV as maps from column to value.
fn rows(path: &Path) -> Vec<std::collections::HashMap<String, String>> {
    common::csv_rows(path)
}

fn num(row: &std::collections::HashMap<String, String>, key: &str) -> f64 {
    row[key]
        .parse()
        .unwrap_or_else(|_| panic!("{key} = {}", row[key]))
}

fn objectivity(out: &Path, extra: &[&str]) -> Output {
    let head = [
        "study",
        "objectivity",
        "lattices/uniaxial_tension.toml",
        "--quiet",
        "--jobs",
        "2",
        "--out",
        out.to_str().unwrap(),
    ];
    sppm(&[&head[..], extra].concat())
}

#[test]
fn objectivity_writes_rows_plots_and_crack_maps_and_resumes() {
    let out = tmp("objectivity");
    let o = objectivity(
        &out,
        &[&TINY[..], &["--angles", "0,30", "--offsets", "1"]].concat(),
    );
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    let line = stdout
        .lines()
        .find(|l| l.starts_with("peak force spread (max − min)/mean = "))
        .unwrap_or_else(|| panic!("no spread line in {stdout}"));
    assert!(line.contains("% over 4 runs (min "), "{line}");
    let csv_path = out.join("objectivity.csv");
    let first = std::fs::read_to_string(&csv_path).unwrap();
    let header = first.lines().next().unwrap();
    for col in [
        "label",
        "angle_deg",
        "offset",
        "offset_x_m",
        "offset_y_m",
        "seed",
        "particles",
        "peak_force_N",
        "displacement_at_peak_m",
        "dissipated_energy_J",
        "wall_time_s",
        "status",
        "cracked_particles",
        "crack_particles",
        "crack_axis_deg",
        "crack_rms_width_m",
        "crack_centroid_x_m",
        "crack_centroid_y_m",
        "crack_core_axis_deg",
        "crack_core_rms_width_m",
    ] {
        assert!(
            header.split(',').any(|c| c == col),
            "no column {col}: {header}"
        );
    }
    let rs = rows(&csv_path);
    assert_eq!(rs.len(), 4, "{first}");
    let mut labels: Vec<&str> = rs.iter().map(|r| r["label"].as_str()).collect();
    labels.sort();
    assert_eq!(labels, ["a0_o0", "a0_o1", "a30_o0", "a30_o1"]);
    for r in &rs {
        assert_eq!(r["status"], "completed");
        assert!(num(r, "peak_force_N") > 0.0);
        assert!(num(r, "particles") > 30.0);
        let (ox, oy) = (num(r, "offset_x_m"), num(r, "offset_y_m"));
        if r["offset"] == "0" {
            assert_eq!((ox, oy), (0.0, 0.0));
        } else {
            // a random offset inside the lattice cell (|offset| < 2·L0)
            assert!(ox.hypot(oy) > 0.0 && ox.hypot(oy) < 0.06, "{ox} {oy}");
        }
        assert_eq!(num(r, "rotation_deg"), num(r, "angle_deg"));
        let dir = out.join(&r["label"]);
        for f in ["summary.json", "crack_map.svg", "force_displacement.csv"] {
            assert!(dir.join(f).is_file(), "{} lacks {f}", dir.display());
        }
    }
    let overlay = std::fs::read_to_string(out.join("force_displacement_overlay.svg")).unwrap();
    assert!(overlay.contains("<svg") && overlay.contains("θ = 30°, offset 1"));
    assert!(overlay.matches("<polyline").count() >= 4);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("objectivity.json")).unwrap())
            .unwrap();
    assert_eq!(json["runs"], 4);
    assert!(json["seed"].as_u64().is_some());
    assert_eq!(json["crack_damage"], 0.9);
    assert!(json["peak_force"]["spread"].as_f64().unwrap() >= 0.0);

    // Started again: nothing runs, the CSV is unchanged and the line is the same.
    let o = objectivity(
        &out,
        &[&TINY[..], &["--angles", "0,30", "--offsets", "1"]].concat(),
    );
    assert!(o.status.success(), "{}", text(&o).1);
    assert_eq!(std::fs::read_to_string(&csv_path).unwrap(), first);
    assert!(text(&o).0.contains(line), "{}", text(&o).0);

    // A lost row (an interrupted study) is run again, and only that one.
    let kept: Vec<&str> = first.lines().take(4).collect(); // the header and three rows
    let lost = rows(&csv_path)[3]["label"].clone();
    std::fs::write(&csv_path, kept.join("\n") + "\n").unwrap();
    let o = objectivity(
        &out,
        &[&TINY[..], &["--angles", "0,30", "--offsets", "1"]].concat(),
    );
    assert!(o.status.success(), "{}", text(&o).1);
    let again = std::fs::read_to_string(&csv_path).unwrap();
    assert!(again.starts_with(&(kept.join("\n") + "\n")));
    let rs = rows(&csv_path);
    assert_eq!(rs.len(), 4);
    assert_eq!(rs[3]["label"], lost);
    // the same run gives the same peak (runs are deterministic)
    let before = rows_from_text(&first);
    assert_eq!(before[3]["peak_force_N"], rs[3]["peak_force_N"]);

    // Another seed in the same folder is refused: its rows would be other runs.
    let o = objectivity(
        &out,
        &[
            &TINY[..],
            &["--angles", "0,30", "--offsets", "1", "--seed", "5"],
        ]
        .concat(),
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).1.contains("other inputs"), "{}", text(&o).1);
    let _ = std::fs::remove_dir_all(&out);
}

fn rows_from_text(t: &str) -> Vec<std::collections::HashMap<String, String>> {
    let p = tmp("rows").with_extension("csv");
    std::fs::write(&p, t).unwrap();
    let r = rows(&p);
    let _ = std::fs::remove_file(&p);
    r
}

#[test]
fn an_unstable_run_is_a_row_not_the_end_of_the_study() {
    let out = tmp("unstable");
    // the literal force lag (reading A) is unstable at the safe step of reading B
    let o = objectivity(
        &out,
        &[
            &TINY[..],
            &["--angles", "0", "--set", "solver.force_lag=previous"],
        ]
        .concat(),
    );
    assert_eq!(o.status.code(), Some(3), "{:?}", text(&o));
    let rs = rows(&out.join("objectivity.csv"));
    assert_eq!(rs.len(), 1);
    assert_eq!(rs[0]["status"], "unstable");
    assert!(rs[0]["message"].contains("unstable at step"), "{:?}", rs[0]);
    assert!(text(&o)
        .0
        .contains("undefined, none of the 1 runs completed"));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn convergence_writes_its_table_reference_and_plot() {
    let out = tmp("convergence");
    let o = sppm(&[
        "study",
        "convergence",
        "lattices/uniaxial_tension.toml",
        "--spacings",
        "0.03,0.025,0.02",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stdout.lines().any(|l| l.starts_with("peak force: ")),
        "{stdout}"
    );
    assert!(
        stdout.lines().any(|l| l.starts_with("dissipated energy: ")),
        "{stdout}"
    );
    let header = std::fs::read_to_string(out.join("convergence.csv")).unwrap();
    let header = header.lines().next().unwrap().to_string();
    for col in [
        "spacing_m",
        "particles",
        "peak_force_N",
        "dissipated_energy_J",
        "wall_time_s",
        "status",
    ] {
        assert!(
            header.split(',').any(|c| c == col),
            "no column {col}: {header}"
        );
    }
    let rs = rows(&out.join("convergence.csv"));
    assert_eq!(rs.len(), 3);
    let mut h: Vec<f64> = rs.iter().map(|r| num(r, "spacing_m")).collect();
    h.sort_by(f64::total_cmp);
    assert_eq!(h, [0.02, 0.025, 0.03]);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("convergence.json")).unwrap())
            .unwrap();
    for q in ["peak_force", "dissipated_energy"] {
        let e = &json[q];
        assert!(e["reference"].as_f64().unwrap().is_finite(), "{json}");
        assert!(e.get("observed_order").is_some() && e.get("note").is_some());
        assert_eq!(e["spacings_m"], serde_json::json!([0.03, 0.025, 0.02]));
    }
    let svg = std::fs::read_to_string(out.join("convergence.svg")).unwrap();
    assert!(svg.contains("lattice spacing L0 (mm)") && svg.contains("peak force (kN)"));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn bad_study_arguments_stop_with_one_message_and_status_2() {
    let out = tmp("bad");
    let o_ = out.to_str().unwrap();
    let cases: [(&[&str], &str); 6] = [
        (
            &[
                "study",
                "objectivity",
                "lattices/uniaxial_tension.toml",
                "--angles",
                "",
                "--out",
                o_,
            ],
            "--angles",
        ),
        (
            &[
                "study",
                "objectivity",
                "lattices/uniaxial_tension.toml",
                "--angles",
                "0,x",
                "--out",
                o_,
            ],
            "`x` is not a number",
        ),
        (
            &[
                "study",
                "convergence",
                "lattices/uniaxial_tension.toml",
                "--spacings",
                "0.01,0,0.005",
                "--out",
                o_,
            ],
            "--spacings: 0 is not a lattice spacing",
        ),
        (
            &[
                "study",
                "convergence",
                "lattices/uniaxial_tension.toml",
                "--spacings",
                "0.01,-0.005",
                "--out",
                o_,
            ],
            "--spacings: -0.005 is not a lattice spacing",
        ),
        (
            &[
                "study",
                "objectivity",
                "lattices/no_such_scene.toml",
                "--out",
                o_,
            ],
            "cannot read lattices/no_such_scene.toml",
        ),
        (
            &[
                "study",
                "objectivity",
                "lattices/uniaxial_tension.toml",
                "--set",
                "material.nu=0.7",
                "--out",
                o_,
            ],
            "material.nu",
        ),
    ];
    for (args, expect) in cases {
        let o = sppm(args);
        let (_, err) = text(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(expect), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "one message: {err}");
        assert!(!out.exists(), "{args:?} made the study folder");
    }
}

/// Lattice symmetry: the hexagonal lattice turned by 60° about the origin is the same set
/// of particles, so the run is the same run up to the order of the bond sums.
#[test]
fn a_60_degree_turn_gives_the_same_peak() {
    let out = tmp("sixty");
    let o = objectivity(
        &out,
        &["--set", "discretisation.spacing=0.02", "--angles", "0,60"],
    );
    assert!(o.status.success(), "{}", text(&o).1);
    let rs = rows(&out.join("objectivity.csv"));
    let peak = |a: &str| {
        num(
            rs.iter().find(|r| r["angle_deg"] == a).unwrap(),
            "peak_force_N",
        )
    };
    assert_eq!(rs[0]["particles"], rs[1]["particles"]);
    assert!(
        (peak("60") / peak("0") - 1.0).abs() < 1e-4,
        "{} {}",
        peak("0"),
        peak("60")
    );
    let _ = std::fs::remove_dir_all(&out);
}

/// docs/validation.md §B: the tension block's peak at lattice rotations 0° and 30° agrees within
/// 3%, and the crack crosses the block perpendicular to the load. The shipped block is
/// shortened to 150 × 150 mm and loaded over 15 fundamental periods (instead of 60) to run in
/// seconds, at L0 = 5 mm, 30 particles across, where benchmarks/RESULTS.md found the shipped
/// block within 3% (at L0 = 10 mm it is not: 6.9%). The peak is also within 3% of f't·A =
/// 58.9 kN (§B).
#[test]
fn tension_block_peak_is_objective_at_0_and_30_degrees() {
    let out = tmp("tension");
    let o = objectivity(
        &out,
        &[
            "--set",
            "discretisation.spacing=0.005",
            "--set",
            "body.height=0.15",
            "--set",
            "loading.end_periods=15",
            "--angles",
            "0,30",
        ],
    );
    assert!(o.status.success(), "{}", text(&o).1);
    let rs = rows(&out.join("objectivity.csv"));
    let row = |a: &str| rs.iter().find(|r| r["angle_deg"] == a).unwrap();
    let (p0, p30) = (
        num(row("0"), "peak_force_N"),
        num(row("30"), "peak_force_N"),
    );
    assert!((p30 - p0).abs() / (0.5 * (p0 + p30)) < 0.03, "{p0} {p30}");
    for p in [p0, p30] {
        assert!((p / (2.6168e6 * 0.15 * 0.15) - 1.0).abs() < 0.03, "{p}");
    }
    for a in ["0", "30"] {
        let r = row(a);
        // a straight crack across the 150 mm block: its axis within 5° of horizontal (a
        // rise of 13 mm over the width, inside one crack band of 2.8·L0 = 14 mm)
        let axis = num(r, "crack_axis_deg");
        let off = axis.min(180.0 - axis);
        assert!(off < 5.0, "{a}°: crack axis {axis}");
        assert!(num(r, "cracked_particles") >= 25.0, "{r:?}");
        assert!((num(r, "crack_centroid_x_m") - 0.075).abs() < 0.01, "{r:?}");
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// The objectivity study on random particles: "offset" k is a particle set of its
/// own seed (k = 0: the scene's), the same sets at every angle, each turned by the angle; the
/// report gives per angle the mean and CoV of the peak and energy.
#[test]
fn objectivity_on_random_particles_turns_the_same_sets() {
    let out = tmp("objectivity-random");
    let o = sppm(&[
        "study",
        "objectivity",
        "lattices/uniaxial_tension_random.toml",
        "--quiet",
        "--jobs",
        "2",
        "--out",
        out.to_str().unwrap(),
        "--set",
        "discretisation.spacing=0.03",
        "--angles",
        "0,30",
        "--offsets",
        "1",
    ]);
    let (_, stderr) = text(&o);
    assert!(o.status.success(), "{stderr}");
    let rows = rows(&out.join("objectivity.csv"));
    assert_eq!(rows.len(), 4);
    let seed = |a: &str, k: &str| {
        rows.iter()
            .find(|r| r["angle_deg"] == a && r["offset"] == k)
            .unwrap()["seed"]
            .clone()
    };
    // k = 0 is the scene's seed (1); k = 1 another; the same at both angles
    assert_eq!(seed("0", "0"), "1");
    assert_eq!(seed("30", "0"), "1");
    assert_eq!(seed("0", "1"), seed("30", "1"));
    assert_ne!(seed("0", "1"), "1");
    // turning a set changes it: the peaks of one seed differ between the angles
    let peak = |a: &str, k: &str| {
        num(
            rows.iter()
                .find(|r| r["angle_deg"] == a && r["offset"] == k)
                .unwrap(),
            "peak_force_N",
        )
    };
    assert_ne!(peak("0", "0"), peak("30", "0"));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("objectivity.json")).unwrap())
            .unwrap();
    for a in report["per_angle"].as_array().unwrap() {
        assert_eq!(a["runs"], 2);
        assert!(a["cov_peak_force"].as_f64().unwrap() >= 0.0);
        assert!(a["cov_dissipated_energy"].as_f64().unwrap() >= 0.0);
    }
    // the angle effect of the peak: the spread of the two angles' means over the mean of
    // all four runs; with two runs per angle only the observed split of the four values and
    // its mirror image reach that spread at most, so p ≥ 2/6 less the shuffles' scatter
    let m = |a: &str| 0.5 * (peak(a, "0") + peak(a, "1"));
    let all = 0.5 * (m("0") + m("30"));
    let effect = &report["peak_force_angle_effect"];
    let spread = effect["spread_of_means"].as_f64().unwrap();
    assert!(
        (spread - (m("0") - m("30")).abs() / all).abs() < 1e-12 * spread.max(1e-300),
        "{effect}"
    );
    let p = effect["p_value"].as_f64().unwrap();
    assert!(p > 0.3 && p <= 1.0, "{effect}");
    assert_eq!(effect["permutations"], 10_000);
    assert!(
        report["dissipated_energy_angle_effect"]["p_value"]
            .as_f64()
            .unwrap()
            > 0.3
    );
}
