//! `[output]`: the number of records, a probe group with a reaction, and the maps'
//! magnifications.

use super::{invalid, SceneError};
use crate::scene::Scene;

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
        Ok(())
    }
}
