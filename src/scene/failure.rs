//! `[failure]`: the criterion that decides whether a specimen holds a force-controlled load
//! or fails under it (docs/failure.md).

use serde::{Deserialize, Serialize};

/// How a held load is judged (docs/failure.md, (F.1)–(F.3)).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Criterion {
    /// (F.1): the loaded particles' mean speed has fallen below `velocity_tolerance`.
    VelocityDecay,
    /// (F.2): the loaded particles' mean out-of-balance force, over the force applied to
    /// them, has fallen below `force_tolerance` (Huang, Lu & Qiao 2015).
    ForceDecay,
    /// (F.3): damage has stopped growing, and then the loaded particles move against the
    /// load and slow below `velocity_tolerance` (held), or keep moving with it (failed)
    /// (Ness 2019).
    BondDamage,
}

impl Criterion {
    /// The key's value.
    pub fn name(self) -> &'static str {
        match self {
            Criterion::VelocityDecay => "velocity_decay",
            Criterion::ForceDecay => "force_decay",
            Criterion::BondDamage => "bond_damage",
        }
    }
}

/// `[failure]`: the criterion and its tolerances. A load not judged held by t_end has failed.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct FailureSpec {
    pub criterion: Criterion,
    /// τ_u (m/s): the mean speed of the loaded particles below which the load is held
    /// (`velocity_decay`, `bond_damage`). No default: it is a speed of the specimen.
    #[serde(default)]
    pub velocity_tolerance: Option<f64>,
    /// β: the mean out-of-balance ratio below which the load is held (`force_decay`).
    #[serde(default = "default_force_tolerance")]
    pub force_tolerance: f64,
    /// τ_D: the growth of the damaged share between two checks below which damage counts as
    /// stable (`bond_damage`).
    #[serde(default = "default_damage_tolerance")]
    pub damage_tolerance: f64,
    /// S* (steps) of stable damage before the load is judged (`bond_damage`); without it,
    /// twice the steps of the ramp.
    #[serde(default)]
    pub stable_steps: Option<usize>,
    /// F* (steps) of motion with the load, after damage is stable, that fail it
    /// (`bond_damage`); without it, twice the steps of the ramp.
    #[serde(default)]
    pub failing_steps: Option<usize>,
    /// Steps between two checks.
    #[serde(default = "default_check_every")]
    pub check_every: usize,
}

/// β of Ness (2019), Table 6.3.
pub const DEFAULT_FORCE_TOLERANCE: f64 = 0.5;
/// τ_D of Ness (2019), §6.2.3.
pub const DEFAULT_DAMAGE_TOLERANCE: f64 = 1e-5;
/// Ness (2019) checked every 50 steps.
pub const DEFAULT_CHECK_EVERY: usize = 50;

fn default_force_tolerance() -> f64 {
    DEFAULT_FORCE_TOLERANCE
}

fn default_damage_tolerance() -> f64 {
    DEFAULT_DAMAGE_TOLERANCE
}

fn default_check_every() -> usize {
    DEFAULT_CHECK_EVERY
}
