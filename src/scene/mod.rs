//! Scene files: the TOML description of one specimen, its discretisation, material, loading
//! and outputs (docs/architecture.md, "scene"). Parsing rejects unknown keys (serde's
//! `deny_unknown_fields`), and [`Scene::validate`] rejects impossible values, each with one
//! message that names the key, the value and what is allowed.

mod body;
pub mod concrete;
mod discretisation;
pub mod failure;
pub mod gauge;
mod loading;
pub mod model_family;
mod overrides;
mod plausible;
pub mod random_fields;
mod resolve;
mod solver_settings;
mod validate;

pub use body::{BodySpec, CutoutSpec};
pub use discretisation::{Discretisation, DiscretisationSpec, Lattice, Rotation, Surface};
pub use loading::{
    BondScheme, DampingSpec, LoadSpec, LoadingSpec, Pace, Ramp, DEFAULT_END_PERIODS, KINETIC_LIMIT,
};
pub use model_family::{Family, ModelSpec};
pub use overrides::apply_overrides;
pub use solver_settings::{ControlSpec, ForceLag, SolverMethod, SolverSpec};
pub use validate::SceneError;

use concrete::{Derived, Preset};
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
    /// The seed of every random choice the scene makes (its random fields); recorded in the
    /// summary. Defaults to [`DEFAULT_SEED`] when the scene has random fields.
    #[serde(default)]
    pub seed: Option<u64>,
    pub body: BodySpec,
    /// Holes, slits, notches and crack lines cut out of the body (`[[cutouts]]`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cutouts: Vec<CutoutSpec>,
    pub discretisation: DiscretisationSpec,
    pub material: MaterialSpec,
    /// Concrete damage and plasticity (docs/model.md §6–9, §11); its presence turns them on.
    #[serde(default)]
    pub concrete: Option<ConcreteSpec>,
    /// Random-field material properties (docs/model.md §12), one table per property.
    #[serde(default)]
    pub random_field: Vec<RandomFieldSpec>,
    #[serde(default)]
    pub groups: Vec<GroupSpec>,
    #[serde(default)]
    pub loading: LoadingSpec,
    #[serde(default)]
    pub damping: DampingSpec,
    /// The criterion that judges a force-controlled load (`[failure]`, docs/failure.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub failure: Option<failure::FailureSpec>,
    #[serde(default)]
    pub solver: SolverSpec,
    /// The model family and the bond-based model's choices (`[model]`; default the
    /// state-based lattice).
    #[serde(default)]
    pub model: ModelSpec,
    #[serde(default)]
    pub output: OutputSpec,
    /// Openings measured during the run (`[[gauges]]`): CMOD, LVDTs.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub gauges: Vec<gauge::GaugeSpec>,
    /// Every material value the run uses and where it came from (scene, preset or
    /// correlation), filled by [`Scene::resolve`]; not read from the file.
    #[serde(skip_deserializing)]
    pub derived: Vec<Derived>,
    /// Inputs outside the usual range of their quantity, accepted (docs/scenes.md, "Units
    /// and plausible values"); repeated in the run's summary.json. Not read from the file.
    #[serde(skip)]
    pub warnings: Vec<String>,
}

/// The seed of a scene's random choices when it gives none.
pub const DEFAULT_SEED: u64 = 20_240_401;

/// A material property that a random field can vary per particle (docs/model.md §12).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, Hash)]
pub enum FieldProperty {
    /// Tensile strength f't.
    #[serde(rename = "ft")]
    Ft,
    /// Young's modulus E.
    #[serde(rename = "E")]
    E,
    /// Fracture energy G_f.
    #[serde(rename = "Gf")]
    Gf,
    /// Compressive strength f'c (with f_y and f_ult in proportion).
    #[serde(rename = "fc")]
    Fc,
}

impl FieldProperty {
    /// The name as a scene writes it.
    pub fn name(self) -> &'static str {
        match self {
            FieldProperty::Ft => "ft",
            FieldProperty::E => "E",
            FieldProperty::Gf => "Gf",
            FieldProperty::Fc => "fc",
        }
    }
}

/// Correlation function of a random field (`random_field.correlation`).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum CorrelationKind {
    Exponential,
    SquaredExponential,
}

/// One-point distribution of a random field (`random_field.marginal`).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum MarginalKind {
    /// Normal truncated at zero.
    Normal,
    Lognormal,
    Weibull,
}

