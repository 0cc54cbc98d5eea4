//! `[discretisation]`: the particles a body is filled with (lattice or random particles),
//! their spacing, rotation and offset, and how boundary particles are weighted.

use serde::{Deserialize, Serialize};

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
    /// The regular grid of the bond-based family: points at the centres of cubic cells of
    /// side `spacing` in a solid, of square cells in a 2D shape.
    Cubic,
}

impl Lattice {
    /// The name a scene gives it.
    pub fn name(self) -> &'static str {
        match self {
            Lattice::Hexagonal => "hexagonal",
            Lattice::Fcc => "fcc",
            Lattice::Random => "random",
            Lattice::Cubic => "cubic",
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
    /// The cubic grid in a solid (bond-based family only).
    CubicGrid,
    /// The square grid in a 2D shape (bond-based family only).
    SquareGrid,
}

impl Discretisation {
    /// The spatial dimension of its runs.
    pub fn dim(self) -> usize {
        match self {
            Discretisation::Hexagonal
            | Discretisation::RandomPlane
            | Discretisation::SquareGrid => 2,
            Discretisation::Fcc | Discretisation::RandomSolid | Discretisation::CubicGrid => 3,
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
