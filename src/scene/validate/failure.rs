//! `[failure]`: a criterion with the tolerances it reads, in a scene with a force-controlled
//! load.

use super::{invalid, positive, SceneError};
use crate::scene::failure::Criterion;
use crate::scene::Scene;

impl Scene {
    pub(super) fn validate_failure(&self) -> Result<(), SceneError> {
        let Some(f) = &self.failure else {
            return Ok(());
        };
        let key = format!("failure.criterion = \"{}\"", f.criterion.name());
        if !self
            .groups
            .iter()
            .any(|g| g.load.as_ref().is_some_and(|l| l.force.is_some()))
        {
            return Err(invalid(
                "failure.criterion",
                format!("\"{}\"", f.criterion.name()),
                "a scene with a force-controlled load (a group's load.force): the criteria judge whether a held force is carried",
            ));
        }
        let uses_speed = f.criterion != Criterion::ForceDecay;
        match f.velocity_tolerance {
            Some(v) => positive("failure.velocity_tolerance", v)?,
            None if uses_speed => {
                return Err(invalid(
                    "failure.velocity_tolerance",
                    "(missing)",
                    format!("the mean speed τ_u in m/s below which the loaded particles count as at rest; {key} needs it"),
                ))
            }
            None => {}
        }
        positive("failure.force_tolerance", f.force_tolerance)?;
        positive("failure.damage_tolerance", f.damage_tolerance)?;
        for (k, v) in [
            ("failure.stable_steps", f.stable_steps),
            ("failure.failing_steps", f.failing_steps),
            ("failure.check_every", Some(f.check_every)),
        ] {
            if v == Some(0) {
                return Err(invalid(k, 0, "a number of steps of at least 1"));
            }
        }
        Ok(())
    }
}