/// `[[random_field]]`: one material property drawn per particle from a correlated random
/// field (docs/model.md §12).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RandomFieldSpec {
    pub property: FieldProperty,
    pub correlation: CorrelationKind,
    /// Correlation length ℓ in m; 0 gives an uncorrelated (white) field.
    pub length: f64,
    pub marginal: MarginalKind,
    /// Mean of the property; defaults to its deterministic value (scene, preset or correlation).
    #[serde(default)]
    pub mean: Option<f64>,
    /// Coefficient of variation (give this or, for Weibull, `modulus`).
    #[serde(default)]
    pub cov: Option<f64>,
    /// Weibull modulus m (instead of `cov`).
    #[serde(default)]
    pub modulus: Option<f64>,
    /// Seed of this field; defaults to one derived from the scene's `seed` and the property.
    #[serde(default)]
    pub seed: Option<u64>,
    /// Only for `property = "ft"`: G_f follows f't in proportion, G_f,i = G_f·f't,i/mean, so
    /// that COD_c stays the same everywhere.
    #[serde(default)]
    pub tie_gf: bool,
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
    /// Young's modulus E (Pa). May be left out when a `[concrete]` section is given: it then
    /// follows from f'c and ρ by ACI 318-14 (5.2). Always set after [`Scene::resolve`].
    #[serde(rename = "E", default)]
    pub e: Option<f64>,
    /// Poisson's ratio ν.
    pub nu: f64,
    /// Density ρ (kg/m³).
    pub rho: f64,
    /// Thickness t (m) of the 2D specimen (required in 2D; a 3D body has its own extent and
    /// refuses it).
    #[serde(default)]
    pub thickness: Option<f64>,
    /// Plane stress or plane strain (2D; default plane stress; refused in 3D).
    #[serde(default)]
    pub plane: Option<Plane>,
}

impl MaterialSpec {
    /// The 2D thickness t (m; validated present in 2D, NaN in 3D).
    pub fn thickness(&self) -> f64 {
        self.thickness.unwrap_or(f64::NAN)
    }

    /// Plane stress or strain of a 2D scene (plane stress unless given; the 3D formulas
    /// ignore it).
    pub fn plane(&self) -> Plane {
        self.plane.unwrap_or(Plane::Stress)
    }

    /// Young's modulus (Pa) after [`Scene::resolve`].
    pub fn youngs_modulus(&self) -> f64 {
        self.e.unwrap_or(f64::NAN)
    }
}

/// How tensile damage starts (docs/model.md §8).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Initiation {
    /// σ_PI ≥ f't.
    Rankine,
    /// σ_PI/f't − min(σ_PIII, 0)/f'c ≥ 1.
    Interaction,
}

/// Which crack opening drives the softening law (docs/model.md §8).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum CrackOpening {
    /// COD_eq = 2·L0·ε_I as written in (4.13) (w_t jumps at initiation).
    Total,
    /// COD_eq measured from initiation: 2·L0·(ε_I − ε_I at initiation).
    Inelastic,
    /// COD_eq from the stress (4.14) softens, over E: crack_band·L0·σ_ref/E (S.23). With
    /// `softening_stress = "stress"` that is σ̃_I/E, the strain the particle would have in
    /// uniaxial tension at its principal stress; with `"strain"` it is ε_I, as written.
    Stress,
}

/// What the tensile damage (4.14) makes follow the softening law (docs/model.md §8, (S.22)).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum SofteningStress {
    /// (1 − w_t)·E·ε_I, as (4.14) writes it (the 2D default).
    Strain,
    /// (1 − w_t)·σ̃_I, σ̃_I the largest principal stress of the particle's undamaged elastic
    /// strain (the effective stress): equal to E·ε_I in uniaxial tension, below it where the
    /// particle is compressed across the crack (the 3D default).
    Stress,
}

/// Which strain the concrete criteria (initiation, yield) read (docs/model.md §7, (S.16)).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum CriteriaStrain {
    /// The volume-weighted mean over the particle and its undamaged bonded neighbours (S.16).
    Neighbourhood,
    /// The particle's own least-squares strain (the source's pointwise criteria).
    Own,
    /// The mean (S.16) at surface particles (those with fewer bonds than the bulk), each
    /// particle's own strain in the bulk.
    Surface,
}

