//! `sppm study montecarlo` and `sppm study merge` as a user meets them: one row per finished
//! realisation, seeds that depend on (S, D, r) only, resuming an interrupted study, shards
//! that split the runs without overlap and merge back into the unsharded study, the
//! size-effect table against its definition σN = P_max/(0.6·D·t), and clear errors.
//!
//! The scene is a coarse dog-bone (D0 = 0.1 m at L0 = 8 mm, 223 particles, relaxation with a
//! stop after the peak: about 0.4 s a run) for the mechanics of the study, not for physics.

use crate::common;
use common::sppm;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::process::Output;

const SCENE: &str = common::TINY_DOGBONE;

const THICKNESS: f64 = 0.1;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sppm-mc-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn scene_file(dir: &Path) -> PathBuf {
    let p = dir.join("tiny_dogbone.toml");
    std::fs::write(&p, SCENE).unwrap();
    p
}

fn ok(o: &Output) -> String {
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    );
    assert!(o.status.success(), "sppm failed: {out}\n{err}");
    out
}

fn failure(o: &Output) -> String {
    assert_eq!(o.status.code(), Some(2), "bad input is exit status 2");
    String::from_utf8_lossy(&o.stderr).into_owned()
}

type Row = HashMap<String, String>;

fn rows(path: &Path) -> Vec<Row> {
    common::csv_rows(path)
}

fn by_label(rows: &[Row]) -> BTreeMap<String, Row> {
    rows.iter()
        .map(|r| (r["label"].clone(), r.clone()))
        .collect()
}

fn num(row: &Row, key: &str) -> f64 {
    row[key]
        .parse()
        .unwrap_or_else(|_| panic!("{key} = {}", row[key]))
}

