//! The size-effect report of a Monte Carlo study: the statistics of σN per size over the
//! completed realisations, the deterministic σN, the fits of the means and of the
//! deterministic runs ([`super::size_effect`]), written as size_effect.csv, size_effect.json
//! and size_effect.svg.

use super::plots::{log_ticks, round_sig};
use super::runner::RunRow;
use super::size_effect::{fit_bazant, fit_weibull, sample, BazantFit, WeibullFit};
use crate::output::plots::{draw_legend, err};
use plotters::prelude::*;
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

/// A size in whole µm (the key of a size in seeds, labels and merges).
pub fn size_um(d: f64) -> u64 {
    (d * 1e6).round() as u64
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
        size_effect_figure(title, &effect, tmp)
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

/// The statistical size effect on log–log axes: σN (MPa) against D (m), the Monte Carlo
/// mean ± one standard deviation per size, the deterministic runs, and the fits of the
/// means (Bažant type-1, Weibull power law).
pub fn size_effect_figure(title: &str, effect: &SizeEffect, path: &Path) -> anyhow::Result<()> {
    let mpa = 1e-6;
    let stats = &effect.sizes;
    let mc: Vec<(f64, f64, f64)> = stats
        .iter()
        .filter(|s| s.n > 0)
        .map(|s| {
            let sd = if s.std_sigma_n_pa.is_finite() {
                s.std_sigma_n_pa
            } else {
                0.0
            };
            (s.size_d_m, s.mean_sigma_n_pa * mpa, sd * mpa)
        })
        .collect();
    let det: Vec<(f64, f64)> = stats
        .iter()
        .filter(|s| s.deterministic_sigma_n_pa.is_finite())
        .map(|s| (s.size_d_m, s.deterministic_sigma_n_pa * mpa))
        .collect();
    let (mut x0, mut x1) = (f64::INFINITY, 0.0f64);
    for s in stats {
        x0 = x0.min(s.size_d_m);
        x1 = x1.max(s.size_d_m);
    }
    if !x0.is_finite() {
        (x0, x1) = (0.1, 1.0);
    }
    let (x0, x1) = (x0 / 1.4, x1 * 1.4);
    // fit curves on 60 log-spaced sizes
    let grid: Vec<f64> = (0..60)
        .map(|k| x0 * (x1 / x0).powf(k as f64 / 59.0))
        .collect();
    let bazant: Vec<(f64, f64)> = effect
        .fits
        .bazant
        .map(|f| grid.iter().map(|d| (*d, f.sigma(*d) * mpa)).collect())
        .unwrap_or_default();
    let weibull: Vec<(f64, f64)> = effect
        .fits
        .weibull
        .map(|f| grid.iter().map(|d| (*d, f.sigma(*d) * mpa)).collect())
        .unwrap_or_default();
    let (mut y0, mut y1) = (f64::INFINITY, 0.0f64);
    for v in mc
        .iter()
        .flat_map(|(_, m, s)| [m - s, m + s, *m])
        .chain(det.iter().map(|p| p.1))
        .chain(bazant.iter().chain(&weibull).map(|p| p.1))
        .filter(|v| *v > 0.0 && v.is_finite())
    {
        y0 = y0.min(v);
        y1 = y1.max(v);
    }
    if !y0.is_finite() {
        (y0, y1) = (0.1, 10.0);
    }
    // at least a factor 2.5 so that the log axis carries labels
    let widen = (2.5 / (y1 / y0)).max(1.15 * 1.15).sqrt();
    let (y0, y1) = (y0 / widen, y1 * widen);
    let root = SVGBackend::new(path, (900, 640)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (x0..x1).log_scale().with_key_points(log_ticks(x0, x1)),
            (y0..y1).log_scale().with_key_points(log_ticks(y0, y1)),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("specimen size D (m)")
        .y_desc("nominal strength σN = Pmax/(0.6·D·t) (MPa)")
        .x_label_formatter(&|v| format!("{}", round_sig(*v)))
        .y_label_formatter(&|v| format!("{}", round_sig(*v)))
        .draw()
        .map_err(err)?;
    let blue = BLUE.stroke_width(2);
    // error bars: a vertical line from mean − std to mean + std with caps
    for &(d, m, s) in &mc {
        let lo = (m - s).max(y0);
        let hi = m + s;
        let (dl, dr) = (d / 1.06, d * 1.06);
        chart
            .draw_series([
                PathElement::new(vec![(d, lo), (d, hi)], blue),
                PathElement::new(vec![(dl, lo), (dr, lo)], blue),
                PathElement::new(vec![(dl, hi), (dr, hi)], blue),
            ])
            .map_err(err)?;
    }
    chart
        .draw_series(
            mc.iter()
                .map(|&(d, m, _)| Circle::new((d, m), 5, BLUE.filled())),
        )
        .map_err(err)?
        .label("Monte Carlo mean ± 1 std")
        .legend(|(x, y)| Circle::new((x + 10, y), 5, BLUE.filled()));
    if !det.is_empty() {
        let colour = BLACK.stroke_width(2);
        chart
            .draw_series(LineSeries::new(det.iter().copied(), colour))
            .map_err(err)?
            .label("deterministic (mean properties)")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        chart
            .draw_series(
                det.iter()
                    .map(|&p| TriangleMarker::new(p, 6, BLACK.filled())),
            )
            .map_err(err)?;
    }
    if let Some(f) = effect.fits.bazant {
        let colour = RED.stroke_width(2);
        chart
            .draw_series(DashedLineSeries::new(bazant, 8, 5, colour))
            .map_err(err)?
            .label(format!(
                "Bažant type-1 (r = 1): f∞ = {:.3} MPa, Db = {:.3} m",
                f.f_inf_pa * mpa,
                f.d_b_m
            ))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
    }
    if let Some(f) = effect.fits.weibull {
        let colour = GREEN.stroke_width(2);
        chart
            .draw_series(DashedLineSeries::new(weibull, 3, 4, colour))
            .map_err(err)?
            .label(format!(
                "Weibull (n_d = 2): σ1 = {:.3} MPa, m = {:.2}",
                f.sigma_1_pa * mpa,
                f.modulus
            ))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
    }
    draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    root.present().map_err(err)?;
    Ok(())
}
