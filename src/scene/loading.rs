//! `[loading]` and `[damping]`: the time history of the displacement loading
//! (docs/model.md §10) and the damping ratios (docs/model.md §5).

use super::Axis;
use serde::{Deserialize, Serialize};

/// Loading of one component of a group: a displacement (the default) or a force.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// Loaded component: "x" or "y".
    pub component: Axis,
    /// Δmax (m): the displacement at the end of the ramp (signed). May be left out in a
    /// scene with `[concrete]`: it then defaults to +1.5·COD_c (tension, docs/model.md §10).
    /// Always set after [`Scene::resolve`](super::Scene::resolve) unless `force` is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub displacement: Option<f64>,
    /// P (N): a force-controlled load instead, the group's total force at the end of the
    /// ramp (signed), shared among its members by volume and held after the ramp
    /// (docs/failure.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force: Option<f64>,
}

impl LoadSpec {
    /// Δmax (m) after [`Scene::resolve`](super::Scene::resolve); NaN for a force-controlled
    /// load, which has none.
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
    /// t_end as a multiple of the computed fundamental period T1; without it and without
    /// `end_s`, [`DEFAULT_END_PERIODS`].
    #[serde(default)]
    pub end_periods: Option<f64>,
    /// t_end in seconds (instead of end_periods).
    #[serde(default)]
    pub end_s: Option<f64>,
    /// Stop the run once, after the peak, the probe force has fallen below this fraction of
    /// the peak and a particle has failed (w_t or w_c ≥ 0.99); scenes with `[concrete]`.
    #[serde(default)]
    pub stop_after_peak: Option<f64>,
    /// How fast the explicit run reads the ramp: `fixed` (in time) or `adaptive`
    /// (docs/model.md §10, "Adaptive pace").
    #[serde(default = "default_pace")]
    pub pace: Pace,
    /// The largest pace factor of an adaptive pace.
    #[serde(default = "default_max_pace")]
    pub max_pace: f64,
}

/// How fast an explicit run reads the ramp (docs/model.md §10).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Pace {
    /// The ramp in time, t_ramp = ramp_fraction × t_end.
    Fixed,
    /// The ramp at a load time that runs up to max_pace times faster on the post-peak tail.
    Adaptive,
}

impl Pace {
    /// The key's value.
    pub fn name(self) -> &'static str {
        match self {
            Pace::Fixed => "fixed",
            Pace::Adaptive => "adaptive",
        }
    }
}

fn default_max_pace() -> f64 {
    2.0
}

fn default_pace() -> Pace {
    Pace::Fixed
}

impl Default for LoadingSpec {
    fn default() -> Self {
        LoadingSpec {
            ramp: default_ramp(),
            ramp_fraction: default_ramp_fraction(),
            end_periods: None,
            end_s: None,
            stop_after_peak: None,
            pace: default_pace(),
            max_pace: default_max_pace(),
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
    /// How the explicit step integrates the bond dampers (docs/model.md §5).
    #[serde(default = "default_bond_scheme")]
    pub bond_scheme: BondScheme,
}

fn default_bond_scheme() -> BondScheme {
    BondScheme::Explicit
}

/// How the explicit step integrates the bond dampers (docs/model.md §5).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum BondScheme {
    /// Wholly at v^{n−½} (3.55): the dampers lower the stable step,
    /// Δt ≤ (2/ω_max)(√(1+ζ²) − ζ). The default: the scheme the crack bands were calibrated
    /// with (benchmarks/RESULTS.md, "Bond dampers that keep the undamped step").
    Explicit,
    /// A diagonal share implicitly (S.17): the stable step is the undamped one, 2/ω_max.
    SemiImplicit,
}

impl Default for DampingSpec {
    fn default() -> Self {
        DampingSpec {
            internal: 0.0,
            external: 0.0,
            bond_scheme: default_bond_scheme(),
        }
    }
}

/// t_end / T1 of a scene that gives neither `loading.end_periods` nor `loading.end_s`.
/// Measured on the 2D three-point bending beams of lattices/ with their strokes: the largest
/// kinetic/internal energy ratio around the peak of the notched beam is 0.36, 0.098 and
/// 0.027 at 10, 20 and 40 periods (about 36/n², as a load rate ∝ 1/n predicts); the
/// unnotched beam on random particles, which snaps at its peak, reads 0.050 at 40. 60
/// periods keep every beam below [`KINETIC_LIMIT`] (benchmarks/RESULTS.md, "Loading rate").
pub const DEFAULT_END_PERIODS: f64 = 60.0;

/// The largest kinetic/internal energy ratio around the peak of a run that counts as
/// quasi-static: above it the run warns, with the loading time that would bring it below.
pub const KINETIC_LIMIT: f64 = 0.05;
