//! `[body]`: a shape of the scene's dimension and the values of that shape.

use super::{finite, invalid, positive, simple_polygon, SceneError};
use crate::scene::{BodySpec, Scene};

impl Scene {
    /// The body's shape against the dimension of the lattice (a 3D body also refuses the 2D
    /// keys of `[material]`), then its values.
    pub(super) fn validate_body(&self) -> Result<(), SceneError> {
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
        BodySpec::Polygon { vertices } => simple_polygon(
            key,
            vertices,
            |i, v| {
                finite(&format!("body.vertices[{i}][0]"), v[0])?;
                finite(&format!("body.vertices[{i}][1]"), v[1])
            },
            "a simple polygon: each vertex once, edges that neither cross, touch nor overlap (an outline traversed twice is refused)",
        )?,
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
        } => cylinder(key, *diameter, *length, axis, base)?,
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
        } => notched_beam(key, *length, *depth, *notch_depth, *notch_width)?,
    }
    Ok(())
}

/// A cylinder's values: its size, and an axis of non-zero length.
fn cylinder(
    key: &str,
    diameter: f64,
    length: f64,
    axis: &[f64; 3],
    base: &[f64; 3],
) -> Result<(), SceneError> {
    positive(&format!("{key}.diameter"), diameter)?;
    positive(&format!("{key}.length"), length)?;
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
    Ok(())
}

/// A notched beam's values: its size, and a notch that leaves some of the beam.
fn notched_beam(
    key: &str,
    length: f64,
    depth: f64,
    notch_depth: f64,
    notch_width: f64,
) -> Result<(), SceneError> {
    positive(&format!("{key}.length"), length)?;
    positive(&format!("{key}.depth"), depth)?;
    if !(notch_depth.is_finite() && notch_depth >= 0.0 && notch_depth < depth) {
        return Err(invalid(
            format!("{key}.notch_depth"),
            notch_depth,
            format!("0 <= notch_depth < depth ({depth})"),
        ));
    }
    if !(notch_width.is_finite() && notch_width >= 0.0 && notch_width < length) {
        return Err(invalid(
            format!("{key}.notch_width"),
            notch_width,
            format!("0 <= notch_width < length ({length})"),
        ));
    }
    Ok(())
}
