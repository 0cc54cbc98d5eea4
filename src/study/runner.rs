//! A parallel runner of scene variants, reusable by every study: each variant is the
//! scene file with the user's `--set` overrides and its own extra `key=value` overrides.
//! Runs go in parallel across variants (`jobs` at a time, each run on one thread), each
//! writes its outputs into `<study dir>/<label>/`, and its row is appended to the study
//! CSV and flushed as soon as it finishes. Started again, the runner skips every variant
//! whose label already has a row (resume) and reads those rows back, so an interrupted
//! study loses nothing. A run that goes unstable (or cannot be set up) is a row with its
//! status, not the end of the study.
//!
//! - **Lazy runs.** A study gives the runner a count and a function from an index to a
//!   variant ([`Runs`]); the variants are made when a worker takes them, never listed up
//!   front. The scenes of the first, the last and one variant of each kind ([`Runs::probes`])
//!   are read before anything runs, so bad input still stops the study at once.
//! - **Memory.** A study keeps about [`Study::bytes_per_run`] per run (its row, read back
//!   for the report, and its curve); the studies check their counts against the memory
//!   budget ([`crate::limits`]) before anything is made.
//! - **One study per folder.** [`Study::run`] needs the folder's [`FolderLock`], which the
//!   study takes for its whole length: a second study started into the same folder is
//!   refused with [`crate::fsio::FolderBusy`].
//! - **Inputs record.** `study_inputs.json` records what the rows depend on; a folder whose
//!   rows were made with other inputs, or that holds study rows but no inputs record, is
//!   refused, never adopted ([`Study::check_inputs`]).

use crate::fsio::{self, FolderLock, IoFailure};
use crate::run::{Outcome, RunOptions};
use crate::Scene;
use anyhow::{bail, Context};
use serde::Serialize;
use std::collections::{HashMap, HashSet};
use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

/// The record of a study's inputs in its folder.
pub const INPUTS_FILE: &str = "study_inputs.json";

/// Memory one run of a study takes while the study runs and reports, besides its curve:
/// its row (about 450 bytes with its label, tags, status and message) read back from the
/// CSV, moved into the result list and copied into the study's report, its label in the
/// done and uniqueness sets, with the maps' overhead.
pub const ROW_BYTES: f64 = 2048.0;

/// Memory per point of a run's force–displacement curve kept for the overlay plot: the
/// (displacement, force) pair and the plot's text of it.
pub const CURVE_POINT_BYTES: f64 = 64.0;

/// The runs of a study, made one at a time from their index (never listed up front).
pub struct Runs<'a> {
    pub count: usize,
    /// Variant of run `k` (0 ≤ k < count), in the order the runs are taken.
    pub variant: &'a (dyn Fn(usize) -> Variant + Sync),
    /// Runs whose scenes are read before anything runs, besides the first and the last:
    /// one of each kind (an angle, a size), so that bad input stops the study at once.
    pub probes: Vec<usize>,
}

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

