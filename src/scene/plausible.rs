//! Plausibility of the physical inputs (docs/scenes.md, "Units and plausible values"). Every
//! value a scene writes is in SI units; a value outside the range that real concrete (or,
//! in an elastic scene, any engineering solid) spans is a unit slip far more often than an
//! exotic material. Such a value is refused in the key the user wrote, with the range and,
//! where multiplying by a common unit's factor lands it inside the range, the likely unit.
//! A value inside the hard bounds but outside the usual range of structural concrete is
//! accepted with a warning (fibre-reinforced or lightweight concretes are legitimate).

use super::validate::invalid;
use super::{Scene, SceneError};

/// 1 psi in Pa.
const PSI: f64 = super::concrete::PSI;
/// 1 lb/ft³ in kg/m³.
const LB_FT3: f64 = super::concrete::LB_PER_FT3;

/// One physical quantity: its SI unit, the hard bounds outside which it is refused, the
/// usual range (outside it a warning), and the units a user may have meant.
pub struct Quantity {
    /// What the value is, for messages ("Young's modulus E").
    pub what: &'static str,
    pub unit: &'static str,
    /// Refused outside [lo, hi].
    pub hard: (f64, f64),
    /// Warned outside [lo, hi] (inside `hard`).
    pub usual: (f64, f64),
    /// What `usual` is the range of ("structural concrete").
    pub of: &'static str,
    /// (factor to SI, the unit's name): the units a slip may have used.
    pub slips: &'static [(f64, &'static str)],
}

const STRESS_SLIPS: &[(f64, &str)] = &[
    (1e6, "MPa (N/mm²)"),
    (1e9, "GPa"),
    (PSI, "psi"),
    (1e3 * PSI, "ksi"),
    (1e3, "kPa"),
];

/// Young's modulus of concrete: lightweight (about 10 GPa) to ultra-high-performance
/// (about 60 GPa).
pub const CONCRETE_E: Quantity = Quantity {
    what: "Young's modulus E",
    unit: "Pa",
    hard: (1e9, 2e11),
    usual: (8e9, 7e10),
    of: "concrete",
    slips: STRESS_SLIPS,
};

/// Young's modulus of an elastic scene: from soft polymers to diamond (1.2e12 Pa); below
/// 1e5 Pa no solid carries a load.
pub const SOLID_E: Quantity = Quantity {
    what: "Young's modulus E",
    unit: "Pa",
    hard: (1e5, 2e12),
    usual: (1e8, 1.2e12),
    of: "engineering solids from polymers to ceramics",
    slips: STRESS_SLIPS,
};

/// Compressive strength f'c (and the yield and ultimate strengths that follow it).
pub const CONCRETE_FC: Quantity = Quantity {
    what: "compressive strength",
    unit: "Pa",
    hard: (1e6, 4e8),
    usual: (8e6, 2e8),
    of: "concrete from lean to ultra-high-performance",
    slips: STRESS_SLIPS,
};

/// Tensile strength f't.
pub const CONCRETE_FT: Quantity = Quantity {
    what: "tensile strength f't",
    unit: "Pa",
    hard: (1e5, 5e7),
    usual: (8e5, 1.5e7),
    of: "concrete",
    slips: STRESS_SLIPS,
};

const ENERGY_SLIPS: &[(f64, &str)] = &[(1e3, "N/mm (kN/m, kJ/m²)"), (1e-3, "N/km")];

/// Fracture energy G_f: about 50–200 N/m for plain concrete (CEB-FIP 1990), up to tens of
/// kN/m with fibres.
pub const CONCRETE_GF: Quantity = Quantity {
    what: "fracture energy",
    unit: "N/m (J/m²)",
    hard: (2.0, 1e5),
    usual: (20.0, 500.0),
    of: "plain concrete",
    slips: ENERGY_SLIPS,
};

/// The base fracture energy G_f0 of CEB-FIP 1990 (25–58 N/m over its table).
pub const CONCRETE_GF0: Quantity = Quantity {
    what: "base fracture energy G_f0",
    unit: "N/m (J/m²)",
    hard: (2.0, 1e4),
    usual: (15.0, 100.0),
    of: "the CEB-FIP 1990 table (25–58 N/m) with a margin",
    slips: ENERGY_SLIPS,
};

const DENSITY_SLIPS: &[(f64, &str)] = &[(1e3, "t/m³ (g/cm³)"), (LB_FT3, "lb/ft³")];

