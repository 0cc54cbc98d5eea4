//! Scene validation: every impossible value is refused before any work, with one message
//! naming the key, the value and what is allowed. One function per scene table, called in a
//! fixed order by [`Scene::validate`]: the first problem found is the one reported.

mod body;
mod cutouts;
mod discretisation;
mod failure;
mod gauges;
mod groups;
mod loading;
mod material;
mod model;
mod output;
mod solver;

use super::Scene;
use crate::geometry::polygon_self_intersects;
use nalgebra::Vector2;

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

/// The vertices under `key` (a body's or a cutout's) of a simple polygon: at least three,
/// each accepted by `vertex` (its index and value), a non-zero area, and no edges that cross
/// (`simple`: what the message asks for).
fn simple_polygon(
    key: &str,
    vertices: &[[f64; 2]],
    vertex: impl Fn(usize, &[f64; 2]) -> Result<(), SceneError>,
    simple: &str,
) -> Result<(), SceneError> {
    if vertices.len() < 3 {
        return Err(invalid(
            format!("{key}.vertices"),
            format!("{} vertices", vertices.len()),
            "at least 3 vertices",
        ));
    }
    for (i, v) in vertices.iter().enumerate() {
        vertex(i, v)?;
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
            simple,
        ));
    }
    Ok(())
}

impl Scene {
    /// Check every value, table by table; the first problem found is returned.
    pub fn validate(&self) -> Result<(), SceneError> {
        self.validate_geometry()?;
        self.validate_resolved()
    }

    /// The tables after the geometry, which need the resolved material values;
    /// [`Scene::from_toml_str`] runs it after [`Scene::resolve`].
    pub(crate) fn validate_resolved(&self) -> Result<(), SceneError> {
        super::random_fields::check(self)?;
        self.validate_material()?;
        self.validate_groups()?;
        self.validate_loading()?;
        self.validate_damping()?;
        self.validate_failure()?;
        self.validate_solver()?;
        self.validate_model()?;
        self.validate_output()?;
        self.validate_gauges()
    }

    /// The name, the body, its cutouts and the discretisation: what the material's
    /// correlations and checks need to be valid (the spacing against the body), so
    /// [`Scene::from_toml_str`] runs it before [`Scene::resolve`].
    pub fn validate_geometry(&self) -> Result<(), SceneError> {
        self.validate_name()?;
        self.validate_body()?;
        self.validate_cutouts()?;
        self.validate_discretisation()
    }

    /// `name` is no group of the scene: the error under `key`, naming the groups there are.
    fn unknown_group(&self, key: &str, name: &str) -> SceneError {
        let known: Vec<_> = self.groups.iter().map(|g| g.name.as_str()).collect();
        invalid(
            key,
            format!("{name:?}"),
            format!("one of the groups: {known:?}"),
        )
    }

    /// `name`: it names the output folder.
    fn validate_name(&self) -> Result<(), SceneError> {
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
        Ok(())
    }
}
