//! The study plots: the overlay of the runs' force–displacement curves, the peak force and
//! dissipated energy against the lattice spacing with their extrapolated references, and the
//! statistical size effect on log–log axes (its figure is drawn
//! with its report, `size_effect_report`).

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

/// Tick values m·10^k inside [lo, hi] for a log axis (lo > 0): the mantissas 1, 1.2, 1.5, 2,
/// 2.5, 3, 4, 5, 6, 8, thinned to 1, 2, 5 and then 1 while there are more than 12.
pub(super) fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
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
pub(super) fn round_sig(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let scale = 10f64.powi(5 - v.abs().log10().floor() as i32);
    (v * scale).round() / scale
}
