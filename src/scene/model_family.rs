//! `[model]`: which family of models a scene runs with, the state-based lattice (SPLM, and
//! its random-particle form SPPM; docs/model.md) or bond-based peridynamics
//! (docs/bond_based.md), and the bond-based model's choices.

use serde::{Deserialize, Serialize};

/// `[model]`; absent, the scene runs with the state-based lattice.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// The model family (default "splm").
    #[serde(default)]
    pub family: Family,
    /// Bond-based: the horizon δ as a multiple m of the grid spacing Δx (default π).
    #[serde(default)]
    pub horizon: Option<f64>,
    /// Bond-based: the influence function (default "constant").
    #[serde(default)]
    pub influence: Option<InfluenceKind>,
    /// Bond-based with `[concrete]`: the softening law (default "non_linear").
    #[serde(default)]
    pub softening: Option<SofteningKind>,
    /// Bond-based: the volume method's correction of the bonds near free surfaces (default
    /// true).
    #[serde(default)]
    pub surface_correction: Option<bool>,
    /// Bond-based: fit each bond's softening law to its surface-corrected micromodulus
    /// (default true; without it surfaces are tougher than the bulk).
    #[serde(default)]
    pub critical_stretch_correction: Option<bool>,
    /// Bond-based: the compressive critical stretch s_cc (positive): a bond shortened by
    /// more breaks. Absent, bonds never fail in compression.
    #[serde(default)]
    pub compressive_stretch: Option<f64>,
    /// Bond-based: the short-range repulsive force between points pressed closer than their
    /// contact distance (default false).
    #[serde(default)]
    pub contact: Option<bool>,
}

/// The model family (`model.family`).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Family {
    /// The state-based peridynamic lattice model and its random particles (docs/model.md).
    #[default]
    Splm,
    /// Bond-based peridynamics with many bonds per point (docs/bond_based.md).
    BondBased,
}

impl Family {
    pub fn name(self) -> &'static str {
        match self {
            Family::Splm => "splm",
            Family::BondBased => "bond_based",
        }
    }
}

/// The influence function of a bond-based body (`model.influence`).
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum InfluenceKind {
    Constant,
    /// ω(ξ) = 1 − ξ/δ.
    Conical,
}

/// The softening law of a bond-based body (`model.softening`; docs/bond_based.md,
/// "Softening laws").
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum SofteningKind {
    Linear,
    Bilinear,
    Trilinear,
    NonLinear,
}

impl SofteningKind {
    pub fn name(self) -> &'static str {
        match self {
            SofteningKind::Linear => "linear",
            SofteningKind::Bilinear => "bilinear",
            SofteningKind::Trilinear => "trilinear",
            SofteningKind::NonLinear => "non_linear",
        }
    }
}

/// The horizon ratio m = δ/Δx when the scene gives none (Hobbs 2021).
pub const DEFAULT_HORIZON: f64 = std::f64::consts::PI;

impl ModelSpec {
    pub fn is_bond_based(&self) -> bool {
        self.family == Family::BondBased
    }

    pub fn horizon(&self) -> f64 {
        self.horizon.unwrap_or(DEFAULT_HORIZON)
    }

    pub fn influence(&self) -> InfluenceKind {
        self.influence.unwrap_or(InfluenceKind::Constant)
    }

    pub fn softening(&self) -> SofteningKind {
        self.softening.unwrap_or(SofteningKind::NonLinear)
    }

    pub fn surface_correction(&self) -> bool {
        self.surface_correction.unwrap_or(true)
    }

    pub fn critical_stretch_correction(&self) -> bool {
        self.critical_stretch_correction.unwrap_or(true)
    }

    pub fn contact(&self) -> bool {
        self.contact.unwrap_or(false)
    }

    /// The bond-based keys the scene set, by name (each refused with the state-based family).
    pub fn bond_based_keys(&self) -> Vec<&'static str> {
        [
            ("horizon", self.horizon.is_some()),
            ("influence", self.influence.is_some()),
            ("softening", self.softening.is_some()),
            ("surface_correction", self.surface_correction.is_some()),
            (
                "critical_stretch_correction",
                self.critical_stretch_correction.is_some(),
            ),
            ("compressive_stretch", self.compressive_stretch.is_some()),
            ("contact", self.contact.is_some()),
        ]
        .into_iter()
        .filter_map(|(k, set)| set.then_some(k))
        .collect()
    }
}
