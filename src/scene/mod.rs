//! Scene files: the TOML description of one specimen, its discretisation, material, loading
//! and outputs (docs/architecture.md, "scene"). Parsing rejects unknown keys (serde's
//! `deny_unknown_fields`), and [`Scene::validate`] rejects impossible values, each with one
//! message that names the key, the value and what is allowed.

pub mod concrete;
mod overrides;
pub mod random_fields;
mod resolve;
mod validate;

pub use overrides::apply_overrides;
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
    #[serde(default)]
    pub solver: SolverSpec,
    #[serde(default)]
    pub output: OutputSpec,
    /// Every material value the run uses and where it came from (scene, preset or
    /// correlation), filled by [`Scene::resolve`]; not read from the file.
    #[serde(skip_deserializing)]
    pub derived: Vec<Derived>,
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
    /// van Vliet dog-bone of size D (docs/validation.md §D).
    Dogbone {
        size: f64,
    },
    NotchedBeam {
        length: f64,
        depth: f64,
        notch_depth: f64,
        notch_width: f64,
    },
    /// A box (3D): `size` = [x, y, z] from its lower corner `origin`.
    Box {
        size: [f64; 3],
        #[serde(default)]
        origin: [f64; 3],
    },
    /// A circular cylinder (3D) of `diameter` and `length` along `axis` (default z) from the
    /// centre of its base `base`.
    Cylinder {
        diameter: f64,
        length: f64,
        #[serde(default = "z_axis")]
        axis: [f64; 3],
        #[serde(default)]
        base: [f64; 3],
    },
    /// A 2D `section` (any 2D shape, with the scene's cutouts) extruded through
    /// z ∈ [0, thickness] (3D): the dog-bone and the notched beam as prisms.
    Prism {
        section: std::boxed::Box<BodySpec>,
        thickness: f64,
    },
}

fn z_axis() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

impl BodySpec {
    /// The shape's name as a scene writes it (`body.shape`).
    pub fn name(&self) -> &'static str {
        match self {
            BodySpec::Rectangle { .. } => "rectangle",
            BodySpec::Polygon { .. } => "polygon",
            BodySpec::Disc { .. } => "disc",
            BodySpec::Dogbone { .. } => "dogbone",
            BodySpec::NotchedBeam { .. } => "notched_beam",
            BodySpec::Box { .. } => "box",
            BodySpec::Cylinder { .. } => "cylinder",
            BodySpec::Prism { .. } => "prism",
        }
    }

    /// Whether the shape is a solid (box, cylinder, prism) rather than a 2D section.
    pub fn is_solid(&self) -> bool {
        matches!(
            self,
            BodySpec::Box { .. } | BodySpec::Cylinder { .. } | BodySpec::Prism { .. }
        )
    }
}

/// A region cut out of the body (`[[cutouts]] shape = "..."`). Lengths in metres. The body
/// is the outer shape less the open interiors of its cutouts: a particle on a cutout's edge
/// belongs to the body. A cutout may lie inside the body (a hole, an internal slit) or cross
/// its outline (a notch); cutouts must not overlap (a crack line may cross others).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum CutoutSpec {
    /// A circular hole.
    Disc { centre: [f64; 2], diameter: f64 },
    /// A simple polygon, vertices in either orientation.
    Polygon { vertices: Vec<[f64; 2]> },
    /// The rectangle of `width` about the segment start–end, at any angle; `width = 0` is a
    /// crack line: it removes no area, only the bonds that cross it.
    Slit {
        start: [f64; 2],
        end: [f64; 2],
        width: f64,
    },
    /// A rectangle `width` × `height` with its lower-left corner at `origin`, turned by
    /// `rotation_deg` about the origin.
    Rectangle {
        origin: [f64; 2],
        width: f64,
        height: f64,
        #[serde(default)]
        rotation_deg: f64,
    },
}

impl CutoutSpec {
    /// The cutout's geometry.
    pub fn cutout(&self) -> crate::geometry::Cutout {
        use crate::geometry::Cutout;
        use nalgebra::Vector2;
        let v = |a: &[f64; 2]| Vector2::new(a[0], a[1]);
        match self {
            CutoutSpec::Disc { centre, diameter } => Cutout::Disc {
                centre: v(centre),
                radius: 0.5 * diameter,
            },
            CutoutSpec::Polygon { vertices } => {
                Cutout::polygon(&vertices.iter().map(v).collect::<Vec<_>>())
            }
            CutoutSpec::Slit { start, end, width } => Cutout::slit(v(start), v(end), *width),
            CutoutSpec::Rectangle {
                origin,
                width,
                height,
                rotation_deg,
            } => Cutout::rectangle(v(origin), *width, *height, *rotation_deg),
        }
    }

