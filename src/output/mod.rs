//! Reports of a run (ARCHITECTURE.md, "Interfaces"): summary.json, force_displacement.csv, particles.csv,
//! force_displacement.svg, crack_map.svg (scenes with damage), random_field_<property>.svg (each
//! random field, with the crack on top), particle_map.svg and particles.vtk in the run's folder.

pub mod csv;
pub mod fields;
pub mod plots;
pub mod vtk;

use crate::run::Outcome;
use anyhow::Context;
use std::path::{Path, PathBuf};

/// Write every output the scene asks for into `dir`; returns the files written.
pub fn write_all(outcome: &Outcome, dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the output folder {}", dir.display()))?;
    let mut files = Vec::new();
    let summary = dir.join("summary.json");
    std::fs::write(
        &summary,
        serde_json::to_string_pretty(&outcome.summary)? + "\n",
    )
    .with_context(|| format!("cannot write {}", summary.display()))?;
    files.push(summary);
    let f = dir.join("force_displacement.csv");
    csv::write_records(&outcome.records, &f)?;
    files.push(f);
    let f = dir.join("particles.csv");
    csv::write_particles(outcome, &f)?;
    files.push(f);
    let f = dir.join("force_displacement.svg");
    plots::force_displacement(outcome, &f)?;
    files.push(f);
    let o = &outcome.scene.output;
    if outcome.damage.is_some() {
        let f = dir.join("crack_map.svg");
        plots::crack_map(outcome, o.crack_map_scale, &f)?;
        files.push(f);
    }
    for (k, field) in outcome.fields.iter().enumerate() {
        let f = dir.join(format!("random_field_{}.svg", field.property.name()));
        plots::field_map(outcome, k, o.crack_map_scale, &f)?;
        files.push(f);
    }
    if o.map {
        let f = dir.join("particle_map.svg");
        plots::particle_map(outcome, o.field, o.deformed_scale, &f)?;
        files.push(f);
    }
    if o.vtk {
        let f = dir.join("particles.vtk");
        vtk::write_particles(outcome, &f)?;
        files.push(f);
    }
    Ok(files)
}
