//! A parallel runner of scene variants, reusable by every study: each variant is the
//! scene file with the user's `--set` overrides and its own extra `key=value` overrides.
//! Runs go in parallel across variants (`jobs` at a time, each run on one thread), each
//! writes its outputs into `<study dir>/<label>/`, and its row is appended to the study
//! CSV and flushed as soon as it finishes. Started again, the runner skips every variant
//! whose label already has a row (resume) and reads those rows back, so an interrupted
//! study loses nothing. A run that goes unstable (or cannot be set up) is a row with its
//! status, not the end of the study.

use crate::run::{Outcome, RunOptions};
use crate::Scene;
use anyhow::{bail, Context};
use serde::Serialize;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

/// One run of a study: a label (also its folder name and CSV key), the extra overrides
/// on top of the study's base overrides, and the values of the study's tag columns.
#[derive(Clone, Debug)]
pub struct Variant {
    pub label: String,
    pub overrides: Vec<String>,
    pub tags: Vec<String>,
}

/// Numbers a study derives from a finished run, beyond the summary (one per metric column).
pub type Metrics = dyn Fn(&Outcome) -> Vec<f64> + Sync;

/// A study: where it lives, its CSV layout and how its runs are made.
pub struct Study<'a> {
    /// The scene file.
    pub scene: PathBuf,
    /// The user's `--set` overrides, applied to every variant before its own.
    pub base_overrides: Vec<String>,
    /// The study folder; run `label` writes into `dir/label/`.
    pub dir: PathBuf,
    /// File name of the study CSV inside `dir`.
    pub csv_name: String,
    /// Columns after `label` that the variants fill (their `tags`).
    pub tag_columns: Vec<String>,
    /// Columns after the summary columns that `metrics` fills.
    pub metric_columns: Vec<String>,
    pub metrics: &'a Metrics,
    /// What must be the same for rows already in the folder to be reused (the scene,
    /// the base overrides, a seed): written to `dir/study_inputs.json` and compared on resume.
    pub inputs: serde_json::Value,
    /// Runs at a time.
    pub jobs: usize,
    /// Progress bar over runs.
    pub progress: bool,
    /// What each run writes into `dir/label/`.
    pub outputs: RunOutputs,
}

/// What each run of a study writes into its folder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RunOutputs {
    /// Every output the scene asks for (`output::write_all`).
    All,
    /// Only summary.json (Monte Carlo: hundreds of runs whose maps nobody reads).
    Summary,
}

/// The summary columns every study CSV has, after the label and the tags.
pub const SUMMARY_COLUMNS: [&str; 11] = [
    "spacing_m",
    "rotation_deg",
    "offset_x_m",
    "offset_y_m",
    "particles",
    "peak_force_N",
    "displacement_at_peak_m",
    "dissipated_energy_J",
    "wall_time_s",
    "total_time_s",
    "status",
];

/// One row of a study CSV: the run's label, tags, summary values and metrics.
#[derive(Clone, Debug, Serialize)]
pub struct RunRow {
    pub label: String,
    pub tags: Vec<String>,
    pub spacing_m: f64,
    pub rotation_deg: f64,
    pub offset_m: [f64; 2],
    pub particles: usize,
    #[serde(rename = "peak_force_N")]
    pub peak_force_n: f64,
    pub displacement_at_peak_m: f64,
    #[serde(rename = "dissipated_energy_J")]
    pub dissipated_energy_j: f64,
    /// Time of the explicit run (summary.json's wall_time_s).
    pub wall_time_s: f64,
    /// Time of set-up, run and outputs together.
    pub total_time_s: f64,
    /// "completed", "unstable", or "error" (the run could not be set up).
    pub status: String,
    pub metrics: Vec<f64>,
    pub message: String,
}

impl RunRow {
    pub fn completed(&self) -> bool {
        self.status == "completed"
    }
}

/// A run's row and its force–displacement curve (displacement m, force N) for overlays.
#[derive(Clone, Debug)]
pub struct RunResult {
    pub row: RunRow,
    pub curve: Vec<(f64, f64)>,
}

