//! Parsing of the studies' command-line lists (comma-separated angles, spacings, sizes), and
//! the default folder of a study.

use anyhow::bail;
use std::path::{Path, PathBuf};

/// The non-empty, trimmed items of a comma-separated option value.
pub fn comma_items(text: &str) -> Vec<&str> {
    text.split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect()
}

/// A comma-separated list of numbers; `option` names it in the message.
pub fn parse_list(option: &str, text: &str) -> anyhow::Result<Vec<f64>> {
    let items = comma_items(text);
    if items.is_empty() {
        bail!("{option} `{text}`: give a comma-separated list of at least one number");
    }
    items
        .iter()
        .map(|s| {
            s.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    anyhow::anyhow!("{option} `{text}`: `{s}` is not a number (a comma-separated list of numbers is expected)")
                })
        })
        .collect()
}

/// The default folder of a study of a scene file: output/<file stem>-<study>.
pub fn default_folder(scene: &Path, study: &str) -> PathBuf {
    let stem = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    PathBuf::from("output").join(format!("{stem}-{study}"))
}
