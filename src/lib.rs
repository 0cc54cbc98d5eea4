//! sppm: the state-based peridynamic lattice model (SPLM) and its random-particle
//! generalisation (SPPM) for fracture of concrete.
//!
//! The data flow (ARCHITECTURE.md): [`scene::Scene`] → [`geometry`] → [`discretise`] →
//! [`model`] → [`solver`] → [`output`]. A run is [`run::run`]; the CLI is a thin caller.

pub mod bench;
pub mod console;
pub mod discretise;
pub mod fsio;
pub mod geometry;
pub mod limits;
pub mod material;
pub mod model;
pub mod output;
pub mod random_field;
pub mod run;
pub mod scene;
pub mod solver;
pub mod study;

pub use run::{run, Outcome, RunOptions};
pub use scene::Scene;
