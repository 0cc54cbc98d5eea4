//! The records of a Monte Carlo folder, typed: study_inputs.json (what its rows depend on),
//! study_request.json (what the last command in the folder asked for) and the tags of its
//! rows. [`crate::study::monte_carlo::monte_carlo`] writes them and `sppm study merge` reads
//! them back; the files are JSON objects with their keys in the order serde_json's map keeps
//! them ([`write_record`]).

use crate::study::monte_carlo::MonteCarloArgs;
use crate::study::runner::RunRow;
use crate::study::size_effect_report::{size_um, tag_f64};
use crate::Scene;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// study_inputs.json: what the rows of a Monte Carlo folder depend on. Folders whose inputs
/// agree but for the shard and the sizes are one study ([`StudyInputs::identity`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudyInputs {
    /// "montecarlo".
    pub study: String,
    /// The scene file as given.
    pub scene: String,
    pub scene_name: String,
    /// FNV-1a of the scene file's bytes ([`fnv1a`]).
    pub scene_fnv1a: String,
    /// The `--set` overrides.
    pub overrides: Vec<String>,
    /// The study seed S.
    pub seed: u64,
    /// The sizes D (m) of the command; always written (`None` only in [`Self::identity`]).
    pub sizes_m: Option<Vec<f64>>,
    /// The scene's own size D0 (m) and spacing s0 (m).
    pub scene_size_m: f64,
    pub scene_spacing_m: f64,
    /// The shard `k/n` of the command; `None` for the whole study.
    pub shard: Option<String>,
}

/// The `study` of a Monte Carlo folder's inputs.
pub const MONTE_CARLO: &str = "montecarlo";

impl StudyInputs {
    /// The inputs of a Monte Carlo command: `scene_text` the scene file's bytes, `d0` the
    /// scene's own size.
    pub fn of(
        args: &MonteCarloArgs,
        base: &Scene,
        sizes: &[f64],
        scene_text: &[u8],
        d0: f64,
    ) -> StudyInputs {
        StudyInputs {
            study: MONTE_CARLO.into(),
            scene: args.scene.display().to_string(),
            scene_name: base.name().to_string(),
            scene_fnv1a: fnv1a(scene_text),
            overrides: args.overrides.clone(),
            seed: args.seed,
            sizes_m: Some(sizes.to_vec()),
            scene_size_m: d0,
            scene_spacing_m: base.discretisation.spacing,
            shard: args.shard.map(|s| s.to_string()),
        }
    }

    /// What makes folders one study: the inputs without the shard and the sizes (shards, and
    /// studies of other sizes, combine: a realisation's seed depends on (S, D, r) only).
    pub fn identity(&self) -> StudyInputs {
        StudyInputs {
            sizes_m: None,
            shard: None,
            ..self.clone()
        }
    }

    /// The inputs without the shard (a merged folder is the whole study).
    pub fn unsharded(&self) -> StudyInputs {
        StudyInputs {
            shard: None,
            ..self.clone()
        }
    }

    /// As JSON, the form the runner compares and the files hold.
    pub fn value(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or_default()
    }
}

/// study_request.json: what a Monte Carlo command in a folder was last asked for, written
/// when it starts; `sppm study merge` checks the folder's rows against it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyRequest {
    pub realisations: usize,
    pub sizes_m: Vec<f64>,
    /// The shard `k/n`; `None` for the whole study.
    pub shard: Option<String>,
}

/// Write a record as a JSON object whose keys are in the order serde_json's map keeps them,
/// as these files have always been written.
pub fn write_record(path: &Path, record: &impl Serialize) -> anyhow::Result<()> {
    crate::fsio::write_json(path, &serde_json::to_value(record)?)
}

/// FNV-1a of bytes (a fingerprint of the scene file in study_inputs.json).
pub fn fnv1a(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h = (h ^ *b as u64).wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// A row of realisations.csv or deterministic.csv with its tags read (the tag columns
/// `TAGS` and `DET_TAGS`: the two tables differ only in the realisation column).
#[derive(Clone, Debug)]
pub struct TaggedRow {
    /// D in µm (`size_D_m`).
    pub size_um: u64,
    /// The realisation r of a realisations.csv row (`None` if its column is not a whole
    /// number); `None` in deterministic.csv.
    pub realisation: Option<usize>,
    /// The seed column as written.
    pub seed: String,
    pub row: RunRow,
}

impl TaggedRow {
    /// A row of realisations.csv (`size_D_m`, `realisation`, `seed`).
    pub fn realisation(row: RunRow) -> TaggedRow {
        TaggedRow {
            size_um: size_um(tag_f64(&row, 0)),
            realisation: row.tags[1].parse().ok(),
            seed: row.tags[2].clone(),
            row,
        }
    }

    /// A row of deterministic.csv (`size_D_m`, `seed`).
    pub fn deterministic(row: RunRow) -> TaggedRow {
        TaggedRow {
            size_um: size_um(tag_f64(&row, 0)),
            realisation: None,
            seed: row.tags[1].clone(),
            row,
        }
    }
}
