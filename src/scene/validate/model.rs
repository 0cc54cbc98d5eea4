//! `[model]`: the bond-based keys only with the bond-based family, their ranges, and what the
//! bond-based run does not offer (refused under the key the scene set); the cubic grid only
//! with the bond-based family.

use super::{invalid, SceneError};
use crate::scene::{Lattice, Pace, Scene, SolverMethod};

/// The range of the horizon ratio m = δ/Δx a bond-based body accepts: from the nearest
/// neighbours' reach (1.5: at least the faces' and edges' neighbours of a cubic grid) to
/// 8 (about 2,100 bonds per point in 3D).
pub const HORIZON_RANGE: (f64, f64) = (1.5, 8.0);

impl Scene {
    pub(super) fn validate_model(&self) -> Result<(), SceneError> {
        let m = &self.model;
        if !m.is_bond_based() {
            if let Some(k) = m.bond_based_keys().first() {
                return Err(invalid(
                    format!("model.{k}"),
                    "set",
                    "only with model.family = \"bond_based\" (the state-based lattice, model.family = \"splm\", has no such choice)",
                ));
            }
            if self.discretisation.lattice == Lattice::Cubic {
                return Err(invalid(
                    "discretisation.lattice",
                    "\"cubic\"",
                    "\"hexagonal\", \"fcc\" or \"random\" with model.family = \"splm\"; the cubic grid is for model.family = \"bond_based\"",
                ));
            }
            return Ok(());
        }
        let turn = self.discretisation.rotation_deg.angles();
        if self.discretisation.lattice == Lattice::Cubic && turn.iter().any(|a| *a != 0.0) {
            return Err(invalid(
                "discretisation.rotation_deg",
                format!("{turn:?}"),
                "0 (or absent) for lattice = \"cubic\": the grid is aligned with the axes; turn the body or use another discretisation's points",
            ));
        }
        let (lo, hi) = HORIZON_RANGE;
        if let Some(h) = m.horizon {
            if !(h.is_finite() && (lo..=hi).contains(&h)) {
                return Err(invalid(
                    "model.horizon",
                    h,
                    format!("a horizon ratio δ/Δx from {lo} to {hi} (default π)"),
                ));
            }
        }
        if let Some(s) = m.compressive_stretch {
            if !(s.is_finite() && s > 0.0 && s < 1.0) {
                return Err(invalid(
                    "model.compressive_stretch",
                    s,
                    "a positive stretch below 1 (a bond shortened by this fraction breaks, e.g. f_c/E ≈ 1e-3)",
                ));
            }
        }
        if let Some(s) = m.softening {
            if self.concrete.is_none() {
                return Err(invalid(
                    "model.softening",
                    format!("\"{}\"", s.name()),
                    "only with [concrete], whose ft and Gf the law is fitted to",
                ));
            }
        }
        self.refuse_outside_bond_based()
    }

    /// What a bond-based run does not offer, refused under the key the scene set.
    fn refuse_outside_bond_based(&self) -> Result<(), SceneError> {
        let only = |key: &str, value: String, allowed: &str| {
            Err(invalid(
                key,
                value,
                format!("{allowed} with model.family = \"bond_based\""),
            ))
        };
        if self.solver.method != SolverMethod::Explicit {
            return only(
                "solver.method",
                format!("\"{}\"", self.solver.method.name()),
                "\"explicit\" (the bond-based run integrates in time)",
            );
        }
        if self.damping.internal != 0.0 {
            return only(
                "damping.internal",
                self.damping.internal.to_string(),
                "0 (the bond-based body has no bond dampers; damping.external damps the fundamental mode)",
            );
        }
        if let Some(q) = self.solver.mass_scaling {
            return only("solver.mass_scaling", q.to_string(), "absent");
        }
        if self.loading.pace == Pace::Adaptive {
            return only("loading.pace", "\"adaptive\"".into(), "\"fixed\"");
        }
        if let Some(n) = self.output.snapshots {
            return only("output.snapshots", n.to_string(), "absent");
        }
        if !self.random_field.is_empty() {
            return only(
                "random_field",
                format!("{} random fields", self.random_field.len()),
                "absent",
            );
        }
        Ok(())
    }
}