/// Concrete (docs/model.md §6–9, §11). Strengths in Pa, G_f in N/m (J/m²), lengths in m. A value
/// left out comes from the preset, else from the correlation of §11, else the default shown.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ConcreteSpec {
    /// A concrete of the source (see [`Preset`]); fills f'c, d_max and, for the dog-bones, f't.
    #[serde(default)]
    pub preset: Option<Preset>,
    /// Compressive strength f'c (Pa).
    #[serde(default)]
    pub fc: Option<f64>,
    /// Tensile strength f't (Pa); default ACI 318-92, 6·√f'c psi (5.1).
    #[serde(default)]
    pub ft: Option<f64>,
    /// Yield strength f_y (Pa); default (5/6)·f'c.
    #[serde(default)]
    pub fy: Option<f64>,
    /// Ultimate strength f_ult (Pa) reached at ε_ult; default f'c.
    #[serde(default)]
    pub fult: Option<f64>,
    /// Fracture energy G_f (N/m); default CEB-FIP 1990 (5.3) from G_f0 and f'c.
    #[serde(rename = "Gf", default)]
    pub gf: Option<f64>,
    /// Base fracture energy G_f0 (N/m); default from the maximum aggregate size.
    #[serde(rename = "Gf0", default)]
    pub gf0: Option<f64>,
    /// Maximum aggregate size d_max (m): 0.008, 0.016, 0.019 or 0.032.
    #[serde(default)]
    pub max_aggregate: Option<f64>,
    /// Ultimate strain ε_ult: w_c = 1 beyond it (4.17); default 0.0035.
    #[serde(default = "default_eps_ult")]
    pub eps_ult: f64,
    /// Knee of the bilinear softening law at COD_1 = α·COD_c; default 0.1.
    #[serde(default = "default_alpha")]
    pub alpha: f64,
    /// Stress at the knee γ·f't; default 0.25.
    #[serde(default = "default_gamma")]
    pub gamma: f64,
    /// w_t above which compressive damage starts (4.16); default 1/3.
    #[serde(default = "default_wt_cr")]
    pub wt_cr: f64,
    /// Largest compressive damage from (4.16); default 1.
    #[serde(default = "default_wc_max")]
    pub wc_max: f64,
    /// The crack-band length of (4.13) in units of L0 (each particle's own length):
    /// COD_eq = crack_band·L0·ε_I. (4.13) writes 2; the defaults are measured. Lattices 2.8:
    /// with 2, a block in uniaxial tension dissipates 1.32 and 1.47 × G_f·A at L0 = 10 and
    /// 5 mm; with 2.8, 0.975 and 1.029 × G_f·A (benchmarks/RESULTS.md, "Concrete in 2D").
    /// Random particles 3.2 (docs/sppm.md, "Crack band"); the FCC lattice 3.45
    /// (benchmarks/RESULTS.md, "The effective stress as the 3D default"); random particles in 3D
    /// (`scene::resolve::RANDOM_3D_CRACK_BAND`; benchmarks/RESULTS.md, "Random particles in 3D").
    /// Always set after [`Scene::resolve`].
    #[serde(default)]
    pub crack_band: Option<f64>,
    #[serde(default = "default_initiation")]
    pub initiation: Initiation,
    /// The opening (4.14) reads (docs/model.md §8): default `stress` (S.23) in 3D, `total`
    /// (4.13) in 2D. Always set after [`Scene::resolve`].
    #[serde(default)]
    pub crack_opening: Option<CrackOpening>,
    /// What (4.14) softens (docs/model.md §8, (S.22)): default `stress` in 3D, `strain` (as
    /// the source writes) in 2D. Always set after [`Scene::resolve`].
    #[serde(default)]
    pub softening_stress: Option<SofteningStress>,
    /// The strain initiation and yield read (docs/model.md §7): default the neighbourhood mean
    /// (S.16) on random particles, each particle's own strain on the lattices. Always set
    /// after [`Scene::resolve`].
    #[serde(default)]
    pub criteria_strain: Option<CriteriaStrain>,
    /// Tensile damage (4.12–4.14); default on (off isolates plasticity, e.g. in tests).
    #[serde(default = "default_true")]
    pub tensile_damage: bool,
    /// Compressive damage (4.16, 4.17); default on.
    #[serde(default = "default_true")]
    pub compressive_damage: bool,
    /// Plasticity with hardening (3.38–3.48, 4.15); default on.
    #[serde(default = "default_true")]
    pub plasticity: bool,
}

fn default_eps_ult() -> f64 {
    0.0035
}
fn default_alpha() -> f64 {
    0.1
}
fn default_gamma() -> f64 {
    0.25
}
fn default_wt_cr() -> f64 {
    1.0 / 3.0
}
fn default_wc_max() -> f64 {
    1.0
}
fn default_initiation() -> Initiation {
    Initiation::Rankine
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
    /// μ: the group is a platen with Coulomb friction (docs/model.md §10). Its normal is the
    /// loaded component, or the one fixed component; its members slide along the other
    /// components only where the tangential force exceeds μ times the platen's pressure.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<f64>,
    /// A bearing strip (plywood, hardboard) between the platen and the group's members: the
    /// loaded component then moves the platen, which presses the members through the strip's
    /// stiffness E/thickness per unit area (docs/model.md §10).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bearing: Option<BearingSpec>,
}

