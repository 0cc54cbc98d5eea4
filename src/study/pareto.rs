//! Run time against error: the Pareto front of a sweep of solver and
//! discretisation settings, and how near the shipped defaults lie to it.
//!
//! A sweep varies one setting at a time around the scene's defaults (lattice spacing, time-step
//! safety factor, loading time in fundamental periods, internal and external damping), plus a
//! few combinations of a coarse lattice with short loading. The error of a run is the deviation
//! of its peak load from a converged reference ([`reference`]).

use super::extrapolation::richardson;
use serde::{Deserialize, Serialize};

/// One run of a sweep.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct SweepRun {
    pub label: String,
    /// The setting this run varies ("default", "spacing", "end_periods", "safety",
    /// "internal_damping", "external_damping", "combined").
    pub parameter: String,
    pub spacing_m: f64,
    pub end_periods: f64,
    pub safety: f64,
    pub internal_damping: f64,
    pub external_damping: f64,
    pub particles: usize,
    pub steps: usize,
    pub wall_time_s: f64,
    #[serde(rename = "peak_force_N")]
    pub peak_force_n: f64,
    pub status: String,
    /// The solver (`solver.method`); runs.csv files written before the quasi-static solver existed lack it.
    #[serde(default = "explicit")]
    pub method: String,
    /// Load increments of the relaxation and quasi-static solvers.
    #[serde(default)]
    pub increments: Option<usize>,
}

fn explicit() -> String {
    "explicit".into()
}

/// The converged reference peak load and how it was composed.
#[derive(Clone, Debug, Serialize)]
pub struct Reference {
    /// Richardson extrapolation of the spacing sweep to L0 → 0 (default loading time).
    #[serde(rename = "spacing_extrapolated_N")]
    pub spacing_extrapolated_n: f64,
    /// Observed order of the spacing convergence (None: oscillatory, the finest value is used).
    pub spacing_order: Option<f64>,
    /// Peak at the longest loading minus the peak at the default loading time (default spacing).
    #[serde(rename = "loading_correction_N")]
    pub loading_correction_n: f64,
    /// Peak at the smallest safety factor minus the peak at the default (default spacing).
    #[serde(rename = "time_step_correction_N")]
    pub time_step_correction_n: f64,
    #[serde(rename = "reference_N")]
    pub reference_n: f64,
}

/// The converged reference: the spacing sweep extrapolated to L0 → 0, corrected by how much
/// the longest loading and the smallest safety factor change the peak at the default spacing
/// (the three errors taken as independent and additive). None without a default run and at
/// least three completed spacings.
pub fn reference(runs: &[SweepRun]) -> Option<Reference> {
    let ok: Vec<&SweepRun> = runs.iter().filter(|r| r.status == "completed").collect();
    let default = ok.iter().find(|r| r.parameter == "default")?;
    let mut spacing: Vec<(f64, f64)> = ok
        .iter()
        .filter(|r| r.parameter == "spacing" || r.parameter == "default")
        .map(|r| (r.spacing_m, r.peak_force_n))
        .collect();
    spacing.sort_by(|a, b| a.0.total_cmp(&b.0)); // fine first
    spacing.dedup_by(|a, b| a.0 == b.0);
    if spacing.len() < 3 {
        return None;
    }
    // coarse to fine
    let r = richardson(
        [spacing[2].0, spacing[1].0, spacing[0].0],
        [spacing[2].1, spacing[1].1, spacing[0].1],
    );
    let (f0, order) = (r.reference, r.order);
    let extreme = |parameter: &str, key: fn(&SweepRun) -> f64, longest: bool| {
        ok.iter()
            .filter(|r| r.parameter == parameter)
            .max_by(|a, b| {
                let o = key(a).total_cmp(&key(b));
                if longest {
                    o
                } else {
                    o.reverse()
                }
            })
            .map(|r| r.peak_force_n - default.peak_force_n)
            .unwrap_or(0.0)
    };
    let loading = extreme("end_periods", |r| r.end_periods, true);
    let time_step = extreme("safety", |r| r.safety, false);
    Some(Reference {
        spacing_extrapolated_n: f0,
        spacing_order: order,
        loading_correction_n: loading,
        time_step_correction_n: time_step,
        reference_n: f0 + loading + time_step,
    })
}

