//! The convergence study: the same scene at several lattice spacings, the peak force and
//! dissipated energy of each, and from the three finest spacings the Richardson-extrapolated
//! reference and the observed order ([`super::extrapolation::richardson`]).

use super::extrapolation::{richardson, Richardson};
use super::runner::{RunResult, RunRow, Study, Variant};
use crate::Scene;
use anyhow::bail;
use serde::Serialize;
use std::path::PathBuf;

/// The study's inputs.
#[derive(Clone, Debug)]
pub struct ConvergenceArgs {
    pub scene: PathBuf,
    pub spacings_m: Vec<f64>,
    pub overrides: Vec<String>,
    pub out: Option<PathBuf>,
    pub jobs: usize,
    pub progress: bool,
}

/// The extrapolation of one quantity and the spacings it used.
#[derive(Clone, Debug, Serialize)]
pub struct Extrapolated {
    pub quantity: String,
    /// The three finest spacings of completed runs (coarse to fine), m.
    pub spacings_m: Vec<f64>,
    pub values: Vec<f64>,
    pub reference: f64,
    pub observed_order: Option<f64>,
    pub note: String,
    /// Finest value relative to the reference, minus one.
    pub finest_error: f64,
}

/// convergence.json.
#[derive(Clone, Debug, Serialize)]
pub struct ConvergenceReport {
    pub scene: String,
    pub scene_file: String,
    pub overrides: Vec<String>,
    pub runs: usize,
    pub completed: usize,
    pub peak_force: Option<Extrapolated>,
    pub dissipated_energy: Option<Extrapolated>,
    pub rows: Vec<RunRow>,
    pub dir: PathBuf,
}

impl ConvergenceReport {
    /// The lines the CLI prints, one per quantity.
    pub fn lines(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (name, unit, e) in [
            ("peak force", "N", &self.peak_force),
            ("dissipated energy", "J", &self.dissipated_energy),
        ] {
            out.push(match e {
                Some(e) => match e.observed_order {
                    Some(p) => format!(
                        "{name}: extrapolated reference {:.5e} {unit}, observed order p = {p:.3} (spacings {:?} m; finest value {:+.2}% from the reference)",
                        e.reference,
                        e.spacings_m,
                        100.0 * e.finest_error
                    ),
                    None => format!(
                        "{name}: {} (spacings {:?} m); reference = finest value {:.5e} {unit}",
                        e.note, e.spacings_m, e.reference
                    ),
                },
                None => format!(
                    "{name}: no extrapolation, it needs three completed runs at different spacings ({} completed)",
                    self.completed
                ),
            });
        }
        out
    }
}

/// The label of spacing h: "h0.005".
pub fn label(h: f64) -> String {
    format!("h{h}")
}

fn extrapolate(
    quantity: &str,
    rows: &[&RunRow],
    value: impl Fn(&RunRow) -> f64,
) -> Option<Extrapolated> {
    if rows.len() < 3 {
        return None;
    }
    let three = &rows[rows.len() - 3..];
    let h = [three[0].spacing_m, three[1].spacing_m, three[2].spacing_m];
    let f = [value(three[0]), value(three[1]), value(three[2])];
    let Richardson {
        reference,
        order,
        note,
    } = richardson(h, f);
    Some(Extrapolated {
        quantity: quantity.into(),
        spacings_m: h.to_vec(),
        values: f.to_vec(),
        reference,
        observed_order: order,
        note,
        finest_error: f[2] / reference - 1.0,
    })
}

