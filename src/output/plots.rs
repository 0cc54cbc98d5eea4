//! SVG plots with plotters: the force–displacement curve (kN against mm) and the particle
//! map coloured by a field, optionally on the magnified deformed shape.

use super::fields;
use crate::run::Outcome;
use crate::scene::Field;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::path::Path;

/// The legend box of sppm's plots: translucent white, framed in black, at `position`.
pub fn draw_legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> anyhow::Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(err)?;
    Ok(())
}

/// A plotting error as an anyhow error (plotters' errors are generic over the backend).
pub fn err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow::anyhow!("plotting failed: {e}")
}

/// The range lo..hi widened by 5% of its length on each side (at least 5e-14).
pub fn padded(lo: f64, hi: f64) -> std::ops::Range<f64> {
    let d = (hi - lo).abs().max(1e-12) * 0.05;
    (lo - d)..(hi + d)
}

/// Viridis colour map, t in [0, 1].
pub fn viridis(t: f64) -> RGBColor {
    const ANCHORS: [(f64, f64, f64); 6] = [
        (68.0, 1.0, 84.0),
        (65.0, 68.0, 135.0),
        (42.0, 120.0, 142.0),
        (34.0, 168.0, 132.0),
        (122.0, 209.0, 81.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (ANCHORS.len() - 1) as f64;
    let k = (x.floor() as usize).min(ANCHORS.len() - 2);
    let f = x - k as f64;
    let (a, b) = (ANCHORS[k], ANCHORS[k + 1]);
    let mix = |p: f64, q: f64| (p + (q - p) * f).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// A chart on `root` with the axes of a force–displacement plot: reaction force (kN) against
/// `displacement` (mm), both marked when their signs are turned (compression).
pub fn force_displacement_axes<'a, 'b>(
    root: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
    title: &str,
    (x, y): (std::ops::Range<f64>, std::ops::Range<f64>),
    displacement: &str,
    turned: bool,
) -> anyhow::Result<ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>> {
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(x, y)
        .map_err(err)?;
    let turned = if turned { " (sign turned)" } else { "" };
    chart
        .configure_mesh()
        .x_desc(format!("{displacement} (mm){turned}"))
        .y_desc(format!("reaction force (kN){turned}"))
        .draw()
        .map_err(err)?;
    Ok(chart)
}

/// force_displacement.svg: reaction of the probe group (kN) against its displacement (mm);
/// a group pushed in the negative direction (compression) is plotted with both signs turned,
/// so that the curve rises from the origin either way.
pub fn force_displacement(o: &Outcome, path: &Path) -> anyhow::Result<()> {
    let sign = if o.records.iter().any(|r| r.displacement_m < 0.0) {
        -1.0
    } else {
        1.0
    };
    let pts: Vec<(f64, f64)> = o
        .records
        .iter()
        .map(|r| (sign * r.displacement_m * 1e3, sign * r.force_n * 1e-3))
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for &(x, y) in &pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }

    let root = SVGBackend::new(path, (800, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let group = o.summary.probe_group.clone().unwrap_or_else(|| "-".into());
    let mut chart = force_displacement_axes(
        &root,
        &format!("{}: force–displacement", o.summary.scene),
        (padded(x0, x1), padded(y0, y1)),
        &format!("displacement of group '{group}'"),
        sign < 0.0,
    )?;
    chart
        .draw_series(LineSeries::new(pts.iter().copied(), BLUE.stroke_width(2)))
        .map_err(err)?;
    if o.summary.peak_force_n != 0.0 {
        chart
            .draw_series(std::iter::once(Circle::new(
                (
                    sign * o.summary.displacement_at_peak_m * 1e3,
                    o.summary.peak_force_n * 1e-3,
                ),
                5,
                RED.filled(),
            )))
            .map_err(err)?
            .label(format!("peak {:.4} kN", o.summary.peak_force_n * 1e-3))
            .legend(|(x, y)| Circle::new((x, y), 5, RED.filled()));
        // plotters' default place
        draw_legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
    }
    root.present().map_err(err)?;
    Ok(())
}

/// force_gauge_<name>.svg: the probe group's reaction (kN, with the sign of
/// force_displacement.svg) against the opening of gauge `k` (mm), the peak marked.
pub fn force_gauge(o: &Outcome, k: usize, path: &Path) -> anyhow::Result<()> {
    let sign = if o.summary.sign_turned { -1.0 } else { 1.0 };
    let pts: Vec<(f64, f64)> = o
        .records
        .iter()
        .map(|r| (r.gauges[k] * 1e3, sign * r.force_n * 1e-3))
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for &(x, y) in &pts {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    let name = &o.scene.gauges[k].name;
    let root = SVGBackend::new(path, (800, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let mut chart = force_displacement_axes(
        &root,
        &format!("{}: force against gauge '{name}'", o.summary.scene),
        (padded(x0, x1), padded(y0, y1)),
        &format!("opening of gauge '{name}'"),
        false,
    )?;
    chart
        .draw_series(LineSeries::new(pts.iter().copied(), BLUE.stroke_width(2)))
        .map_err(err)?;
    if let Some(g) = o.summary.gauges.get(k) {
        chart
            .draw_series(std::iter::once(Circle::new(
                (g.at_peak_m * 1e3, o.summary.peak_force_n * 1e-3),
                5,
                RED.filled(),
            )))
            .map_err(err)?
            .label(format!(
                "peak {:.4} kN at {:.4} mm",
                o.summary.peak_force_n * 1e-3,
                g.at_peak_m * 1e3
            ))
            .legend(|(x, y)| Circle::new((x, y), 5, RED.filled()));
        draw_legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
    }
    root.present().map_err(err)?;
    Ok(())
}

/// The particle drawing shared by the particle and crack maps: positions x0 + scale·u in mm,
/// the bounds with a margin of one spacing, a plot area sized to the body's aspect ratio
/// and the disc radius that makes neighbouring particles touch.
struct Frame {
    pos: Vec<(f64, f64)>,
    /// Random particles: each particle's Voronoi cell (mm), moved with the particle.
    cells: Option<Vec<Vec<(f64, f64)>>>,
    /// The edges of the body's cutouts (holes, slits, notches; mm), each point moved with the
    /// particle nearest it; empty without cutouts.
    cutouts: Vec<Vec<(f64, f64)>>,
    x: std::ops::Range<f64>,
    y: std::ops::Range<f64>,
    plot_w: f64,
    plot_h: f64,
    radius: i32,
}

impl Frame {
    fn new(o: &Outcome, scale: f64) -> Frame {
        let pos: Vec<(f64, f64)> =
            o.x0.iter()
                .zip(&o.displacement)
                .map(|(x, u)| ((x[0] + scale * u[0]) * 1e3, (x[1] + scale * u[1]) * 1e3))
                .collect();
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for &(x, y) in &pos {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        let l0 = o.summary.spacing_m * 1e3;
        let (x0, x1, y0, y1) = (x0 - l0, x1 + l0, y0 - l0, y1 + l0);
        let plot_w = 700.0;
        let cells = o.cells.as_ref().map(|cells| {
            cells
                .iter()
                .zip(&o.displacement)
                .map(|(c, u)| {
                    c.iter()
                        .map(|v| ((v[0] + scale * u[0]) * 1e3, (v[1] + scale * u[1]) * 1e3))
                        .collect()
                })
                .collect()
        });
        Frame {
            cutouts: cutout_edges(o, scale),
            pos,
            cells,
            x: x0..x1,
            y: y0..y1,
            plot_w,
            plot_h: (plot_w * (y1 - y0) / (x1 - x0)).clamp(150.0, 1400.0),
            radius: ((0.5 * l0 * plot_w / (x1 - x0)).round() as i32).max(1),
        }
    }

    /// Every particle filled with its colour: its Voronoi cell for random particles, else a
    /// disc of [`Self::radius`].
    fn fill<'a, 'b>(
        &self,
        chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
        colours: impl Iterator<Item = RGBColor>,
    ) -> anyhow::Result<()> {
        match &self.cells {
            Some(cells) => chart
                .draw_series(
                    cells
                        .iter()
                        .zip(colours)
                        .map(|(c, col)| Polygon::new(c.clone(), col.filled())),
                )
                .map(|_| ())
                .map_err(err),
            None => chart
                .draw_series(
                    self.pos
                        .iter()
                        .zip(colours)
                        .map(|(&p, col)| Circle::new(p, self.radius, col.filled())),
                )
                .map(|_| ())
                .map_err(err),
        }
    }

    /// The cutouts' edges as thin black lines (nothing without cutouts).
    fn draw_cutouts<'a, 'b>(
        &self,
        chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    ) -> anyhow::Result<()> {
        chart
            .draw_series(
                self.cutouts
                    .iter()
                    .map(|line| PathElement::new(line.clone(), BLACK.stroke_width(1))),
            )
            .map(|_| ())
            .map_err(err)
    }

    /// Axes in mm on `area`, titled "<scene>: <what>" (with the magnification if any).
    fn chart<'a, 'b>(
        &self,
        area: &'a DrawingArea<SVGBackend<'b>, plotters::coord::Shift>,
        o: &Outcome,
        what: &str,
        scale: f64,
        x_desc: String,
        x_label_area: u32,
    ) -> anyhow::Result<ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>>
    {
        let title = if scale > 0.0 {
            format!("{}: {what} (deformed ×{scale})", o.summary.scene)
        } else {
            format!("{}: {what}", o.summary.scene)
        };
        let mut chart = ChartBuilder::on(area)
            .caption(title, ("sans-serif", 18))
            .margin(10)
            .x_label_area_size(x_label_area)
            .y_label_area_size(60)
            .build_cartesian_2d(self.x.clone(), self.y.clone())
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(x_desc)
            .y_desc(format!("{} (mm)", o.axes[1]))
            .draw()
            .map_err(err)?;
        Ok(chart)
    }
}

/// The edges of the scene's cutouts in mm (`Shape2::cutout_outlines`), each point moved by
/// scale × the displacement of the particle nearest it; empty without cutouts.
fn cutout_edges(o: &Outcome, scale: f64) -> Vec<Vec<(f64, f64)>> {
    if o.scene.cutouts.is_empty() || o.x0.is_empty() {
        return vec![];
    }
    let lines = o.scene.shape().cutout_outlines();
    let tree = (scale != 0.0).then(|| {
        rstar::RTree::bulk_load(
            o.x0.iter()
                .enumerate()
                .map(|(i, x)| rstar::primitives::GeomWithData::new([x[0], x[1]], i))
                .collect::<Vec<_>>(),
        )
    });
    lines
        .iter()
        .map(|line| {
            line.iter()
                .map(|p| {
                    let u = tree
                        .as_ref()
                        .and_then(|t| t.nearest_neighbor(&[p.x, p.y]))
                        .map_or([0.0; 3], |q| o.displacement[q.data]);
                    ((p.x + scale * u[0]) * 1e3, (p.y + scale * u[1]) * 1e3)
                })
                .collect()
        })
        .collect()
}

/// particle_map.svg: every particle as a disc (random particles: as its Voronoi cell)
/// coloured by `field`, at x0 + scale·u.
pub fn particle_map(o: &Outcome, field: Field, scale: f64, path: &Path) -> anyhow::Result<()> {
    value_map(
        o,
        &fields::values(o, field),
        fields::label(field),
        scale,
        false,
        path,
    )
}

/// random_field_<property>.svg: a random field's values (docs/model.md §12) at every particle, at
/// x0 + scale·u, with the cracked particles (w_t ≥ 0.99) drawn as black dots on top, so the
/// crack can be read against the field.
pub fn field_map(o: &Outcome, k: usize, scale: f64, path: &Path) -> anyhow::Result<()> {
    let f = &o.fields[k];
    let (name, unit) = f.label();
    let values: Vec<f64> = f.values.iter().map(|v| v * unit).collect();
    let label = format!(
        "random field {name} (seed {}; black: w_t ≥ 0.99)",
        f.report.seed
    );
    value_map(o, &values, &label, scale, true, path)
}

/// Particles as discs coloured by `values` (viridis over the 1st–99th percentile) with a
/// colour bar; with `cracks`, the cracked particles as black dots.
fn value_map(
    o: &Outcome,
    values: &[f64],
    label: &str,
    scale: f64,
    cracks: bool,
    path: &Path,
) -> anyhow::Result<()> {
    let frame = Frame::new(o, scale);
    // colour range: 1st to 99th percentile, so that a few boundary particles (whose
    // one-sided bond sums give low particle stresses) do not wash out the interior
    let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    sorted.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let quantile = |f: f64| {
        let k = ((sorted.len().max(1) - 1) as f64 * f).round() as usize;
        sorted.get(k).copied().unwrap_or(0.0)
    };
    let (vmin, vmax) = (quantile(0.01), quantile(0.99));
    let span = if vmax > vmin { vmax - vmin } else { 1.0 };
    let width = frame.plot_w as u32 + 230;
    let height = frame.plot_h as u32 + 110;
    let root = SVGBackend::new(path, (width, height)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let (main, bar) = root.split_horizontally(width - 140);
    let mut chart = frame.chart(&main, o, label, scale, format!("{} (mm)", o.axes[0]), 40)?;
    let radius = frame.radius;
    frame.fill(
        &mut chart,
        values.iter().map(|&v| viridis((v - vmin) / span)),
    )?;
    frame.draw_cutouts(&mut chart)?;
    if let (true, Some(damage)) = (cracks, &o.damage) {
        chart
            .draw_series(
                frame
                    .pos
                    .iter()
                    .zip(damage)
                    .filter(|(_, d)| d.cracked())
                    .map(|(&p, _)| Circle::new(p, (radius / 2).max(1), BLACK.filled())),
            )
            .map_err(err)?;
    }
    // colour bar
    let mut cb = ChartBuilder::on(&bar)
        .caption("1st–99th pct", ("sans-serif", 13))
        .margin_top(20)
        .margin_bottom(60)
        .margin_right(10)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..1.0, vmin..(vmin + span))
        .map_err(err)?;
    cb.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(8)
        .y_label_style(("sans-serif", 14))
        .y_label_formatter(&|v| format!("{v:.3}"))
        .draw()
        .map_err(err)?;
    let steps = 100;
    cb.draw_series((0..steps).map(|k| {
        let a = vmin + span * k as f64 / steps as f64;
        let b = vmin + span * (k + 1) as f64 / steps as f64;
        Rectangle::new(
            [(0.0, a), (1.0, b)],
            viridis((k as f64 + 0.5) / steps as f64).filled(),
        )
    }))
    .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}

/// Colour of a tensile damage value: light grey (intact) to dark red (w_t = 1).
fn damage_colour(w: f64) -> RGBColor {
    let w = w.clamp(0.0, 1.0);
    let lerp = |a: f64, b: f64| (a + (b - a) * w).round() as u8;
    RGBColor(lerp(225.0, 150.0), lerp(225.0, 0.0), lerp(225.0, 0.0))
}

/// crack_map.svg: particles coloured by tensile damage w_t (grey intact → dark red fully
/// cracked), crushed particles (w_c ≥ 0.99 without w_t ≥ 0.99) marked with a
/// black ×, particles that yielded with a blue ring; at x0 + scale·u.
pub fn crack_map(o: &Outcome, scale: f64, path: &Path) -> anyhow::Result<()> {
    let Some(damage) = &o.damage else {
        return Ok(());
    };
    let frame = Frame::new(o, scale);
    let width = frame.plot_w as u32 + 90;
    let height = frame.plot_h as u32 + 130;
    let root = SVGBackend::new(path, (width, height)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let cracked = damage.iter().filter(|p| p.cracked()).count();
    let crushed = damage.iter().filter(|p| p.crushed()).count();
    let yielded = damage.iter().filter(|p| p.yielded).count();
    let mut chart = frame.chart(
        &root,
        o,
        "tensile damage",
        scale,
        format!(
            "{} (mm)   —   red: w_t (grey 0 → dark red 1; {cracked} with w_t ≥ 0.99)   ×: crushed, w_c ≥ 0.99 ({crushed})   blue ring: yielded ({yielded})",
            o.axes[0]
        ),
        60,
    )?;
    let (pos, radius) = (&frame.pos, frame.radius);
    frame.fill(&mut chart, damage.iter().map(|d| damage_colour(d.wt)))?;
    frame.draw_cutouts(&mut chart)?;
    chart
        .draw_series(
            pos.iter()
                .zip(damage)
                .filter(|(_, d)| d.yielded)
                .map(|(&p, _)| Circle::new(p, (radius - 1).max(1), BLUE.stroke_width(1))),
        )
        .map_err(err)?;
    chart
        .draw_series(
            pos.iter()
                .zip(damage)
                .filter(|(_, d)| d.crushed())
                .map(|(&p, _)| Cross::new(p, (radius - 1).max(2), BLACK.stroke_width(1))),
        )
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}
