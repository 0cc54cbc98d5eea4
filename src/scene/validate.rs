//! Scene validation: every impossible value is refused before any work, with one message
//! naming the key, the value and what is allowed.

use super::*;
use crate::geometry::polygon_self_intersects;
use nalgebra::Vector2;
use std::collections::HashSet;

/// Everything that can be wrong with a scene.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("{0}")]
    Io(String),
    #[error("scene file is not valid: {0}")]
    Parse(String),
    #[error("--set {key}: {message}")]
    Override { key: String, message: String },
    #[error("{key} = {value}: {allowed}")]
    Invalid {
        key: String,
        value: String,
        allowed: String,
    },
    #[error("{file}: {inner}")]
    InFile {
        file: String,
        inner: Box<SceneError>,
    },
}

impl SceneError {
    pub(crate) fn in_file(self, path: &std::path::Path) -> SceneError {
        SceneError::InFile {
            file: path.display().to_string(),
            inner: Box::new(self),
        }
    }
}

pub(crate) fn invalid(
    key: impl Into<String>,
    value: impl std::fmt::Display,
    allowed: impl Into<String>,
) -> SceneError {
    SceneError::Invalid {
        key: key.into(),
        value: value.to_string(),
        allowed: allowed.into(),
    }
}

fn positive(key: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(invalid(key, v, "must be a finite number greater than zero"))
    }
}

fn finite(key: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(invalid(key, v, "must be a finite number"))
    }
}

