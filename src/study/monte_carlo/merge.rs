//! `sppm study merge`: shard folders of one Monte Carlo study combined into one folder, its
//! rows checked against what each folder's command asked for (study_request.json).

use super::records::{write_record, StudyInputs, StudyRequest, TaggedRow, MONTE_CARLO};
use super::shards::{parse_shard, Shard, ShardRuns};
use super::{studies, REQUEST_FILE, SPACING_RULE};
use crate::study::runner::{self, RunOutputs, RunRow};
use crate::study::size_effect_report::{report, size_um, SizeEffect};
use anyhow::{bail, Context};
use serde_json::json;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// What `sppm study merge` did: the size effect, what the folders lack against what their
/// commands asked for (empty: the whole study), and the counts of runs.
pub struct MergeReport {
    pub effect: SizeEffect,
    pub missing: Vec<String>,
    /// Notes on folders whose request is not recorded (made by an older sppm).
    pub notes: Vec<String>,
    pub runs: usize,
    pub completed: usize,
}

/// Combine shard folders of one study into `out` (default: output/<scene>-montecarlo/):
/// realisations.csv, deterministic.csv, study_inputs.json (without the shard) and the
/// size-effect report. Folders of the same study at other sizes (another `--sizes`) combine
/// too: a realisation's seed depends on (S, D, r) only, so e.g. the small sizes at N = 100 and
/// the largest at fewer realisations make one report. Duplicate runs with the same seed are
/// kept once; the same run with different seeds, or folders of different studies (scene,
/// overrides, seed), are an error.
///
/// The folders must hold every run their commands asked for (study_request.json: the
/// realisations, sizes and shard): a missing shard, a shard that has not finished, or a
/// size with fewer realisations than asked is named and refused, unless `partial`, which
/// writes the report of the runs there are and records in size_effect.json that it is
/// partial and what is missing.
pub fn merge(dirs: &[PathBuf], out: Option<PathBuf>, partial: bool) -> anyhow::Result<MergeReport> {
    if dirs.is_empty() {
        bail!("merge: give at least one shard folder");
    }
    let (study, mut folders) = read_folders(dirs)?;
    let mut sizes: Vec<f64> = folders.iter().flat_map(|f| f.sizes.clone()).collect();
    sizes.sort_by(f64::total_cmp);
    sizes.dedup_by(|a, b| size_um(*a) == size_um(*b));
    let inputs = StudyInputs {
        sizes_m: Some(sizes.clone()),
        ..study
    };
    let out = out.unwrap_or_else(|| {
        PathBuf::from("output").join(format!("{}-montecarlo", inputs.scene_name))
    });
    check_merge_out(&out, &inputs)?;
    let mut merged = Merged::default();
    let mut folder_missing = Vec::new();
    let mut notes = Vec::new();
    for f in &mut folders {
        let held = merged.add(f, &inputs)?;
        folder_missing.extend(f.missing(held, &mut notes));
    }
    let size_missing = merged.missing(&sizes, &folders);
    let mut missing = Vec::new();
    if !folder_missing.is_empty() || !size_missing.is_empty() {
        missing.extend(shards_not_given(&folders));
        missing.extend(folder_missing);
        missing.extend(size_missing);
    }
    if !missing.is_empty() && !partial {
        bail!(
            "merge: the folders do not hold the whole study: {}. Give the missing shard folders (or finish a shard by running its command again), or add --partial to write the report of the runs there are",
            missing.join("; ")
        );
    }
    let (effect, runs, completed) = write_merged(&out, dirs, &folders, merged, &inputs, &missing)?;
    Ok(MergeReport {
        effect,
        missing,
        notes,
        runs,
        completed,
    })
}

/// One folder given to the merge: its inputs record, and what its command asked for.
struct Folder {
    dir: PathBuf,
    /// Its sizes D (m), from study_inputs.json.
    sizes: Vec<f64>,
    shard: Option<Shard>,
    /// The realisations asked for (study_request.json); `None` for a folder of an older
    /// sppm, until [`Folder::missing`] takes them from its rows.
    realisations: Option<usize>,
}

