//! sppm: the state-based peridynamic lattice model (SPLM) and its random-particle
//! generalisation (SPPM) for fracture of concrete.
//!
//! The data flow (docs/architecture.md): [`scene::Scene`] → [`geometry`] → [`discretise`] →
//! [`model`] → [`solver`] → [`output`]. A run is [`run::run`]; the CLI is a thin caller.
//!
//! # Layers
//!
//! One pipeline serves every discretisation and dimension, in layers that import only from
//! below (checked by `tests/suite/layering.rs`, which also finds no import circle between the
//! files of a module):
//!
//! 0. tools: [`aligned`], [`console`], [`fsio`], [`limits`], [`geometry`], [`random_field`];
//! 1. [`scene`]: describes and validates a specimen; it imports nothing from the model, the
//!    material or the solver;
//! 2. [`discretise`] fills a body (positions, volumes, horizons, length scales, micro-moduli,
//!    bonds in fixed slots); [`model`] is the constitutive law: the force law
//!    ([`model::force_state`]), dimension as a type ([`model::dimension`]), damage laws behind
//!    a trait ([`model::damage_law`]). The two do not import each other;
//! 3. [`material`]: properties per particle (random fields sampled on a body);
//! 4. [`solver`]: step kernels (elastic, and inelastic generic over law and dimension), time
//!    step, modal analysis, relaxation;
//! 5. [`run`]: prepare → execute → summary, ending in a dimension-erased [`run::Outcome`];
//! 6. [`output`]: the reports of an outcome;
//! 7. [`study`] and [`bench`]: many runs.

pub mod aligned;
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
