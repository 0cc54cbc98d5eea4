//! The command line as a user meets it: `run` writes every output, `check` reports, `bench`
//! prints one JSON line, bad input and unstable runs stop with a message and a non-zero
//! status.

use std::path::Path;
use std::process::Command;

fn sppm(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_sppm"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("sppm runs")
}

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("sppm-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// `sppm run` of the shipped plate, coarsened and shortened, into `out`, with extra options.
fn run_plate(out: &Path, extra: &[&str]) -> std::process::Output {
    let fast = [
        "--set",
        "discretisation.spacing=0.005",
        "--set",
        "loading.end_periods=3",
    ];
    let head = [
        "run",
        "lattices/elastic_plate.toml",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ];
    sppm(&[&head[..], &fast[..], extra].concat())
}

#[test]
fn run_writes_every_output() {
    let out = tmp("run");
    let o = run_plate(&out, &[]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "summary.json",
        "force_displacement.csv",
        "force_displacement.svg",
        "particle_map.svg",
        "particles.vtk",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    for key in [
        "scene",
        "particles",
        "bonds",
        "steps",
        "dt_s",
        "wall_time_s",
        "peak_force_N",
        "displacement_at_peak_m",
        "final_displacement_m",
        "dissipated_energy_J",
        "max_kinetic_to_internal_energy",
        "status",
    ] {
        assert!(summary.get(key).is_some(), "summary.json lacks {key}");
    }
    assert_eq!(summary["status"], "completed");
    assert_eq!(summary["scene"], "elastic_plate");
    // the plate's elastic answer: F = E·ε·W·t with ε = Δ/(grip distance): the two held
    // rows at each end leave H − 2·p free (p = (√3/2)·L0, the row pitch at L0 = 5 mm)
    let eps = 2e-5 / (0.2 - 2.0 * 0.5 * 3f64.sqrt() * 0.005);
    let f = summary["peak_force_N"].as_f64().unwrap();
    assert!((f / (30e9 * eps * 0.1 * 0.05) - 1.0).abs() < 0.03, "{f}");
    let csv = std::fs::read_to_string(out.join("force_displacement.csv")).unwrap();
    assert!(csv.starts_with(
        "step,time_s,displacement_m,force_N,kinetic_J,internal_J,external_work_J,damping_J"
    ));
    assert!(csv.lines().count() > 100);
    let svg = std::fs::read_to_string(out.join("force_displacement.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("reaction force (kN)") && svg.contains("(mm)"));
    let map = std::fs::read_to_string(out.join("particle_map.svg")).unwrap();
    assert!(map.matches("<circle").count() >= summary["particles"].as_u64().unwrap() as usize);
    let vtk = std::fs::read(out.join("particles.vtk")).unwrap();
    assert!(vtk.starts_with(b"# vtk DataFile Version 3.0"));
    // binary layout: points (12 B), cells (8 B), cell types (4 B), displacement (12 B),
    // stress tensor (36 B), two stress scalars, volume, id and three group flags (4 B each)
    // per particle
    let n = summary["particles"].as_u64().unwrap() as usize;
    let text = String::from_utf8_lossy(&vtk);
    for marker in [
        format!("POINTS {n} float"),
        format!("CELLS {n} {}", 2 * n),
        format!("CELL_TYPES {n}"),
        format!("POINT_DATA {n}"),
        "SCALARS volume_m3 float 1".into(),
        "SCALARS id int 1".into(),
        // in Pa, as the stress tensor
        "SCALARS von_mises_Pa float 1".into(),
        "SCALARS max_principal_Pa float 1".into(),
    ] {
        assert!(text.contains(&marker), "VTK lacks {marker}");
    }
    let payload = n * (12 + 8 + 4 + 12 + 36 + 7 * 4);
    assert!(
        vtk.len() > payload && vtk.len() < payload + 1024,
        "VTK size {} vs payload {payload}",
        vtk.len()
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn check_reports_size_step_and_estimates() {
    let o = sppm(&["check", "lattices/elastic_plate.toml"]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    for word in [
        "particles",
        "bonds",
        "time step dt",
        "steps",
        "memory (est.)",
        "run time (est.)",
        "fundamental T1",
    ] {
        assert!(text.contains(word), "check output lacks {word}:\n{text}");
    }
    // a relaxation scene has no step count in advance: check gives the increments and an
    // upper bound of the iterations (200 × 500 by default)
    let o = sppm(&[
        "check",
        "lattices/elastic_plate.toml",
        "--set",
        "solver.method=relaxation",
    ]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("relaxation: 200 increments of at most 500 iterations"));
    assert!(text.contains("(100000 iterations)"), "{text}");
    assert!(!text.contains("\nsteps "), "{text}");
}

#[test]
fn bench_prints_one_json_line() {
    let o = sppm(&[
        "bench",
        "--particles",
        "3000",
        "--steps",
        "20",
        "--threads",
        "1",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert_eq!(text.lines().count(), 1);
    let v: serde_json::Value = serde_json::from_str(text.trim()).unwrap();
    for key in [
        "particles",
        "steps",
        "threads",
        "model",
        "particle_steps_per_s",
    ] {
        assert!(v.get(key).is_some(), "{key}");
    }
    assert!(v["particle_steps_per_s"].as_f64().unwrap() > 0.0);
}

/// `bench --dim 3` times the elastic kernel and the damage kernels on an FCC cube; a
/// dimension other than 2 or 3 is refused with the flag and its value.
#[test]
fn bench_dim_3_runs_the_fcc_kernels() {
    let o = sppm(&["bench", "--dim", "3", "--particles", "3000", "--steps", "5"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value =
        serde_json::from_str(String::from_utf8_lossy(&o.stdout).trim()).unwrap();
    assert_eq!(v["lattice"], "fcc");
    assert_eq!(v["model"], "elastic");
    // 4N³ + 6N² + 3N + 1 with N = 9, the cube nearest 3000
    assert_eq!(v["particles"], 3430);
    assert_eq!(
        v["bytes_per_particle"].as_u64(),
        Some(sppm::discretise::bytes_per_particle(3, 18) as u64)
    );
    for model in ["tension", "full"] {
        let o = sppm(&[
            "bench",
            "--dim",
            "3",
            "--model",
            model,
            "--particles",
            "3000",
            "--steps",
            "2",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let v: serde_json::Value =
            serde_json::from_str(String::from_utf8_lossy(&o.stdout).trim()).unwrap();
        assert_eq!(v["model"], model);
        assert_eq!(
            v["bytes_per_particle"].as_u64(),
            Some(
                (sppm::discretise::bytes_per_particle(3, 18)
                    + sppm::solver::inelastic::bytes_per_particle(3, 18)) as u64
            )
        );
    }
    let o = sppm(&["bench", "--dim", "4"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--dim 4"));
}

#[test]
fn bad_input_stops_with_the_key_and_a_non_zero_status() {
    let o = sppm(&[
        "run",
        "lattices/elastic_plate.toml",
        "--quiet",
        "--set",
        "material.nu=0.7",
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("material.nu = 0.7") && err.contains("-1 < nu < 0.5"),
        "{err}"
    );
    assert!(err.lines().count() == 1, "one clear message: {err}");
    let o = sppm(&["run", "lattices/no_such_scene.toml"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot read lattices/no_such_scene.toml"));
    assert!(!Path::new("output/no_such_scene").exists());
}

#[test]
fn an_unstable_run_names_step_and_particle() {
    let out = tmp("unstable");
    let o = run_plate(&out, &["--set", "solver.force_lag=previous"]);
    assert_eq!(o.status.code(), Some(3));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("unstable at step") && err.contains("at particle"),
        "{err}"
    );
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    assert!(summary.contains("\"status\": \"unstable\""));
    let _ = std::fs::remove_dir_all(&out);
}

/// A concrete scene writes the crack map and particles.csv, and its summary lists the damage
/// figures and the material values with their sources. The shipped tension block, coarsened
/// to L0 = 25 mm and shortened: the crack map is checked for existence, not for physics
/// (tests/suite/concrete.rs does that).
#[test]
fn concrete_run_writes_crack_map_and_damage_summary() {
    let out = tmp("concrete");
    let o = sppm(&[
        "run",
        "lattices/uniaxial_tension.toml",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
        "--set",
        "discretisation.spacing=0.025",
        "--set",
        "loading.end_periods=20",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["crack_map.svg", "particles.csv", "summary.json"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let svg = std::fs::read_to_string(out.join("crack_map.svg")).unwrap();
    assert!(svg.contains("tensile damage"));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    for key in [
        "dissipated_energy_J",
        "max_damage",
        "cracked_particles",
        "max_kinetic_to_internal_energy",
        "concrete",
        "material_values",
    ] {
        assert!(s.get(key).is_some(), "summary.json lacks {key}");
    }
    assert_eq!(s["max_damage"], 1.0, "the block breaks");
    let sources: Vec<String> = s["material_values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| format!("{}: {}", d["key"], d["source"]))
        .collect();
    assert!(
        sources
            .iter()
            .any(|t| t.contains("\"E\"") && t.contains("ACI")),
        "{sources:?}"
    );
    let csv = std::fs::read_to_string(out.join("particles.csv")).unwrap();
    assert!(csv.lines().next().unwrap().contains("tensile_damage"));
}
