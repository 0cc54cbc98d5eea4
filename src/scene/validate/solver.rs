//! `[solver]`: the time step and threads, the keys of the relaxation and quasi-static solvers,
//! and indirect displacement control.

use super::{invalid, positive, SceneError};
use crate::scene::{ControlSpec, ForceLag, Scene, SolverMethod};

impl Scene {
    pub(super) fn validate_solver(&self) -> Result<(), SceneError> {
        let s = &self.solver;
        if !(s.safety > 0.0 && s.safety <= 1.0) {
            return Err(invalid(
                "solver.safety",
                s.safety,
                "must satisfy 0 < safety <= 1 (a fraction of the stable time step)",
            ));
        }
        if let Some(dt) = s.dt {
            positive("solver.dt", dt)?;
        }
        if let Some(q) = s.mass_scaling {
            if !(q > 0.0 && q <= 1.0) {
                return Err(invalid(
                    "solver.mass_scaling",
                    q,
                    "must satisfy 0 < mass_scaling <= 1 (the fraction of the median particle's stable step that every particle's step is raised to by added mass)",
                ));
            }
            if s.method.is_incremental() {
                return Err(invalid(
                    "solver.mass_scaling",
                    q,
                    format!("only with solver.method = \"explicit\" (here \"{}\", whose step is its own)", s.method.name()),
                ));
            }
        }
        if let Some(t) = s.threads {
            if t == 0 || t > 1024 {
                return Err(invalid("solver.threads", t, "an integer from 1 to 1024"));
            }
        }
        self.validate_relaxation()
    }

    /// The keys of `solver.method = "relaxation"` (and `"quasi_static"`).
    fn validate_relaxation(&self) -> Result<(), SceneError> {
        let s = &self.solver;
        if s.increments == 0 || s.increments > 1_000_000 {
            return Err(invalid(
                "solver.increments",
                s.increments,
                "an integer from 1 to 1000000 (load increments of the relaxation solver)",
            ));
        }
        if !(s.tolerance.is_finite() && s.tolerance > 0.0 && s.tolerance < 1.0) {
            return Err(invalid(
                "solver.tolerance",
                s.tolerance,
                "must satisfy 0 < tolerance < 1 (out-of-balance force norm relative to the largest reaction norm)",
            ));
        }
        if s.max_iterations() == 0 || s.max_iterations() > 100_000_000 {
            return Err(invalid(
                "solver.max_iterations",
                s.max_iterations(),
                "an integer from 1 to 100000000 (iterations of one load increment)",
            ));
        }
        if let Some(r) = s.max_residual {
            if !(r.is_finite() && r >= s.tolerance && r < 1.0) {
                return Err(invalid(
                    "solver.max_residual",
                    r,
                    format!("must satisfy solver.tolerance = {} ≤ max_residual < 1 (the out-of-balance ratio accepted for an increment that stops at solver.max_iterations)", s.tolerance),
                ));
            }
        }
        if let Some(c) = &s.control {
            self.validate_control(c)?;
        }
        if s.method.is_incremental() && s.force_lag == ForceLag::Previous {
            return Err(invalid(
                "solver.force_lag",
                "\"previous\"",
                format!("\"current\" with solver.method = \"{}\" (the relaxation iterates on the forces at the current positions)", s.method.name()),
            ));
        }
        Ok(())
    }

    /// `solver.control`: the quasi-static solver on concrete, a gauge between two groups whose
    /// displacement along it is free, and a loaded group whose direction it scales.
    fn validate_control(&self, c: &ControlSpec) -> Result<(), SceneError> {
        let s = &self.solver;
        if s.method != SolverMethod::QuasiStatic || self.concrete.is_none() {
            return Err(invalid(
                "solver.control",
                format!("{{ plus = {:?}, minus = {:?} }}", c.plus, c.minus),
                format!("only with solver.method = \"quasi_static\" on a scene with [concrete] (here solver.method = \"{}\"{})", s.method.name(), if self.concrete.is_none() { ", no [concrete]" } else { "" }),
            ));
        }
        for (key, name) in [
            ("solver.control.plus", &c.plus),
            ("solver.control.minus", &c.minus),
        ] {
            let Some(g) = self.groups.iter().find(|g| &g.name == name) else {
                return Err(self.unknown_group(key, name));
            };
            if g.fix.contains(&c.component)
                || g.load.as_ref().is_some_and(|l| l.component == c.component)
            {
                return Err(invalid(
                    key,
                    format!("{name:?}"),
                    format!("a group whose {} displacement is free (the gauge measures the body, not a prescribed displacement): groups.{name} prescribes it", format!("{:?}", c.component).to_lowercase()),
                ));
            }
        }
        if c.component.index() >= self.dim() {
            return Err(invalid(
                "solver.control.component",
                format!("{:?}", c.component).to_lowercase(),
                "\"x\" or \"y\" in 2D (\"z\" also in 3D)",
            ));
        }
        if c.plus == c.minus {
            return Err(invalid(
                "solver.control.minus",
                format!("{:?}", c.minus),
                "a group other than solver.control.plus",
            ));
        }
        if !(c.opening.is_finite() && c.opening > 0.0 && c.opening < 1.0) {
            return Err(invalid(
                "solver.control.opening",
                c.opening,
                "a gauge opening in metres, 0 < opening < 1",
            ));
        }
        if !self.groups.iter().any(|g| g.load.is_some()) {
            return Err(invalid(
                "solver.control",
                format!("{{ plus = {:?}, minus = {:?} }}", c.plus, c.minus),
                "a scene with a loaded group (its Δmax sets the direction of the prescribed displacements the control scales)",
            ));
        }
        Ok(())
    }
}
