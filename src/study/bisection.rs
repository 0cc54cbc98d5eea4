//! `sppm study bisection`: the failure load of a specimen under a force-controlled load, by
//! the geometric binary search of Ness (2019, Algorithm 1; docs/failure.md, "The failure
//! load"): each test runs the scene with its one `load.force` group at T = √(L·U) and the
//! `[failure]` criterion's verdict moves the lower bound L up (held) or the upper bound U
//! down (failed), until U − L ≤ the tolerance. Each finished test is written to
//! bisection.csv at once; the same command resumes an interrupted study by replaying it.

use crate::run::{run, RunOptions};
use crate::scene::Scene;
use crate::solver::failure::Verdict;
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The columns of bisection.csv.
pub const COLUMNS: &[&str] = &[
    "test",
    "load_N",
    "verdict",
    "decided_at_step",
    "decided_at_s",
    "final_displacement_m",
    "wall_time_s",
    "reason",
];

/// The search's bounds (N, magnitudes).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Bracket {
    #[serde(rename = "lower_N")]
    pub lower: f64,
    #[serde(rename = "upper_N")]
    pub upper: f64,
}

impl Bracket {
    /// The next test load, T = √(L·U).
    pub fn next(&self) -> f64 {
        (self.lower * self.upper).sqrt()
    }

    /// The bracket after a test at `load` that held (or failed).
    pub fn after(self, load: f64, held: bool) -> Bracket {
        if held {
            Bracket {
                lower: load,
                ..self
            }
        } else {
            Bracket {
                upper: load,
                ..self
            }
        }
    }

    /// Whether U − L ≤ `tolerance` (N).
    pub fn done(&self, tolerance: f64) -> bool {
        self.upper - self.lower <= tolerance
    }
}

/// The study's result (bisection.json).
#[derive(Clone, Debug, Serialize)]
pub struct BisectionReport {
    pub scene: String,
    pub group: String,
    pub criterion: String,
    pub initial: Bracket,
    #[serde(rename = "tolerance_N")]
    pub tolerance: f64,
    /// The final bounds: the largest load held and the smallest that failed (or the initial
    /// bound where no test reached it).
    pub bracket: Bracket,
    /// √(L·U) of the final bounds, with the group's sign.
    #[serde(rename = "failure_load_N")]
    pub failure_load: f64,
    pub tests: usize,
    /// Every test held (the failure load is above the upper bound) or every test failed
    /// (below the lower bound): the bracket did not hold the failure load.
    pub warning: Option<String>,
}

/// The one force-controlled group of the scene: its name and the sign of its force.
fn loaded_group(scene: &Scene) -> anyhow::Result<(String, f64)> {
    let forced: Vec<_> = scene
        .groups
        .iter()
        .filter_map(|g| Some((g.name.clone(), g.load.as_ref()?.force?)))
        .collect();
    match forced.as_slice() {
        [(name, p)] if scene.failure.is_some() => Ok((name.clone(), p.signum())),
        [_] => anyhow::bail!("the scene has no [failure] section: a bisection needs a criterion that judges each test load (docs/failure.md)"),
        _ => anyhow::bail!(
            "the scene has {} groups with load.force: a bisection searches the force of exactly one",
            forced.len()
        ),
    }
}

/// The tests an unfinished study has written: (load magnitude, held).
fn replay(csv: &Path) -> anyhow::Result<Vec<(f64, bool)>> {
    if !csv.exists() {
        return Ok(Vec::new());
    }
    let mut reader = ::csv::Reader::from_path(csv)?;
    let mut tests = Vec::new();
    for r in reader.records() {
        let r = r?;
        let load: f64 = r.get(1).unwrap_or("").parse()?;
        tests.push((load.abs(), r.get(2) == Some("holds")));
    }
    Ok(tests)
}