/// Indices of the runs on the Pareto front of (wall time, error): no other run is both at
/// least as fast and at least as accurate, and strictly better in one. Sorted by wall time.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..points.len()).collect();
    idx.sort_by(|&a, &b| {
        points[a]
            .0
            .total_cmp(&points[b].0)
            .then(points[a].1.total_cmp(&points[b].1))
    });
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in idx {
        if points[i].1 < best {
            best = points[i].1;
            front.push(i);
        }
    }
    front
}

/// How near a point (wall time t, error e) lies to a front (points sorted by wall time):
/// the front's smallest error at a wall time ≤ t (divided by e: 1 on the front), and the
/// shortest wall time at which the front reaches an error ≤ e (divided by t: 1 on the front).
pub fn nearness(front: &[(f64, f64)], t: f64, e: f64) -> (f64, f64) {
    let best_error = front
        .iter()
        .filter(|p| p.0 <= t)
        .map(|p| p.1)
        .fold(f64::INFINITY, f64::min);
    let best_time = front
        .iter()
        .filter(|p| p.1 <= e)
        .map(|p| p.0)
        .fold(f64::INFINITY, f64::min);
    (best_error / e, best_time / t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_extrapolates_spacing_and_adds_the_loading_and_step_corrections() {
        let run = |parameter: &str, h: f64, periods: f64, safety: f64, peak: f64| SweepRun {
            label: format!("{parameter}{h}{periods}{safety}"),
            parameter: parameter.into(),
            spacing_m: h,
            end_periods: periods,
            safety,
            internal_damping: 0.2,
            external_damping: 0.0,
            particles: 1,
            steps: 1,
            wall_time_s: 1.0,
            peak_force_n: peak,
            status: "completed".into(),
            method: "explicit".into(),
            increments: None,
        };
        let f = |h: f64| 100.0 + 2.0e4 * h * h;
        let runs = vec![
            run("default", 0.01, 80.0, 0.9, f(0.01)),
            run("spacing", 0.02, 80.0, 0.9, f(0.02)),
            run("spacing", 0.005, 80.0, 0.9, f(0.005)),
            run("spacing", 0.0035, 80.0, 0.9, f(0.0035)),
            run("end_periods", 0.01, 160.0, 0.9, f(0.01) - 1.0),
            run("end_periods", 0.01, 320.0, 0.9, f(0.01) - 1.5),
            run("end_periods", 0.01, 20.0, 0.9, f(0.01) + 9.0),
            run("safety", 0.01, 80.0, 0.5, f(0.01) + 0.25),
            run("safety", 0.01, 80.0, 0.97, f(0.01) + 3.0),
            // the quasi-static solver's runs are measured against the reference, not part of it
            run("quasi_static", 0.01, 80.0, 0.9, 50.0),
            run("quasi_static_spacing", 0.001, 80.0, 0.9, 50.0),
        ];
        let r = reference(&runs).unwrap();
        // the three finest spacings, order 2; the longest loading; the smallest safety factor
        assert!((r.spacing_extrapolated_n - 100.0).abs() < 1e-9);
        assert!((r.spacing_order.unwrap() - 2.0).abs() < 1e-6);
        assert_eq!(r.loading_correction_n, -1.5);
        assert_eq!(r.time_step_correction_n, 0.25);
        assert!((r.reference_n - 98.75).abs() < 1e-9);
    }

    #[test]
    fn front_keeps_only_undominated_points() {
        // (time, error): 1 dominates 3; 4 is slower than 2 with the same error
        let pts = [
            (1.0, 0.10),
            (2.0, 0.05),
            (4.0, 0.01),
            (3.0, 0.08),
            (5.0, 0.05),
        ];
        assert_eq!(pareto_front(&pts), vec![0, 1, 2]);
        let front: Vec<(f64, f64)> = pareto_front(&pts).iter().map(|&i| pts[i]).collect();
        // a point on the front is at 1 on both measures
        assert_eq!(nearness(&front, 2.0, 0.05), (1.0, 1.0));
        // (3, 0.08): the front reaches 0.05 by t = 3 (error ratio 0.625), 0.08 at t = 2
        let (e, t) = nearness(&front, 3.0, 0.08);
        assert!((e - 0.625).abs() < 1e-12 && (t - 2.0 / 3.0).abs() < 1e-12);
    }
}