fn montecarlo(scene: &Path, out: &Path, n: usize, jobs: usize, extra: &[&str]) -> String {
    let n = n.to_string();
    let jobs = jobs.to_string();
    let mut args = vec![
        "study",
        "montecarlo",
        scene.to_str().unwrap(),
        "--realisations",
        &n,
        "--seed",
        "42",
        "--sizes",
        "0.05,0.1",
        "--jobs",
        &jobs,
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    ok(&sppm(&args))
}

/// The seed of realisation r of size D, as the CSV and the run's summary.json record it.
fn seed_of(rows: &BTreeMap<String, Row>, label: &str) -> u64 {
    rows[label]["seed"].parse().unwrap()
}

#[test]
fn a_study_resumes_and_its_shards_merge_into_the_same_realisations() {
    let base = tmp("resume");
    let scene = scene_file(&base);
    let full = base.join("full");

    // N = 2: 2 sizes × (2 realisations + 1 deterministic run)
    montecarlo(&scene, &full, 2, 2, &[]);
    let first = by_label(&rows(&full.join("realisations.csv")));
    assert_eq!(
        first.keys().cloned().collect::<Vec<_>>(),
        ["D100mm-r0", "D100mm-r1", "D50mm-r0", "D50mm-r1"]
    );
    assert_eq!(rows(&full.join("deterministic.csv")).len(), 2);
    // only summary.json per run unless --keep-outputs
    let files: Vec<_> = std::fs::read_dir(full.join("D50mm-r0"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(files, ["summary.json"]);

    // N = 3: only the third realisation of each size runs; the earlier rows stay as they were
    montecarlo(&scene, &full, 3, 2, &[]);
    let all = rows(&full.join("realisations.csv"));
    assert_eq!(all.len(), 6, "two new rows, none repeated");
    let second = by_label(&all);
    for (label, row) in &first {
        assert_eq!(&second[label], row, "{label} ran again");
    }
    assert!(second.contains_key("D50mm-r2") && second.contains_key("D100mm-r2"));
    assert_eq!(rows(&full.join("deterministic.csv")).len(), 2);

    // seeds: distinct, recorded in summary.json, and a function of (S, D, r) only
    let seeds: std::collections::HashSet<u64> =
        second.keys().map(|l| seed_of(&second, l)).collect();
    assert_eq!(seeds.len(), 6);
    for (label, row) in &second {
        let summary: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(full.join(label).join("summary.json")).unwrap(),
        )
        .unwrap();
        assert_eq!(summary["seed"].as_u64(), Some(seed_of(&second, label)));
        let d = num(row, "size_D_m");
        let r: usize = row["realisation"].parse().unwrap();
        assert_eq!(
            seed_of(&second, label),
            sppm::study::monte_carlo::realisation_seed(42, d, r)
        );
    }

    // shards 1/2 and 2/2 of the N = 3 study: disjoint, together all runs, seeds unchanged
    let s1 = base.join("shard-1");
    let s2 = base.join("shard-2");
    let o1 = montecarlo(&scene, &s1, 3, 2, &["--shard", "1/2"]);
    assert!(o1.contains("shard done"), "{o1}");
    assert!(
        !s1.join("size_effect.csv").exists(),
        "a shard writes no report"
    );
    montecarlo(&scene, &s2, 3, 1, &["--shard", "2/2"]);
    let mut labels = vec![];
    for s in [&s1, &s2] {
        for f in ["realisations.csv", "deterministic.csv"] {
            labels.extend(rows(&s.join(f)).into_iter().map(|r| r["label"].clone()));
        }
    }
    let n = labels.len();
    labels.sort();
    labels.dedup();
    assert_eq!(n, labels.len(), "the shards overlap");
    assert_eq!(n, 8, "2 sizes × (3 realisations + 1 deterministic run)");
    for s in [&s1, &s2] {
        for (label, row) in by_label(&rows(&s.join("realisations.csv"))) {
            assert_eq!(row["seed"], second[&label]["seed"], "{label}");
        }
    }

    // merge: the same realisations and deterministic runs as the unsharded study
    let merged = base.join("merged");
    let out = ok(&sppm(&[
        "study",
        "merge",
        s1.to_str().unwrap(),
        s2.to_str().unwrap(),
        s1.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]));
    assert!(out.contains("Bažant"), "{out}");
    let key = |rows: Vec<Row>| -> BTreeMap<String, (String, String, String)> {
        rows.into_iter()
            .map(|r| {
                (
                    r["label"].clone(),
                    (
                        r["seed"].clone(),
                        r["peak_force_N"].clone(),
                        r["sigma_N_Pa"].clone(),
                    ),
                )
            })
            .collect()
    };
    for f in ["realisations.csv", "deterministic.csv"] {
        assert_eq!(
            key(rows(&merged.join(f))),
            key(rows(&full.join(f))),
            "merged {f} differs from the unsharded study"
        );
    }
    let table = |dir: &Path| rows(&dir.join("size_effect.csv"));
    assert_eq!(table(&merged), table(&full));

    // the size-effect table is the statistics of σN = P_max/(0.6·D·t) over the realisations
    let real = rows(&full.join("realisations.csv"));
    let det = by_label(&rows(&full.join("deterministic.csv")));
    for s in table(&full) {
        let d = num(&s, "size_D_m");
        let sig: Vec<f64> = real
            .iter()
            .filter(|r| (num(r, "size_D_m") - d).abs() < 1e-9)
            .map(|r| {
                let sigma = num(r, "sigma_N_Pa");
                let by_hand = num(r, "peak_force_N").abs() / (0.6 * d * THICKNESS);
                assert!((sigma / by_hand - 1.0).abs() < 1e-12);
                sigma
            })
            .collect();
        assert_eq!(sig.len(), 3);
        // each realisation draws its own f't field, so the peaks differ
        let mut distinct = sig.clone();
        distinct.sort_by(f64::total_cmp);
        distinct.dedup();
        assert_eq!(
            distinct.len(),
            3,
            "realisations of D = {d} m share a peak: {sig:?}"
        );
        assert_eq!(s["n"], "3");
        assert_eq!(s["failed"], "0");
        let mean = sig.iter().sum::<f64>() / 3.0;
        let std = (sig.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 2.0).sqrt();
        assert!((num(&s, "mean_sigma_N_Pa") / mean - 1.0).abs() < 1e-12);
        assert!((num(&s, "std_sigma_N_Pa") - std).abs() <= 1e-9 * mean);
        let label = format!("D{}mm-det", d * 1e3);
        assert!(
            (num(&s, "deterministic_sigma_N_Pa") / num(&det[&label], "sigma_N_Pa") - 1.0).abs()
                < 1e-12
        );
        // σN of a 0.05–0.1 m dog-bone with the mean f't = 2.415 MPa everywhere: within 10% of
        // f't (docs/validation.md §D; measured 4.8% and 7.2% below at this coarse spacing)
        assert!((num(&s, "deterministic_sigma_N_Pa") / 2.415e6 - 1.0).abs() < 0.1);
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(full.join("size_effect.json")).unwrap())
            .unwrap();
    assert_eq!(json["seed"], 42);
    assert_eq!(json["realisations"], 3);
    assert!(json["spacing_rule"]
        .as_str()
        .unwrap()
        .contains("min(1, D/D0)"));
    assert!(json["fits_of_the_means"]["bazant"]["f_inf_Pa"].is_number());
    assert!(json["fits_of_the_means"]["weibull"]["modulus"].is_number());
    let svg = std::fs::read_to_string(full.join("size_effect.svg")).unwrap();
    assert!(svg.contains("specimen size D (m)") && svg.contains("Monte Carlo mean"));

    // studies of other sizes merge too (a seed depends on (S, D, r) only): 0.05 m at N = 3
    // and 0.1 m at N = 2 give the unsharded study's rows for those runs
    let small = base.join("small");
    let large = base.join("large");
    for (dir, size, n) in [(&small, "0.05", "3"), (&large, "0.1", "2")] {
        ok(&sppm(&[
            "study",
            "montecarlo",
            scene.to_str().unwrap(),
            "--realisations",
            n,
            "--seed",
            "42",
            "--sizes",
            size,
            "--jobs",
            "2",
            "--quiet",
            "--out",
            dir.to_str().unwrap(),
        ]));
    }
    let both = base.join("both");
    ok(&sppm(&[
        "study",
        "merge",
        small.to_str().unwrap(),
        large.to_str().unwrap(),
        "--out",
        both.to_str().unwrap(),
    ]));
    let combined = key(rows(&both.join("realisations.csv")));
    let unsharded = key(rows(&full.join("realisations.csv")));
    assert_eq!(combined.len(), 5);
    for (label, v) in &combined {
        assert_eq!(&unsharded[label], v, "{label}");
    }
    let ns: Vec<String> = table(&both).iter().map(|r| r["n"].clone()).collect();
    assert_eq!(ns, ["3", "2"]);

    // shards of another study (other seed) do not merge with these
    let other = base.join("other");
    ok(&sppm(&[
        "study",
        "montecarlo",
        scene.to_str().unwrap(),
        "--realisations",
        "1",
        "--seed",
        "43",
        "--sizes",
        "0.05,0.1",
        "--shard",
        "1/4",
        "--quiet",
        "--out",
        other.to_str().unwrap(),
    ]));
    let e = failure(&sppm(&[
        "study",
        "merge",
        s1.to_str().unwrap(),
        other.to_str().unwrap(),
        "--out",
        base.join("bad").to_str().unwrap(),
    ]));
    assert!(e.contains("different studies"), "{e}");
    // nor into the merged folder of this one
    let e = failure(&sppm(&[
        "study",
        "merge",
        other.to_str().unwrap(),
        "--out",
        merged.to_str().unwrap(),
    ]));
    assert!(e.contains("holds another study"), "{e}");
    let _ = std::fs::remove_dir_all(&base);
}

#[test]
fn bad_shards_and_sizes_are_refused_with_the_option_named() {
    let base = tmp("errors");
    let scene = scene_file(&base);
    let out = base.join("out");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "study",
            "montecarlo",
            scene.to_str().unwrap(),
            "--realisations",
            "1",
            "--seed",
            "1",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        failure(&sppm(&args))
    };
    for bad in ["0/3", "4/3", "2", "x/3"] {
        let e = run(&["--shard", bad]);
        assert!(
            e.contains("--shard") && e.contains(bad) && e.contains("1 ≤ k ≤ n"),
            "{e}"
        );
    }
    for bad in ["A,G", "0.1,-1", "B,big"] {
        let e = run(&["--sizes", bad]);
        assert!(e.contains("--sizes") && e.contains("A–F"), "{e}");
    }
    let e = failure(&sppm(&[
        "study",
        "montecarlo",
        scene.to_str().unwrap(),
        "--realisations",
        "0",
        "--seed",
        "1",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]));
    assert!(e.contains("--realisations 0"), "{e}");
    // --sizes needs a dog-bone
    let e = failure(&sppm(&[
        "study",
        "montecarlo",
        "lattices/uniaxial_tension.toml",
        "--realisations",
        "1",
        "--seed",
        "1",
        "--sizes",
        "A,B",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]));
    assert!(
        e.contains("--sizes") && e.contains("dogbone") && e.contains("`rectangle`"),
        "{e}"
    );
    // a random field with its own seed would give every realisation the same field
    let e = run(&["--set", "random_field.0.seed=7"]);
    assert!(e.contains("random_field[0].seed"), "{e}");
    assert!(!out.join("realisations.csv").exists(), "nothing ran");
    let _ = std::fs::remove_dir_all(&base);
}

/// On random particles the study draws the mesostructure anew per realisation:
/// without any random field, the realisations of one size differ (their particle sets come
/// from their seeds), and the same study run again gives the same rows.
#[test]
fn random_particles_draw_a_new_mesostructure_per_realisation() {
    let dir = tmp("random");
    let scene = dir.join("tiny_random.toml");
    let text = SCENE
        .replace("spacing = 0.008", "lattice = \"random\"\nspacing = 0.008")
        .replace(
            "[[random_field]]\nproperty = \"ft\"\ncorrelation = \"exponential\"\nlength = 0.016\nmarginal = \"normal\"\ncov = 0.1\n",
            "",
        );
    assert!(!text.contains("random_field") && text.contains("\"random\""));
    std::fs::write(&scene, text).unwrap();
    let (a, b) = (dir.join("a"), dir.join("b"));
    montecarlo(&scene, &a, 3, 2, &[]);
    montecarlo(&scene, &b, 3, 2, &[]);
    let ra = by_label(&rows(&a.join("realisations.csv")));
    let rb = by_label(&rows(&b.join("realisations.csv")));
    assert_eq!(ra.len(), 6, "2 sizes × 3 realisations");
    let peaks: Vec<f64> = ra
        .values()
        .filter(|r| num(r, "size_D_m") == 0.1)
        .map(|r| num(r, "peak_force_N"))
        .collect();
    assert_eq!(peaks.len(), 3);
    assert!(
        peaks.windows(2).all(|w| w[0] != w[1]),
        "the realisations' peaks {peaks:?} should differ"
    );
    for (label, row) in &ra {
        assert_eq!(row["peak_force_N"], rb[label]["peak_force_N"], "{label}");
        assert_eq!(row["seed"], rb[label]["seed"], "{label}");
    }
}
