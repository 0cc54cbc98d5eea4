//! Run time against error.
//!
//! `cargo run --release --example pareto -- SCENE [--threads 2] [--out DIR] [--set k=v]...`
//!
//! Sweeps the lattice spacing, the time-step safety factor, the loading time (fundamental
//! periods), internal and external damping one at a time around the scene's values, plus
//! coarse-and-fast combinations; and the quasi-static solver (`solver.method =
//! "quasi_static"`) at ½, 1, 2 and 4 × the scene's load increments and at spacings
//! ×2, ×1.5 and ×0.7, measured against the reference of the explicit runs alone. The runs go
//! one after another, each on `--threads` threads, so that their wall times compare. Each
//! finished run is appended to `runs.csv` at once; a second invocation skips the runs already
//! there. Wall times include the set-up (lattice, fundamental period, stable step). Then the
//! error of each run (deviation of its peak load from the converged reference,
//! `sppm::study::pareto::reference`) goes to `pareto.csv`, the error against wall time to
//! `pareto.svg`, and one line says how near the shipped default lies to the front. f32 is
//! not offered by the kernels, so it is not swept.

use anyhow::{bail, Context};
use plotters::prelude::*;
use sppm::output::plots::err;
use sppm::study::pareto::{nearness, pareto_front, reference, SweepRun};
use sppm::{RunOptions, Scene};
use std::collections::HashSet;
use std::io::Write;
use std::path::{Path, PathBuf};

/// One variant: label, swept parameter, overrides.
fn variants(scene: &Scene) -> anyhow::Result<Vec<(String, &'static str, Vec<String>)>> {
    let h = scene.discretisation.spacing;
    let Some(periods) = scene.loading.end_periods else {
        bail!("loading.end_periods: the sweep scales the loading time in fundamental periods; the scene gives loading.end_s instead");
    };
    let mut v = vec![("default".to_string(), "default", vec![])];
    for f in [2.0, 1.5, 0.7, 0.5] {
        v.push((
            format!("spacing={:.4}", h * f),
            "spacing",
            vec![format!("discretisation.spacing={}", h * f)],
        ));
    }
    for f in [0.25, 0.5, 2.0, 4.0] {
        v.push((
            format!("end_periods={}", periods * f),
            "end_periods",
            vec![format!("loading.end_periods={}", periods * f)],
        ));
    }
    for s in [0.5, 0.7, 0.97] {
        v.push((
            format!("safety={s}"),
            "safety",
            vec![format!("solver.safety={s}")],
        ));
    }
    for x in [0.05, 0.1, 0.2, 0.4] {
        if x != scene.damping.internal {
            v.push((
                format!("internal_damping={x}"),
                "internal_damping",
                vec![format!("damping.internal={x}")],
            ));
        }
    }
    for x in [0.0, 0.1, 0.2, 0.4] {
        if x != scene.damping.external {
            v.push((
                format!("external_damping={x}"),
                "external_damping",
                vec![format!("damping.external={x}")],
            ));
        }
    }
    let qs = "solver.method=quasi_static".to_string();
    let n = scene.solver.increments;
    for m in [n, 2 * n, 4 * n, n / 2] {
        v.push((
            format!("quasi_static,increments={m}"),
            "quasi_static",
            vec![qs.clone(), format!("solver.increments={m}")],
        ));
    }
    for f in [2.0, 1.5, 0.7] {
        v.push((
            format!("quasi_static,spacing={:.4}", h * f),
            "quasi_static_spacing",
            vec![qs.clone(), format!("discretisation.spacing={}", h * f)],
        ));
    }
    for (fh, fp) in [(2.0, 0.25), (2.0, 0.5), (1.5, 0.25), (1.5, 0.5), (0.7, 0.5)] {
        v.push((
            format!("spacing={:.4},end_periods={}", h * fh, periods * fp),
            "combined",
            vec![
                format!("discretisation.spacing={}", h * fh),
                format!("loading.end_periods={}", periods * fp),
            ],
        ));
    }
    Ok(v)
}

struct Args {
    scene: PathBuf,
    threads: usize,
    out: Option<PathBuf>,
    set: Vec<String>,
}

