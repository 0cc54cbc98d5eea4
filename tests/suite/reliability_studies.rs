//! Reliability of `sppm study` (docs/reliability.md "Studies"): counts checked
//! against the memory before anything is made, a Monte Carlo study whose runs all fail is not
//! a success, a merge names what is missing, a folder whose rows have no inputs record is not
//! adopted, and one study at a time per folder.
//!
//! The runs are the shipped tension block at L0 = 30 mm (about 0.2 s a run) and a coarse
//! dog-bone (D = 50 mm at L0 = 4 mm, about 0.2 s a run): for the mechanics of the studies.

use crate::common;
use common::sppm;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// The dog-bone of tests/suite/montecarlo.rs (D0 = 0.1 m, L0 = 8 mm, an f't random field).
const DOGBONE: &str = common::TINY_DOGBONE;

/// The shipped tension block at L0 = 30 mm.
const TINY: [&str; 2] = ["--set", "discretisation.spacing=0.03"];

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sppm-rel-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn scene_file(dir: &Path) -> PathBuf {
    let p = dir.join("tiny_dogbone.toml");
    std::fs::write(&p, DOGBONE).unwrap();
    p
}

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Run sppm with at most 4 GiB of address space and `secs` seconds: a command that would
/// allocate or loop over a huge count fails (or is killed) instead of exhausting the machine.
/// Returns the exit code (`None`: killed or timed out), stderr and the time taken.
fn sppm_bounded(args: &[&str], secs: u64) -> (Option<i32>, String, Duration) {
    let start = Instant::now();
    let out = common::run_limited(
        Command::new("sh")
            .arg("-c")
            .arg("ulimit -v 4194304 && exec \"$@\"")
            .arg("sh")
            .arg(env!("CARGO_BIN_EXE_sppm"))
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR")),
        Duration::from_secs(secs),
    );
    let code = out.as_ref().and_then(|o| o.status.code());
    let err = out
        .map(|o| String::from_utf8_lossy(&o.stderr).into_owned())
        .unwrap_or_default();
    (code, err, start.elapsed())
}

#[test]
fn huge_counts_are_refused_before_anything_is_made() {
    let base = tmp("counts");
    let scene = scene_file(&base);
    let out = base.join("out");
    let cases: [(Vec<&str>, &[&str]); 3] = [
        (
            vec![
                "study",
                "objectivity",
                "lattices/uniaxial_tension.toml",
                "--angles",
                "0",
                "--offsets",
                "1000000000",
            ],
            &["--angles 0 and --offsets 1000000000: 1000000001 runs", "at most"],
        ),
        (
            vec![
                "study",
                "montecarlo",
                s(&scene),
                "--realisations",
                "100000000",
                "--seed",
                "1",
                "--sizes",
                "A",
            ],
            &[
                "--realisations 100000000 with 1 size: 100000001 runs",
                "at most",
                "--shard",
            ],
        ),
        (
            vec![
                "study",
                "montecarlo",
                s(&scene),
                "--realisations",
                "18446744073709551615",
                "--seed",
                "1",
                "--sizes",
                "A,B",
                "--shard",
                "1/1000000",
            ],
            // 2 sizes × 2^64 runs over a million shards
            &[
                "--realisations 18446744073709551615 with 2 sizes and --shard 1/1000000: 36893488147420 runs in this shard",
                "at most",
            ],
        ),
    ];
    for (mut args, expect) in cases {
        args.extend(["--quiet", "--out", s(&out)]);
        let (code, err, took) = sppm_bounded(&args, 30);
        assert_eq!(code, Some(2), "{args:?}: {err}");
        for e in expect {
            assert!(err.contains(e), "{args:?}: no `{e}` in {err}");
        }
        assert!(err.contains("GiB"), "{err}");
        assert!(took < Duration::from_secs(10), "{args:?} took {took:?}");
        assert!(!out.exists(), "{args:?} made the study folder");
    }
    let _ = std::fs::remove_dir_all(&base);
}