/// Run the search from `initial` to `tolerance` (N), writing each test's row and its
/// summary.json (test_<k>/) under `out`.
pub fn bisection(
    path: &Path,
    overrides: &[String],
    out: &Path,
    initial: Bracket,
    tolerance: f64,
) -> anyhow::Result<BisectionReport> {
    if !(initial.lower > 0.0 && initial.upper > initial.lower && tolerance > 0.0) {
        anyhow::bail!(
            "--lower {} --upper {} --tolerance {}: loads in N with 0 < lower < upper and a tolerance > 0",
            initial.lower,
            initial.upper,
            tolerance
        );
    }
    let base = Scene::from_file(path, overrides)?;
    let (group, sign) = loaded_group(&base)?;
    std::fs::create_dir_all(out)?;
    let csv = out.join("bisection.csv");
    let done = replay(&csv)?;
    if done.is_empty() {
        std::fs::write(&csv, format!("{}\n", COLUMNS.join(",")))?;
    }
    let mut bracket = done
        .iter()
        .fold(initial, |b, &(load, held)| b.after(load, held));
    let mut tests = done.len();
    while !bracket.done(tolerance) {
        let load = bracket.next();
        let mut o = overrides.to_vec();
        o.push(format!("groups.{group}.load.force={:e}", sign * load));
        let scene = Scene::from_file(path, &o)?;
        let outcome = run(&scene, &RunOptions::default())?;
        let Some(t) = outcome.summary.load_test.clone() else {
            anyhow::bail!(
                "test {} at {load:.6e} N: the run ended without a verdict: {}",
                tests + 1,
                outcome.summary.message.clone().unwrap_or_default()
            );
        };
        tests += 1;
        crate::output::write_summary(&outcome, &out.join(format!("test_{tests}")))?;
        let held = t.verdict == Verdict::Holds;
        let row = [
            tests.to_string(),
            format!("{:.9e}", sign * load),
            if held { "holds" } else { "fails" }.to_string(),
            t.decided_at_step.to_string(),
            format!("{:.6e}", t.decided_at_s),
            format!("{:.6e}", outcome.summary.final_displacement_m),
            format!("{:.2}", outcome.summary.wall_time_s),
            format!("\"{}\"", t.reason.replace('"', "\"\"")),
        ];
        let mut f = std::fs::OpenOptions::new().append(true).open(&csv)?;
        writeln!(f, "{}", row.join(","))?;
        crate::say!(
            "test {tests}: {:.4e} N {}",
            sign * load,
            if held { "holds" } else { "fails" }
        );
        bracket = bracket.after(load, held);
    }
    let warning = if bracket.upper == initial.upper {
        Some(format!("every test held: the failure load is above --upper {} N (or within the tolerance of it)", initial.upper))
    } else if bracket.lower == initial.lower {
        Some(format!("every test failed: the failure load is below --lower {} N (or within the tolerance of it)", initial.lower))
    } else {
        None
    };
    let report = BisectionReport {
        scene: path.display().to_string(),
        group,
        criterion: base
            .failure
            .as_ref()
            .map(|f| f.criterion.name().to_string())
            .unwrap_or_default(),
        initial,
        tolerance,
        bracket,
        failure_load: sign * bracket.next(),
        tests,
        warning,
    };
    std::fs::write(
        out.join("bisection.json"),
        serde_json::to_string_pretty(&report)?,
    )?;
    Ok(report)
}

/// The default folder of the study of a scene.
pub fn default_out(scene: &Path) -> PathBuf {
    super::options::default_folder(scene, "bisection")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_geometric_search_halves_the_log_of_the_bracket() {
        let mut b = Bracket {
            lower: 1000.0,
            upper: 16000.0,
        };
        assert_eq!(b.next(), 4000.0);
        // a specimen that fails at 5000 N
        let mut loads = Vec::new();
        while !b.done(100.0) {
            let t = b.next();
            loads.push(t);
            b = b.after(t, t < 5000.0);
        }
        assert!(b.lower < 5000.0 && 5000.0 <= b.upper, "{b:?}");
        assert!(b.upper - b.lower <= 100.0);
        assert_eq!(loads[0], 4000.0);
        assert_eq!(loads[1], 8000.0);
    }
}
