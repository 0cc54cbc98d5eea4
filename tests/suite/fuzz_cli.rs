//! Fuzzing the command line: random counts for `bench`, `study objectivity` and
//! `study montecarlo`, and random `--set` values for `run` and `check` of a tiny scene. Every
//! command must end without a panic, and none may exit 0 with a NaN result. Each command is
//! given a few seconds (a huge but acceptable count simply runs; it is stopped there), so
//! the fuzzer's time is bounded: at most CASES × LIMIT.

use crate::common;
use proptest::prelude::*;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

const CASES: u32 = 64;
const LIMIT: Duration = Duration::from_secs(4);

const PLATE: &str = r#"
name = "fuzz_plate"
[body]
shape = "rectangle"
width = 0.1
height = 0.2
[discretisation]
spacing = 0.02
[material]
E = 30.0e9
nu = 0.2
rho = 2400.0
thickness = 0.05
[[groups]]
name = "bottom"
select = { by = "edge", edge = "bottom", rows = 1 }
fix = ["x", "y"]
[[groups]]
name = "top"
select = { by = "edge", edge = "top", rows = 1 }
load = { component = "y", displacement = 1.0e-5 }
[loading]
end_periods = 2.0
"#;

const DOGBONE: &str = common::TINY_DOGBONE;

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("sppm-fuzz-cli-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn scene(name: &str, text: &str) -> String {
    let p = dir().join(name);
    if !p.exists() {
        std::fs::write(&p, text).unwrap();
    }
    p.to_string_lossy().into_owned()
}

/// Run sppm for at most LIMIT: (exit code, None if stopped), stdout, stderr.
fn run(args: &[String]) -> (Option<i32>, String, String) {
    match common::run_limited(
        Command::new(env!("CARGO_BIN_EXE_sppm"))
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR")),
        LIMIT,
    ) {
        Some(o) => (
            o.status.code(),
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        ),
        None => (None, String::new(), String::new()),
    }
}

/// No panic; exit 0 only with finite results.
fn judge(args: &[String], out_dir: Option<&Path>) -> Result<(), TestCaseError> {
    let (code, out, err) = run(args);
    if std::env::var_os("SPPM_FUZZ_VERBOSE").is_some() {
        eprintln!(
            "fuzz: {:?} -> {code:?} {}",
            args,
            err.lines().next().unwrap_or("")
        );
    }
    prop_assert!(
        !err.contains("panicked") && code != Some(101),
        "{args:?} panicked: {err}"
    );
    if code == Some(0) {
        prop_assert!(!out.contains("NaN"), "{args:?} exit 0 with NaN: {out}");
        if let Some(d) = out_dir {
            if let Ok(text) = std::fs::read_to_string(d.join("summary.json")) {
                let s: serde_json::Value = serde_json::from_str(&text).unwrap();
                for key in ["peak_force_N", "dissipated_energy_J", "external_work_J"] {
                    prop_assert!(
                        s[key].as_f64().is_some_and(f64::is_finite),
                        "{args:?} exit 0 with {key} = {}",
                        s[key]
                    );
                }
                prop_assert_eq!(&s["status"], "completed");
            }
        }
    }
    Ok(())
}

/// Counts as a user might type them: mostly small, sometimes large, at the integer limits,
/// or not numbers.
fn count() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => (0u64..4).prop_map(|v| v.to_string()),
        2 => (0u64..1_000_000_000_000).prop_map(|v| v.to_string()),
        1 => prop_oneof![
            Just(u64::MAX.to_string()),
            Just("18446744073709551616".to_string()),
            Just("-1".to_string()),
            Just("1e9".to_string()),
            Just("".to_string()),
        ],
    ]
}

