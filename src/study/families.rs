//! `sppm study families`: one specimen under each model family, side by side (docs/bond_based.md,
//! "Side by side"): the scene as written (the state-based lattice SPLM), its body in random
//! particles (SPPM) and the bond-based model on the scene's own particles, each row with its
//! peak force, dissipated energy, crack and wall time. Each finished row is written to
//! families.csv at once; the same command resumes an interrupted study.

use super::crack_path::{crack_path, Clearance, CLEARANCE_SPACINGS, CRACK_PATH_DAMAGE};
use crate::run::{run, Outcome, RunOptions};
use crate::scene::Scene;
use nalgebra::Vector2;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The point damage φ (the share of a point's bond stiffness lost) at and above which a
/// bond-based point belongs to the crack: a point beside a straight crack through a whole
/// family loses about half of it; 0.35 keeps the row of points on either side of the crack
/// and not the points a spacing further, which lose a fifth or less.
pub const BOND_CRACK_DAMAGE: f64 = 0.35;

/// One row of the study: a family and the scene overrides that select it.
#[derive(Clone, Debug)]
pub struct Variant {
    pub label: &'static str,
    pub overrides: Vec<String>,
}

/// What the bond-based row says it left out of the scene file, besides its overrides.
const SNAPSHOTS_LEFT_OUT: &str = "(output.snapshots left out)";

/// The scene of a variant: the file with the overrides; for the bond-based family without
/// `output.snapshots` (its run records no time series; the row's overrides say so).
fn variant_scene(path: &Path, overrides: &[String], bond_based: bool) -> anyhow::Result<Scene> {
    if !bond_based {
        return Ok(Scene::from_file(path, overrides)?);
    }
    let text = crate::scene::read_scene_text(path)?;
    let mut table: toml::Table = text.parse()?;
    if let Some(toml::Value::Table(out)) = table.get_mut("output") {
        out.remove("snapshots");
    }
    let mut scene =
        Scene::from_toml_str(&table.to_string(), overrides).map_err(|e| e.in_file(path))?;
    if scene.name.is_none() {
        scene.name = path.file_stem().map(|s| s.to_string_lossy().into_owned());
    }
    Ok(scene)
}

/// The variants of a scene: as written; random particles (lattice scenes only); bond-based
/// on the scene's particles (bond dampers off: the bond-based body has none).
pub fn variants(scene: &Scene) -> Vec<Variant> {
    let mut out = vec![Variant {
        label: if scene.discretisation.is_random() {
            "sppm"
        } else {
            "splm"
        },
        overrides: vec![],
    }];
    if !scene.discretisation.is_random() && !scene.model.is_bond_based() {
        out.push(Variant {
            label: "sppm",
            // a random particle set has no origin: the lattice's offset goes
            overrides: vec![
                "discretisation.lattice=random".into(),
                "discretisation.offset=[0.0, 0.0]".into(),
            ],
        });
    }
    let mut bond = vec!["model.family=bond_based".to_string()];

    if scene.damping.internal != 0.0 {
        bond.push("damping.internal=0".into());
    }
    out.push(Variant {
        label: "bond_based",
        overrides: bond,
    });
    out
}

/// The columns of families.csv.
pub const COLUMNS: &[&str] = &[
    "family",
    "overrides",
    "status",
    "particles",
    "bonds",
    "peak_force_N",
    "displacement_at_peak_m",
    "dissipated_energy_J",
    "crack_points",
    "crack_centroid_x_m",
    "crack_centroid_y_m",
    "crack_axis_deg",
    "wall_time_s",
    "message",
];

/// The crack of a run: its points (w_t ≥ [`CRACK_PATH_DAMAGE`] for the lattice and random
/// particles, φ ≥ [`BOND_CRACK_DAMAGE`] for the bond-based model) beyond
/// [`CLEARANCE_SPACINGS`] spacings of a support or a loaded group (as the objectivity study
/// counts them; in 3D the distance in space), their centroid in the x–y plane and, in 2D,
/// their principal axis (°; NaN in 3D).
pub fn crack_of(o: &Outcome) -> (usize, [f64; 2], f64) {
    let Some(d) = &o.damage else {
        return (0, [f64::NAN; 2], f64::NAN);
    };
    let threshold = if o.scene.model.is_bond_based() {
        BOND_CRACK_DAMAGE
    } else {
        CRACK_PATH_DAMAGE
    };
    let x0: Vec<Vector2<f64>> = (0..o.x0.len()).map(|i| o.point2(i)).collect();
    let mut wt: Vec<f64> = d.iter().map(|p| p.wt).collect();
    let distance = CLEARANCE_SPACINGS * o.scene.discretisation.spacing;
    let held = super::objectivity::held_points(o);
    let clear = if o.dim == 3 {
        // in 3D the clearance is a distance in space: the x–y projections of a prism's
        // loaded end faces cover its whole section
        clear_in_space(o, &mut wt, distance);
        Clearance::NONE
    } else {
        Clearance {
            held: &held,
            distance,
        }
    };
    match crack_path(&x0, &wt, threshold, &clear) {
        Ok(p) => (
            p.particles,
            p.centroid_m,
            if o.dim == 2 { p.axis_deg } else { f64::NAN },
        ),
        Err(_) => (0, [f64::NAN; 2], f64::NAN),
    }
}

/// Leaves out (damage 0) the particles within `distance` of a support or a loaded group in
/// space, for a 3D run.
fn clear_in_space(o: &Outcome, wt: &mut [f64], distance: f64) {
    let held: Vec<[f64; 3]> = o
        .scene
        .groups
        .iter()
        .filter(|g| !g.fix.is_empty() || g.load.is_some())
        .filter_map(|g| o.groups.iter().find(|m| m.name == g.name))
        .flat_map(|g| g.members.iter().map(|&i| o.x0[i as usize]))
        .collect();
    let d2 = distance * distance;
    for (i, w) in wt.iter_mut().enumerate() {
        let p = o.x0[i];
        let near = held
            .iter()
            .any(|h| (0..3).map(|c| (h[c] - p[c]) * (h[c] - p[c])).sum::<f64>() <= d2);
        if *w > 0.0 && near {
            *w = 0.0;
        }
    }
}

/// The families an unfinished study in `csv` has finished; a row that failed is dropped
/// from the file, so that the same command tries it again.
fn finished(csv: &Path) -> anyhow::Result<Vec<String>> {
    if !csv.exists() {
        return Ok(Vec::new());
    }
    let mut reader = ::csv::Reader::from_path(csv)?;
    let header = reader.headers()?.clone();
    let kept: Vec<::csv::StringRecord> = reader
        .records()
        .filter_map(Result::ok)
        .filter(|r| r.get(2) != Some("failed"))
        .collect();
    let mut writer = ::csv::Writer::from_path(csv)?;
    writer.write_record(&header)?;
    for r in &kept {
        writer.write_record(r)?;
    }
    writer.flush()?;
    Ok(kept
        .iter()
        .filter_map(|r| r.get(0).map(String::from))
        .collect())
}

/// Run every variant of the scene among the `wanted` families not yet in
/// `<out>/families.csv` (with the `overrides` of every run), appending each row as it
/// finishes; the table's rows.
pub fn families(
    scene: &Path,
    overrides: &[String],
    out: &Path,
    wanted: &[&str],
) -> anyhow::Result<Vec<String>> {
    let base = Scene::from_file(scene, overrides)?;
    std::fs::create_dir_all(out)?;
    let csv = out.join("families.csv");
    if !csv.exists() {
        std::fs::write(&csv, format!("{}\n", COLUMNS.join(",")))?;
    }
    let done = finished(&csv)?;
    for v in variants(&base) {
        if done.iter().any(|f| f == v.label) || !wanted.contains(&v.label) {
            continue;
        }
        let mut o = overrides.to_vec();
        o.extend(v.overrides.iter().cloned());
        let row = match variant_scene(scene, &o, v.label == "bond_based")
            .and_then(|s| Ok(run(&s, &RunOptions::default())?))
        {
            Ok(outcome) => {
                let dir = out.join(v.label);
                crate::output::write_all(&outcome, &dir)?;
                row_of(v.label, &said(&v, &base), &outcome)
            }
            Err(e) => failed_row(v.label, &said(&v, &base), &e.to_string()),
        };
        let mut f = std::fs::OpenOptions::new().append(true).open(&csv)?;
        writeln!(f, "{row}")?;
    }
    Ok(std::fs::read_to_string(&csv)?
        .lines()
        .map(String::from)
        .collect())
}

/// The overrides of a variant as its row says them, with what it left out of the file.
fn said(v: &Variant, base: &Scene) -> Vec<String> {
    let mut o = v.overrides.clone();
    if v.label == "bond_based" && base.output.snapshots.is_some() {
        o.push(SNAPSHOTS_LEFT_OUT.into());
    }
    o
}

fn row_of(label: &str, overrides: &[String], o: &Outcome) -> String {
    let s = &o.summary;
    let (n, c, axis) = crack_of(o);
    let fields = [
        label.to_string(),
        quote(&overrides.join(" ")),
        s.status.clone(),
        s.particles.to_string(),
        s.bonds.to_string(),
        format!("{:.6e}", s.peak_force_n),
        format!("{:.6e}", s.displacement_at_peak_m),
        format!("{:.6e}", s.dissipated_energy_j),
        n.to_string(),
        format!("{:.6e}", c[0]),
        format!("{:.6e}", c[1]),
        format!("{axis:.3}"),
        format!("{:.2}", s.wall_time_s),
        quote(s.message.as_deref().unwrap_or("")),
    ];
    fields.join(",")
}

fn failed_row(label: &str, overrides: &[String], message: &str) -> String {
    let mut fields = vec![
        label.to_string(),
        quote(&overrides.join(" ")),
        "failed".into(),
    ];
    fields.extend(std::iter::repeat_n(String::new(), COLUMNS.len() - 4));
    fields.push(quote(message));
    fields.join(",")
}

/// A CSV field, quoted when it holds a comma or a quote.
fn quote(text: &str) -> String {
    if text.contains([',', '"']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// The default folder of the study of a scene.
pub fn default_out(scene: &Path) -> PathBuf {
    super::options::default_folder(scene, "families")
}
