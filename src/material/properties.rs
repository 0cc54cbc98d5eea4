//! Per-particle material properties from a scene's `[[random_field]]` tables (docs/model.md §12).
//!
//! Each table draws one property (f't, E, G_f or f'c) at every particle as
//! `marginal.map(g(x0))`, g the standard Gaussian field of [`GaussianField`] generated over the
//! body's bounding box (not the particles' box, so that every lattice filling the body samples
//! the same field). The mean defaults to the property's deterministic value (scene, preset or
//! correlation, docs/model.md §11).
//!
//! **Seeds.** A table's `seed` if given, else `splitmix64(scene seed ^ tag(property))`, so that
//! the properties of one scene are independent fields and one scene seed fixes them all.
//!
//! **Decisions where the source is silent.**
//! - E varies the micro-moduli a_i and b_i in proportion (they are linear in E, (3.11)); a bond
//!   between particles of different E takes the mean (a_i + a_j)/2 as the kernel always does.
//!   The stable time step is computed from the varied stiffness, so it shrinks with the
//!   stiffest particle.
//! - f'c varies f_y and f_ult in the same proportion (they are fixed fractions of f'c, §9).
//! - `tie_gf` makes G_f,i = G_f·f't,i/mean(f't): the critical opening COD_c (5.4) stays the
//!   same everywhere and the fracture energy follows the strength.
//! - Without ties, COD_c,i = 2·G_f,i/(f't,i·(α + γ)) at each particle, so a weak particle
//!   softens more gently.

use crate::model::damage::{ConcreteLaw, LocalProperties};
use crate::random_field::{splitmix64, weibull_cov, Correlation, GaussianField, Marginal};
use crate::scene::random_fields::{marginal, scene_error};
use crate::scene::{
    CorrelationKind, FieldProperty, MarginalKind, RandomFieldSpec, Scene, SceneError,
};
use nalgebra::Vector2;
use serde::Serialize;

/// What the summary reports of one sampled field.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct FieldReport {
    pub property: FieldProperty,
    pub correlation: CorrelationKind,
    pub length_m: f64,
    pub marginal: MarginalKind,
    /// Target mean and CoV of the marginal (for Weibull, those of its modulus and scale).
    pub mean: f64,
    pub cov: f64,
    /// Weibull modulus, for a Weibull marginal.
    pub modulus: Option<f64>,
    pub seed: u64,
    pub tie_gf: bool,
    /// Grid spacing h of the generated field (none for white noise).
    pub grid_spacing_m: Option<f64>,
    /// Share of the circulant embedding's spectrum clipped (negative eigenvalues).
    pub clipped_fraction: Option<f64>,
    /// Statistics of the particles' values.
    pub sample_mean: f64,
    pub sample_cov: f64,
    pub sample_min: f64,
    pub sample_max: f64,
}

/// One property's values at every particle.
#[derive(Clone, Debug)]
pub struct SampledField {
    pub property: FieldProperty,
    pub values: Vec<f64>,
    pub report: FieldReport,
}

impl SampledField {
    /// Name and unit for maps and VTK, e.g. `ft_MPa`.
    pub fn label(&self) -> (&'static str, f64) {
        match self.property {
            FieldProperty::Ft => ("ft_MPa", 1e-6),
            FieldProperty::E => ("E_GPa", 1e-9),
            FieldProperty::Gf => ("Gf_N_per_m", 1.0),
            FieldProperty::Fc => ("fc_MPa", 1e-6),
        }
    }
}

/// Tag of a property in the seed hash.
fn tag(p: FieldProperty) -> u64 {
    match p {
        FieldProperty::Ft => 0x6674_5f66_6965_6c64, // "ft_field"
        FieldProperty::E => 0x455f_5f66_6965_6c64,
        FieldProperty::Gf => 0x4766_5f66_6965_6c64,
        FieldProperty::Fc => 0x6663_5f66_6965_6c64,
    }
}

/// The seed of a field: its own, else derived from the scene's seed and the property.
pub fn field_seed(scene_seed: u64, spec: &RandomFieldSpec) -> u64 {
    spec.seed
        .unwrap_or_else(|| splitmix64(scene_seed ^ tag(spec.property)))
}

fn correlation(kind: CorrelationKind) -> Correlation {
    match kind {
        CorrelationKind::Exponential => Correlation::Exponential,
        CorrelationKind::SquaredExponential => Correlation::SquaredExponential,
    }
}

