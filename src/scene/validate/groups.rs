//! `[[groups]]`: unique names, selections of the scene's dimension, and supports and loads on
//! axes it has.

use super::{finite, invalid, positive, SceneError};
use crate::scene::{Edge, GroupSpec, Scene, Selection};
use std::collections::HashSet;

impl Scene {
    pub(super) fn validate_groups(&self) -> Result<(), SceneError> {
        let mut names = HashSet::new();
        for (gi, g) in self.groups.iter().enumerate() {
            let key = format!("groups[{gi}]");
            if g.name.is_empty() {
                return Err(invalid(
                    format!("{key}.name"),
                    "\"\"",
                    "a non-empty group name",
                ));
            }
            if !names.insert(g.name.clone()) {
                return Err(invalid(
                    format!("{key}.name"),
                    format!("{:?}", g.name),
                    "group names must be unique",
                ));
            }
            let key = format!("groups.{}", g.name);
            self.validate_selection(&key, &g.select)?;
            self.validate_supports_and_load(&key, g)?;
            self.validate_friction(&key, g)?;
            self.validate_bearing(&key, g)?;
        }
        Ok(())
    }

    /// `groups.<name>.select`, its keys under `key` (`groups.<name>`).
    fn validate_selection(&self, key: &str, select: &Selection) -> Result<(), SceneError> {
        let dim = self.dim();
        match select {
            Selection::Edge { edge, rows } => {
                if dim == 2 && matches!(edge, Edge::Front | Edge::Back) {
                    return Err(invalid(
                        format!("{key}.select.edge"),
                        format!("{edge:?}").to_lowercase(),
                        "bottom, top, left or right in 2D (front and back are the faces at the smallest and largest z of a 3D body)",
                    ));
                }
                if *rows == 0 || *rows > 20 {
                    return Err(invalid(
                        format!("{key}.select.rows"),
                        rows,
                        "an integer from 1 to 20",
                    ));
                }
            }
            Selection::Strip {
                edge,
                width,
                depth,
                centre,
            } => {
                if matches!(edge, Edge::Front | Edge::Back) {
                    return Err(invalid(
                        format!("{key}.select.edge"),
                        format!("{edge:?}").to_lowercase(),
                        "bottom, top, left or right: a strip runs along the body's section (in 3D along z, the generatrix of a cylinder or a prism)",
                    ));
                }
                if dim == 3 && !self.has_section_along_z() {
                    return Err(invalid(
                        format!("{key}.select"),
                        select.scene_text(),
                        format!(
                            "a strip follows the section of a prism or of a cylinder along z, and this body (\"{}\") has none: select a face with by = \"edge\", or a region with by = \"box\"",
                            self.body.name()
                        ),
                    ));
                }
                positive(&format!("{key}.select.width"), *width)?;
                if let Some(c) = centre {
                    finite(&format!("{key}.select.centre"), *c)?;
                }
                if let Some(dp) = depth {
                    positive(&format!("{key}.select.depth"), *dp)?;
                }
            }
            Selection::Box { min, max } => select_box(key, min, max, dim)?,
            Selection::Nearest { point } => {
                components(&format!("{key}.select.point"), point, dim)?;
                for (c, v) in point.iter().enumerate() {
                    finite(&format!("{key}.select.point[{c}]"), *v)?;
                }
            }
            Selection::All => {}
        }
        Ok(())
    }