    /// The cutout as the scene writes it, an inline TOML table
    /// (`{ shape = "disc", centre = [0.1, 0.1], diameter = 0.01 }`), for messages.
    pub fn scene_text(&self) -> String {
        inline_table(self, "shape")
    }
}

/// How the body is filled with particles.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DiscretisationSpec {
    /// The particles the body is filled with ([`Lattice`]; default hexagonal).
    #[serde(default)]
    pub lattice: Lattice,
    /// Nearest-neighbour spacing L0 (m); for random particles the mean spacing: the particle
    /// density of a hexagonal lattice of this L0.
    pub spacing: f64,
    /// Random particles: the smallest distance between two particles, as a fraction of
    /// `spacing` (default `discretise::random::DEFAULT_MIN_DISTANCE`).
    #[serde(default)]
    pub min_distance: Option<f64>,
    /// Lattice rotation about the origin, degrees: one angle in 2D; in 3D (FCC) one angle
    /// about z or three, [α, β, γ] about z, y and x (R = Rz(α)·Ry(β)·Rx(γ)).
    #[serde(default)]
    pub rotation_deg: Rotation,
    /// Lattice offset (m), applied after rotation: [x, y] in 2D; [x, y] or [x, y, z] in 3D.
    #[serde(default = "default_offset")]
    pub offset: Vec<f64>,
    /// How a lattice treats its boundary particles ([`Surface`]; default
    /// [`Surface::VoronoiFit`]).
    #[serde(default)]
    pub surface: Option<Surface>,
    /// Before `surface` existed: `true` is `surface = "lattice_fit"`, `false` is
    /// `surface = "lattice"` (the behaviour such scenes were written for). Give one or the
    /// other.
    #[serde(default)]
    pub surface_correction: Option<bool>,
}

/// The particles a body is filled with (`discretisation.lattice`); with the body's kind it
/// decides the [`Discretisation`] a scene runs with.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Lattice {
    /// The hexagonal close-packed lattice (2D SPLM).
    #[default]
    Hexagonal,
    /// The face-centred cubic lattice (3D SPLM).
    Fcc,
    /// Random Voronoi-weighted particles (SPPM), in a 2D shape or a solid.
    Random,
}

impl Lattice {
    /// The name a scene gives it.
    pub fn name(self) -> &'static str {
        match self {
            Lattice::Hexagonal => "hexagonal",
            Lattice::Fcc => "fcc",
            Lattice::Random => "random",
        }
    }
}

/// The discretisation a scene runs with: the lattice in the body's dimension. It fixes the
/// dimension and the bond slots of the run (`run::dispatch`, the one place a scene becomes a
/// typed run).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Discretisation {
    /// The hexagonal lattice in a 2D shape: 6 slots.
    Hexagonal,
    /// Random particles in a 2D shape.
    RandomPlane,
    /// The FCC lattice in a solid: 18 slots.
    Fcc,
    /// Random particles in a solid.
    RandomSolid,
}

impl Discretisation {
    /// The spatial dimension of its runs.
    pub fn dim(self) -> usize {
        match self {
            Discretisation::Hexagonal | Discretisation::RandomPlane => 2,
            Discretisation::Fcc | Discretisation::RandomSolid => 3,
        }
    }

    /// Whether its particles are random (SPPM).
    pub fn is_random(self) -> bool {
        matches!(
            self,
            Discretisation::RandomPlane | Discretisation::RandomSolid
        )
    }
}

/// A lattice's rotation (`discretisation.rotation_deg`): one angle (2D, or about z in 3D) or
/// three angles [α, β, γ] about z, y and x (3D).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Rotation {
    Angle(f64),
    Angles([f64; 3]),
}

impl Default for Rotation {
    fn default() -> Self {
        Rotation::Angle(0.0)
    }
}

impl Rotation {
    /// The angle in the plane (2D); `None` for three angles.
    pub fn planar(self) -> Option<f64> {
        match self {
            Rotation::Angle(a) => Some(a),
            Rotation::Angles(_) => None,
        }
    }

    /// The one angle of a rotation about one axis (the plane's, or one of three; 0 for no
    /// turn); NaN for a turn about more than one axis. The rotation column of study CSVs.
    pub fn single_angle(self) -> f64 {
        match self {
            Rotation::Angle(a) => a,
            Rotation::Angles(v) if v.iter().filter(|a| **a != 0.0).count() <= 1 => v.iter().sum(),
            Rotation::Angles(_) => f64::NAN,
        }
    }

    /// The angle in the plane of a 2D scene (validated to be one angle; NaN otherwise).
    pub fn angle(self) -> f64 {
        self.planar().unwrap_or(f64::NAN)
    }

