//! Scalar particle fields for maps and VTK, with their labels and units.

use crate::model::stress::{max_principal, von_mises};
use crate::run::Outcome;
use crate::scene::Field;

/// Label (with unit) of a field.
pub fn label(field: Field) -> &'static str {
    match field {
        Field::Displacement => "displacement magnitude (mm)",
        Field::DisplacementX => "displacement u_x (mm)",
        Field::DisplacementY => "displacement u_y (mm)",
        Field::StressXx => "stress σxx (MPa)",
        Field::StressYy => "stress σyy (MPa)",
        Field::StressXy => "stress σxy (MPa)",
        Field::StressVonMises => "von Mises stress (MPa)",
        Field::MaxPrincipalStress => "max principal stress (MPa)",
    }
}

/// Values of a field at every particle, in the units of [`label`].
pub fn values(o: &Outcome, field: Field) -> Vec<f64> {
    let n = o.x0.len();
    (0..n)
        .map(|i| {
            let u = o.displacement[i];
            let s = o.stress[i];
            match field {
                Field::Displacement => u.norm() * 1e3,
                Field::DisplacementX => u.x * 1e3,
                Field::DisplacementY => u.y * 1e3,
                Field::StressXx => s[(0, 0)] * 1e-6,
                Field::StressYy => s[(1, 1)] * 1e-6,
                Field::StressXy => s[(0, 1)] * 1e-6,
                Field::StressVonMises => von_mises(&s) * 1e-6,
                Field::MaxPrincipalStress => max_principal(&s) * 1e-6,
            }
        })
        .collect()
}
