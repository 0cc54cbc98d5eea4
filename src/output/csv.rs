//! CSV of the probe records (force–displacement and energies).

use crate::solver::Record;
use anyhow::Context;
use std::path::Path;

/// Column names of force_displacement.csv.
pub const COLUMNS: [&str; 8] = [
    "step",
    "time_s",
    "displacement_m",
    "force_N",
    "kinetic_J",
    "internal_J",
    "external_work_J",
    "damping_J",
];

pub fn write_records(records: &[Record], path: &Path) -> anyhow::Result<()> {
    let mut w = ::csv::Writer::from_path(path)
        .with_context(|| format!("cannot write {}", path.display()))?;
    w.write_record(COLUMNS)?;
    for r in records {
        w.write_record([
            r.step.to_string(),
            format!("{:e}", r.time_s),
            format!("{:e}", r.displacement_m),
            format!("{:e}", r.force_n),
            format!("{:e}", r.kinetic_j),
            format!("{:e}", r.internal_j),
            format!("{:e}", r.external_work_j),
            format!("{:e}", r.damping_j),
        ])?;
    }
    w.flush()?;
    Ok(())
}
