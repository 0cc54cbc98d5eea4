//! `[output]`: the number of records, a probe group with a reaction, the maps'
//! magnifications and the frames of the time series.

use super::{invalid, SceneError};
use crate::scene::Scene;

/// The most frames `output.snapshots` may ask for.
pub const MAX_SNAPSHOTS: usize = 1000;

impl Scene {
    pub(super) fn validate_output(&self) -> Result<(), SceneError> {
        let o = &self.output;
        if o.records < 2 || o.records > 1_000_000 {
            return Err(invalid(
                "output.records",
                o.records,
                "an integer from 2 to 1000000",
            ));
        }
        if let Some(p) = &o.probe_group {
            match self.groups.iter().find(|g| &g.name == p) {
                None => return Err(self.unknown_group("output.probe_group", p)),
                Some(g) if g.load.is_none() && g.fix.is_empty() => {
                    return Err(invalid(
                        "output.probe_group",
                        format!("{p:?}"),
                        "a group that is loaded or fixed (it has a reaction)",
                    ));
                }
                _ => {}
            }
        }
        for (key, v) in [
            ("output.deformed_scale", o.deformed_scale),
            ("output.crack_map_scale", o.crack_map_scale),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(invalid(
                    key,
                    v,
                    "a magnification >= 0 (0 draws the reference shape)",
                ));
            }
        }
        if let Some(n) = o.snapshots {
            if !(1..=MAX_SNAPSHOTS).contains(&n) {
                return Err(invalid(
                    "output.snapshots",
                    n,
                    format!(
                        "an integer from 1 to {MAX_SNAPSHOTS} (frames of the time series; leave the key out for none)"
                    ),
                ));
            }
        }
        Ok(())
    }
}
