//! The size-effect report of a Monte Carlo study: the statistics of σN per size over the
//! completed realisations, the deterministic σN, the fits of the means and of the
//! deterministic runs ([`super::size_effect`]), written as size_effect.csv, size_effect.json
//! and size_effect.svg.

use super::monte_carlo::size_um;
use super::runner::RunRow;
use super::size_effect::{fit_bazant, fit_weibull, sample, BazantFit, WeibullFit};
use serde::Serialize;
use serde_json::json;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Dimension of geometric similarity of the 2D specimens in the Weibull law.
pub const WEIBULL_DIMENSION: f64 = 2.0;

/// Statistics of one size.
#[derive(Clone, Debug, Serialize)]
pub struct SizeStats {
    pub size_d_m: f64,
    /// Completed realisations (those in the statistics).
    pub n: usize,
    pub mean_sigma_n_pa: f64,
    pub std_sigma_n_pa: f64,
    pub cov_sigma_n: f64,
    /// σN of the deterministic run (NaN if it did not complete or did not run).
    pub deterministic_sigma_n_pa: f64,
    /// Realisations that went unstable or could not be set up (excluded).
    pub failed: usize,
}

/// The fits of one series of σN against D.
#[derive(Clone, Debug, Serialize)]
pub struct Fits {
    pub bazant: Option<BazantFit>,
    pub weibull: Option<WeibullFit>,
}

fn fits(points: &[(f64, f64)]) -> Fits {
    let d: Vec<f64> = points.iter().map(|p| p.0).collect();
    let s: Vec<f64> = points.iter().map(|p| p.1).collect();
    Fits {
        bazant: fit_bazant(&d, &s),
        weibull: fit_weibull(&d, &s, WEIBULL_DIMENSION),
    }
}

/// What the study reports: the statistics per size and the fits of the means.
#[derive(Clone, Debug)]
pub struct SizeEffect {
    pub dir: PathBuf,
    pub sizes: Vec<SizeStats>,
    pub fits: Fits,
    pub deterministic_fits: Fits,
    pub completed: usize,
    pub failed: usize,
}

impl SizeEffect {
    /// The printed summary.
    pub fn lines(&self) -> Vec<String> {
        let mut l = vec![];
        for s in &self.sizes {
            if s.n == 0 {
                l.push(format!(
                    "D = {} m: no completed realisation ({} failed): no statistics, NaN in size_effect.csv",
                    s.size_d_m, s.failed
                ));
                continue;
            }
            l.push(format!(
                "D = {} m: n = {}, mean σN = {:.4} MPa, std {:.4} MPa, CoV {:.4}, deterministic {:.4} MPa{}",
                s.size_d_m,
                s.n,
                s.mean_sigma_n_pa * 1e-6,
                s.std_sigma_n_pa * 1e-6,
                s.cov_sigma_n,
                s.deterministic_sigma_n_pa * 1e-6,
                if s.failed > 0 {
                    format!(", {} failed (excluded)", s.failed)
                } else {
                    String::new()
                }
            ));
        }
        match &self.fits.bazant {
            Some(b) => l.push(format!(
                "Bažant type-1 (r = 1): f_inf = {:.4} MPa, D_b = {:.4} m, RMS rel. residual {:.4}",
                b.f_inf_pa * 1e-6,
                b.d_b_m,
                b.rms_relative_residual
            )),
            None => l.push("Bažant type-1: no fit (two sizes with a positive f_inf needed)".into()),
        }
        match &self.fits.weibull {
            Some(w) => l.push(format!(
                "Weibull (n_d = 2): sigma_1 = {:.4} MPa, m = {:.3}, RMS rel. residual {:.4}",
                w.sigma_1_pa * 1e-6,
                w.modulus,
                w.rms_relative_residual
            )),
            None => l.push("Weibull: no fit (two sizes needed)".into()),
        }
        if self.failed > 0 {
            l.push(format!(
                "{} of {} realisations failed and are excluded from the statistics",
                self.failed,
                self.failed + self.completed
            ));
        }
        l
    }
}

impl SizeEffect {
    /// Sizes (m) without a completed realisation: their statistics are NaN (null in the JSON).
    pub fn sizes_without_realisations(&self) -> Vec<f64> {
        self.sizes
            .iter()
            .filter(|s| s.n == 0)
            .map(|s| s.size_d_m)
            .collect()
    }
}

/// Tag column `i` of a row as a number (NaN if it is not one).
pub fn tag_f64(row: &RunRow, i: usize) -> f64 {
    row.tags[i].parse().unwrap_or(f64::NAN)
}

fn sigma_of(row: &RunRow) -> Option<f64> {
    let s = row.metrics[0];
    (row.completed() && s.is_finite()).then_some(s)
}