impl Scene {
    /// Check every value; the first problem found is returned.
    pub fn validate(&self) -> Result<(), SceneError> {
        if let Some(n) = &self.name {
            if n.is_empty()
                || n.contains(['/', '\\'])
                || n.starts_with('.')
                || n.chars().any(char::is_control)
                || n.len() > 200
            {
                return Err(invalid(
                    "name",
                    format!("{n:?}"),
                    "a plain folder name (it names output/<name>/): 1 to 200 characters, no path separators or control characters, not starting with '.'",
                ));
            }
        }
        self.validate_body()?;
        self.validate_cutouts()?;
        super::random_fields::check(self)?;
        let d = &self.discretisation;
        if d.is_random() {
            if let Some(f) = d.min_distance {
                if !(f.is_finite() && (0.5..=0.75).contains(&f)) {
                    return Err(invalid(
                        "discretisation.min_distance",
                        f,
                        "a fraction of the spacing in [0.5, 0.75]: the elastic calibration of random particles is measured there (model::sppm_calibration), and above 0.75 random placement can hardly reach a hexagonal lattice's density (the jamming limit of random sequential packing is about 0.78)",
                    ));
                }
            }
            if d.offset.iter().any(|&o| o != 0.0) {
                return Err(invalid(
                    "discretisation.offset",
                    format!("{:?}", d.offset),
                    "zeros (or absent) for lattice = \"random\": a random particle set has no origin (change `seed` for another particle set; rotation_deg turns the set against the body)",
                ));
            }
            if d.surface_correction == Some(true) {
                return Err(invalid(
                    "discretisation.surface_correction",
                    "true",
                    "false (or absent) for lattice = \"random\": every random particle gets its own least-squares micro-moduli already",
                ));
            }
            if let Some(s) = d.surface {
                if s != super::Surface::VoronoiFit {
                    return Err(invalid(
                        "discretisation.surface",
                        format!("\"{}\"", s.name()),
                        "\"voronoi_fit\" (or absent) for lattice = \"random\": random particles always have their clipped Voronoi cells and their own least-squares micro-moduli",
                    ));
                }
            }
        } else if let Some(f) = d.min_distance {
            return Err(invalid(
                "discretisation.min_distance",
                f,
                "absent for lattice = \"hexagonal\" (it sets the random particles' spacing rule)",
            ));
        }
        if let (Some(s), Some(c)) = (d.surface, d.surface_correction) {
            return Err(invalid(
                "discretisation.surface_correction",
                c,
                format!("absent when discretisation.surface is given (surface = \"{}\"): surface_correction = true is surface = \"lattice_fit\", false is surface = \"lattice\"", s.name()),
            ));
        }
        positive("discretisation.spacing", d.spacing)?;
        for (k, a) in d.rotation_deg.angles().iter().enumerate() {
            finite(&format!("discretisation.rotation_deg[{k}]"), *a)?;
        }
        let components = if self.dim() == 3 { "2 or 3" } else { "2" };
        if d.offset.len() != 2 && !(self.dim() == 3 && d.offset.len() == 3) {
            return Err(invalid(
                "discretisation.offset",
                format!("{:?}", d.offset),
                format!(
                    "{components} components (m), [x, y]{}",
                    if self.dim() == 3 { " or [x, y, z]" } else { "" }
                ),
            ));
        }
        for (k, o) in d.offset.iter().enumerate() {
            finite(&format!("discretisation.offset[{k}]"), *o)?;
        }
        if self.dim() == 2 && d.rotation_deg.planar().is_none() {
            return Err(invalid(
                "discretisation.rotation_deg",
                format!("{:?}", d.rotation_deg.angles()),
                "one angle (degrees) for a 2D lattice; three angles [α, β, γ] are for lattice = \"fcc\"",
            ));
        }
        let size = self.body_size();
        if d.spacing > 0.5 * size {
            return Err(invalid(
                "discretisation.spacing",
                d.spacing,
                format!(
                    "must be at most half the body's smallest dimension ({:.4e} m)",
                    0.5 * size
                ),
            ));
        }

        let m = &self.material;
        positive("material.E", m.youngs_modulus())?;
        positive("material.rho", m.rho)?;
        if self.dim() == 2 {
            match m.thickness {
                Some(t) => positive("material.thickness", t)?,
                None => {
                    return Err(invalid(
                        "material.thickness",
                        "absent",
                        "the thickness t (m) of the 2D specimen, > 0",
                    ))
                }
            }
        }
        if !(m.nu.is_finite() && m.nu > -1.0 && m.nu < 0.5) {
            return Err(invalid("material.nu", m.nu, "must satisfy -1 < nu < 0.5"));
        }

        let mut names = HashSet::new();
        let mut any_load = false;
        let dim = self.dim();
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
            match &g.select {
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
                            g.select.scene_text(),
                            format!(
                                "a strip follows the section of a prism or of a cylinder along z, and this body (\"{}\") has none: select a face with by = \"edge\", or a region with by = \"box\"",
                                self.body.name()
                            ),
                        ));
                    }
                    positive(&format!("{key}.select.width"), *width)?;
                    finite(&format!("{key}.select.centre"), *centre)?;
                    if let Some(dp) = depth {
                        positive(&format!("{key}.select.depth"), *dp)?;
                    }
                }
                Selection::Box { min, max } => {
                    for (corner, v) in [("min", min), ("max", max)] {
                        if v.len() != dim {
                            return Err(invalid(
                                format!("{key}.select.{corner}"),
                                format!("{v:?}"),
                                format!("{dim} components (m), one per dimension of the scene"),
                            ));
                        }
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
                }
                Selection::Nearest { point } => {
                    if point.len() != dim {
                        return Err(invalid(
                            format!("{key}.select.point"),
                            format!("{point:?}"),
                            format!("{dim} components (m), one per dimension of the scene"),
                        ));
                    }
                    for (c, v) in point.iter().enumerate() {
                        finite(&format!("{key}.select.point[{c}]"), *v)?;
                    }
                }
                Selection::All => {}
            }
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
                any_load = true;
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
        }

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
            (None, None) => {
                if any_load && self.solver.method == SolverMethod::Explicit {
                    return Err(invalid(
                        "loading.end_periods",
                        "(missing)",
                        "a scene with a loaded group needs loading.end_periods (multiples of the computed fundamental period) or loading.end_s",
                    ));
                }
            }
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

        for (k, v) in [
            ("damping.internal", self.damping.internal),
            ("damping.external", self.damping.external),
        ] {
            if !(v.is_finite() && (0.0..=10.0).contains(&v)) {
                return Err(invalid(k, v, "a damping ratio from 0 to 10"));
            }
        }

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
        if let Some(t) = s.threads {
            if t == 0 || t > 1024 {
                return Err(invalid("solver.threads", t, "an integer from 1 to 1024"));
            }
        }
        self.validate_relaxation()?;

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
                None => {
                    let known: Vec<_> = self.groups.iter().map(|g| g.name.as_str()).collect();
                    return Err(invalid(
                        "output.probe_group",
                        format!("{p:?}"),
                        format!("one of the groups: {known:?}"),
                    ));
                }
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

    fn validate_body(&self) -> Result<(), SceneError> {
        let dim = self.dim();
        if dim == 3 && !self.body.is_solid() {
            return Err(invalid(
                "body.shape",
                format!("\"{}\"", self.body.name()),
                format!("a solid for discretisation.lattice = \"fcc\" (3D; \"random\" takes a 2D shape or a solid): \"box\", \"cylinder\", or \"prism\" (a 2D section extruded through a thickness: shape = \"prism\", thickness = …, section = {{ shape = \"{}\", … }})", self.body.name()),
            ));
        }
        if dim == 2 && self.body.is_solid() {
            return Err(invalid(
                "body.shape",
                format!("\"{}\"", self.body.name()),
                "a 2D shape (rectangle, polygon, disc, dogbone, notched_beam) for the hexagonal lattice; the solids box, cylinder and prism need discretisation.lattice = \"fcc\" or \"random\"",
            ));
        }
        if dim == 3 {
            if let Some(t) = self.material.thickness {
                return Err(invalid(
                    "material.thickness",
                    t,
                    "absent in 3D: the body's own extent gives its thickness (a prism's `body.thickness`)",
                ));
            }
            if let Some(p) = self.material.plane {
                return Err(invalid(
                    "material.plane",
                    format!("{p:?}").to_lowercase(),
                    "absent in 3D: plane stress and plane strain are 2D idealisations of a solid",
                ));
            }
        }
        validate_shape(&self.body, "body")
    }
}