fn parse_args() -> anyhow::Result<Args> {
    let mut it = std::env::args().skip(1);
    let mut a = Args {
        scene: PathBuf::new(),
        threads: 2,
        out: None,
        set: vec![],
    };
    while let Some(x) = it.next() {
        match x.as_str() {
            "--threads" => a.threads = it.next().context("--threads N")?.parse()?,
            "--out" => a.out = Some(it.next().context("--out DIR")?.into()),
            "--set" => a.set.push(it.next().context("--set key=value")?),
            s if s.starts_with("--") => bail!("unknown option {s}"),
            s => a.scene = s.into(),
        }
    }
    if a.scene.as_os_str().is_empty() {
        bail!("usage: pareto SCENE [--threads T] [--out DIR] [--set key=value]...");
    }
    Ok(a)
}

/// x to six decimals.
fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

fn read_runs(path: &Path) -> anyhow::Result<Vec<SweepRun>> {
    if !path.exists() {
        return Ok(vec![]);
    }
    let mut r = csv::Reader::from_path(path)?;
    Ok(r.deserialize().collect::<Result<_, _>>()?)
}

fn main() -> anyhow::Result<()> {
    let a = parse_args()?;
    let base = Scene::from_file(&a.scene, &a.set)?;
    let dir = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("output").join(format!("{}-pareto", base.name())));
    std::fs::create_dir_all(&dir)?;
    let runs_csv = dir.join("runs.csv");
    let mut runs = read_runs(&runs_csv)?;
    let done: HashSet<String> = runs.iter().map(|r| r.label.clone()).collect();
    let todo: Vec<_> = variants(&base)?
        .into_iter()
        .filter(|v| !done.contains(&v.0))
        .collect();
    println!(
        "{}: {} runs done, {} to run on {} threads",
        base.name(),
        done.len(),
        todo.len(),
        a.threads
    );
    for (label, parameter, overrides) in todo {
        let mut o = a.set.clone();
        o.extend(overrides);
        let scene = Scene::from_file(&a.scene, &o)?;
        // set-up (lattice, T1, stable step) included: what a user waits for
        let clock = std::time::Instant::now();
        let outcome = sppm::run(
            &scene,
            &RunOptions {
                progress: false,
                threads: Some(a.threads),
            },
        )?;
        let wall_time_s = clock.elapsed().as_secs_f64();
        let s = &outcome.summary;
        let run = SweepRun {
            label: label.clone(),
            parameter: parameter.into(),
            spacing_m: s.spacing_m,
            // t_end/T1 and dt/dt_stable give back the scene's values to round-off
            end_periods: round6(s.t_end_s / s.fundamental_period_s),
            safety: round6(s.safety),
            internal_damping: scene.damping.internal,
            external_damping: scene.damping.external,
            particles: s.particles,
            steps: s.steps,
            wall_time_s,
            peak_force_n: s.peak_force_n,
            status: s.status.clone(),
            method: s.solver_method.name().to_string(),
            increments: s.increments,
        };
        println!(
            "{label:<40} {:>8} particles {:>8.2} s  peak {:.5e} N  {}",
            s.particles, wall_time_s, s.peak_force_n, s.status
        );
        let new = !runs_csv.exists();
        let file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&runs_csv)?;
        let mut w = csv::WriterBuilder::new().has_headers(new).from_writer(file);
        w.serialize(&run)?;
        w.flush()?;
        runs.push(run);
    }

    let Some(r) = reference(&runs) else {
        bail!("no reference: the sweep needs the default and two more spacings completed");
    };
    let ok: Vec<&SweepRun> = runs.iter().filter(|r| r.status == "completed").collect();
    let pts: Vec<(f64, f64)> = ok
        .iter()
        .map(|x| (x.wall_time_s, (x.peak_force_n / r.reference_n - 1.0).abs()))
        .collect();
    let front_idx = pareto_front(&pts);
    let on_front: HashSet<usize> = front_idx.iter().copied().collect();
    let mut f = std::fs::File::create(dir.join("pareto.csv"))?;
    writeln!(
        f,
        "label,parameter,method,increments,spacing_m,end_periods,safety,internal_damping,external_damping,particles,steps,wall_time_s,peak_force_N,error,on_front"
    )?;
    for (i, x) in ok.iter().enumerate() {
        writeln!(
            f,
            "\"{}\",{},{},{},{},{},{},{},{},{},{},{:.4},{:.6e},{:.6e},{}",
            x.label,
            x.parameter,
            x.method,
            x.increments.map(|n| n.to_string()).unwrap_or_default(),
            x.spacing_m,
            x.end_periods,
            x.safety,
            x.internal_damping,
            x.external_damping,
            x.particles,
            x.steps,
            x.wall_time_s,
            x.peak_force_n,
            pts[i].1,
            on_front.contains(&i)
        )?;
    }
    std::fs::write(
        dir.join("reference.json"),
        serde_json::to_string_pretty(&r)? + "\n",
    )?;
    let front: Vec<(f64, f64)> = front_idx.iter().map(|&i| pts[i]).collect();
    let d = ok
        .iter()
        .position(|x| x.parameter == "default")
        .context("the default run did not complete")?;
    let (err_ratio, time_ratio) = nearness(&front, pts[d].0, pts[d].1);
    println!(
        "reference {:.5e} N (spacing → 0: {:.5e} N, order {}; loading {:+.3e} N; time step {:+.3e} N)",
        r.reference_n,
        r.spacing_extrapolated_n,
        r.spacing_order
            .map(|p| format!("{p:.2}"))
            .unwrap_or_else(|| "undefined".into()),
        r.loading_correction_n,
        r.time_step_correction_n
    );
    for &i in &front_idx {
        println!(
            "front: {:<40} {:>8.2} s  error {:.3}%",
            ok[i].label,
            pts[i].0,
            100.0 * pts[i].1
        );
    }
    println!(
        "default: {:.2} s, error {:.3}%; on the front: {}; the front's error at that time is {:.2}× it, and the front reaches that error in {:.2}× the time",
        pts[d].0,
        100.0 * pts[d].1,
        on_front.contains(&d),
        err_ratio,
        time_ratio
    );
    plot(&dir.join("pareto.svg"), base.name(), &ok, &pts, &front, d)?;
    println!("wrote {}", dir.display());
    Ok(())
}