/// A bearing strip of modulus `E` (Pa) and `thickness` (m) under a loading platen.
#[derive(Clone, Copy, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BearingSpec {
    #[serde(rename = "E")]
    pub e: f64,
    pub thickness: f64,
}

impl GroupSpec {
    /// The normal component of a platen (`friction`, `bearing`): the axis normal to the
    /// edge or face the group selects (by = "edge" or "strip") where the group fixes or
    /// loads it, else the loaded component of a displacement load, else the one component
    /// in `fix`; `None` when none of these names one.
    pub fn platen_normal(&self) -> Option<usize> {
        let displaced = self.load.as_ref().filter(|l| l.force.is_none());
        let held = |c: usize| {
            self.fix.iter().any(|a| a.index() == c)
                || displaced.is_some_and(|l| l.component.index() == c)
        };
        let edge = match &self.select {
            Selection::Edge { edge, .. } | Selection::Strip { edge, .. } => Some(*edge),
            _ => None,
        };
        if let Some(c) = edge.map(Edge::axis).filter(|&c| held(c)) {
            return Some(c);
        }
        match (&self.load, displaced) {
            (_, Some(l)) => Some(l.component.index()),
            (Some(_), None) => None,
            (None, None) if self.fix.len() == 1 => Some(self.fix[0].index()),
            (None, None) => None,
        }
    }
}

/// A coordinate axis.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    X,
    Y,
    /// 3D only.
    Z,
}

impl Axis {
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
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
    /// The face at the smallest z (3D only).
    Front,
    /// The face at the largest z (3D only).
    Back,
}

impl Edge {
    /// The axis normal to the edge or face: y for bottom and top, x for left and right, z
    /// for front and back.
    pub fn axis(self) -> usize {
        match self {
            Edge::Bottom | Edge::Top => 1,
            Edge::Left | Edge::Right => 0,
            Edge::Front | Edge::Back => 2,
        }
    }
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
        /// The strip's middle (m): the x coordinate on a bottom or top edge, the y
        /// coordinate on a left or right one; default the middle of the body's extent
        /// along the edge.
        #[serde(default)]
        centre: Option<f64>,
        #[serde(default)]
        depth: Option<f64>,
    },
    /// Particles inside an axis-aligned box (two corners of as many components as the
    /// scene has dimensions).
    Box { min: Vec<f64>, max: Vec<f64> },
    /// The one particle nearest a point (for a point support that must exist at every
    /// lattice rotation and offset).
    Nearest { point: Vec<f64> },
    /// Every particle.
    All,
}

impl Selection {
    /// The selection as the scene writes it, an inline TOML table
    /// (`{ by = "box", max = [0.1, 0.2], min = [0.0, 0.0] }`), for messages.
    pub fn scene_text(&self) -> String {
        inline_table(self, "by")
    }
}