/// The folders, read in the order given, each checked to be of the same study as the first;
/// and that study's inputs ([`StudyInputs::identity`]).
fn read_folders(dirs: &[PathBuf]) -> anyhow::Result<(StudyInputs, Vec<Folder>)> {
    let mut common: Option<(StudyInputs, PathBuf)> = None;
    let mut folders = Vec::new();
    for d in dirs {
        let path = d.join(runner::INPUTS_FILE);
        let inputs = read_inputs(d, &path)?;
        let shard = match &inputs.shard {
            Some(t) => Some(parse_shard(t).with_context(|| format!("{}: shard", path.display()))?),
            None => None,
        };
        let realisations = read_request(&d.join(REQUEST_FILE))?.map(|r| r.realisations);
        let identity = inputs.identity();
        folders.push(Folder {
            dir: d.clone(),
            sizes: inputs.sizes_m.unwrap_or_default(),
            shard,
            realisations,
        });
        match &common {
            None => common = Some((identity, path)),
            Some((c, first)) if *c != identity => bail!(
                "{} and {} are from different studies (their study_inputs.json differ beyond the shard): {} against {}",
                first.display(),
                path.display(),
                c.value(),
                identity.value()
            ),
            _ => {}
        }
    }
    let (study, _) = common.expect("at least one folder");
    Ok((study, folders))
}

/// The study_inputs.json of folder `dir` at `path`, of a Monte Carlo study.
fn read_inputs(dir: &Path, path: &Path) -> anyhow::Result<StudyInputs> {
    let text = std::fs::read_to_string(path).with_context(|| {
        format!(
            "cannot read {} (is {} a Monte Carlo study folder?)",
            path.display(),
            dir.display()
        )
    })?;
    let v: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("cannot read {}", path.display()))?;
    if v.get("study").and_then(|s| s.as_str()) != Some(MONTE_CARLO) {
        bail!("{} is not from a Monte Carlo study", path.display());
    }
    serde_json::from_value(v).with_context(|| format!("cannot read {}", path.display()))
}

