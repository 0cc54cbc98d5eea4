//! `[discretisation]`: the keys of random particles or of a lattice, the spacing against the
//! body, and a rotation and offset of the scene's dimension.

use super::{finite, invalid, positive, SceneError};
use crate::scene::{DiscretisationSpec, Scene, Surface};

impl Scene {
    pub(super) fn validate_discretisation(&self) -> Result<(), SceneError> {
        let d = &self.discretisation;
        if d.is_random() {
            random_particles(d)?;
        } else if let Some(f) = d.min_distance {
            return Err(invalid(
                "discretisation.min_distance",
                f,
                "absent for lattice = \"hexagonal\" (it sets the random particles' spacing rule)",
            ));
        }
        if let (Some(s), Some(c)) = (d.surface, d.surface_correction) {
            return Err(invalid(
                "discretisation.surface_correction",
                c,
                format!("absent when discretisation.surface is given (surface = \"{}\"): surface_correction = true is surface = \"lattice_fit\", false is surface = \"lattice\"", s.name()),
            ));
        }
        positive("discretisation.spacing", d.spacing)?;
        for (k, a) in d.rotation_deg.angles().iter().enumerate() {
            finite(&format!("discretisation.rotation_deg[{k}]"), *a)?;
        }
        let components = if self.dim() == 3 { "2 or 3" } else { "2" };
        if d.offset.len() != 2 && !(self.dim() == 3 && d.offset.len() == 3) {
            return Err(invalid(
                "discretisation.offset",
                format!("{:?}", d.offset),
                format!(
                    "{components} components (m), [x, y]{}",
                    if self.dim() == 3 { " or [x, y, z]" } else { "" }
                ),
            ));
        }
        for (k, o) in d.offset.iter().enumerate() {
            finite(&format!("discretisation.offset[{k}]"), *o)?;
        }
        if self.dim() == 2 && d.rotation_deg.planar().is_none() {
            return Err(invalid(
                "discretisation.rotation_deg",
                format!("{:?}", d.rotation_deg.angles()),
                "one angle (degrees) for a 2D lattice; three angles [α, β, γ] are for lattice = \"fcc\"",
            ));
        }
        let size = self.body_size();
        if d.spacing > 0.5 * size {
            // a spacing written in mm is 1000 times too large: far larger than the body,
            // and fine enough once read as mm
            let hint = if d.spacing > 10.0 * size && d.spacing * 1e-3 <= 0.5 * size {
                format!(
                    ": {} looks like a value in mm, which is {:e} m",
                    d.spacing,
                    d.spacing * 1e-3
                )
            } else {
                String::new()
            };
            return Err(invalid(
                "discretisation.spacing",
                d.spacing,
                format!(
                    "the spacing in m must be at most half the body's smallest dimension ({:.4e} m){hint}",
                    0.5 * size
                ),
            ));
        }
        Ok(())
    }
}

/// The keys of `lattice = "random"`: a minimum distance in the calibrated range, and none of
/// a lattice's offset or surface treatments.
fn random_particles(d: &DiscretisationSpec) -> Result<(), SceneError> {
    if let Some(f) = d.min_distance {
        if !(f.is_finite() && (0.5..=0.75).contains(&f)) {
            return Err(invalid(
                "discretisation.min_distance",
                f,
                "a fraction of the spacing in [0.5, 0.75]: the elastic calibration of random particles is measured there (model::sppm_calibration), and above 0.75 random placement can hardly reach a hexagonal lattice's density (the jamming limit of random sequential packing is about 0.78)",
            ));
        }
    }
    if d.offset.iter().any(|&o| o != 0.0) {
        return Err(invalid(
            "discretisation.offset",
            format!("{:?}", d.offset),
            "zeros (or absent) for lattice = \"random\": a random particle set has no origin (change `seed` for another particle set; rotation_deg turns the set against the body)",
        ));
    }
    if d.surface_correction == Some(true) {
        return Err(invalid(
            "discretisation.surface_correction",
            "true",
            "false (or absent) for lattice = \"random\": every random particle gets its own least-squares micro-moduli already",
        ));
    }
    if let Some(s) = d.surface {
        if s != Surface::VoronoiFit {
            return Err(invalid(
                "discretisation.surface",
                format!("\"{}\"", s.name()),
                "\"voronoi_fit\" (or absent) for lattice = \"random\": random particles always have their clipped Voronoi cells and their own least-squares micro-moduli",
            ));
        }
    }
    Ok(())
}