/// The values of one body shape, its keys under `key` (`body`, or `body.section` of a prism).
fn validate_shape(body: &BodySpec, key: &str) -> Result<(), SceneError> {
    {
        match body {
            BodySpec::Rectangle {
                width,
                height,
                origin,
            } => {
                positive(&format!("{key}.width"), *width)?;
                positive(&format!("{key}.height"), *height)?;
                finite(&format!("{key}.origin[0]"), origin[0])?;
                finite(&format!("{key}.origin[1]"), origin[1])?;
            }
            BodySpec::Polygon { vertices } => {
                if vertices.len() < 3 {
                    return Err(invalid(
                        format!("{key}.vertices"),
                        format!("{} vertices", vertices.len()),
                        "at least 3 vertices",
                    ));
                }
                for (i, v) in vertices.iter().enumerate() {
                    finite(&format!("body.vertices[{i}][0]"), v[0])?;
                    finite(&format!("body.vertices[{i}][1]"), v[1])?;
                }
                let pts: Vec<_> = vertices.iter().map(|v| Vector2::new(v[0], v[1])).collect();
                if crate::geometry::polygon_area(&pts).abs() <= 0.0 {
                    return Err(invalid(
                        format!("{key}.vertices"),
                        format!("{vertices:?}"),
                        "a polygon with non-zero area",
                    ));
                }
                if polygon_self_intersects(&pts) {
                    return Err(invalid(
                        format!("{key}.vertices"),
                        format!("{vertices:?}"),
                        "a simple polygon: each vertex once, edges that neither cross, touch nor overlap (an outline traversed twice is refused)",
                    ));
                }
            }
            BodySpec::Disc { diameter, centre } => {
                positive(&format!("{key}.diameter"), *diameter)?;
                finite(&format!("{key}.centre[0]"), centre[0])?;
                finite(&format!("{key}.centre[1]"), centre[1])?;
            }
            BodySpec::Dogbone { size } => positive(&format!("{key}.size"), *size)?,
            BodySpec::Box { size, origin } => {
                for d in 0..3 {
                    positive(&format!("{key}.size[{d}]"), size[d])?;
                    finite(&format!("{key}.origin[{d}]"), origin[d])?;
                }
            }
            BodySpec::Cylinder {
                diameter,
                length,
                axis,
                base,
            } => {
                positive(&format!("{key}.diameter"), *diameter)?;
                positive(&format!("{key}.length"), *length)?;
                for d in 0..3 {
                    finite(&format!("{key}.axis[{d}]"), axis[d])?;
                    finite(&format!("{key}.base[{d}]"), base[d])?;
                }
                let norm = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
                if !(norm > 0.0 && norm.is_finite()) {
                    return Err(invalid(
                        format!("{key}.axis"),
                        format!("{axis:?}"),
                        "a direction [x, y, z] of non-zero length (it is normalised)",
                    ));
                }
            }
            BodySpec::Prism { section, thickness } => {
                positive(&format!("{key}.thickness"), *thickness)?;
                if section.is_solid() {
                    return Err(invalid(
                        format!("{key}.section.shape"),
                        format!("\"{}\"", section.name()),
                        "a 2D shape: rectangle, polygon, disc, dogbone or notched_beam",
                    ));
                }
                validate_shape(section, &format!("{key}.section"))?;
            }
            BodySpec::NotchedBeam {
                length,
                depth,
                notch_depth,
                notch_width,
            } => {
                positive(&format!("{key}.length"), *length)?;
                positive(&format!("{key}.depth"), *depth)?;
                if !(notch_depth.is_finite() && *notch_depth >= 0.0 && notch_depth < depth) {
                    return Err(invalid(
                        format!("{key}.notch_depth"),
                        notch_depth,
                        format!("0 <= notch_depth < depth ({depth})"),
                    ));
                }
                if !(notch_width.is_finite() && *notch_width >= 0.0 && notch_width < length) {
                    return Err(invalid(
                        format!("{key}.notch_width"),
                        notch_width,
                        format!("0 <= notch_width < length ({length})"),
                    ));
                }
            }
        }
    }
    Ok(())
}

