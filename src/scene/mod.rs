//! Scene files: the TOML description of one specimen, its discretisation, material, loading
//! and outputs (ARCHITECTURE.md, "scene"). Parsing rejects unknown keys (serde's
//! `deny_unknown_fields`), and [`Scene::validate`] rejects impossible values, each with one
//! message that names the key, the value and what is allowed.

mod overrides;
mod validate;

pub use overrides::apply_overrides;
pub use validate::SceneError;

use serde::{Deserialize, Serialize};
use std::path::Path;

/// A complete scene as read from a TOML file.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Name used for the output folder; defaults to the file stem.
    #[serde(default)]
    pub name: Option<String>,
    /// Free text shown in the summary.
    #[serde(default)]
    pub description: Option<String>,
    pub body: BodySpec,
    pub discretisation: DiscretisationSpec,
    pub material: MaterialSpec,
    #[serde(default)]
    pub groups: Vec<GroupSpec>,
    #[serde(default)]
    pub loading: LoadingSpec,
    #[serde(default)]
    pub damping: DampingSpec,
    #[serde(default)]
    pub solver: SolverSpec,
    #[serde(default)]
    pub output: OutputSpec,
}

/// The specimen's shape (`[body] shape = "..."`). Lengths in metres.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum BodySpec {
    Rectangle {
        width: f64,
        height: f64,
        #[serde(default)]
        origin: [f64; 2],
    },
    Polygon {
        vertices: Vec<[f64; 2]>,
    },
    Disc {
        diameter: f64,
        #[serde(default)]
        centre: [f64; 2],
    },
    /// van Vliet dog-bone of size D (VALIDATION.md §D).
    Dogbone {
        size: f64,
    },
    NotchedBeam {
        length: f64,
        depth: f64,
        notch_depth: f64,
        notch_width: f64,
    },
}

/// How the body is filled with particles.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DiscretisationSpec {
    /// "hexagonal" (2D SPLM). Later: "fcc", "random".
    #[serde(default = "default_lattice")]
    pub lattice: String,
    /// Nearest-neighbour spacing L0 (m).
    pub spacing: f64,
    /// Lattice rotation about the origin, degrees.
    #[serde(default)]
    pub rotation_deg: f64,
    /// Lattice offset (m), applied after rotation.
    #[serde(default)]
    pub offset: [f64; 2],
    /// Per-particle micro-moduli for particles with missing bonds, fitted the SPPM way
    /// (MODEL.md §3, "surface correction"). Default off: on a plate in tension it makes the
    /// edges too stiff by about as much as they are too soft without it (E +0.25% on,
    /// −0.20% off at W/L0 = 100; +1.02% / −0.77% at W/L0 = 25; tests/elastic_plate.rs).
    #[serde(default)]
    pub surface_correction: bool,
}

fn default_lattice() -> String {
    "hexagonal".into()
}
fn default_true() -> bool {
    true
}

/// Plane stress or plane strain (2D).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Plane {
    Stress,
    Strain,
}

/// Elastic material (SI units). Concrete parameters arrive with the damage model.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Young's modulus E (Pa).
    #[serde(rename = "E")]
    pub e: f64,
    /// Poisson's ratio ν.
    pub nu: f64,
    /// Density ρ (kg/m³).
    pub rho: f64,
    /// Thickness t (m) of the 2D specimen.
    pub thickness: f64,
    #[serde(default = "default_plane")]
    pub plane: Plane,
}

fn default_plane() -> Plane {
    Plane::Stress
}

/// A named set of particles, with its supports and displacement loading.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GroupSpec {
    pub name: String,
    pub select: Selection,
    /// Components held at zero displacement: any of "x", "y".
    #[serde(default)]
    pub fix: Vec<Axis>,
    /// Displacement-controlled loading of this group.
    #[serde(default)]
    pub load: Option<LoadSpec>,
}

/// A coordinate axis.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    X,
    Y,
}

impl Axis {
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
        }
    }
}

/// An edge of the body's bounding box.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Edge {
    Bottom,
    Top,
    Left,
    Right,
}

/// How the particles of a group are chosen.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(tag = "by", rename_all = "snake_case", deny_unknown_fields)]
pub enum Selection {
    /// The `rows` particle rows nearest an edge (row pitch √3/2·L0).
    Edge { edge: Edge, rows: u32 },
    /// The particles under a loading strip (platen) of `width` centred at `centre` along the
    /// edge: those within `depth` of the body's surface at their position (default: two
    /// row pitches, √3·L0), so that a curved surface is followed.
    Strip {
        edge: Edge,
        width: f64,
        #[serde(default)]
        centre: f64,
        #[serde(default)]
        depth: Option<f64>,
    },
    /// Particles inside an axis-aligned box.
    Box { min: [f64; 2], max: [f64; 2] },
    /// Every particle.
    All,
}

/// Displacement loading of one component of a group.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// Loaded component: "x" or "y".
    pub component: Axis,
    /// Δmax (m): the displacement at the end of the ramp (signed).
    pub displacement: f64,
}