/// The statistics and fits of realisation and deterministic rows; writes size_effect.csv,
/// size_effect.json (with `meta` merged in) and size_effect.svg into `dir`.
pub fn report(
    dir: &Path,
    realisations: &[RunRow],
    deterministic: &[RunRow],
    meta: serde_json::Value,
    title: &str,
) -> anyhow::Result<SizeEffect> {
    let mut by_size: BTreeMap<u64, (Vec<f64>, usize, f64)> = BTreeMap::new();
    for r in realisations {
        let e = by_size
            .entry(size_um(tag_f64(r, 0)))
            .or_insert((vec![], 0, f64::NAN));
        match sigma_of(r) {
            Some(s) => e.0.push(s),
            None => e.1 += 1,
        }
    }
    for r in deterministic {
        let e = by_size
            .entry(size_um(tag_f64(r, 0)))
            .or_insert((vec![], 0, f64::NAN));
        e.2 = sigma_of(r).unwrap_or(f64::NAN);
    }
    let sizes: Vec<SizeStats> = by_size
        .iter()
        .map(|(um, (values, failed, det))| {
            // summed in one order whatever the order of the rows (merged or not)
            let mut values = values.clone();
            values.sort_by(f64::total_cmp);
            let s = sample(&values);
            SizeStats {
                size_d_m: *um as f64 / 1e6,
                n: s.n,
                mean_sigma_n_pa: s.mean,
                std_sigma_n_pa: s.std,
                cov_sigma_n: s.cov,
                deterministic_sigma_n_pa: *det,
                failed: *failed,
            }
        })
        .collect();
    let means: Vec<(f64, f64)> = sizes
        .iter()
        .filter(|s| s.n > 0)
        .map(|s| (s.size_d_m, s.mean_sigma_n_pa))
        .collect();
    let det: Vec<(f64, f64)> = sizes
        .iter()
        .filter(|s| s.deterministic_sigma_n_pa.is_finite())
        .map(|s| (s.size_d_m, s.deterministic_sigma_n_pa))
        .collect();
    let effect = SizeEffect {
        dir: dir.to_path_buf(),
        fits: fits(&means),
        deterministic_fits: fits(&det),
        completed: sizes.iter().map(|s| s.n).sum(),
        failed: sizes.iter().map(|s| s.failed).sum(),
        sizes,
    };

    crate::fsio::write_with(
        &dir.join("size_effect.csv"),
        |tmp: &Path| -> anyhow::Result<()> {
            let mut w = csv::Writer::from_path(tmp)?;
            w.write_record([
                "size_D_m",
                "n",
                "mean_sigma_N_Pa",
                "std_sigma_N_Pa",
                "cov_sigma_N",
                "deterministic_sigma_N_Pa",
                "failed",
            ])?;
            for s in &effect.sizes {
                w.write_record([
                    s.size_d_m.to_string(),
                    s.n.to_string(),
                    s.mean_sigma_n_pa.to_string(),
                    s.std_sigma_n_pa.to_string(),
                    s.cov_sigma_n.to_string(),
                    s.deterministic_sigma_n_pa.to_string(),
                    s.failed.to_string(),
                ])?;
            }
            w.flush()?;
            Ok(())
        },
    )?;

    let mut json = json!({
        "sigma_N": "P_max/(0.6*D*t) (dog-bone; P_max/(D*t) with D the body's width otherwise)",
        "sizes_m": effect.sizes.iter().map(|s| s.size_d_m).collect::<Vec<_>>(),
        "per_size": effect.sizes.iter().map(|s| json!({
            "size_D_m": s.size_d_m,
            "n": s.n,
            "failed": s.failed,
            "mean_sigma_N_Pa": finite(s.mean_sigma_n_pa),
            "std_sigma_N_Pa": finite(s.std_sigma_n_pa),
            "cov_sigma_N": finite(s.cov_sigma_n),
            "deterministic_sigma_N_Pa": finite(s.deterministic_sigma_n_pa),
        })).collect::<Vec<_>>(),
        "completed_realisations": effect.completed,
        "sizes_without_completed_realisations": effect.sizes_without_realisations(),
        "failed_realisations": effect.failed,
        "fits_of_the_means": effect.fits,
        "fits_of_the_deterministic_runs": effect.deterministic_fits,
        "bazant_law": "sigma_N = f_inf*(1 + r*D_b/D)^(1/r), r = 1: linear least squares in 1/D",
        "weibull_law": "sigma_N = sigma_1*(D/1 m)^(-n_d/m), n_d = 2: least squares in log-log",
    });
    if let (Some(m), serde_json::Value::Object(o)) = (meta.as_object(), &mut json) {
        for (k, v) in m {
            o.insert(k.clone(), v.clone());
        }
    }
    crate::fsio::write_json(&dir.join("size_effect.json"), &json)?;
    crate::fsio::write_with(&dir.join("size_effect.svg"), |tmp: &Path| {
        super::plots::size_effect(title, &effect, tmp)
    })?;
    Ok(effect)
}

fn finite(v: f64) -> serde_json::Value {
    if v.is_finite() {
        json!(v)
    } else {
        serde_json::Value::Null
    }
}
