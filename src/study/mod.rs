//! Studies: many runs of one scene, aggregated (ARCHITECTURE.md, "Studies").

pub mod pareto;