/// Run (or resume) the study and write convergence.csv, convergence.json and convergence.svg.
pub fn convergence(args: &ConvergenceArgs) -> anyhow::Result<ConvergenceReport> {
    if args.spacings_m.is_empty() {
        bail!(
            "--spacings: give at least one lattice spacing in m, e.g. --spacings 0.01,0.005,0.0025"
        );
    }
    if let Some(h) = args
        .spacings_m
        .iter()
        .find(|h| !(h.is_finite() && **h > 0.0))
    {
        bail!("--spacings: {h} is not a lattice spacing; each must be a number > 0 (m)");
    }
    for (i, h) in args.spacings_m.iter().enumerate() {
        if args.spacings_m[..i].contains(h) {
            bail!("--spacings: {h} appears twice");
        }
    }
    if args.jobs == 0 {
        bail!("--jobs 0: at least 1");
    }
    let base = Scene::from_file(&args.scene, &args.overrides)?;
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("output").join(format!("{}-convergence", base.name())));
    // coarse to fine; the coarse runs are fast, the finest is the one worth waiting for
    let mut spacings = args.spacings_m.clone();
    spacings.sort_by(|a, b| b.total_cmp(a));
    let make = |k: usize| {
        let h = spacings[k];
        Variant {
            label: label(h),
            overrides: vec![format!("discretisation.spacing={h:?}")],
            tags: vec![],
        }
    };
    let metrics = |_: &crate::run::Outcome| Vec::new();
    let study = Study {
        scene: args.scene.clone(),
        base_overrides: args.overrides.clone(),
        dir: dir.clone(),
        csv_name: "convergence.csv".into(),
        tag_columns: vec![],
        metric_columns: vec![],
        metrics: &metrics,
        notes: None,
        inputs: serde_json::json!({
            "study": "convergence",
            "scene_file": args.scene.display().to_string(),
            "overrides": args.overrides,
        }),
        jobs: args.jobs,
        progress: args.progress,
        outputs: super::runner::RunOutputs::All,
    };
    crate::limits::check_count_of(
        &format!("--spacings: {} runs", spacings.len()),
        spacings.len() as f64,
        study.bytes_per_run(&base),
        "runs",
        "fewer --spacings",
    )?;
    let runs = super::runner::Runs {
        count: spacings.len(),
        variant: &make,
        // every spacing is a kind of its own (its own lattice)
        probes: (0..spacings.len()).collect(),
    };
    study.check(&runs)?;
    let lock = crate::fsio::FolderLock::acquire(&dir)?;
    let results: Vec<RunResult> = study.run(&lock, &runs)?;
    let done: Vec<&RunRow> = results
        .iter()
        .map(|r| &r.row)
        .filter(|r| r.completed())
        .collect();
    let report = ConvergenceReport {
        scene: base.name().to_string(),
        scene_file: args.scene.display().to_string(),
        overrides: args.overrides.clone(),
        runs: results.len(),
        completed: done.len(),
        peak_force: extrapolate("peak_force_N", &done, |r| r.peak_force_n),
        dissipated_energy: extrapolate("dissipated_energy_J", &done, |r| r.dissipated_energy_j),
        rows: results.iter().map(|r| r.row.clone()).collect(),
        dir: dir.clone(),
    };
    let panel = |y_desc,
                 e: &Option<Extrapolated>,
                 scale: f64,
                 unit: &str,
                 value: &dyn Fn(&RunRow) -> f64| {
        super::plots::Panel {
            y_desc,
            points: done
                .iter()
                .map(|r| (r.spacing_m, scale * value(r)))
                .collect(),
            reference: e.as_ref().map(|e| scale * e.reference),
            reference_label: match e {
                Some(Extrapolated {
                    observed_order: Some(p),
                    reference,
                    ..
                }) => format!("extrapolated {:.4} {unit} (p = {p:.2})", scale * reference),
                Some(e) => format!("finest {:.4} {unit} (order undefined)", scale * e.reference),
                None => String::new(),
            },
        }
    };
    let title = format!("{}: convergence with the lattice spacing", base.name());
    let panels = [
        panel("peak force (kN)", &report.peak_force, 1e-3, "kN", &|r| {
            r.peak_force_n
        }),
        panel(
            "dissipated energy (J)",
            &report.dissipated_energy,
            1.0,
            "J",
            &|r| r.dissipated_energy_j,
        ),
    ];
    crate::fsio::write_with(&dir.join("convergence.svg"), |tmp: &std::path::Path| {
        super::plots::convergence(&title, &panels, tmp)
    })?;
    crate::fsio::write_json(&dir.join("convergence.json"), &report)?;
    drop(lock);
    Ok(report)
}