    /// [α, β, γ] about z, y and x (one angle is α).
    pub fn angles(self) -> [f64; 3] {
        match self {
            Rotation::Angle(a) => [a, 0.0, 0.0],
            Rotation::Angles(v) => v,
        }
    }
}

fn default_offset() -> Vec<f64> {
    vec![0.0, 0.0]
}

/// How a lattice's boundary particles are weighted (`discretisation.surface`; docs/model.md §1,
/// §3; measured in benchmarks/RESULTS.md, "Surfaces").
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Surface {
    /// Each particle's volume is its Voronoi cell clipped to the body (the body's mass and
    /// area at any rotation and offset); a particle whose cell is clipped or which misses
    /// bonds gets micro-moduli fitted to D by least squares from its own bonds and that
    /// volume (3.20), as random particles do. The default.
    VoronoiFit,
    /// Clipped Voronoi volumes; the bulk micro-moduli scaled by the volume fraction.
    Voronoi,
    /// The source's SPLM: every particle the full lattice cell and the bulk moduli.
    Lattice,
    /// Full lattice cells; particles with missing bonds fitted (the former
    /// `surface_correction = true`).
    LatticeFit,
}

impl Surface {
    pub fn name(self) -> &'static str {
        match self {
            Surface::VoronoiFit => "voronoi_fit",
            Surface::Voronoi => "voronoi",
            Surface::Lattice => "lattice",
            Surface::LatticeFit => "lattice_fit",
        }
    }

    /// Whether boundary particles get micro-moduli fitted by least squares.
    pub fn fits(self) -> bool {
        matches!(self, Surface::VoronoiFit | Surface::LatticeFit)
    }
}

impl DiscretisationSpec {
    /// The boundary treatment: `surface`, or what `surface_correction` meant.
    pub fn surface(&self) -> Surface {
        match (self.surface, self.surface_correction) {
            (Some(s), _) => s,
            (None, Some(true)) => Surface::LatticeFit,
            (None, Some(false)) => Surface::Lattice,
            (None, None) => Surface::VoronoiFit,
        }
    }

    /// Whether the body is random particles (SPPM) rather than a lattice.
    pub fn is_random(&self) -> bool {
        self.lattice == Lattice::Random
    }

    /// The offset in the plane (2D; validated to have two components).
    pub fn offset2(&self) -> [f64; 2] {
        [
            self.offset.first().copied().unwrap_or(0.0),
            self.offset.get(1).copied().unwrap_or(0.0),
        ]
    }

    /// The offset in space (3D; a missing z is 0).
    pub fn offset3(&self) -> [f64; 3] {
        let [x, y] = self.offset2();
        [x, y, self.offset.get(2).copied().unwrap_or(0.0)]
    }
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
    /// Random particles 3.2 (docs/sppm.md, "Crack band"); the FCC lattice 3.3
    /// (benchmarks/RESULTS.md, "Concrete in 3D"); random particles in 3D
    /// (`scene::resolve::RANDOM_3D_CRACK_BAND`; benchmarks/RESULTS.md, "Random particles in 3D").
    /// Always set after [`Scene::resolve`].
    #[serde(default)]
    pub crack_band: Option<f64>,
    #[serde(default = "default_initiation")]
    pub initiation: Initiation,
    #[serde(default = "default_crack_opening")]
    pub crack_opening: CrackOpening,
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
fn default_crack_opening() -> CrackOpening {
    CrackOpening::Total
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

/// Displacement loading of one component of a group.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// Loaded component: "x" or "y".
    pub component: Axis,
    /// Δmax (m): the displacement at the end of the ramp (signed). May be left out in a
    /// scene with `[concrete]`: it then defaults to +1.5·COD_c (tension, docs/model.md §10).
    /// Always set after [`Scene::resolve`].
    #[serde(default)]
    pub displacement: Option<f64>,
}

impl LoadSpec {
    /// Δmax (m) after [`Scene::resolve`].
    pub fn delta(&self) -> f64 {
        self.displacement.unwrap_or(f64::NAN)
    }
}

/// Time history of the displacement loading (docs/model.md §10).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LoadingSpec {
    /// "cosine" (5.5) or "smoothstep" (Hobbs (2021), Eq. 4.9).
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
    /// Stop the run once, after the peak, the probe force has fallen below this fraction of
    /// the peak and a particle has failed (w_t or w_c ≥ 0.99); scenes with `[concrete]`.
    #[serde(default)]
    pub stop_after_peak: Option<f64>,
}