#[test]
fn a_shard_beyond_the_runs_is_empty() {
    let base = tmp("emptyshard");
    let scene = scene_file(&base);
    let out = base.join("out");
    // 1 size × (1 realisation + 1 deterministic run): shard 9/9 holds none of the 2 runs
    let o = sppm(&[
        "study",
        "montecarlo",
        s(&scene),
        "--realisations",
        "1",
        "--seed",
        "1",
        "--sizes",
        "0.05",
        "--shard",
        "9/9",
        "--quiet",
        "--out",
        s(&out),
    ]);
    let (stdout, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert!(stdout.contains("shard done: 0 runs"), "{stdout}");
    assert!(
        stderr.contains("--shard 9/9 of 2 runs holds none of them"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&base);
}

#[test]
fn a_montecarlo_study_whose_runs_all_fail_exits_3_and_names_the_size() {
    let base = tmp("allfail");
    let scene = scene_file(&base);
    let out = base.join("out");
    // a 1000 m dog-bone at L0 = 8 mm: every run is refused at set-up (too many particles)
    let o = sppm(&[
        "study",
        "montecarlo",
        s(&scene),
        "--realisations",
        "2",
        "--seed",
        "1",
        "--sizes",
        "1000",
        "--quiet",
        "--out",
        s(&out),
    ]);
    let (stdout, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(3), "{stdout}\n{stderr}");
    assert!(
        stderr.contains("no realisation completed at D = 1000 m"),
        "{stderr}"
    );
    assert!(stderr.contains("3 of 3 runs did not complete"), "{stderr}");
    assert!(
        stdout.contains("D = 1000 m: no completed realisation (2 failed)"),
        "{stdout}"
    );
    assert!(
        !stdout.contains("NaN MPa"),
        "NaN printed as a result: {stdout}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("size_effect.json")).unwrap())
            .unwrap();
    assert_eq!(
        json["sizes_without_completed_realisations"],
        serde_json::json!([1000.0])
    );
    assert_eq!(json["per_size"][0]["n"], 0);
    assert!(json["per_size"][0]["mean_sigma_N_Pa"].is_null());
    let _ = std::fs::remove_dir_all(&base);
}

fn montecarlo_shard(scene: &Path, out: &Path, shard: &str) -> Output {
    sppm(&[
        "study",
        "montecarlo",
        s(scene),
        "--realisations",
        "2",
        "--seed",
        "42",
        "--sizes",
        "0.05",
        "--shard",
        shard,
        "--quiet",
        "--out",
        s(out),
    ])
}

#[test]
fn a_merge_names_missing_shards_and_runs_and_needs_partial() {
    let base = tmp("merge");
    let scene = scene_file(&base);
    let (s1, s2, merged) = (base.join("s1"), base.join("s2"), base.join("merged"));
    // 1 size × (2 realisations + 1 deterministic run) = runs 0, 1, 2 (det, r0, r1): shard 1/2
    // holds the deterministic run and r1, shard 2/2 holds r0
    assert!(montecarlo_shard(&scene, &s1, "1/2").status.success());
    let merge = |dirs: &[&Path], extra: &[&str]| {
        let mut args = vec!["study", "merge"];
        args.extend(dirs.iter().map(|d| s(d)));
        args.extend(["--out", s(&merged)]);
        args.extend_from_slice(extra);
        sppm(&args)
    };

    // one shard of two: refused, naming the shard and the realisations
    let o = merge(&[&s1], &[]);
    let err = text(&o).1;
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("shard 2/2 of the study of 0.05 m not given"),
        "{err}"
    );
    assert!(err.contains("D = 0.05 m: 1 of 2 realisations"), "{err}");
    assert!(err.contains("--partial"), "{err}");
    assert!(!merged.join("size_effect.json").exists());

    // with --partial: the report of what there is, a warning, and the JSON says partial
    let o = merge(&[&s1], &["--partial"]);
    let (stdout, err) = text(&o);
    assert_eq!(o.status.code(), Some(0), "{stdout}\n{err}");
    assert!(err.contains("warning: partial merge"), "{err}");
    assert!(err.contains("D = 0.05 m: 1 of 2 realisations"), "{err}");
    let json = |dir: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join("size_effect.json")).unwrap())
            .unwrap()
    };
    let j = json(&merged);
    assert_eq!(j["partial"], true);
    assert!(
        j["missing"][0]
            .as_str()
            .unwrap()
            .contains("shard 2/2 of the study of 0.05 m not given"),
        "{j}"
    );
    assert_eq!(j["per_size"][0]["n"], 1);

    // both shards: the whole study, not partial
    assert!(montecarlo_shard(&scene, &s2, "2/2").status.success());
    let o = merge(&[&s1, &s2], &[]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o).1);
    let j = json(&merged);
    assert_eq!(j["partial"], false);
    assert_eq!(j["missing"], serde_json::json!([]));
    assert_eq!(j["per_size"][0]["n"], 2);

    // a half-finished shard (its realisation row lost): refused, naming the folder
    let csv = s2.join("realisations.csv");
    let header = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .next()
        .unwrap()
        .to_string();
    std::fs::write(&csv, header + "\n").unwrap();
    let o = merge(&[&s1, &s2], &[]);
    let err = text(&o).1;
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!(
            "{} (shard 2/2, 2 realisations of 0.05 m) holds 0 of the 1 realisations of D = 0.05 m it was asked for",
            s2.display()
        )),
        "{err}"
    );
    assert!(err.contains("D = 0.05 m: 1 of 2 realisations"), "{err}");
    assert!(!err.contains("not given"), "both shards were given: {err}");

    // the merged folder is locked while a merge writes it: a merge into a folder another
    // process holds is refused, naming the holder (here this test process)
    let lock = sppm::fsio::FolderLock::acquire(&merged).unwrap();
    let o = merge(&[&s1, &s2], &["--partial"]);
    let err = text(&o).1;
    assert!(o.status.code() == Some(5), "{:?} {err}", o.status);
    assert!(
        err.contains(&format!(
            "{} is in use by another sppm process (process {}:",
            merged.display(),
            std::process::id()
        )),
        "{err}"
    );
    drop(lock);
    let _ = std::fs::remove_dir_all(&base);
}