    /// `fix` and `load` of a group, its keys under `key`: axes the scene has, each fixed at
    /// most once, and a load of a finite displacement, at most the body's size, on a free axis.
    fn validate_supports_and_load(&self, key: &str, g: &GroupSpec) -> Result<(), SceneError> {
        let dim = self.dim();
        let mut fixed = HashSet::new();
        let axes = g
            .fix
            .iter()
            .map(|a| (a, "fix"))
            .chain(g.load.as_ref().map(|l| (&l.component, "load.component")));
        for (a, what) in axes {
            if a.index() >= dim {
                return Err(invalid(
                    format!("{key}.{what}"),
                    "\"z\"",
                    "the axes \"x\" and \"y\" in 2D (\"z\" is for 3D scenes, lattice = \"fcc\")",
                ));
            }
        }
        for a in &g.fix {
            if !fixed.insert(a.index()) {
                return Err(invalid(
                    format!("{key}.fix"),
                    format!("{:?}", g.fix),
                    "each axis at most once",
                ));
            }
        }
        if let Some(l) = &g.load {
            if let Some(force) = l.force {
                return self.validate_force_load(key, l, force, &fixed);
            }
            finite(&format!("{key}.load.displacement"), l.delta())?;
            // a displacement beyond the body's size is no loading of a specimen (and at
            // 1e300 m the energies overflow)
            if l.delta().abs() > self.body_size() {
                return Err(invalid(
                    format!("{key}.load.displacement"),
                    l.delta(),
                    format!(
                        "at most the body's smallest dimension ({:.4e} m) in magnitude",
                        self.body_size()
                    ),
                ));
            }
            if fixed.contains(&l.component.index()) {
                return Err(invalid(
                    format!("{key}.load.component"),
                    format!("{:?}", l.component).to_lowercase(),
                    "a component that is not also in fix",
                ));
            }
        }
        Ok(())
    }
}

/// A point or corner under `key` with one component per dimension of the scene.
fn components(key: &str, v: &[f64], dim: usize) -> Result<(), SceneError> {
    if v.len() != dim {
        return Err(invalid(
            key,
            format!("{v:?}"),
            format!("{dim} components (m), one per dimension of the scene"),
        ));
    }
    Ok(())
}

/// `select = { by = "box" }`: two corners of the scene's dimension, `max` above `min`.
fn select_box(key: &str, min: &[f64], max: &[f64], dim: usize) -> Result<(), SceneError> {
    for (corner, v) in [("min", min), ("max", max)] {
        components(&format!("{key}.select.{corner}"), v, dim)?;
    }
    for c in 0..dim {
        finite(&format!("{key}.select.min[{c}]"), min[c])?;
        finite(&format!("{key}.select.max[{c}]"), max[c])?;
        if max[c] <= min[c] {
            return Err(invalid(
                format!("{key}.select.max[{c}]"),
                max[c],
                format!("must be greater than select.min[{c}] = {}", min[c]),
            ));
        }
    }
    Ok(())
}

impl Scene {
    /// A force-controlled load (`load.force`, docs/failure.md): a finite, non-zero force on a
    /// free component, and a run that can hold it (the explicit solver, a fixed pace, no stop
    /// after a peak of a displacement-controlled curve).
    fn validate_force_load(
        &self,
        key: &str,
        l: &crate::scene::LoadSpec,
        force: f64,
        fixed: &HashSet<usize>,
    ) -> Result<(), SceneError> {
        let k = format!("{key}.load.force");
        if let Some(d) = l.displacement {
            return Err(invalid(
                format!("{key}.load.displacement"),
                d,
                "either load.displacement or load.force, not both",
            ));
        }
        if !(force.is_finite() && force != 0.0) {
            return Err(invalid(&k, force, "a finite, non-zero force in N (signed)"));
        }
        // E over the section on the body's smallest dimension is a strain of one: no loading
        // of a specimen (and far beyond it the energies overflow within a few steps)
        let size = self.body_size();
        let section = size
            * if self.dim() == 3 {
                size
            } else {
                self.material.thickness()
            };
        let largest = self.material.youngs_modulus() * section;
        if force.abs() > largest {
            return Err(invalid(
                &k,
                force,
                format!("at most {largest:.4e} N in magnitude: E times a section of the body's smallest dimension by {} (a mean stress of E, a strain of one)", if self.dim() == 3 { "itself" } else { "material.thickness" }),
            ));
        }
        if fixed.contains(&l.component.index()) {
            return Err(invalid(
                format!("{key}.load.component"),
                format!("{:?}", l.component).to_lowercase(),
                "a component that is not also in fix",
            ));
        }
        let method = self.solver.method;
        if method.is_incremental() {
            return Err(invalid(
                &k,
                force,
                format!("a force-controlled load runs with solver.method = \"explicit\" only (this scene sets \"{}\"); use load.displacement", method.name()),
            ));
        }
        if let Some(f) = self.loading.stop_after_peak {
            return Err(invalid(
                "loading.stop_after_peak",
                f,
                format!("no stop after the peak with a force-controlled load ({k}): a [failure] criterion decides when it has failed"),
            ));
        }
        if self.loading.pace == crate::scene::Pace::Adaptive {
            return Err(invalid(
                "loading.pace",
                "\"adaptive\"",
                format!("\"fixed\" with a force-controlled load ({k})"),
            ));
        }
        Ok(())
    }
}