/// Time history of the displacement loading (MODEL.md §10).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LoadingSpec {
    /// "cosine" (5.5) or "smoothstep" (seed 000, Eq. 4.9).
    #[serde(default = "default_ramp")]
    pub ramp: Ramp,
    /// t_ramp / t_end (5.5 uses 0.8).
    #[serde(default = "default_ramp_fraction")]
    pub ramp_fraction: f64,
    /// t_end as a multiple of the computed fundamental period T1.
    #[serde(default)]
    pub end_periods: Option<f64>,
    /// t_end in seconds (instead of end_periods).
    #[serde(default)]
    pub end_s: Option<f64>,
}

impl Default for LoadingSpec {
    fn default() -> Self {
        LoadingSpec {
            ramp: default_ramp(),
            ramp_fraction: default_ramp_fraction(),
            end_periods: None,
            end_s: None,
        }
    }
}

/// Ramp shapes.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Ramp {
    Cosine,
    Smoothstep,
}

fn default_ramp() -> Ramp {
    Ramp::Cosine
}
fn default_ramp_fraction() -> f64 {
    0.8
}

/// Damping ratios (MODEL.md §5).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DampingSpec {
    /// ξ_in, bond dampers (3.55).
    #[serde(default)]
    pub internal: f64,
    /// ξ_ex, particle-velocity dampers on the fundamental mode (3.56).
    #[serde(default)]
    pub external: f64,
}

impl Default for DampingSpec {
    fn default() -> Self {
        DampingSpec {
            internal: 0.0,
            external: 0.0,
        }
    }
}

/// Which reading of the source's one-step force lag (MODEL.md §4). Default chosen by
/// measurement (tests/vibration_and_stability.rs, tests/run_plate.rs):
///
/// - undamped free vibration of a bar over 100 periods: (B) drifts by −6.6e-6 in energy
///   (largest excursion 1.2e-3); (A) blows up within 51 steps (energy ×3.8e25);
/// - damped plate in tension (ξ_in = 0.2, ξ_ex = 1): (A) is unstable from 0.6× the stable
///   step of (B) upwards, stable at 0.45–0.5× where its peak force agrees with (B) to 1.4e-6.
///
/// So (B) is as accurate and needs half the steps or fewer; (A) stays selectable.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ForceLag {
    /// (B) elastic forces from the current positions (default: stable, see solver docs).
    Current,
    /// (A) the literal reading: forces computed at step n−1 used at step n.
    Previous,
}

/// Time integration settings.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// Δt = safety × the computed stable limit.
    #[serde(default = "default_safety")]
    pub safety: f64,
    /// A fixed time step (s); refused if above the stable limit.
    #[serde(default)]
    pub dt: Option<f64>,
    #[serde(default = "default_lag")]
    pub force_lag: ForceLag,
    /// Worker threads (default: all cores).
    #[serde(default)]
    pub threads: Option<usize>,
}

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec {
            safety: default_safety(),
            dt: None,
            force_lag: default_lag(),
            threads: None,
        }
    }
}

fn default_safety() -> f64 {
    0.9
}
fn default_lag() -> ForceLag {
    ForceLag::Current
}

/// A per-particle field shown in the particle map and written to VTK.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Field {
    Displacement,
    DisplacementX,
    DisplacementY,
    StressXx,
    StressYy,
    StressXy,
    StressVonMises,
    MaxPrincipalStress,
}

/// What is written, and how often the probes sample.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Number of samples of the force–displacement curve and energies.
    #[serde(default = "default_records")]
    pub records: usize,
    /// The group whose reaction and displacement make the force–displacement curve
    /// (default: the first loaded group).
    #[serde(default)]
    pub probe_group: Option<String>,
    /// Field of the particle map.
    #[serde(default = "default_field")]
    pub field: Field,
    /// Magnification of displacements in the particle map (0: reference shape).
    #[serde(default)]
    pub deformed_scale: f64,
    /// Write the particle map SVG.
    #[serde(default = "default_true")]
    pub map: bool,
    /// Write a VTK file of the particles.
    #[serde(default = "default_true")]
    pub vtk: bool,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            records: default_records(),
            probe_group: None,
            field: default_field(),
            deformed_scale: 0.0,
            map: true,
            vtk: true,
        }
    }
}

fn default_records() -> usize {
    200
}
fn default_field() -> Field {
    Field::Displacement
}

impl Scene {
    /// Parse TOML text, apply `key=value` overrides, and validate.
    pub fn from_toml_str(text: &str, overrides: &[String]) -> Result<Scene, SceneError> {
        let mut value: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| SceneError::Parse(e.to_string()))?;
        apply_overrides(&mut value, overrides)?;
        let scene: Scene = Scene::deserialize(toml::Value::Table(value))
            .map_err(|e| SceneError::Parse(e.to_string()))?;
        scene.validate()?;
        Ok(scene)
    }

    /// Read a scene file; the scene's name defaults to the file stem.
    pub fn from_file(path: &Path, overrides: &[String]) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| SceneError::Io(format!("cannot read {}: {e}", path.display())))?;
        let mut scene = Scene::from_toml_str(&text, overrides).map_err(|e| e.in_file(path))?;
        if scene.name.is_none() {
            scene.name = path.file_stem().map(|s| s.to_string_lossy().into_owned());
        }
        Ok(scene)
    }

    pub fn name(&self) -> &str {
        self.name.as_deref().unwrap_or("scene")
    }
}