impl Scene {
    /// The values of `[[cutouts]]`, then their geometry: each must meet the body, one that
    /// crosses the outline must have an exact area (every cutout but a disc across a disc's
    /// or a dog-bone's arc), none may overlap another (crack lines aside), and together they
    /// must leave some of the body.
    fn validate_cutouts(&self) -> Result<(), SceneError> {
        use crate::geometry::{cutout_area_in, Cutout, Shape2};
        if self.cutouts.is_empty() {
            return Ok(());
        }
        if matches!(self.body, BodySpec::Box { .. } | BodySpec::Cylinder { .. }) {
            return Err(invalid(
                "cutouts",
                format!("{} cutouts on body.shape = \"{}\"", self.cutouts.len(), self.body.name()),
                "cutouts on a 2D body or on a prism's section (shape = \"prism\"), through its whole thickness",
            ));
        }
        let outer = self.outer_shape();
        let size = outer.size();
        // a cutout lies within a thousand times the body's size of it (beyond, its numbers
        // would only lose the body's digits)
        let reach = 1e3 * size;
        let (lo, hi) = outer.bounding_box();
        let point = |key: &str, p: &[f64; 2]| -> Result<(), SceneError> {
            for (c, (l, h)) in [(lo.x, hi.x), (lo.y, hi.y)].into_iter().enumerate() {
                let k = format!("{key}[{c}]");
                finite(&k, p[c])?;
                if p[c] < l - reach || p[c] > h + reach {
                    return Err(invalid(
                        k,
                        p[c],
                        format!("within 1000 × the body's size ({reach:.4e} m) of the body, [{:.4e}, {:.4e}] m", l - reach, h + reach),
                    ));
                }
            }
            Ok(())
        };
        let length = |key: String, v: f64| -> Result<(), SceneError> {
            positive(&key, v)?;
            if v > reach {
                return Err(invalid(
                    key,
                    v,
                    format!("at most 1000 × the body's size ({reach:.4e} m)"),
                ));
            }
            Ok(())
        };
        for (i, c) in self.cutouts.iter().enumerate() {
            let key = format!("cutouts[{i}]");
            match c {
                CutoutSpec::Disc { centre, diameter } => {
                    point(&format!("{key}.centre"), centre)?;
                    length(format!("{key}.diameter"), *diameter)?;
                }
                CutoutSpec::Polygon { vertices } => {
                    if vertices.len() < 3 {
                        return Err(invalid(
                            format!("{key}.vertices"),
                            format!("{} vertices", vertices.len()),
                            "at least 3 vertices",
                        ));
                    }
                    for (k, v) in vertices.iter().enumerate() {
                        point(&format!("{key}.vertices[{k}]"), v)?;
                    }
                    let pts: Vec<_> = vertices.iter().map(|v| Vector2::new(v[0], v[1])).collect();
                    if crate::geometry::polygon_area(&pts).abs() <= 0.0 {
                        return Err(invalid(
                            format!("{key}.vertices"),
                            format!("{vertices:?}"),
                            "a polygon with non-zero area",
                        ));
                    }
                    if polygon_self_intersects(&pts) {
                        return Err(invalid(
                            format!("{key}.vertices"),
                            format!("{vertices:?}"),
                            "a simple polygon: each vertex once, edges that neither cross, touch nor overlap",
                        ));
                    }
                }
                CutoutSpec::Slit { start, end, width } => {
                    point(&format!("{key}.start"), start)?;
                    point(&format!("{key}.end"), end)?;
                    let length = (Vector2::new(end[0] - start[0], end[1] - start[1])).norm();
                    if length <= 1e-9 * size {
                        return Err(invalid(
                            format!("{key}.end"),
                            format!("{end:?}"),
                            format!(
                                "a slit of non-zero length: end must differ from start = {start:?}"
                            ),
                        ));
                    }
                    if !(width.is_finite() && *width >= 0.0 && *width <= reach) {
                        return Err(invalid(
                            format!("{key}.width"),
                            width,
                            format!("a width from 0 to 1000 × the body's size ({reach:.4e} m); 0 is a crack line, which removes no area, only the bonds that cross it"),
                        ));
                    }
                }
                CutoutSpec::Rectangle {
                    origin,
                    width,
                    height,
                    rotation_deg,
                } => {
                    point(&format!("{key}.origin"), origin)?;
                    length(format!("{key}.width"), *width)?;
                    length(format!("{key}.height"), *height)?;
                    finite(&format!("{key}.rotation_deg"), *rotation_deg)?;
                }
            }
        }
        let cutouts: Vec<Cutout> = self.cutouts.iter().map(CutoutSpec::cutout).collect();
        let outer_area = outer.area();
        for (i, (c, spec)) in cutouts.iter().zip(&self.cutouts).enumerate() {
            let (lo, hi) = outer.bounding_box();
            let outside = || {
                invalid(
                    format!("cutouts[{i}]"),
                    spec.scene_text(),
                    format!(
                        "a cutout that meets the body; this one lies outside the body (the body spans x ∈ [{:.6}, {:.6}] m, y ∈ [{:.6}, {:.6}] m)",
                        lo.x, hi.x, lo.y, hi.y
                    ),
                )
            };
            let whole = || {
                invalid(
                    format!("cutouts[{i}]"),
                    spec.scene_text(),
                    "a cutout that leaves some of the body; this one removes the whole body",
                )
            };
            if !c.removes_area() {
                let alone = Shape2::WithCutouts {
                    outer: Box::new(outer.clone()),
                    cutouts: vec![c.clone()],
                };
                if alone.cutout_outlines().is_empty() {
                    return Err(outside());
                }
                continue;
            }
            let own = c.area();
            match cutout_area_in(&outer, c, None) {
                Some(a) if a <= 1e-9 * own => return Err(outside()),
                Some(a) if a >= (1.0 - 1e-9) * outer_area => return Err(whole()),
                Some(_) => {}
                None => {
                    // a disc across an arc: classify it on the chords, to name the problem
                    let a = crate::geometry::cutout_area_in_or_chords(&outer, c, None);
                    if a <= 1e-6 * own {
                        return Err(outside());
                    }
                    if a >= (1.0 - 1e-6) * outer_area {
                        return Err(whole());
                    }
                    return Err(invalid(
                        format!("cutouts[{i}]"),
                        spec.scene_text(),
                        "a disc cutout inside the body or clear of it: a disc that crosses the arc of a disc or dog-bone body has no exact area here (its particles' volumes would be wrong); move it inside the body, or cut the notch as a polygon",
                    ));
                }
            }
        }
        for j in 0..cutouts.len() {
            for i in 0..j {
                let overlap = cutouts[i].overlap_area(&cutouts[j]);
                if overlap > 1e-9 * cutouts[i].area().min(cutouts[j].area()) {
                    return Err(invalid(
                        format!("cutouts[{j}]"),
                        self.cutouts[j].scene_text(),
                        format!(
                            "cutouts must not overlap: this one overlaps cutouts[{i}] = {} by {overlap:.4e} m² (a slit of width 0, a crack line, may cross others)",
                            self.cutouts[i].scene_text()
                        ),
                    ));
                }
            }
        }
        let area = self.shape().area();
        if area <= 1e-9 * outer_area {
            return Err(invalid(
                "cutouts",
                format!("{} cutouts", cutouts.len()),
                format!(
                    "cutouts that leave some of the body; cutouts[0] to cutouts[{}] together remove all of it ({outer_area:.4e} m²)",
                    cutouts.len() - 1
                ),
            ));
        }
        Ok(())
    }