impl Scene {
    /// `friction` of a group (a platen, docs/model.md §10): a coefficient from 0 to 10 on a
    /// group with one normal component (its displacement load, or one fixed axis), run by the
    /// explicit solver of the SPLM/SPPM family.
    fn validate_friction(&self, key: &str, g: &GroupSpec) -> Result<(), SceneError> {
        let Some(mu) = g.friction else {
            return Ok(());
        };
        let k = format!("{key}.friction");
        if !(mu.is_finite() && (0.0..=10.0).contains(&mu)) {
            return Err(invalid(
                &k,
                mu,
                "a Coulomb coefficient from 0 (sliding freely) to 10",
            ));
        }
        if g.platen_normal().is_none() {
            return Err(invalid(
                &k,
                mu,
                format!(
                    "a platen: a group that selects an edge or a strip and fixes or displaces the axis normal to it, or one with a load.displacement or exactly one fixed axis (the platen's normal); this group has fix = {:?}{}",
                    g.fix,
                    if g.load.is_some() { " and a force-controlled load" } else { "" }
                ),
            ));
        }
        self.platens_run_here(&k, mu, "platens with friction")
    }

    /// A platen (friction, a bearing strip) under `key`, set to `value`, runs with the explicit
    /// solver of the SPLM/SPPM family.
    fn platens_run_here(
        &self,
        key: &str,
        value: impl std::fmt::Display,
        what: &str,
    ) -> Result<(), SceneError> {
        let method = self.solver.method;
        if method.is_incremental() {
            return Err(invalid(
                key,
                value,
                format!(
                    "{what} run with solver.method = \"explicit\" only (this scene sets \"{}\")",
                    method.name()
                ),
            ));
        }
        if self.model.is_bond_based() {
            return Err(invalid(
                key,
                value,
                format!("{what} in the SPLM/SPPM family (this scene sets model.family = \"bond_based\")"),
            ));
        }
        Ok(())
    }
}

impl Scene {
    /// `bearing` of a group (a bearing strip, docs/model.md §10): a finite positive modulus
    /// and thickness, on a strip selection with one normal component (its displacement load
    /// or one fixed axis), without friction, run by the explicit solver of the SPLM/SPPM
    /// family.
    fn validate_bearing(&self, key: &str, g: &GroupSpec) -> Result<(), SceneError> {
        let Some(b) = g.bearing else {
            return Ok(());
        };
        let k = format!("{key}.bearing");
        positive(&format!("{k}.E"), b.e)?;
        positive(&format!("{k}.thickness"), b.thickness)?;
        let text = format!("{{ E = {:e}, thickness = {} }}", b.e, b.thickness);
        if self.strip_area(&g.select).is_none() {
            return Err(invalid(
                &k,
                &text,
                format!(
                    "a group selected as a strip (select = {{ by = \"strip\", ... }}, whose width and length give the strip's area); this group selects {}",
                    g.select.scene_text()
                ),
            ));
        }
        if g.platen_normal().is_none() {
            return Err(invalid(
                &k,
                &text,
                "a platen: a group that fixes or displaces the axis normal to its strip's edge",
            ));
        }
        if g.friction.is_some() {
            return Err(invalid(
                &k,
                &text,
                format!("either friction or a bearing strip on one group ({key} sets both)"),
            ));
        }
        self.platens_run_here(&k, &text, "bearing strips")
    }
}
