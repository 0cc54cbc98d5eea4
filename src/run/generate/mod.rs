//! The generators: one per discretisation, each turning a scene into its assembled elastic
//! [`Model`] (the particles in the body, their volumes and micro-moduli, groups and
//! supports). [`Generator`] is the one contract; `run::dispatch` picks the generator of a
//! scene once. Adding a discretisation is a new module here, an arm of
//! `scene::Discretisation` and one line of `run::dispatch`.

mod fcc;
mod grid;
mod hexagonal;
pub mod moduli;
mod plane;
mod random_plane;
mod random_solid;
mod solid;

pub use fcc::{fcc_body, surface_treatment as fcc_surface_treatment, Fcc, SolidBody};
pub use grid::{CubicGrid, SquareGrid};
pub use hexagonal::Hexagonal;
pub use random_plane::RandomPlane;
pub use random_solid::RandomSolid;

use super::model::Model;
use super::RunError;
use crate::scene::{Discretisation, Scene};

/// A discretisation in `D` dimensions and `K` bond slots: how a scene's body is filled and
/// its model assembled.
pub trait Generator<const D: usize, const K: usize> {
    /// The discretisation it builds (checked against the scene's).
    const KIND: Discretisation;

    /// The assembled elastic model of `scene`; `stage` is told what starts (for `sppm check`
    /// of large bodies).
    fn model(&self, scene: &Scene, stage: &dyn Fn(&str)) -> Result<Model<K, D>, RunError>;
}