/// A tagged table as an inline TOML table, its tag `first` (`{ by = "box", max = [0.1, 0.2],
/// min = [0.0, 0.0] }`), for messages.
fn inline_table<T: Serialize>(table: &T, first: &str) -> String {
    fn inline(v: &serde_json::Value) -> String {
        match v {
            serde_json::Value::Array(items) => {
                let items: Vec<String> = items.iter().map(inline).collect();
                format!("[{}]", items.join(", "))
            }
            other => other.to_string(),
        }
    }
    let value = serde_json::to_value(table).unwrap_or_default();
    let Some(map) = value.as_object() else {
        return inline(&value);
    };
    // the tag first, as a scene writes it
    let mut items: Vec<String> = map
        .iter()
        .filter(|(_, v)| !v.is_null())
        .map(|(k, v)| format!("{k} = {}", inline(v)))
        .collect();
    let tag = format!("{first} =");
    items.sort_by_key(|s| !s.starts_with(&tag));
    format!("{{ {} }}", items.join(", "))
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
    /// Magnification of displacements in the crack map (default 0: the reference shape, where
    /// a crack shows as a band of red particles; fully cracked particles move freely and
    /// scatter in a magnified view).
    #[serde(default)]
    pub crack_map_scale: f64,
    /// Write the particle map SVG.
    #[serde(default = "default_true")]
    pub map: bool,
    /// Write a VTK file of the particles.
    #[serde(default = "default_true")]
    pub vtk: bool,
    /// Frames of the run's time series (`snapshots/`: one `.vtu` file per frame, a `.pvd`
    /// collection and `crack_growth.html`), spread evenly over the load path; absent: none.
    #[serde(default)]
    pub snapshots: Option<usize>,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            records: default_records(),
            probe_group: None,
            field: default_field(),
            deformed_scale: 0.0,
            crack_map_scale: 0.0,
            map: true,
            vtk: true,
            snapshots: None,
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
    /// The discretisation the scene runs with: the FCC lattice, or random particles in a
    /// solid (box, cylinder, prism), are 3D; the hexagonal lattice and random particles in a
    /// 2D shape are 2D. (An FCC lattice in a 2D shape, or a hexagonal one in a solid, is
    /// refused by validation.)
    pub fn discretisation(&self) -> Discretisation {
        match (self.discretisation.lattice, self.body.is_solid()) {
            (Lattice::Fcc, _) => Discretisation::Fcc,
            (Lattice::Random, true) => Discretisation::RandomSolid,
            (Lattice::Random, false) => Discretisation::RandomPlane,
            (Lattice::Hexagonal, _) => Discretisation::Hexagonal,
            (Lattice::Cubic, true) => Discretisation::CubicGrid,
            (Lattice::Cubic, false) => Discretisation::SquareGrid,
        }
    }

    /// The spatial dimension: 3 for the FCC lattice and for random particles in a solid
    /// (box, cylinder, prism), 2 otherwise.
    pub fn dim(&self) -> usize {
        self.discretisation().dim()
    }

    /// How an explicit run of this scene reads its ramp (`loading.pace`, docs/model.md §10);
    /// `None` for the relaxation and quasi-static solvers, whose increments set the pace.
    pub fn pace(&self) -> Option<Pace> {
        (!self.solver.method.is_incremental()).then_some(self.loading.pace)
    }

    /// Parse TOML text, apply `key=value` overrides, and validate.
    pub fn from_toml_str(text: &str, overrides: &[String]) -> Result<Scene, SceneError> {
        let mut value: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| SceneError::Parse(e.to_string()))?;
        apply_overrides(&mut value, overrides)?;
        let mut scene: Scene = Scene::deserialize(toml::Value::Table(value))
            .map_err(|e| SceneError::Parse(e.to_string()))?;
        scene.validate_geometry()?;
        scene.resolve()?;
        scene.validate_resolved()?;
        Ok(scene)
    }

    /// Read a scene file; the scene's name defaults to the file stem.
    pub fn from_file(path: &Path, overrides: &[String]) -> Result<Scene, SceneError> {
        let text = read_scene_text(path)?;
        let mut scene = Scene::from_toml_str(&text, overrides).map_err(|e| e.in_file(path))?;
        if scene.name.is_none() {
            scene.name = path.file_stem().map(|s| s.to_string_lossy().into_owned());
        }
        Ok(scene)
    }

    pub fn name(&self) -> &str {
        self.name.as_deref().unwrap_or("scene")
    }

    /// The seed of the scene's random choices: `seed`, else [`DEFAULT_SEED`] if the scene
    /// makes any (random fields), else `None`.
    pub fn effective_seed(&self) -> Option<u64> {
        self.seed.or(
            if self.random_field.is_empty() && !self.discretisation.is_random() {
                None
            } else {
                Some(DEFAULT_SEED)
            },
        )
    }
}

/// Largest scene file sppm reads: a scene is a few kB of TOML, and this bounds a mistaken
/// `/dev/zero` or data file given as the scene.
pub const MAX_SCENE_BYTES: u64 = 1 << 20;

/// The text of a scene file, read up to [`MAX_SCENE_BYTES`] (a larger file, or an endless
/// one such as `/dev/zero`, is refused without reading it all).
pub fn read_scene_text(path: &Path) -> Result<String, SceneError> {
    use std::io::Read;
    let file = std::fs::File::open(path)
        .map_err(|e| SceneError::Io(format!("cannot read {}: {e}", path.display())))?;
    let mut bytes = Vec::new();
    file.take(MAX_SCENE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| SceneError::Io(format!("cannot read {}: {e}", path.display())))?;
    if bytes.len() as u64 > MAX_SCENE_BYTES {
        return Err(SceneError::Io(format!(
            "{}: a scene file is a TOML text of at most {} bytes; this one is larger (is it the scene?)",
            path.display(),
            MAX_SCENE_BYTES
        )));
    }
    String::from_utf8(bytes).map_err(|e| {
        SceneError::Io(format!(
            "{}: a scene file is UTF-8 text; byte {} is not",
            path.display(),
            e.utf8_error().valid_up_to()
        ))
    })
}
