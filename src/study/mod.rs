//! Studies: many runs of one scene that differ in a few values, run in parallel, each
//! finished run written at once so that a study resumes where it stopped.
//!
//! - [`runner`]: the generic parallel runner of scene variants and its CSV.
//! - [`objectivity`]: lattice rotations and offsets (peak-force spread, crack path).
//! - [`convergence`]: lattice spacings (Richardson reference and observed order).
//! - [`crack_path`], [`crack_bands`], [`extrapolation`]: the pure functions the studies
//!   report with;
//!   [`angle_effect`]: whether per-angle means differ by more than their realisations' scatter.
//! - [`plots`]: the overlay, convergence and size-effect plots; [`cli`]: the `sppm study`
//!   command.
//! - [`monte_carlo`]: realisations of the random fields per specimen size, shards and their
//!   merge; [`size_effect`]: the statistics and the size-effect fits;
//!   [`size_effect_report`]: the size-effect table, JSON and plot.
//! - [`pareto`]: run time against error (`benchmarks/pareto.rs`).
//! - [`families`]: one specimen under each model family; [`bisection`]: the failure load
//!   under a force-controlled load (docs/failure.md).

pub mod angle_effect;
pub mod bisection;
pub mod cli;
pub mod convergence;
pub mod crack_bands;
pub mod crack_kink;
pub mod crack_path;
pub mod elastic_checks;
pub mod extrapolation;
pub mod families;
pub mod monte_carlo;
pub mod objectivity;
pub mod options;
pub mod pareto;
pub mod plots;
pub mod runner;
pub mod size_effect;
pub mod size_effect_report;

pub use runner::{RunResult, RunRow, Study, Variant};
