//! Scalar particle fields for maps and VTK, with their labels and units.

use crate::model::dimension::{Dim, Dimension};
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
            let u = nalgebra::Vector3::from(o.displacement[i]);
            let s = &o.stress[i];
            match field {
                Field::Displacement => u.norm() * 1e3,
                Field::DisplacementX => u.x * 1e3,
                Field::DisplacementY => u.y * 1e3,
                Field::StressXx => s[0] * 1e-6,
                Field::StressYy => s[1] * 1e-6,
                Field::StressXy => s[5] * 1e-6,
                Field::StressVonMises => {
                    equivalent(o, i, Dim::<2>::von_mises, Dim::<3>::von_mises) * 1e-6
                }
                Field::MaxPrincipalStress => {
                    equivalent(o, i, Dim::<2>::max_principal, Dim::<3>::max_principal) * 1e-6
                }
            }
        })
        .collect()
}

/// A scalar of particle i's stress: of the in-plane tensor in 2D (plane stress, as the 2D maps
/// always showed it), of the full tensor in 3D.
fn equivalent(
    o: &Outcome,
    i: usize,
    in_plane: fn(&nalgebra::Matrix2<f64>) -> f64,
    solid: fn(&nalgebra::Matrix3<f64>) -> f64,
) -> f64 {
    scalar_of(o.dim, &o.stress[i], in_plane, solid)
}

/// A scalar of a Voigt stress [xx, yy, zz, yz, xz, xy]: of its in-plane tensor in 2D, of the
/// full tensor in 3D.
fn scalar_of(
    dim: usize,
    s: &[f64; 6],
    in_plane: fn(&nalgebra::Matrix2<f64>) -> f64,
    solid: fn(&nalgebra::Matrix3<f64>) -> f64,
) -> f64 {
    if dim == 2 {
        in_plane(&nalgebra::Matrix2::new(s[0], s[5], s[5], s[1]))
    } else {
        solid(&nalgebra::Matrix3::from_row_slice(
            &crate::run::arrays::tensor9(s),
        ))
    }
}

/// The von Mises stress of a Voigt stress [xx, yy, zz, yz, xz, xy] in the unit of the stress
/// (plane stress of the in-plane tensor in 2D, as the maps show it).
pub fn von_mises(dim: usize, s: &[f64; 6]) -> f64 {
    scalar_of(dim, s, Dim::<2>::von_mises, Dim::<3>::von_mises)
}