fn plot(
    path: &Path,
    name: &str,
    runs: &[&SweepRun],
    pts: &[(f64, f64)],
    front: &[(f64, f64)],
    default: usize,
) -> anyhow::Result<()> {
    let floor = 1e-4; // errors below 0.01% are drawn at 0.01%
    let y = |v: f64| v.max(floor);
    let (t0, t1) = pts
        .iter()
        .fold((f64::INFINITY, 0f64), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let e1 = pts.iter().map(|p| y(p.1)).fold(floor, f64::max);
    let root = SVGBackend::new(path, (900, 620)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{name}: peak-load error against wall time"),
            ("sans-serif", 22),
        )
        .margin(15)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(
            ((t0 * 0.8)..(t1 * 1.25)).log_scale(),
            (floor * 0.8..e1 * 1.5).log_scale(),
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("wall time (s)")
        .y_desc("|peak − reference| / reference")
        .y_label_formatter(&|v| format!("{:.2}%", v * 100.0))
        .draw()
        .map_err(err)?;
    let params = [
        "spacing",
        "end_periods",
        "safety",
        "internal_damping",
        "external_damping",
        "combined",
        "quasi_static",
        "quasi_static_spacing",
    ];
    for (k, p) in params.iter().enumerate() {
        let c = Palette99::pick(k).to_rgba();
        let series: Vec<(f64, f64)> = runs
            .iter()
            .zip(pts)
            .filter(|(r, _)| r.parameter == *p)
            .map(|(_, q)| (q.0, y(q.1)))
            .collect();
        chart
            .draw_series(series.iter().map(|q| Circle::new(*q, 5, c.filled())))
            .map_err(err)?
            .label(*p)
            .legend(move |(x, yy)| Circle::new((x + 10, yy), 5, c.filled()));
    }
    // the front as a staircase: the best error reached by each wall time
    let mut stairs = Vec::new();
    for (k, q) in front.iter().enumerate() {
        if k > 0 {
            stairs.push((q.0, y(front[k - 1].1)));
        }
        stairs.push((q.0, y(q.1)));
    }
    if let Some(last) = front.last() {
        stairs.push((t1 * 1.25, y(last.1)));
    }
    chart
        .draw_series(LineSeries::new(stairs, BLACK.stroke_width(2)))
        .map_err(err)?
        .label("Pareto front")
        .legend(|(x, yy)| PathElement::new(vec![(x, yy), (x + 20, yy)], BLACK.stroke_width(2)));
    let dp = (pts[default].0, y(pts[default].1));
    chart
        .draw_series(std::iter::once(Cross::new(dp, 9, RED.stroke_width(3))))
        .map_err(err)?
        .label("shipped default")
        .legend(|(x, yy)| Cross::new((x + 10, yy), 6, RED.stroke_width(3)));
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE.mix(0.85))
        .position(SeriesLabelPosition::LowerLeft)
        .draw()
        .map_err(err)?;
    root.present().map_err(err)?;
    Ok(())
}
