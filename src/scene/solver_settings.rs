//! `[solver]`: time integration, the quasi-static solvers' increments and iterations, and
//! indirect displacement control.

use super::Axis;
use serde::{Deserialize, Serialize};

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
    /// Selective mass scaling (docs/model.md §5, (S.18)): every particle's own stable step
    /// raised to this fraction of the median particle's by added mass; left out, none.
    #[serde(default)]
    pub mass_scaling: Option<f64>,
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
            mass_scaling: None,
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
