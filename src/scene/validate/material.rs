//! `[material]`: the elastic constants, and the thickness of a 2D specimen.

use super::{invalid, positive, SceneError};
use crate::scene::Scene;

impl Scene {
    pub(super) fn validate_material(&self) -> Result<(), SceneError> {
        let m = &self.material;
        positive("material.E", m.youngs_modulus())?;
        positive("material.rho", m.rho)?;
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
