//! `[material]`: the elastic constants, and the thickness of a 2D specimen.

use super::{invalid, positive, SceneError};
use crate::scene::Scene;

/// The largest density a scene may give (kg/m³): four times the densest element's.
const MAX_DENSITY: f64 = 1e5;

impl Scene {
    pub(super) fn validate_material(&self) -> Result<(), SceneError> {
        let m = &self.material;
        positive("material.E", m.youngs_modulus())?;
        positive("material.rho", m.rho)?;
        // Far above any material's density the masses, energies and dampers overflow to
        // NaN at the first step; no real specimen comes near the bound.
        if m.rho > MAX_DENSITY {
            return Err(invalid(
                "material.rho",
                m.rho,
                "at most 1e5 kg/m³ (the densest material, osmium, is 22,590 kg/m³; concrete 1,500–2,500 kg/m³): the density in kg/m³",
            ));
        }
        if self.dim() == 2 {
            match m.thickness {
                Some(t) => positive("material.thickness", t)?,
                None => {
                    return Err(invalid(
                        "material.thickness",
                        "absent",
                        "the thickness t (m) of the 2D specimen, > 0",
                    ))
                }
            }
        }
        if !(m.nu.is_finite() && m.nu > -1.0 && m.nu < 0.5) {
            return Err(invalid("material.nu", m.nu, "must satisfy -1 < nu < 0.5"));
        }
        Ok(())
    }
}
