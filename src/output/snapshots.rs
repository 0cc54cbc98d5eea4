//! The time series of a run (`output.snapshots`) for ParaView: `snapshots/frame_0000.vtu` …
//! (one `.vtu` per frame, `run::snapshots` says when each is taken) and `snapshots.pvd`, the
//! collection that lists them with their load fraction as the time step.
//!
//! Point data of each frame, in SI units: `displacement_m` (3 components), `stress_Pa` (the
//! full tensor, 9 components row by row), `von_mises_Pa` (plane stress of the in-plane tensor
//! in 2D), with `[concrete]` `damage_wt` and `damage_wc`, then `volume_m3` (the particle's
//! ΔV, for glyph scaling) and `id` (the particle's index, Int32, as in particles.csv). Field
//! data: `load_fraction` and `probe_displacement_m`.

use super::vtu::{self, Array, Field, Values};
use crate::fsio;
use crate::run::snapshots::Snapshot;
use crate::run::Outcome;
use std::path::{Path, PathBuf};

/// The folder of the frames, inside the run's folder.
pub const FOLDER: &str = "snapshots";

/// The collection file, in the run's folder.
pub const PVD: &str = "snapshots.pvd";

/// The file name of frame `k` (from 0).
pub fn frame_name(k: usize) -> String {
    format!("frame_{k:04}.vtu")
}

/// Is `name` a frame file sppm writes (`frame_` digits `.vtu`)?
pub fn is_frame_file(name: &str) -> bool {
    name.strip_prefix("frame_")
        .and_then(|rest| rest.strip_suffix(".vtu"))
        .is_some_and(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))
}

/// Write the frames of `o` into `dir`/snapshots/ and the collection `dir`/snapshots.pvd;
/// returns the files written. Frames of an earlier run beyond these are removed.
pub fn write_series(o: &Outcome, dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let folder = dir.join(FOLDER);
    std::fs::create_dir_all(&folder)
        .map_err(|e| fsio::IoFailure::new("create the folder", &folder, e))?;
    let id: Vec<i32> = (0..o.x0.len() as i32).collect();
    let mut files = Vec::with_capacity(o.snapshots.len() + 1);
    let mut listed = Vec::with_capacity(o.snapshots.len());
    for (k, frame) in o.snapshots.iter().enumerate() {
        let name = frame_name(k);
        let path = folder.join(&name);
        fsio::write_with(&path, |tmp| write_frame(o, frame, &id, tmp))?;
        files.push(path);
        listed.push((frame.load_fraction, format!("{FOLDER}/{name}")));
    }
    remove_stale_frames(dir, &files)?;
    let pvd = dir.join(PVD);
    fsio::write_atomic(&pvd, vtu::pvd(&listed).as_bytes())?;
    files.push(pvd);
    Ok(files)
}

/// Write one frame's `.vtu` to `path`.
fn write_frame(o: &Outcome, f: &Snapshot, id: &[i32], path: &Path) -> anyhow::Result<()> {
    let file = std::fs::File::create(path)?;
    let mut w = std::io::BufWriter::new(file);
    let displacement: Vec<f64> = f.displacement.iter().flatten().copied().collect();
    let stress: Vec<f64> = f
        .stress
        .iter()
        .flat_map(crate::run::arrays::tensor9)
        .collect();
    let von_mises: Vec<f64> = f
        .stress
        .iter()
        .map(|s| super::fields::von_mises(o.dim, s))
        .collect();
    let mut arrays = vec![
        Array {
            name: "displacement_m",
            components: 3,
            values: Values::F64(&displacement),
        },
        Array {
            name: "stress_Pa",
            components: 9,
            values: Values::F64(&stress),
        },
        Array {
            name: "von_mises_Pa",
            components: 1,
            values: Values::F64(&von_mises),
        },
    ];
    let damage: Option<[Vec<f64>; 2]> = f.damage.as_ref().map(|d| {
        [
            d.iter().map(|w| w[0]).collect(),
            d.iter().map(|w| w[1]).collect(),
        ]
    });
    if let Some([wt, wc]) = &damage {
        for (name, values) in [("damage_wt", wt), ("damage_wc", wc)] {
            arrays.push(Array {
                name,
                components: 1,
                values: Values::F64(values),
            });
        }
    }
    arrays.push(Array {
        name: "volume_m3",
        components: 1,
        values: Values::F64(&o.volume),
    });
    arrays.push(Array {
        name: "id",
        components: 1,
        values: Values::I32(id),
    });
    let fields = [
        Field {
            name: "load_fraction",
            value: f.load_fraction,
        },
        Field {
            name: "probe_displacement_m",
            value: f.probe_displacement_m,
        },
    ];
    vtu::write_vtu(&mut w, &o.x0, &arrays, &fields)?;
    std::io::Write::flush(&mut w)?;
    Ok(())
}

/// Remove the frame files in `dir`/snapshots/ (and temporary files of interrupted writes)
/// that are not in `keep`, then the folder if nothing else is in it; nothing when the folder
/// does not exist.
pub fn remove_stale_frames(dir: &Path, keep: &[PathBuf]) -> anyhow::Result<()> {
    let folder = dir.join(FOLDER);
    let entries = match std::fs::read_dir(&folder) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(fsio::IoFailure::new("list", &folder, e).into()),
    };
    super::remove_unkept(entries, keep, is_frame_file)?;
    if keep.is_empty() {
        // only when empty: a file of the user's stays, and so does its folder
        let _ = std::fs::remove_dir(&folder);
    }
    Ok(())
}