fn objectivity(out: &Path, extra: &[&str]) -> Output {
    let head = [
        "study",
        "objectivity",
        "lattices/uniaxial_tension.toml",
        "--quiet",
        "--out",
        s(out),
    ];
    sppm(&[&head[..], &TINY[..], extra].concat())
}

#[test]
fn rows_without_an_inputs_record_are_not_adopted() {
    let base = tmp("noinputs");
    let out = base.join("out");
    let o = objectivity(&out, &["--angles", "0", "--offsets", "1"]);
    assert!(o.status.success(), "{}", text(&o).1);
    let csv = out.join("objectivity.csv");
    let before = std::fs::read_to_string(&csv).unwrap();
    assert_eq!(before.lines().count(), 3, "header and two rows");
    std::fs::remove_file(out.join("study_inputs.json")).unwrap();

    // another seed: its offset-1 run would be another run under the same label
    let o = objectivity(&out, &["--angles", "0", "--offsets", "1", "--seed", "5"]);
    let err = text(&o).1;
    assert_eq!(o.status.code(), Some(2), "{err}");
    for want in [
        format!(
            "{} holds study rows (2 in {})",
            out.display(),
            csv.display()
        ),
        "but no study_inputs.json".to_string(),
        "does not adopt them".to_string(),
        "use another --out folder".to_string(),
    ] {
        assert!(err.contains(&want), "no `{want}` in {err}");
    }
    assert_eq!(std::fs::read_to_string(&csv).unwrap(), before);
    assert!(!out.join("study_inputs.json").exists());

    // the same holds for a Monte Carlo folder whose deterministic.csv is gone too (the
    // realisations alone are rows of a study)
    let scene = scene_file(&base);
    let mc = base.join("mc");
    assert!(montecarlo_shard(&scene, &mc, "1/2").status.success());
    std::fs::remove_file(mc.join("study_inputs.json")).unwrap();
    std::fs::remove_file(mc.join("deterministic.csv")).unwrap();
    let o = sppm(&[
        "study",
        "montecarlo",
        s(&scene),
        "--realisations",
        "2",
        "--seed",
        "43",
        "--sizes",
        "0.05",
        "--shard",
        "1/2",
        "--quiet",
        "--out",
        s(&mc),
    ]);
    let err = text(&o).1;
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!(
            "holds study rows (1 in {})",
            mc.join("realisations.csv").display()
        )),
        "{err}"
    );
    assert!(!mc.join("deterministic.csv").exists(), "nothing ran");
    let _ = std::fs::remove_dir_all(&base);
}

#[test]
fn a_second_study_into_a_busy_folder_is_refused() {
    let base = tmp("busy");
    let out = base.join("out");
    // 6 angles × 3 offsets = 18 runs on one job: a few seconds
    let args: Vec<String> = [
        "study",
        "objectivity",
        "lattices/uniaxial_tension.toml",
        "--angles",
        "0,10,20,30,40,50",
        "--offsets",
        "2",
        "--jobs",
        "1",
        "--quiet",
        "--out",
        s(&out),
    ]
    .iter()
    .map(|a| a.to_string())
    .chain(TINY.iter().map(|a| a.to_string()))
    .collect();
    let mut first = Command::new(env!("CARGO_BIN_EXE_sppm"))
        .args(&args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // wait until the first has started its study (its CSV exists)
    let csv = out.join("objectivity.csv");
    common::wait_until(Duration::from_secs(30), "the first study's CSV", || {
        csv.exists()
    });
    let arg_refs: Vec<&str> = args.iter().map(String::as_str).collect();
    let second = sppm(&arg_refs);
    let still_running = first.try_wait().unwrap().is_none();
    let status = first.wait().unwrap();
    let mut first_err = String::new();
    use std::io::Read;
    first
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut first_err)
        .unwrap();
    assert!(status.success(), "the first study: {first_err}");
    assert!(
        still_running,
        "the first study ended before the second was done"
    );

    let err = text(&second).1;
    // FolderBusy: exit status 5
    assert!(
        second.status.code() == Some(5),
        "the second study was not refused: {:?} {err}",
        second.status
    );
    assert!(
        err.contains(&format!(
            "{} is in use by another sppm process (process {}:",
            out.display(),
            first.id()
        )),
        "{err}"
    );
    let rows = common::csv_rows(&csv);
    assert_eq!(rows.len(), 18);
    let mut labels: Vec<&str> = rows.iter().map(|r| r["label"].as_str()).collect();
    labels.sort();
    labels.dedup();
    assert_eq!(labels.len(), 18, "a row twice");
    let _ = std::fs::remove_dir_all(&base);
}