    /// The body's smallest overall dimension (m).
    pub fn body_size(&self) -> f64 {
        shape_size(&self.body, &self.shape())
    }

    /// The geometric shape of the body: the outer shape ([`Self::outer_shape`]) and, when the
    /// scene has cutouts, less them (`Shape2::WithCutouts`). For a solid: a prism's section;
    /// the xy-extent of a box or a cylinder (3D code asks for [`Self::solid`]).
    pub fn shape(&self) -> crate::geometry::Shape2 {
        let outer = self.outer_shape();
        if self.cutouts.is_empty() {
            return outer;
        }
        crate::geometry::Shape2::WithCutouts {
            outer: Box::new(outer),
            cutouts: self.cutouts.iter().map(CutoutSpec::cutout).collect(),
        }
    }

    /// The shape of `[body]`, without the cutouts (see [`Self::shape`] for solids).
    pub fn outer_shape(&self) -> crate::geometry::Shape2 {
        section_shape(&self.body)
    }

    /// The 2D section a 3D body keeps all along z (a prism's, a cylinder's along z: the
    /// plane in which its strips are drawn); `None` for other bodies.
    pub fn section_along_z(&self) -> Option<crate::geometry::Shape2> {
        self.has_section_along_z().then(|| self.shape())
    }

    /// Whether the body is a prism or a cylinder along z ([`Self::section_along_z`]).
    fn has_section_along_z(&self) -> bool {
        match &self.body {
            BodySpec::Prism { .. } => true,
            BodySpec::Cylinder { axis, .. } => z_axis_only(axis),
            _ => false,
        }
    }