/// Sample every field of a resolved scene at the particles `x0`, over the body's bounding box
/// `[lo, hi]`.
pub fn sample(
    scene: &Scene,
    lo: Vector2<f64>,
    hi: Vector2<f64>,
    x0: &[Vector2<f64>],
) -> Result<Vec<SampledField>, SceneError> {
    let Some(scene_seed) = scene.effective_seed() else {
        return Ok(vec![]);
    };
    let points: Vec<[f64; 2]> = x0.iter().map(|p| [p.x, p.y]).collect();
    let mut out = Vec::with_capacity(scene.random_field.len());
    for (k, spec) in scene.random_field.iter().enumerate() {
        let marginal = marginal(scene, k)?;
        let seed = field_seed(scene_seed, spec);
        let field = GaussianField::new(
            correlation(spec.correlation),
            spec.length,
            [lo.x, lo.y],
            [hi.x, hi.y],
            seed,
        )
        .map_err(|e| scene_error(k, e))?;
        let g = field.sample(&points).map_err(|e| scene_error(k, e))?;
        let values: Vec<f64> = g.iter().map(|&g| marginal.map(g)).collect();
        let n = values.len().max(1) as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        let (target_mean, target_cov, modulus) = match marginal {
            Marginal::Normal { mean, cov } | Marginal::LogNormal { mean, cov } => (mean, cov, None),
            Marginal::Weibull { modulus, .. } => {
                (marginal.mean(), weibull_cov(modulus), Some(modulus))
            }
        };
        out.push(SampledField {
            property: spec.property,
            report: FieldReport {
                property: spec.property,
                correlation: spec.correlation,
                length_m: spec.length,
                marginal: spec.marginal,
                mean: target_mean,
                cov: target_cov,
                modulus,
                seed,
                tie_gf: spec.tie_gf,
                grid_spacing_m: field.spacing(),
                clipped_fraction: field.embedding().map(|e| e.clipped_fraction),
                sample_mean: mean,
                sample_cov: var.sqrt() / mean,
                sample_min: values.iter().copied().fold(f64::INFINITY, f64::min),
                sample_max: values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            },
            values,
        });
    }
    Ok(out)
}

/// The values of `property` at every particle, if a field draws it.
pub fn values_of(fields: &[SampledField], property: FieldProperty) -> Option<&[f64]> {
    fields
        .iter()
        .find(|f| f.property == property)
        .map(|f| f.values.as_slice())
}

/// The E factor E_i/E of every particle (none without an E field).
pub fn stiffness_factors(fields: &[SampledField], e: f64) -> Option<Vec<f64>> {
    values_of(fields, FieldProperty::E).map(|v| v.iter().map(|x| x / e).collect())
}

/// Each particle's concrete values, if any field varies them (see the module docs).
pub fn local_properties(
    fields: &[SampledField],
    law: &ConcreteLaw,
    n: usize,
) -> Option<Vec<LocalProperties>> {
    if fields.is_empty() {
        return None;
    }
    let get = |p| values_of(fields, p);
    let (e, ft, gf, fc) = (
        get(FieldProperty::E),
        get(FieldProperty::Ft),
        get(FieldProperty::Gf),
        get(FieldProperty::Fc),
    );
    let tie = fields
        .iter()
        .find(|f| f.property == FieldProperty::Ft && f.report.tie_gf);
    Some(
        (0..n)
            .map(|i| {
                let ft_i = ft.map_or(law.ft, |v| v[i]);
                let gf_i = match (gf, tie) {
                    (Some(v), _) => v[i],
                    (None, Some(t)) => law.gf * ft_i / t.report.mean,
                    (None, None) => law.gf,
                };
                law.local(
                    e.map_or(law.e, |v| v[i]),
                    ft_i,
                    fc.map_or(law.fc, |v| v[i]),
                    gf_i,
                )
            })
            .collect(),
    )
}

/// Refuse fields that make a particle's tensile strength reach its compressive strength
/// (f't,i ≥ f'c,i: no concrete, and the two-spring law's criteria would cross), naming the
/// field whose spread did it.
pub fn check_strengths(scene: &Scene, fields: &[SampledField]) -> Result<(), SceneError> {
    let Some(law) = crate::model::damage::ConcreteLaw::from_scene(scene) else {
        return Ok(());
    };
    let ft = values_of(fields, FieldProperty::Ft);
    let fc = values_of(fields, FieldProperty::Fc);
    if ft.is_none() && fc.is_none() {
        return Ok(());
    }
    let n = ft.or(fc).map_or(0, |v| v.len());
    let bad: Vec<usize> = (0..n)
        .filter(|&i| ft.map_or(law.ft, |v| v[i]) >= fc.map_or(law.fc, |v| v[i]))
        .collect();
    let Some(&first) = bad.first() else {
        return Ok(());
    };
    let k = scene
        .random_field
        .iter()
        .position(|f| f.property == FieldProperty::Ft)
        .or_else(|| {
            scene
                .random_field
                .iter()
                .position(|f| f.property == FieldProperty::Fc)
        })
        .unwrap_or(0);
    let spec = &scene.random_field[k];
    let (key, value) = match (spec.cov, spec.modulus) {
        (Some(c), _) => ("cov", c.to_string()),
        (None, Some(m)) => ("modulus", m.to_string()),
        _ => ("cov", "(default)".to_string()),
    };
    Err(SceneError::Invalid {
        key: format!("random_field[{k}].{key}"),
        value,
        allowed: format!(
            "a spread for which f't stays below f'c at every particle: at {} of {n} particles f't ≥ f'c (e.g. particle {first}: f't = {:.3} MPa, f'c = {:.3} MPa); lower the spread or the mean",
            bad.len(),
            ft.map_or(law.ft, |v| v[first]) * 1e-6,
            fc.map_or(law.fc, |v| v[first]) * 1e-6
        ),
    })
}