impl Default for LoadingSpec {
    fn default() -> Self {
        LoadingSpec {
            ramp: default_ramp(),
            ramp_fraction: default_ramp_fraction(),
            end_periods: None,
            end_s: None,
            stop_after_peak: None,
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

/// Damping ratios (docs/model.md §5).
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

/// Which reading of the source's one-step force lag (docs/model.md §4). Default chosen by
/// measurement (tests/suite/vibration_and_stability.rs, tests/suite/run_plate.rs):
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
    /// Damped explicit dynamics, adaptive dynamic relaxation or its secant iterations
    /// (`solver::relaxation`).
    #[serde(default)]
    pub method: SolverMethod,
    /// Relaxation: load increments over the ramp.
    #[serde(default = "default_increments")]
    pub increments: usize,
    /// Relaxation: an increment has converged when the out-of-balance force norm on the free
    /// components is at most `tolerance` × the largest reaction norm so far.
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    /// Relaxation: iteration limit of one increment.
    /// (Left out: [`SolverSpec::max_iterations`].)
    #[serde(default, rename = "max_iterations")]
    pub max_iterations_key: Option<usize>,
    /// Relaxation: the largest out-of-balance ratio (as `tolerance`) accepted at the end of
    /// an increment that stopped at `max_iterations`. Left out, every increment must
    /// converge to `tolerance`, and a run with one that did not has the status
    /// "unconverged" (exit status 3).
    #[serde(default)]
    pub max_residual: Option<f64>,
    /// Quasi-static: indirect displacement control on a crack opening (`solver::secant`,
    /// docs/quasi_static.md). Left out, the prescribed displacement is the load path.
    #[serde(default)]
    pub control: Option<ControlSpec>,
}

/// Indirect displacement control: the load path is the opening of a gauge, the mean
/// displacement of group `plus` less that of group `minus` in `component`, raised to
/// `opening`; the prescribed displacements (the load groups' Δmax times a load factor) follow
/// from equilibrium, and fall where the gauge opens while the body unloads (snap-back).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ControlSpec {
    /// The group whose mean displacement counts positive.
    pub plus: String,
    /// The group whose mean displacement counts negative.
    pub minus: String,
    /// The gauge's direction.
    pub component: Axis,
    /// The opening at the end of the run (m).
    pub opening: f64,
}
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum SolverMethod {
    /// Damped explicit central differences over the loading time (docs/model.md §4–5).
    #[default]
    Explicit,
    /// Adaptive dynamic relaxation (Kilic & Madenci 2010) in load increments, the state
    /// updated in every iteration.
    Relaxation,
    /// The same relaxation as secant iterations: the state held while the positions relax
    /// and committed between equilibria, so that every increment converges
    /// (`solver::relaxation::relax`, docs/quasi_static.md).
    QuasiStatic,
}

impl SolverMethod {
    /// Load increments relaxed to equilibrium (`relaxation`, `quasi_static`), not explicit.
    pub fn is_incremental(self) -> bool {
        self != SolverMethod::Explicit
    }

    /// The key's value.
    pub fn name(self) -> &'static str {
        match self {
            SolverMethod::Explicit => "explicit",
            SolverMethod::Relaxation => "relaxation",
            SolverMethod::QuasiStatic => "quasi_static",
        }
    }
}

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec {
            safety: default_safety(),
            dt: None,
            force_lag: default_lag(),
            threads: None,
            method: SolverMethod::default(),
            increments: default_increments(),
            tolerance: default_tolerance(),
            max_iterations_key: None,
            max_residual: None,
            control: None,
        }
    }
}

fn default_increments() -> usize {
    200
}
fn default_tolerance() -> f64 {
    1e-4
}
impl SolverSpec {
    /// Iteration limit of one load increment: the key's value, else 500 for the relaxation
    /// (docs/relaxation.md) and 20,000 for the quasi-static solver, whose increment at a
    /// crack that runs at a held displacement takes 3,000–9,000 iterations on the shipped
    /// 2D scenes (docs/quasi_static.md).
    pub fn max_iterations(&self) -> usize {
        self.max_iterations_key.unwrap_or(match self.method {
            SolverMethod::QuasiStatic => 20_000,
            _ => 500,
        })
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
        }
    }

    /// The spatial dimension: 3 for the FCC lattice and for random particles in a solid
    /// (box, cylinder, prism), 2 otherwise.
    pub fn dim(&self) -> usize {
        self.discretisation().dim()
    }

    /// Parse TOML text, apply `key=value` overrides, and validate.
    pub fn from_toml_str(text: &str, overrides: &[String]) -> Result<Scene, SceneError> {
        let mut value: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| SceneError::Parse(e.to_string()))?;
        apply_overrides(&mut value, overrides)?;
        let mut scene: Scene = Scene::deserialize(toml::Value::Table(value))
            .map_err(|e| SceneError::Parse(e.to_string()))?;
        scene.resolve()?;
        scene.validate()?;
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
