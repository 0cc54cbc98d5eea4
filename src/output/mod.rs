//! Reports of a run (docs/architecture.md, "Interfaces"): summary.json, force_displacement.csv,
//! increments.csv (relaxation and quasi-static runs), particles.csv,
//! force_displacement.svg, force_gauge_<name>.svg (each gauge), crack_map.svg (scenes with
//! damage), random_field_<property>.svg (each random field, with the crack on top),
//! particle_map.svg and particles.vtk in the run's folder; with `output.snapshots`, the time
//! series (snapshots.pvd and snapshots/frame_NNNN.vtu) and, with damage, crack_growth.html.

pub mod animation;
pub mod csv;
pub mod fields;
pub mod plots;
pub mod section;
pub mod snapshots;
pub mod vtk;
pub mod vtu;

use crate::fsio;
use crate::run::Outcome;
use std::path::{Path, PathBuf};

/// The files of a run that sppm owns in its folder (besides `random_field_<property>.svg`,
/// `force_gauge_<name>.svg` and the frames in `snapshots/`, [`snapshots::is_frame_file`]): a
/// new run into the folder replaces them all, so the folder only ever holds one run.
pub const RUN_FILES: [&str; 10] = [
    "summary.json",
    "force_displacement.csv",
    "increments.csv",
    "particles.csv",
    "force_displacement.svg",
    "crack_map.svg",
    "particle_map.svg",
    "particles.vtk",
    snapshots::PVD,
    "crack_growth.html",
];

/// Is `name` a file that a run writes into its folder?
pub fn is_run_file(name: &str) -> bool {
    RUN_FILES.contains(&name)
        || (name.starts_with("random_field_") && name.ends_with(".svg"))
        || (name.starts_with("force_gauge_") && name.ends_with(".svg"))
}

/// Write every output the scene asks for into `dir`; returns the files written.
///
/// Each file is written under a temporary name and renamed into place ([`fsio`]), so no
/// output is ever seen half-written. The earlier run's summary.json goes first and the new
/// one is written last: a folder whose summary.json is missing holds an unfinished write.
/// Files of an earlier run that this run does not write (a crack map, a random-field map,
/// the VTK file, frames of a time series) are removed, so the folder holds one run only.
pub fn write_all(outcome: &Outcome, dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| fsio::IoFailure::new("create the folder", dir, e))?;
    let summary = dir.join("summary.json");
    match std::fs::remove_file(&summary) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(fsio::IoFailure::new("remove the old", &summary, e).into()),
    }
    let mut files = Vec::new();
    let mut put =
        |name: String, write: &dyn Fn(&Path) -> anyhow::Result<()>| -> anyhow::Result<()> {
            let f = dir.join(name);
            fsio::write_with(&f, write)?;
            files.push(f);
            Ok(())
        };
    let gauges: Vec<&str> = outcome
        .scene
        .gauges
        .iter()
        .map(|g| g.name.as_str())
        .collect();
    put("force_displacement.csv".into(), &|f| {
        csv::write_records(&outcome.records, &gauges, f)
    })?;
    if !outcome.increments.is_empty() {
        put("increments.csv".into(), &|f| {
            csv::write_increments(&outcome.increments, f)
        })?;
    }
    put("particles.csv".into(), &|f| {
        csv::write_particles(outcome, f)
    })?;
    put("force_displacement.svg".into(), &|f| {
        plots::force_displacement(outcome, f)
    })?;
    for (k, g) in gauges.iter().enumerate() {
        put(format!("force_gauge_{g}.svg"), &|f| {
            plots::force_gauge(outcome, k, f)
        })?;
    }
    let o = &outcome.scene.output;
    // a 3D run's maps draw its section (output::section)
    let view = (outcome.dim == 3).then(|| section::section_view(outcome));
    let mapped = view.as_ref().unwrap_or(outcome);
    if outcome.damage.is_some() {
        put("crack_map.svg".into(), &|f| {
            plots::crack_map(mapped, o.crack_map_scale, f)
        })?;
    }
    for (k, field) in outcome.fields.iter().enumerate() {
        put(
            format!("random_field_{}.svg", field.property.name()),
            &|f| plots::field_map(outcome, k, o.crack_map_scale, f),
        )?;
    }
    if o.map {
        put("particle_map.svg".into(), &|f| {
            plots::particle_map(mapped, o.field, o.deformed_scale, f)
        })?;
    }
    if o.vtk {
        put("particles.vtk".into(), &|f| {
            vtk::write_particles(outcome, f)
        })?;
    }
    if outcome.snapshots.is_empty() {
        snapshots::remove_stale_frames(dir, &[])?;
    } else {
        files.extend(snapshots::write_series(outcome, dir)?);
        if let Some(html) = animation::crack_growth_html(outcome) {
            let f = dir.join("crack_growth.html");
            fsio::write_atomic(&f, html.as_bytes())?;
            files.push(f);
        }
    }
    remove_stale(dir, &files)?;
    write_summary(outcome, dir)?;
    files.insert(0, summary);
    Ok(files)
}

/// Write the run's summary.json into `dir` (created if needed), atomically.
pub fn write_summary(outcome: &Outcome, dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| fsio::IoFailure::new("create the folder", dir, e))?;
    fsio::write_json(&dir.join("summary.json"), &outcome.summary)
}

/// Remove the run files in `dir` (and temporary files of interrupted writes) that are not
/// in `keep`.
fn remove_stale(dir: &Path, keep: &[PathBuf]) -> anyhow::Result<()> {
    let entries = std::fs::read_dir(dir).map_err(|e| fsio::IoFailure::new("list", dir, e))?;
    remove_unkept(entries, keep, is_run_file)
}

/// Remove the files of `entries` that sppm writes (`ours`, or a temporary file of an
/// interrupted write of one) and that are not in `keep`.
pub(crate) fn remove_unkept(
    entries: std::fs::ReadDir,
    keep: &[PathBuf],
    ours: fn(&str) -> bool,
) -> anyhow::Result<()> {
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let partial = name.starts_with('.')
            && name.ends_with(".partial")
            && ours(&name[1..name.len() - ".partial".len()]);
        if (ours(&name) || partial) && !keep.contains(&entry.path()) {
            let p = entry.path();
            std::fs::remove_file(&p)
                .map_err(|e| fsio::IoFailure::new("remove the stale", &p, e))?;
        }
    }
    Ok(())
}