impl Study<'_> {
    fn header(&self) -> Vec<String> {
        let mut h = vec!["label".to_string()];
        h.extend(self.tag_columns.iter().cloned());
        h.extend(SUMMARY_COLUMNS.iter().map(|s| s.to_string()));
        h.extend(self.metric_columns.iter().cloned());
        h.push("message".into());
        h
    }

    fn csv_path(&self) -> PathBuf {
        self.dir.join(&self.csv_name)
    }

    fn record(&self, r: &RunRow) -> Vec<String> {
        let mut v = vec![r.label.clone()];
        v.extend(r.tags.iter().cloned());
        v.extend([
            r.spacing_m.to_string(),
            r.rotation_deg.to_string(),
            r.offset_m[0].to_string(),
            r.offset_m[1].to_string(),
            r.particles.to_string(),
            r.peak_force_n.to_string(),
            r.displacement_at_peak_m.to_string(),
            r.dissipated_energy_j.to_string(),
            r.wall_time_s.to_string(),
            r.total_time_s.to_string(),
            r.status.clone(),
        ]);
        v.extend(r.metrics.iter().map(|m| m.to_string()));
        v.push(r.message.clone());
        v
    }

    /// The rows already in the study CSV (none if it does not exist). A last line cut
    /// short by an interruption is dropped from the file.
    pub fn read_rows(&self) -> anyhow::Result<Vec<RunRow>> {
        let path = self.csv_path();
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(vec![]),
            Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
        };
        if !text.is_empty() && !text.ends_with('\n') {
            let keep = text.rfind('\n').map(|i| i + 1).unwrap_or(0);
            std::fs::write(&path, &text[..keep])
                .with_context(|| format!("cannot repair {}", path.display()))?;
            return self.read_rows();
        }
        if text.is_empty() {
            return Ok(vec![]);
        }
        let mut rd = csv::ReaderBuilder::new().from_reader(text.as_bytes());
        let header: Vec<String> = rd
            .headers()
            .with_context(|| format!("cannot read the header of {}", path.display()))?
            .iter()
            .map(String::from)
            .collect();
        if header != self.header() {
            bail!(
                "{} has the columns {:?}, this study writes {:?}: use another --out folder or remove it",
                path.display(),
                header.join(","),
                self.header().join(",")
            );
        }
        let nt = self.tag_columns.len();
        let nm = self.metric_columns.len();
        let mut rows = Vec::new();
        for (k, rec) in rd.records().enumerate() {
            let rec = rec.with_context(|| format!("{} row {}", path.display(), k + 2))?;
            let num = |i: usize| -> anyhow::Result<f64> {
                let s = &rec[i];
                s.parse::<f64>().with_context(|| {
                    format!(
                        "{} row {}, column {}: `{s}` is not a number",
                        path.display(),
                        k + 2,
                        header[i]
                    )
                })
            };
            let b = 1 + nt;
            rows.push(RunRow {
                label: rec[0].to_string(),
                tags: (1..b).map(|i| rec[i].to_string()).collect(),
                spacing_m: num(b)?,
                rotation_deg: num(b + 1)?,
                offset_m: [num(b + 2)?, num(b + 3)?],
                particles: num(b + 4)? as usize,
                peak_force_n: num(b + 5)?,
                displacement_at_peak_m: num(b + 6)?,
                dissipated_energy_j: num(b + 7)?,
                wall_time_s: num(b + 8)?,
                total_time_s: num(b + 9)?,
                status: rec[b + 10].to_string(),
                metrics: (0..nm)
                    .map(|i| num(b + 11 + i))
                    .collect::<anyhow::Result<_>>()?,
                message: rec[b + 11 + nm].to_string(),
            });
        }
        Ok(rows)
    }

    /// Write `rows` as a fresh study CSV (replacing the file), in this study's layout.
    pub fn write_rows(&self, rows: &[RunRow]) -> anyhow::Result<()> {
        std::fs::create_dir_all(&self.dir)
            .with_context(|| format!("cannot create the study folder {}", self.dir.display()))?;
        let path = self.csv_path();
        let mut w = csv::Writer::from_path(&path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        w.write_record(self.header())?;
        for r in rows {
            w.write_record(self.record(r))?;
        }
        w.flush()
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(())
    }

    /// Refuse a folder that holds rows of a study with other inputs; record ours.
    fn check_inputs(&self) -> anyhow::Result<()> {
        let path = self.dir.join("study_inputs.json");
        if let Ok(text) = std::fs::read_to_string(&path) {
            let old: serde_json::Value = serde_json::from_str(&text)
                .with_context(|| format!("cannot read {}", path.display()))?;
            if old != self.inputs && self.csv_path().exists() {
                bail!(
                    "{} holds a study with other inputs ({old}); this one has {}: use another --out folder or remove it",
                    self.dir.display(),
                    self.inputs
                );
            }
        }
        std::fs::write(&path, serde_json::to_string_pretty(&self.inputs)? + "\n")
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(())
    }

    /// The scene of a variant (base overrides, then the variant's).
    pub fn scene_of(&self, v: &Variant) -> anyhow::Result<Scene> {
        let mut o = self.base_overrides.clone();
        o.extend(v.overrides.iter().cloned());
        Ok(Scene::from_file(&self.scene, &o)?)
    }

    fn run_one(&self, v: &Variant, scene: &Scene) -> anyhow::Result<RunRow> {
        let start = Instant::now();
        let d = &scene.discretisation;
        let mut row = RunRow {
            label: v.label.clone(),
            tags: v.tags.clone(),
            spacing_m: d.spacing,
            rotation_deg: d.rotation_deg,
            offset_m: d.offset,
            particles: 0,
            peak_force_n: f64::NAN,
            displacement_at_peak_m: f64::NAN,
            dissipated_energy_j: f64::NAN,
            wall_time_s: f64::NAN,
            total_time_s: f64::NAN,
            status: "error".into(),
            metrics: vec![f64::NAN; self.metric_columns.len()],
            message: String::new(),
        };
        let opts = RunOptions {
            progress: false,
            threads: Some(1),
        };
        match crate::run(scene, &opts) {
            Ok(outcome) => {
                let dir = self.dir.join(&v.label);
                match self.outputs {
                    RunOutputs::All => {
                        crate::output::write_all(&outcome, &dir)?;
                    }
                    RunOutputs::Summary => write_summary(&outcome, &dir)?,
                }
                let s = &outcome.summary;
                row.particles = s.particles;
                row.peak_force_n = s.peak_force_n;
                row.displacement_at_peak_m = s.displacement_at_peak_m;
                row.dissipated_energy_j = s.dissipated_energy_j;
                row.wall_time_s = s.wall_time_s;
                row.status = s.status.clone();
                row.message = s.message.clone().unwrap_or_default();
                row.metrics = (self.metrics)(&outcome);
                anyhow::ensure!(
                    row.metrics.len() == self.metric_columns.len(),
                    "study metrics: {} values for {} columns",
                    row.metrics.len(),
                    self.metric_columns.len()
                );
            }
            Err(e) => row.message = e.to_string(),
        }
        row.total_time_s = start.elapsed().as_secs_f64();
        Ok(row)
    }

    /// Run every variant that has no row yet, `jobs` at a time, appending each row as its
    /// run finishes; then return all variants' rows (in the order given) with their curves.
    pub fn run(&self, variants: &[Variant]) -> anyhow::Result<Vec<RunResult>> {
        let mut seen = std::collections::HashSet::new();
        for v in variants {
            if v.label.is_empty()
                || v.label.contains(['/', '\\', ',', '"', '\n'])
                || v.label.starts_with('.')
            {
                bail!(
                    "study variant label `{}`: a plain file name is needed",
                    v.label
                );
            }
            if !seen.insert(v.label.as_str()) {
                bail!("study variant label `{}` appears twice", v.label);
            }
            if v.tags.len() != self.tag_columns.len() {
                bail!(
                    "study variant `{}`: {} tags for {} tag columns",
                    v.label,
                    v.tags.len(),
                    self.tag_columns.len()
                );
            }
        }
        // every scene is read before anything runs: bad input stops the study at once
        let scenes: Vec<Scene> = variants
            .iter()
            .map(|v| {
                self.scene_of(v)
                    .with_context(|| format!("study variant {}", v.label))
            })
            .collect::<anyhow::Result<_>>()?;
        std::fs::create_dir_all(&self.dir)
            .with_context(|| format!("cannot create the study folder {}", self.dir.display()))?;
        self.check_inputs()?;
        let done: std::collections::HashSet<String> =
            self.read_rows()?.into_iter().map(|r| r.label).collect();
        let pending: Vec<(&Variant, &Scene)> = variants
            .iter()
            .zip(&scenes)
            .filter(|(v, _)| !done.contains(&v.label))
            .collect();

        let path = self.csv_path();
        let fresh = !path.exists() || std::fs::metadata(&path)?.len() == 0;
        let file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .with_context(|| format!("cannot open {}", path.display()))?;
        let mut writer = csv::WriterBuilder::new().from_writer(file);
        if fresh {
            writer.write_record(self.header())?;
            writer.flush()?;
        }
        let writer = Mutex::new(writer);
        let bar = if self.progress && !pending.is_empty() {
            let b = indicatif::ProgressBar::new(pending.len() as u64);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{spinner} {wide_bar} {pos}/{len} runs  {elapsed_precise} ETA {eta}  {msg}",
                )
                .unwrap(),
            );
            if !done.is_empty() {
                b.println(format!(
                    "{} of {} runs already in {}",
                    variants.len() - pending.len(),
                    variants.len(),
                    path.display()
                ));
            }
            Some(b)
        } else {
            None
        };
        // `jobs` worker threads take the pending runs in order. (Not a rayon pool: a rayon
        // worker waiting for a run's own pool would steal further runs, and more than `jobs`
        // runs would go at once.)
        let next = std::sync::atomic::AtomicUsize::new(0);
        let first_error: Mutex<Option<anyhow::Error>> = Mutex::new(None);
        let work = || loop {
            if first_error.lock().unwrap().is_some() {
                return;
            }
            let k = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            let Some((v, scene)) = pending.get(k) else {
                return;
            };
            let result = self.run_one(v, scene).and_then(|row| {
                let mut w = writer.lock().unwrap();
                w.write_record(self.record(&row))?;
                w.flush()
                    .with_context(|| format!("cannot write {}", path.display()))?;
                Ok(row)
            });
            match result {
                Ok(row) => {
                    if let Some(b) = &bar {
                        b.set_message(format!("{} {}", row.label, row.status));
                        b.inc(1);
                    }
                }
                Err(e) => {
                    first_error.lock().unwrap().get_or_insert(e);
                    return;
                }
            }
        };
        std::thread::scope(|s| {
            for _ in 0..self.jobs.max(1).min(pending.len().max(1)) {
                s.spawn(work);
            }
        });
        if let Some(e) = first_error.into_inner().unwrap() {
            return Err(e);
        }
        if let Some(b) = bar {
            b.finish_and_clear();
        }
        drop(writer);

        let rows: HashMap<String, RunRow> = self
            .read_rows()?
            .into_iter()
            .map(|r| (r.label.clone(), r))
            .collect();
        variants
            .iter()
            .map(|v| {
                let row = rows
                    .get(&v.label)
                    .cloned()
                    .with_context(|| format!("{} has no row {}", path.display(), v.label))?;
                let curve = read_curve(&self.dir.join(&v.label).join("force_displacement.csv"))
                    .unwrap_or_default();
                Ok(RunResult { row, curve })
            })
            .collect()
    }
}

/// Write only a run's summary.json into `dir`.
fn write_summary(outcome: &Outcome, dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the output folder {}", dir.display()))?;
    let path = dir.join("summary.json");
    std::fs::write(
        &path,
        serde_json::to_string_pretty(&outcome.summary)? + "\n",
    )
    .with_context(|| format!("cannot write {}", path.display()))
}

/// (displacement_m, force_N) of a run's force_displacement.csv.
pub fn read_curve(path: &Path) -> anyhow::Result<Vec<(f64, f64)>> {
    let mut rd = csv::Reader::from_path(path)?;
    let h = rd.headers()?.clone();
    let col = |name: &str| {
        h.iter()
            .position(|c| c == name)
            .with_context(|| format!("{} has no column {name}", path.display()))
    };
    let (iu, iforce) = (col("displacement_m")?, col("force_N")?);
    let mut out = Vec::new();
    for rec in rd.records() {
        let rec = rec?;
        out.push((rec[iu].parse()?, rec[iforce].parse()?));
    }
    Ok(out)
}

/// The default number of runs at a time: the machine's cores.
pub fn default_jobs() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
}
