//! `run(scene) -> Outcome`: the whole pipeline of one specimen (docs/architecture.md), in three
//! stages that run one way:
//!
//! 1. [`dispatch`] picks the scene's generator ([`generate`]: discretisation, groups,
//!    supports, micro-moduli, random fields → [`Model`]); [`prepare`] adds T1, dampers and
//!    the stable time step;
//! 2. [`execute`]: the explicit or relaxation run with probes, to an [`Outcome`];
//! 3. [`summary`]: what the run measured, as summary.json reports it.
//!
//! The [`Outcome`] handed to `output` and `study` is dimension-erased (3-vector points and
//! displacements, 6-component stresses), so one set of reports serves 2D and 3D. The CLI and
//! the studies are thin callers.

pub mod arrays;
pub mod bond_based;
pub mod check;
pub mod dispatch;
pub mod execute;
pub mod gauges;
pub mod generate;
pub mod load_test;
pub mod model;
pub mod platens;
pub mod prepare;
pub mod recover;
pub mod snapshots;
pub mod stress_recovery;
pub mod summary;

pub use crate::limits::available_memory;
pub use dispatch::{dispatch, estimated_memory, TypedRun};
pub use execute::{build_simulation, damage_kernel, particle_stress, run};
pub use generate::{Fcc, Generator, Hexagonal, RandomPlane, RandomSolid};
pub use model::{estimated_particles, Model, SurfaceCorrection};
pub use prepare::{prepare, prepare_model, prepare_model_with, prepare_with, Prepared};
pub use summary::{Outcome, Summary};

use crate::scene::SceneError;
use crate::solver::modal;

/// Everything that stops a run.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("{0}")]
    Setup(String),
    #[error(transparent)]
    Modal(#[from] modal::ModalError),
}

/// Run options that are not part of the scene.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Show a progress bar on runs longer than about a second.
    pub progress: bool,
    /// Override the scene's thread count.
    pub threads: Option<usize>,
}