/// Density of concrete: lightweight (about 1,400 kg/m³) to heavyweight (about 4,000).
pub const CONCRETE_RHO: Quantity = Quantity {
    what: "density",
    unit: "kg/m³",
    hard: (300.0, 8000.0),
    usual: (1400.0, 4000.0),
    of: "concrete",
    slips: DENSITY_SLIPS,
};

/// Density of an elastic scene's solid: foams to osmium (22,590 kg/m³); the largest
/// density a scene may give is refused by the validation of `[material]`.
pub const SOLID_RHO: Quantity = Quantity {
    what: "density",
    unit: "kg/m³",
    hard: (1.0, f64::INFINITY),
    usual: (100.0, 23000.0),
    of: "engineering solids",
    slips: DENSITY_SLIPS,
};

impl Quantity {
    /// Refuse `value` under `key` outside the hard bounds; a warning outside the usual
    /// range; `None` inside it.
    pub fn judge(&self, key: &str, value: f64) -> Result<Option<String>, SceneError> {
        let inside = |(lo, hi): (f64, f64), v: f64| v >= lo && v <= hi;
        if inside(self.usual, value) {
            return Ok(None);
        }
        let range = format!(
            "{} in {}; {} spans {} to {} {}",
            self.what,
            self.unit,
            self.of,
            show(self.usual.0),
            show(self.usual.1),
            self.unit
        );
        let hint = self
            .slips
            .iter()
            .find(|&&(f, _)| inside(self.usual, value * f))
            .map(|&(f, name)| {
                format!(
                    ": {value} looks like a value in {name}, which is {} {}",
                    show(value * f),
                    self.unit
                )
            })
            .unwrap_or_default();
        if !inside(self.hard, value) {
            return Err(invalid(
                key,
                value,
                format!(
                    "{range}; values outside {} to {} are refused{hint}",
                    show(self.hard.0),
                    show(self.hard.1)
                ),
            ));
        }
        Ok(Some(format!(
            "{key} = {value}: outside the usual range ({range}){hint}; the run goes on with it"
        )))
    }
}

/// A value as a person reads it: plain between 0.001 and 99,999, else in e-notation.
fn show(v: f64) -> String {
    if (1e-3..1e5).contains(&v.abs()) {
        format!("{}", (v * 1e6).round() / 1e6)
    } else {
        format!("{v:e}")
    }
}

impl Scene {
    /// The material inputs a user wrote, judged against [`Quantity`]'s ranges before any
    /// correlation sees them (concrete ranges with `[concrete]`, else those of solids); the
    /// warnings are kept in [`Scene::warnings`].
    pub(super) fn judge_inputs(&mut self) -> Result<(), SceneError> {
        let concrete = self.concrete.as_ref();
        let (e, rho) = match concrete {
            Some(_) => (&CONCRETE_E, &CONCRETE_RHO),
            None => (&SOLID_E, &SOLID_RHO),
        };
        let mut inputs: Vec<(String, Option<f64>, &Quantity)> = vec![
            ("material.E".into(), self.material.e, e),
            ("material.rho".into(), Some(self.material.rho), rho),
        ];
        if let Some(c) = concrete {
            for (key, value, q) in [
                ("fc", c.fc, &CONCRETE_FC),
                ("ft", c.ft, &CONCRETE_FT),
                ("fy", c.fy, &CONCRETE_FC),
                ("fult", c.fult, &CONCRETE_FC),
                ("Gf", c.gf, &CONCRETE_GF),
                ("Gf0", c.gf0, &CONCRETE_GF0),
            ] {
                inputs.push((format!("concrete.{key}"), value, q));
            }
        }
        // a random field's mean is the same quantity as its property
        for (k, f) in self.random_field.iter().enumerate() {
            let q = match f.property {
                super::FieldProperty::E => e,
                super::FieldProperty::Ft => &CONCRETE_FT,
                super::FieldProperty::Gf => &CONCRETE_GF,
                super::FieldProperty::Fc => &CONCRETE_FC,
            };
            inputs.push((format!("random_field[{k}].mean"), f.mean, q));
        }
        let mut warnings = Vec::new();
        for (key, value, q) in inputs {
            // NaN, zero and negative values are the validation's to name
            let Some(v) = value.filter(|v| v.is_finite() && *v > 0.0) else {
                continue;
            };
            warnings.extend(q.judge(&key, v)?);
        }
        self.warnings = warnings;
        Ok(())
    }
}