    /// The solid of a 3D scene: a box, a cylinder (its axis normalised), or the prism of
    /// [`Self::shape`] (the section with the cutouts); `None` for a 2D body.
    pub fn solid(&self) -> Option<crate::geometry::Shape3> {
        use crate::geometry::Shape3;
        use nalgebra::Vector3;
        match &self.body {
            BodySpec::Box { size, origin } => Some(Shape3::Box {
                origin: Vector3::from(*origin),
                size: Vector3::from(*size),
            }),
            BodySpec::Cylinder {
                diameter,
                length,
                axis,
                base,
            } => Some(Shape3::Cylinder {
                base: Vector3::from(*base),
                axis: Vector3::from(*axis).normalize(),
                radius: 0.5 * diameter,
                length: *length,
            }),
            BodySpec::Prism { thickness, .. } => Some(Shape3::Extruded {
                section: self.shape(),
                thickness: *thickness,
            }),
            _ => None,
        }
    }
}

/// Whether a cylinder's axis runs along z.
fn z_axis_only(axis: &[f64; 3]) -> bool {
    let a = nalgebra::Vector3::from(*axis).normalize();
    a.x.abs() < 1e-12 && a.y.abs() < 1e-12
}

/// The smallest overall dimension (m) of a body shape (`shape`: its 2D shape).
fn shape_size(body: &BodySpec, shape: &crate::geometry::Shape2) -> f64 {
    match body {
        BodySpec::Rectangle { width, height, .. } => width.min(*height),
        BodySpec::Polygon { .. } => {
            let (lo, hi) = shape.bounding_box();
            (hi - lo).min()
        }
        BodySpec::Disc { diameter, .. } => *diameter,
        BodySpec::Dogbone { size } => 0.6 * size,
        BodySpec::NotchedBeam { length, depth, .. } => length.min(*depth),
        BodySpec::Box { size, .. } => size[0].min(size[1]).min(size[2]),
        BodySpec::Cylinder {
            diameter, length, ..
        } => diameter.min(*length),
        BodySpec::Prism { section, thickness } => shape_size(section, shape).min(*thickness),
    }
}

