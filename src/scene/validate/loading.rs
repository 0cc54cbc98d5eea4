//! `[loading]` and `[damping]`: the ramp, the end of the run, the stop after the peak, and the
//! damping ratios.

use super::{invalid, positive, SceneError};
use crate::scene::Scene;

impl Scene {
    pub(super) fn validate_loading(&self) -> Result<(), SceneError> {
        let l = &self.loading;
        if !(l.ramp_fraction > 0.0 && l.ramp_fraction <= 1.0) {
            return Err(invalid(
                "loading.ramp_fraction",
                l.ramp_fraction,
                "must satisfy 0 < ramp_fraction <= 1",
            ));
        }
        match (l.end_periods, l.end_s) {
            (Some(_), Some(_)) => {
                return Err(invalid(
                    "loading.end_s",
                    l.end_s.unwrap(),
                    "give either loading.end_periods or loading.end_s, not both",
                ))
            }
            (Some(p), None) => {
                positive("loading.end_periods", p)?;
                if p > 1.0e5 {
                    return Err(invalid(
                        "loading.end_periods",
                        p,
                        "at most 1e5 fundamental periods",
                    ));
                }
            }
            (None, Some(s)) => positive("loading.end_s", s)?,
            // the default, DEFAULT_END_PERIODS
            (None, None) => {}
        }
        if let Some(f) = l.stop_after_peak {
            if !(f > 0.0 && f < 1.0) {
                return Err(invalid(
                    "loading.stop_after_peak",
                    f,
                    "a fraction of the peak force, 0 < stop_after_peak < 1",
                ));
            }
            if self.concrete.is_none() {
                return Err(invalid(
                    "loading.stop_after_peak",
                    f,
                    "a scene with [concrete] (an elastic specimen has no peak to pass)",
                ));
            }
        }
        let m = self.loading.max_pace;
        if !(m.is_finite() && (1.0..=100.0).contains(&m)) {
            return Err(invalid(
                "loading.max_pace",
                m,
                "a factor from 1 to 100 (how much faster than the ramp an adaptive pace may read it)",
            ));
        }
        if self.loading.pace == crate::scene::Pace::Adaptive && self.solver.method.is_incremental()
        {
            return Err(invalid(
                "loading.pace",
                "\"adaptive\"",
                format!("\"fixed\" with solver.method = \"{}\" (its load increments set their own pace); \"adaptive\" only with solver.method = \"explicit\"", self.solver.method.name()),
            ));
        }
        Ok(())
    }

    pub(super) fn validate_damping(&self) -> Result<(), SceneError> {
        for (k, v) in [
            ("damping.internal", self.damping.internal),
            ("damping.external", self.damping.external),
        ] {
            if !(v.is_finite() && (0.0..=10.0).contains(&v)) {
                return Err(invalid(k, v, "a damping ratio from 0 to 10"));
            }
        }
        Ok(())
    }
}