/// A note on a run's metrics ([`Study::notes`]).
pub type Notes = dyn Fn(&Outcome) -> Option<String> + Sync;

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
    /// A note on a completed run's metrics (why one is not measured), added to its message.
    pub notes: Option<&'a Notes>,
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
        // a metric not measured (NaN: no crack to fit, no σN) is an empty cell
        v.extend(r.metrics.iter().map(|m| {
            if m.is_nan() {
                String::new()
            } else {
                m.to_string()
            }
        }));
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
            Err(e) => return Err(IoFailure::new("read", &path, e).into()),
        };
        if !text.is_empty() && !text.ends_with('\n') {
            let keep = text.rfind('\n').map(|i| i + 1).unwrap_or(0);
            fsio::write_atomic(&path, &text.as_bytes()[..keep])?;
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
                    .map(|i| match rec[b + 11 + i].is_empty() {
                        true => Ok(f64::NAN),
                        false => num(b + 11 + i),
                    })
                    .collect::<anyhow::Result<_>>()?,
                message: rec[b + 11 + nm].to_string(),
            });
        }
        Ok(rows)
    }

    /// Write `rows` as a fresh study CSV (replacing the file), in this study's layout.
    pub fn write_rows(&self, rows: &[RunRow]) -> anyhow::Result<()> {
        std::fs::create_dir_all(&self.dir)
            .map_err(|e| IoFailure::new("create the study folder", &self.dir, e))?;
        fsio::write_with(&self.csv_path(), |tmp: &Path| -> anyhow::Result<()> {
            let mut w = csv::Writer::from_path(tmp)?;
            w.write_record(self.header())?;
            for r in rows {
                w.write_record(self.record(r))?;
            }
            w.flush()?;
            Ok(())
        })?;
        Ok(())
    }

    /// Refuse a folder that holds study rows made with other inputs, or study rows without
    /// an inputs record (whose inputs nobody knows); record ours in `study_inputs.json`.
    pub fn check_inputs(&self) -> anyhow::Result<()> {
        let path = self.dir.join(INPUTS_FILE);
        match std::fs::read_to_string(&path) {
            Ok(text) => {
                let old: serde_json::Value = serde_json::from_str(&text)
                    .with_context(|| format!("cannot read {}", path.display()))?;
                if old != self.inputs && study_rows_in(&self.dir)?.is_some() {
                    bail!(
                        "{} holds a study with other inputs ({old}); this one has {}: use another --out folder or remove it",
                        self.dir.display(),
                        self.inputs
                    );
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                if let Some((csv, rows)) = study_rows_in(&self.dir)? {
                    bail!("{}", no_inputs_record(&self.dir, &csv, rows));
                }
            }
            Err(e) => return Err(IoFailure::new("read", &path, e).into()),
        }
        fsio::write_json(&path, &self.inputs)?;
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
            rotation_deg: d.rotation_deg.single_angle(),
            offset_m: d.offset2(),
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
                    RunOutputs::Summary => crate::output::write_summary(&outcome, &dir)?,
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
                if let Some(note) = self.notes.and_then(|n| n(&outcome)) {
                    row.message = match row.message.is_empty() {
                        true => note,
                        false => format!("{}; {note}", row.message),
                    };
                }
            }
            Err(e) => row.message = e.to_string(),
        }
        row.total_time_s = start.elapsed().as_secs_f64();
        Ok(row)
    }

    /// Memory the study keeps per run ([`ROW_BYTES`], and the curve of a run of `scene`
    /// when every output is written and the curves are read back for the overlay).
    pub fn bytes_per_run(&self, scene: &Scene) -> f64 {
        match self.outputs {
            RunOutputs::All => ROW_BYTES + (scene.output.records + 2) as f64 * CURVE_POINT_BYTES,
            RunOutputs::Summary => ROW_BYTES,
        }
    }

    /// A variant's label and tags as this study needs them.
    fn check_variant(&self, v: &Variant) -> anyhow::Result<()> {
        if v.label.is_empty()
            || v.label.contains(['/', '\\', ',', '"', '\n'])
            || v.label.starts_with('.')
        {
            bail!(
                "study variant label `{}`: a plain file name is needed",
                v.label
            );
        }
        if v.tags.len() != self.tag_columns.len() {
            bail!(
                "study variant `{}`: {} tags for {} tag columns",
                v.label,
                v.tags.len(),
                self.tag_columns.len()
            );
        }
        Ok(())
    }

    /// Read the scenes of the first, the last and the probe runs: bad input stops the study
    /// here, before anything runs (and before the study folder is made).
    pub fn check(&self, runs: &Runs) -> anyhow::Result<()> {
        if runs.count == 0 {
            return Ok(());
        }
        let mut probes = vec![0, runs.count - 1];
        probes.extend(runs.probes.iter().copied());
        probes.sort_unstable();
        probes.dedup();
        for k in probes {
            anyhow::ensure!(k < runs.count, "study probe run {k} of {} runs", runs.count);
            let v = (runs.variant)(k);
            self.check_variant(&v)?;
            self.scene_of(&v)
                .with_context(|| format!("study variant {}", v.label))?;
        }
        Ok(())
    }

    /// Run every variant that has no row yet, `jobs` at a time, appending each row as its
    /// run finishes; then return all variants' rows (in the order given) with their curves.
    /// `lock` is the study folder's lock, held by the caller for the whole study; the caller
    /// has read the probe scenes ([`Study::check`]) and checked its count against the memory
    /// budget before it took the lock (and so made the folder).
    pub fn run(&self, lock: &FolderLock, runs: &Runs) -> anyhow::Result<Vec<RunResult>> {
        anyhow::ensure!(
            lock.path() == self.dir.join(fsio::LOCK_FILE),
            "the study in {} runs under the lock {}",
            self.dir.display(),
            lock.path().display()
        );
        let count = runs.count;
        self.check_inputs()?;
        let done: HashSet<String> = self.read_rows()?.into_iter().map(|r| r.label).collect();
        // one pass over the labels (made, checked and dropped one at a time): each once,
        // and how many runs are still to do
        let mut pending = 0usize;
        {
            let mut seen = HashSet::new();
            for k in 0..count {
                let v = (runs.variant)(k);
                self.check_variant(&v)?;
                if !done.contains(&v.label) {
                    pending += 1;
                }
                if let Some(label) = seen.replace(v.label) {
                    bail!("study variant label `{label}` appears twice");
                }
            }
        }

        let path = self.csv_path();
        let fresh = std::fs::metadata(&path)
            .map(|m| m.len() == 0)
            .unwrap_or(true);
        let file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(|e| IoFailure::new("open", &path, e))?;
        let mut writer = csv::WriterBuilder::new().from_writer(file);
        let append = |w: &mut csv::Writer<std::fs::File>, record: Vec<String>| {
            w.write_record(record)
                .map_err(|e| fsio::csv_failure(&path, e))
                .and_then(|()| w.flush().map_err(|e| IoFailure::new("write", &path, e)))
        };
        if fresh {
            append(&mut writer, self.header())?;
        }
        let writer = Mutex::new(writer);
        let bar = if self.progress && pending > 0 {
            let b = indicatif::ProgressBar::new(pending as u64);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{spinner} {wide_bar} {pos}/{len} runs  {elapsed_precise} ETA {eta}  {msg}",
                )
                .unwrap(),
            );
            if pending < count {
                b.println(format!(
                    "{} of {} runs already in {}",
                    count - pending,
                    count,
                    path.display()
                ));
            }
            Some(b)
        } else {
            None
        };
        // `jobs` worker threads take the runs in order, each made when it is taken and
        // skipped if it has a row. (Not a rayon pool: a rayon worker waiting for a run's own
        // pool would steal further runs, and more than `jobs` runs would go at once.)
        let next = std::sync::atomic::AtomicUsize::new(0);
        let first_error: Mutex<Option<anyhow::Error>> = Mutex::new(None);
        let work = || loop {
            if first_error.lock().unwrap().is_some() {
                return;
            }
            let k = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            if k >= count {
                return;
            }
            let v = (runs.variant)(k);
            if done.contains(&v.label) {
                continue;
            }
            let result = self
                .scene_of(&v)
                .with_context(|| format!("study variant {}", v.label))
                .and_then(|scene| self.run_one(&v, &scene))
                .and_then(|row| {
                    append(&mut writer.lock().unwrap(), self.record(&row))?;
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
            for _ in 0..self.jobs.max(1).min(pending.max(1)) {
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
        drop(done);

        let mut rows: HashMap<String, RunRow> = self
            .read_rows()?
            .into_iter()
            .map(|r| (r.label.clone(), r))
            .collect();
        let mut results = Vec::new();
        for k in 0..count {
            let v = (runs.variant)(k);
            let row = rows
                .remove(&v.label)
                .with_context(|| format!("{} has no row {}", path.display(), v.label))?;
            let curve = match self.outputs {
                RunOutputs::All => {
                    read_curve(&self.dir.join(&v.label).join("force_displacement.csv"))
                        .unwrap_or_default()
                }
                RunOutputs::Summary => vec![],
            };
            results.push(RunResult { row, curve });
        }
        Ok(results)
    }
}

/// The first study CSV in `dir` (a `*.csv` whose header starts with `label,`) that holds
/// rows, and its number of rows.
pub fn study_rows_in(dir: &Path) -> anyhow::Result<Option<(PathBuf, usize)>> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(IoFailure::new("read the folder", dir, e).into()),
    };
    let mut names: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "csv") && p.is_file())
        .collect();
    names.sort();
    for path in names {
        let file = std::fs::File::open(&path).map_err(|e| IoFailure::new("read", &path, e))?;
        let mut lines = std::io::BufReader::new(file).lines();
        match lines.next() {
            Some(Ok(h)) if h.starts_with("label,") => {}
            _ => continue,
        }
        let rows = lines
            .map_while(Result::ok)
            .filter(|l| !l.trim().is_empty())
            .count();
        if rows > 0 {
            return Ok(Some((path, rows)));
        }
    }
    Ok(None)
}

/// Why a folder with study rows but no inputs record is refused.
pub fn no_inputs_record(dir: &Path, csv: &Path, rows: usize) -> String {
    format!(
        "{} holds study rows ({rows} in {}) but no {INPUTS_FILE}, the record of the inputs (scene, overrides, seed) they were made with, so sppm cannot tell whether they belong to this study and does not adopt them: use another --out folder, or remove the folder's study CSVs (or the whole folder {}) to start afresh",
        dir.display(),
        csv.display(),
        dir.display()
    )
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