/// A folder's study_request.json; `None` if it has none (a folder of an older sppm).
fn read_request(path: &Path) -> anyhow::Result<Option<StudyRequest>> {
    match std::fs::read_to_string(path) {
        Ok(t) => {
            Ok(Some(serde_json::from_str(&t).with_context(|| {
                format!("cannot read {}", path.display())
            })?))
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(crate::fsio::IoFailure::new("read", path, e).into()),
    }
}

/// Refuse to merge into `out` when it holds another study, or study rows without an inputs
/// record.
fn check_merge_out(out: &Path, inputs: &StudyInputs) -> anyhow::Result<()> {
    let path = out.join(runner::INPUTS_FILE);
    match std::fs::read_to_string(&path) {
        Ok(text) => {
            let old: serde_json::Value = serde_json::from_str(&text).unwrap_or_default();
            let same = serde_json::from_value::<StudyInputs>(old.clone())
                .is_ok_and(|o| o.unsharded() == *inputs);
            if !same {
                bail!(
                    "{} holds another study ({old}); the shards are from {}: use another --out folder or remove it",
                    out.display(),
                    inputs.value()
                );
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            if let Some((csv, rows)) = runner::study_rows_in(out)? {
                bail!("{}", runner::no_inputs_record(out, &csv, rows));
            }
        }
        Err(e) => return Err(crate::fsio::IoFailure::new("read", &path, e).into()),
    }
    Ok(())
}

/// What one folder holds of one size: its realisations, and whether its deterministic run.
#[derive(Default)]
struct Held {
    realisations: BTreeSet<usize>,
    deterministic: bool,
}

/// The rows of the folders by label, each run once: realisations and deterministic runs.
#[derive(Default)]
struct Merged {
    realisations: BTreeMap<String, TaggedRow>,
    deterministic: BTreeMap<String, TaggedRow>,
}

impl Merged {
    /// Add the rows of folder `f`; what it holds per size (µm). The same run with another
    /// seed is an error.
    fn add(&mut self, f: &Folder, inputs: &StudyInputs) -> anyhow::Result<BTreeMap<u64, Held>> {
        let scene = PathBuf::from(&inputs.scene);
        let (mc, det) = studies(
            &scene,
            &inputs.overrides,
            &f.dir,
            inputs,
            1,
            false,
            RunOutputs::Summary,
        );
        let mut held: BTreeMap<u64, Held> = BTreeMap::new();
        for row in mc.read_rows()? {
            let row = TaggedRow::realisation(row);
            let entry = held.entry(row.size_um).or_default();
            entry.realisations.extend(row.realisation);
            keep_once(&mut self.realisations, row, &f.dir)?;
        }
        for row in det.read_rows()? {
            let row = TaggedRow::deterministic(row);
            held.entry(row.size_um).or_default().deterministic = true;
            keep_once(&mut self.deterministic, row, &f.dir)?;
        }
        Ok(held)
    }

    /// Per size: the realisations the folders asked for (the most any asked), against the
    /// distinct realisations there are; and a deterministic run.
    fn missing(&self, sizes: &[f64], folders: &[Folder]) -> Vec<String> {
        let mut missing = Vec::new();
        for &dm in sizes {
            let um = size_um(dm);
            let want = folders
                .iter()
                .filter(|f| f.sizes.iter().any(|x| size_um(*x) == um))
                .map(|f| f.realisations.unwrap_or(0))
                .max()
                .unwrap_or(0);
            let got = self
                .realisations
                .values()
                .filter(|r| r.size_um == um)
                .filter(|r| r.realisation.is_some_and(|x| x < want))
                .count();
            if got < want {
                missing.push(format!("D = {dm} m: {got} of {want} realisations"));
            }
            if !self.deterministic.values().any(|r| r.size_um == um) {
                missing.push(format!("D = {dm} m: no deterministic run"));
            }
        }
        missing
    }

    /// The rows: realisations and deterministic runs, by label.
    fn rows(self) -> (Vec<RunRow>, Vec<RunRow>) {
        let rows = |m: BTreeMap<String, TaggedRow>| m.into_values().map(|r| r.row).collect();
        (rows(self.realisations), rows(self.deterministic))
    }
}

/// Keep `row` in `rows` once by its label; the same label with another seed is refused.
fn keep_once(
    rows: &mut BTreeMap<String, TaggedRow>,
    row: TaggedRow,
    dir: &Path,
) -> anyhow::Result<()> {
    match rows.get(&row.row.label) {
        Some(old) if old.seed != row.seed => bail!(
            "run {} appears with seed {} and with seed {} (in {}): the shards do not belong together",
            row.row.label,
            old.seed,
            row.seed,
            dir.display()
        ),
        Some(_) => {}
        None => {
            rows.insert(row.row.label.clone(), row);
        }
    }
    Ok(())
}

impl Folder {
    /// What this folder lacks of what its command asked for, given what it holds. A folder
    /// without a request is taken to have asked for its largest realisation + 1 (noted).
    fn missing(&mut self, mut held: BTreeMap<u64, Held>, notes: &mut Vec<String>) -> Vec<String> {
        let n_asked = match self.realisations {
            Some(n) => n,
            None => {
                let n = held
                    .values()
                    .filter_map(|h| h.realisations.iter().next_back())
                    .max()
                    .map_or(0, |r| r + 1);
                notes.push(format!(
                    "{} has no {REQUEST_FILE} (a folder of an older sppm): the realisations it was asked for are taken as {n}, its largest realisation + 1",
                    self.dir.display()
                ));
                self.realisations = Some(n);
                n
            }
        };
        let plan = ShardRuns::new(&self.sizes, n_asked, self.shard);
        let det_sizes = plan.deterministic();
        let what = format!(
            "{} ({}{} realisations of {})",
            self.dir.display(),
            self.shard
                .map(|s| format!("shard {s}, "))
                .unwrap_or_default(),
            n_asked,
            sizes_text(&self.sizes)
        );
        let mut missing = Vec::new();
        for (i, &dm) in self.sizes.iter().enumerate() {
            let here = held.remove(&size_um(dm)).unwrap_or_default();
            let want = plan.realisations_of(i);
            let got = here.realisations.iter().filter(|&&r| r < n_asked).count() as u128;
            if got < want {
                missing.push(format!(
                    "{what} holds {got} of the {want} realisations of D = {dm} m it was asked for"
                ));
            }
            if det_sizes.contains(&i) && !here.deterministic {
                missing.push(format!("{what} lacks the deterministic run of D = {dm} m"));
            }
        }
        missing
    }
}

/// The shards not given, per study of n shards and its sizes.
fn shards_not_given(folders: &[Folder]) -> Vec<String> {
    // (shard count, sizes in µm) → (sizes, the shard numbers given)
    type Group = (Vec<f64>, BTreeSet<usize>);
    let mut groups: BTreeMap<(usize, Vec<u64>), Group> = BTreeMap::new();
    for f in folders {
        if let Some(sh) = f.shard {
            let key = (sh.n, f.sizes.iter().map(|d| size_um(*d)).collect());
            groups
                .entry(key)
                .or_insert((f.sizes.clone(), Default::default()))
                .1
                .insert(sh.k);
        }
    }
    let mut missing = Vec::new();
    for ((n, _), (s, ks)) in groups {
        let absent: Vec<String> = (1..=n)
            .filter(|k| !ks.contains(k))
            .map(|k| format!("{k}/{n}"))
            .collect();
        if !absent.is_empty() {
            missing.push(format!(
                "shard{} {} of the study of {} not given",
                if absent.len() == 1 { "" } else { "s" },
                absent.join(", "),
                sizes_text(&s)
            ));
        }
    }
    missing
}

/// Write the merged folder `out` under its lock: the two tables, the inputs and request
/// records, and the size-effect report; the effect and the counts of runs and completed runs.
fn write_merged(
    out: &Path,
    dirs: &[PathBuf],
    folders: &[Folder],
    merged: Merged,
    inputs: &StudyInputs,
    missing: &[String],
) -> anyhow::Result<(SizeEffect, usize, usize)> {
    let lock = crate::fsio::FolderLock::acquire(out)?;
    check_merge_out(out, inputs)?;
    let (mc_rows, det_rows) = merged.rows();
    let scene = PathBuf::from(&inputs.scene);
    let (mc, det) = studies(
        &scene,
        &inputs.overrides,
        out,
        inputs,
        1,
        false,
        RunOutputs::Summary,
    );
    mc.write_rows(&mc_rows)?;
    det.write_rows(&det_rows)?;
    write_record(&out.join(runner::INPUTS_FILE), inputs)?;
    let per_size = mc_rows
        .iter()
        .fold(BTreeMap::<u64, usize>::new(), |mut m, r| {
            *m.entry(size_um(crate::study::size_effect_report::tag_f64(r, 0)))
                .or_default() += 1;
            m
        });
    let realisations = per_size.values().copied().max().unwrap_or(0);
    let request = StudyRequest {
        realisations: folders
            .iter()
            .filter_map(|f| f.realisations)
            .max()
            .unwrap_or(0),
        sizes_m: inputs.sizes_m.clone().unwrap_or_default(),
        shard: None,
    };
    write_record(&out.join(REQUEST_FILE), &request)?;
    let scene_name = &inputs.scene_name;
    let meta = json!({
        "scene": inputs.scene,
        "scene_name": scene_name,
        "seed": inputs.seed,
        "realisations": realisations,
        "spacing_rule": SPACING_RULE,
        "scene_size_m": inputs.scene_size_m,
        "scene_spacing_m": inputs.scene_spacing_m,
        "overrides": inputs.overrides,
        "merged_from": dirs.iter().map(|d| d.display().to_string()).collect::<Vec<_>>(),
        "partial": !missing.is_empty(),
        "missing": missing,
    });
    let fewest = per_size.values().copied().min().unwrap_or(0);
    let mut title = if fewest == realisations {
        format!("{scene_name}: size effect, {realisations} realisations")
    } else {
        format!("{scene_name}: size effect, {fewest}–{realisations} realisations per size")
    };
    if !missing.is_empty() {
        title.push_str(" (partial)");
    }
    let effect = report(out, &mc_rows, &det_rows, meta, &title)?;
    drop(lock);
    let runs = mc_rows.len() + det_rows.len();
    let completed = mc_rows
        .iter()
        .chain(&det_rows)
        .filter(|r| r.completed())
        .count();
    Ok((effect, runs, completed))
}

/// A list of sizes as the messages write it: "0.05, 0.1 m".
fn sizes_text(sizes: &[f64]) -> String {
    let v: Vec<String> = sizes.iter().map(|d| d.to_string()).collect();
    format!("{} m", v.join(", "))
}