/// The 2D shape of a body shape: itself, a prism's section, the xy-extent of a box, the
/// disc of a cylinder along z (the xy-bounding rectangle of one along another axis).
fn section_shape(body: &BodySpec) -> crate::geometry::Shape2 {
    use crate::geometry::Shape2;
    match body {
        BodySpec::Rectangle {
            width,
            height,
            origin,
        } => Shape2::Rectangle {
            origin: Vector2::new(origin[0], origin[1]),
            width: *width,
            height: *height,
        },
        BodySpec::Polygon { vertices } => Shape2::Polygon {
            vertices: vertices.iter().map(|v| Vector2::new(v[0], v[1])).collect(),
        },
        BodySpec::Disc { diameter, centre } => Shape2::Disc {
            centre: Vector2::new(centre[0], centre[1]),
            radius: 0.5 * diameter,
        },
        BodySpec::Dogbone { size } => Shape2::DogBone { size: *size },
        BodySpec::NotchedBeam {
            length,
            depth,
            notch_depth,
            notch_width,
        } => Shape2::NotchedBeam {
            length: *length,
            depth: *depth,
            notch_depth: *notch_depth,
            notch_width: *notch_width,
        },
        BodySpec::Box { size, origin } => Shape2::Rectangle {
            origin: Vector2::new(origin[0], origin[1]),
            width: size[0],
            height: size[1],
        },
        BodySpec::Cylinder {
            diameter,
            length,
            axis,
            base,
        } => {
            let a = nalgebra::Vector3::from(*axis).normalize();
            let r = 0.5 * diameter;
            if z_axis_only(axis) {
                return Shape2::Disc {
                    centre: Vector2::new(base[0], base[1]),
                    radius: r,
                };
            }
            let solid = crate::geometry::Shape3::Cylinder {
                base: nalgebra::Vector3::from(*base),
                axis: a,
                radius: r,
                length: *length,
            };
            let (lo, hi) = solid.bounding_box();
            Shape2::Rectangle {
                origin: Vector2::new(lo.x, lo.y),
                width: hi.x - lo.x,
                height: hi.y - lo.y,
            }
        }
        BodySpec::Prism { section, .. } => section_shape(section),
    }
}

impl Scene {
    /// The keys of `solver.method = "relaxation"`.
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
                    let known: Vec<_> = self.groups.iter().map(|g| g.name.as_str()).collect();
                    return Err(invalid(
                        key,
                        format!("{name:?}"),
                        format!("one of the groups: {known:?}"),
                    ));
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
}