/// Scene values: mostly the key's nominal value scaled (0, ±, tiny, huge), sometimes a number
/// of any magnitude, a non-finite one, or a wrong type.
fn value(key: usize) -> impl Strategy<Value = String> {
    let (nominal, integer) = KEYS[key].1;
    let scaled = prop::sample::select(vec![
        0.0, -1.0, 1e-3, 0.1, 0.5, 0.9, 1.0, 1.1, 2.0, 10.0, 1e3, 1e9,
    ])
    .prop_map(move |f| {
        if integer {
            format!("{}", (nominal * f).round() as i64)
        } else if KEYS[key].0 == "discretisation.offset" {
            format!("[{:e}, {:e}]", nominal * f, -nominal * f)
        } else {
            format!("{:e}", nominal * f)
        }
    });
    prop_oneof![
        6 => scaled,
        1 => any::<f64>().prop_map(|v| format!("{v:e}")),
        1 => any::<i64>().prop_map(|v| v.to_string()),
        1 => prop::sample::select(vec![
            "nan", "inf", "-inf", "18446744073709551615", "\"text\"", "[1.0, 2.0]", "true", "",
        ])
        .prop_map(String::from),
    ]
}

/// The fuzzed scene keys with a nominal value and whether they are integers.
const KEYS: [(&str, (f64, bool)); 18] = [
    ("discretisation.spacing", (0.02, false)),
    ("discretisation.rotation_deg", (15.0, false)),
    ("discretisation.offset", (0.003, false)),
    ("material.E", (30e9, false)),
    ("material.nu", (0.2, false)),
    ("material.rho", (2400.0, false)),
    ("material.thickness", (0.05, false)),
    ("loading.end_periods", (2.0, false)),
    ("loading.ramp_fraction", (0.5, false)),
    ("solver.safety", (0.9, false)),
    ("solver.dt", (1e-6, false)),
    ("solver.threads", (1.0, true)),
    ("damping.internal", (0.2, false)),
    ("damping.external", (1.0, false)),
    ("output.records", (50.0, true)),
    ("groups.top.load.displacement", (1e-5, false)),
    ("seed", (7.0, true)),
    ("output.deformed_scale", (100.0, false)),
];

proptest! {
    #![proptest_config(ProptestConfig { cases: CASES, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn no_command_panics_or_reports_nan(
        which in 0usize..5,
        a in count(),
        b in count(),
        c in count(),
        (key, v) in (0usize..KEYS.len()).prop_flat_map(|k| (Just(k), value(k))),
        (k2, v2) in (0usize..KEYS.len()).prop_flat_map(|k| (Just(k), value(k))),
        case in 0u64..u64::MAX,
    ) {
        let out = dir().join(format!("out-{case}"));
        let o = out.to_string_lossy().into_owned();
        let s = |x: &str| x.to_string();
        let args: Vec<String> = match which {
            0 => vec![s("bench"), s("--particles"), a, s("--steps"), b, s("--threads"), c.chars().take(2).collect()],
            1 => vec![s("study"), s("objectivity"), scene("plate.toml", PLATE), s("--angles"), s("0"),
                      s("--offsets"), a, s("--jobs"), b.chars().take(1).collect(), s("--quiet"), s("--out"), o.clone()],
            2 => vec![s("study"), s("montecarlo"), scene("dogbone.toml", DOGBONE), s("--realisations"), a,
                      s("--seed"), b, s("--shard"), format!("{}/{}", c, a_or(&c)), s("--jobs"), s("1"),
                      s("--quiet"), s("--out"), o.clone()],
            3 => vec![s("run"), scene("plate.toml", PLATE), s("--quiet"), s("--out"), o.clone(),
                      s("--set"), format!("{}={v}", KEYS[key].0), s("--set"), format!("{}={v2}", KEYS[k2].0)],
            _ => vec![s("check"), scene("plate.toml", PLATE),
                      s("--set"), format!("{}={v}", KEYS[key].0), s("--set"), format!("{}={v2}", KEYS[k2].0)],
        };
        let r = judge(&args, Some(&out));
        let _ = std::fs::remove_dir_all(&out);
        r?;
    }
}

/// A shard count to pair with `k`: sometimes the same, sometimes another count.
fn a_or(k: &str) -> String {
    match k.len() % 3 {
        0 => k.to_string(),
        1 => "2".into(),
        _ => "1000000".into(),
    }
}
