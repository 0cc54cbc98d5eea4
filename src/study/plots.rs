//! The study plots: the overlay of the runs' force–displacement curves, the peak force and
//! dissipated energy against the lattice spacing with their extrapolated references, and the
//! statistical size effect on log–log axes.

use super::runner::RunResult;
use crate::output::plots::{draw_legend, err, force_displacement_axes, padded};
use plotters::prelude::*;
use std::path::Path;

/// Every run's force–displacement curve (kN against mm) in one plot, one colour per run,
/// labelled by `legend(result)`. Curves pushed in the negative direction are plotted with
/// both signs turned, as in each run's force_displacement.svg.
pub fn overlay(
    title: &str,
    results: &[RunResult],
    legend: &dyn Fn(&RunResult) -> String,
    path: &Path,
) -> anyhow::Result<()> {
    let sign = if results.iter().flat_map(|r| &r.curve).any(|(u, _)| *u < 0.0) {
        -1.0
    } else {
        1.0
    };
    let (mut x0, mut x1, mut y0, mut y1) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for &(u, f) in results.iter().flat_map(|r| &r.curve) {
        x0 = x0.min(sign * u * 1e3);
        x1 = x1.max(sign * u * 1e3);
        y0 = y0.min(sign * f * 1e-3);
        y1 = y1.max(sign * f * 1e-3);
    }
    let root = SVGBackend::new(path, (900, 620)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let mut chart = force_displacement_axes(
        &root,
        title,
        (padded(x0, x1), padded(y0, y1)),
        "displacement",
        sign < 0.0,
    )?;
    for (k, r) in results.iter().enumerate() {
        let colour = Palette99::pick(k).to_rgba();
        chart
            .draw_series(LineSeries::new(
                r.curve
                    .iter()
                    .map(|(u, f)| (sign * u * 1e3, sign * f * 1e-3)),
                colour.stroke_width(2),
            ))
            .map_err(err)?
            .label(legend(r))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
    }
    draw_legend(&mut chart, SeriesLabelPosition::UpperRight)?;
    root.present().map_err(err)?;
    Ok(())
}

/// One panel of a convergence plot: values against spacing (mm), the reference as a line.
pub struct Panel<'a> {
    pub y_desc: &'a str,
    /// (spacing m, value) of the completed runs.
    pub points: Vec<(f64, f64)>,
    pub reference: Option<f64>,
    pub reference_label: String,
}

/// Panels side by side: each quantity against the lattice spacing (linear axes, spacing in mm
/// down to zero so that the extrapolated reference sits at h = 0).
pub fn convergence(title: &str, panels: &[Panel], path: &Path) -> anyhow::Result<()> {
    let root = SVGBackend::new(path, (520 * panels.len() as u32, 480)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(err)?;
    let areas = root.split_evenly((1, panels.len().max(1)));
    for (panel, area) in panels.iter().zip(&areas) {
        let hmax = panel.points.iter().map(|p| p.0 * 1e3).fold(0.0, f64::max);
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for v in panel.points.iter().map(|p| p.1).chain(panel.reference) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if !lo.is_finite() {
            (lo, hi) = (0.0, 1.0);
        }
        let mut chart = ChartBuilder::on(area)
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..hmax * 1.08 + 1e-9, padded(lo, hi))
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("lattice spacing L0 (mm)")
            .y_desc(panel.y_desc)
            .draw()
            .map_err(err)?;
        let pts: Vec<(f64, f64)> = panel.points.iter().map(|(h, v)| (h * 1e3, *v)).collect();
        chart
            .draw_series(LineSeries::new(pts.iter().copied(), BLUE.stroke_width(2)))
            .map_err(err)?;
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 5, BLUE.filled())))
            .map_err(err)?
            .label("runs")
            .legend(|(x, y)| Circle::new((x + 10, y), 5, BLUE.filled()));
        if let Some(r) = panel.reference {
            chart
                .draw_series(LineSeries::new(
                    [(0.0, r), (hmax * 1.08, r)],
                    RED.stroke_width(2),
                ))
                .map_err(err)?
                .label(panel.reference_label.clone())
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
        }
        draw_legend(&mut chart, SeriesLabelPosition::LowerRight)?;
    }
    root.present().map_err(err)?;
    Ok(())
}

/// The statistical size effect on log–log axes: σN (MPa) against D (m), the Monte Carlo
/// mean ± one standard deviation per size, the deterministic runs, and the fits of the
/// means (Bažant type-1, Weibull power law).
pub fn size_effect(
    title: &str,
    effect: &super::size_effect_report::SizeEffect,
    path: &Path,
) -> anyhow::Result<()> {
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

/// Tick values m·10^k inside [lo, hi] for a log axis (lo > 0): the mantissas 1, 1.2, 1.5, 2,
/// 2.5, 3, 4, 5, 6, 8, thinned to 1, 2, 5 and then 1 while there are more than 12.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let sets: [&[f64]; 3] = [
        &[1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0],
        &[1.0, 2.0, 5.0],
        &[1.0],
    ];
    let mut ticks = vec![];
    for set in sets {
        ticks.clear();
        for k in (lo.log10().floor() as i32)..=(hi.log10().ceil() as i32) {
            for m in set {
                let v = round_sig(m * 10f64.powi(k));
                if v >= lo && v <= hi {
                    ticks.push(v);
                }
            }
        }
        if ticks.len() <= 12 {
            break;
        }
    }
    ticks
}

/// A value rounded to 6 significant digits (tick labels without binary noise).
fn round_sig(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let scale = 10f64.powi(5 - v.abs().log10().floor() as i32);
    (v * scale).round() / scale
}
