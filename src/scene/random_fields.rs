//! Validation of a scene's random fields (docs/model.md §12): the keys of each `[[random_field]]`
//! table and the marginal distribution they describe (`crate::random_field`).

use super::{FieldProperty, MarginalKind, Scene, SceneError};
use crate::random_field::{FieldError, Marginal};

/// The deterministic value of a property in a resolved scene (the default mean).
pub fn deterministic_value(scene: &Scene, p: FieldProperty) -> Option<f64> {
    match p {
        FieldProperty::E => Some(scene.material.youngs_modulus()),
        FieldProperty::Ft => scene.derived_value("ft"),
        FieldProperty::Gf => scene.derived_value("Gf"),
        FieldProperty::Fc => scene.derived_value("fc"),
    }
}

/// A field error as a scene error on `random_field[k]`.
pub fn scene_error(k: usize, e: FieldError) -> SceneError {
    match e {
        FieldError::Parameter {
            name,
            value,
            allowed,
        } => {
            let key = match name {
                "correlation_length" => "length",
                n => n,
            };
            SceneError::Invalid {
                key: format!("random_field[{k}].{key}"),
                value: value.to_string(),
                allowed: allowed.to_string(),
            }
        }
        other => SceneError::Invalid {
            key: format!("random_field[{k}]"),
            value: "(the field)".into(),
            allowed: other.to_string(),
        },
    }
}

/// The marginal of table k of a resolved scene (checks the table's values).
pub fn marginal(scene: &Scene, k: usize) -> Result<Marginal, SceneError> {
    let spec = &scene.random_field[k];
    let mean = match spec.mean {
        Some(m) => m,
        None => deterministic_value(scene, spec.property).ok_or_else(|| SceneError::Invalid {
            key: format!("random_field[{k}].property"),
            value: spec.property.name().into(),
            allowed: "E in any scene; ft, Gf and fc only in a scene with [concrete] (or give random_field.mean)".into(),
        })?,
    };
    let m = match (spec.marginal, spec.cov, spec.modulus) {
        (_, Some(_), Some(_)) => {
            return Err(SceneError::Invalid {
                key: format!("random_field[{k}].modulus"),
                value: format!("{:?}", spec.modulus.unwrap()),
                allowed: "give either cov or (for a Weibull marginal) modulus, not both".into(),
            })
        }
        (MarginalKind::Weibull, None, Some(m)) => Marginal::weibull_modulus(mean, m),
        (_, None, Some(m)) => {
            return Err(SceneError::Invalid {
                key: format!("random_field[{k}].modulus"),
                value: m.to_string(),
                allowed: "only a Weibull marginal takes a modulus; give cov".into(),
            })
        }
        (_, None, None) => {
            return Err(SceneError::Invalid {
                key: format!("random_field[{k}].cov"),
                value: "(missing)".into(),
                allowed: "the coefficient of variation, a number > 0 (or modulus for Weibull)"
                    .into(),
            })
        }
        (MarginalKind::Normal, Some(c), None) => Marginal::normal(mean, c),
        (MarginalKind::Lognormal, Some(c), None) => Marginal::lognormal(mean, c),
        (MarginalKind::Weibull, Some(c), None) => Marginal::weibull(mean, c),
    };
    m.map_err(|e| scene_error(k, e))
}

/// Check every `[[random_field]]` table of a resolved scene: values, one table per property,
/// `tie_gf` only on f't and not beside a G_f field, f't/G_f/f'c only with `[concrete]`.
pub fn check(scene: &Scene) -> Result<(), SceneError> {
    let fields = &scene.random_field;
    for (k, spec) in fields.iter().enumerate() {
        if !(spec.length.is_finite() && spec.length >= 0.0) {
            return Err(SceneError::Invalid {
                key: format!("random_field[{k}].length"),
                value: spec.length.to_string(),
                allowed: "the correlation length in m, finite and ≥ 0 (0: uncorrelated)".into(),
            });
        }
        if spec.property != FieldProperty::E && scene.concrete.is_none() {
            return Err(SceneError::Invalid {
                key: format!("random_field[{k}].property"),
                value: spec.property.name().into(),
                allowed: "ft, Gf and fc need a [concrete] section; E works in any scene".into(),
            });
        }
        if let Some(j) = fields[..k].iter().position(|f| f.property == spec.property) {
            return Err(SceneError::Invalid {
                key: format!("random_field[{k}].property"),
                value: spec.property.name().into(),
                allowed: format!(
                    "one table per property; random_field[{j}] already draws {}",
                    spec.property.name()
                ),
            });
        }
        if spec.tie_gf {
            if spec.property != FieldProperty::Ft {
                return Err(SceneError::Invalid {
                    key: format!("random_field[{k}].tie_gf"),
                    value: "true".into(),
                    allowed: "only a table with property = \"ft\" can tie G_f to f't".into(),
                });
            }
            if fields.iter().any(|f| f.property == FieldProperty::Gf) {
                return Err(SceneError::Invalid {
                    key: format!("random_field[{k}].tie_gf"),
                    value: "true".into(),
                    allowed: "false when a random_field table draws Gf itself".into(),
                });
            }
        }
        marginal(scene, k)?;
    }
    Ok(())
}
