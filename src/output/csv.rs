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

/// The records, one row each: [`COLUMNS`], then a column `gauge_<name>_m` per gauge of
/// `gauges` (their names, in the scene's order).
pub fn write_records(records: &[Record], gauges: &[&str], path: &Path) -> anyhow::Result<()> {
    let mut w = ::csv::Writer::from_path(path)
        .with_context(|| format!("cannot write {}", path.display()))?;
    let mut head: Vec<String> = COLUMNS.iter().map(|c| c.to_string()).collect();
    head.extend(gauges.iter().map(|g| format!("gauge_{g}_m")));
    w.write_record(&head)?;
    for r in records {
        let mut row = vec![
            r.step.to_string(),
            format!("{:e}", r.time_s),
            format!("{:e}", r.displacement_m),
            format!("{:e}", r.force_n),
            format!("{:e}", r.kinetic_j),
            format!("{:e}", r.internal_j),
            format!("{:e}", r.external_work_j),
            format!("{:e}", r.damping_j),
        ];
        row.extend(r.gauges[..gauges.len()].iter().map(|g| format!("{g:e}")));
        w.write_record(&row)?;
    }
    w.flush()?;
    Ok(())
}

/// Column names of increments.csv: one row per load increment of a relaxation or
/// quasi-static run (`solver::relaxation::IncrementReport`); `opening_m` is the gauge
/// opening held with `solver.control`, empty without.
pub const INCREMENT_COLUMNS: [&str; 7] = [
    "increment",
    "load_factor",
    "iterations",
    "commits",
    "residual",
    "converged",
    "opening_m",
];

pub fn write_increments(
    increments: &[crate::solver::relaxation::IncrementReport],
    path: &Path,
) -> anyhow::Result<()> {
    let mut w = ::csv::Writer::from_path(path)
        .with_context(|| format!("cannot write {}", path.display()))?;
    w.write_record(INCREMENT_COLUMNS)?;
    for r in increments {
        w.write_record([
            r.increment.to_string(),
            format!("{:e}", r.load_factor),
            r.iterations.to_string(),
            r.commits.to_string(),
            format!("{:e}", r.residual),
            r.converged.to_string(),
            r.opening_m.map(|o| format!("{o:e}")).unwrap_or_default(),
        ])?;
    }
    w.flush()?;
    Ok(())
}

/// Columns of particles.csv (docs/outputs.md).
pub const PARTICLE_COLUMNS: [&str; 7] =
    ["x_m", "y_m", "ux_m", "uy_m", "sxx_Pa", "syy_Pa", "sxy_Pa"];

/// Columns of particles.csv of a 3D run: the position, displacement and stress in 3D.
pub const PARTICLE_COLUMNS_3D: [&str; 12] = [
    "x_m", "y_m", "z_m", "ux_m", "uy_m", "uz_m", "sxx_Pa", "syy_Pa", "szz_Pa", "syz_Pa", "sxz_Pa",
    "sxy_Pa",
];

/// Columns particles.csv adds for scenes with damage: w_t, w_c and yielded (0 or 1).
pub const DAMAGE_COLUMNS: [&str; 3] = ["tensile_damage", "compressive_damage", "yielded"];

/// particles.csv: one row per particle at the end of the run: reference position,
/// displacement, recovered stress (`run::stress_recovery`; in 3D with z, u_z and the six
/// stress components) and, with damage, w_t, w_c and whether it yielded.
pub fn write_particles(o: &crate::run::Outcome, path: &Path) -> anyhow::Result<()> {
    let mut w = ::csv::Writer::from_path(path)
        .with_context(|| format!("cannot write {}", path.display()))?;
    let mut head = if o.dim == 3 {
        PARTICLE_COLUMNS_3D.to_vec()
    } else {
        PARTICLE_COLUMNS.to_vec()
    };
    if o.damage.is_some() {
        head.extend(DAMAGE_COLUMNS);
    }
    w.write_record(&head)?;
    for i in 0..o.x0.len() {
        let (x, u, s) = (o.x0[i], o.displacement[i], o.stress[i]);
        let mut row: Vec<String> = if o.dim == 3 {
            // stress in Voigt order [xx, yy, zz, yz, xz, xy]
            x.iter()
                .chain(&u)
                .chain(&s)
                .map(|v| format!("{v:e}"))
                .collect()
        } else {
            vec![
                format!("{:e}", x[0]),
                format!("{:e}", x[1]),
                format!("{:e}", u[0]),
                format!("{:e}", u[1]),
                format!("{:e}", s[0]),
                format!("{:e}", s[1]),
                format!("{:e}", s[5]),
            ]
        };
        if let Some(d) = &o.damage {
            row.push(format!("{}", d[i].wt));
            row.push(format!("{}", d[i].wc));
            row.push(format!("{}", d[i].yielded as u8));
        }
        w.write_record(&row)?;
    }
    w.flush()?;
    Ok(())
}
