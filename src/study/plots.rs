//! The study plots: the overlay of the runs' force–displacement curves, and the peak force
//! and dissipated energy against the lattice spacing with their extrapolated references.

use super::runner::RunResult;
use crate::output::plots::{err, force_displacement_axes, padded};
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
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
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
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(err)?;
    }
    root.present().map_err(err)?;
    Ok(())
}
