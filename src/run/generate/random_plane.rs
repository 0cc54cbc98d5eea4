//! Random Voronoi-weighted particles in a 2D shape (SPPM; docs/model.md §1, §3): every
//! particle's least-squares micro-moduli against the elastic calibration's target (docs/sppm.md).

use super::moduli::fit_moduli;
use super::plane::{assemble_plane, begin};
use super::Generator;
use crate::discretise::random::{self, RandomParticles};
use crate::model::micro_modulus;
use crate::run::model::{nu_outside_calibration, Model, RandomBody};
use crate::run::RunError;
use crate::scene::{Discretisation, Scene};

/// Random particles in a plane: [`random::SLOTS_2D`] bond slots.
#[derive(Clone, Copy, Debug)]
pub struct RandomPlane {
    /// Fit the moduli to the calibrated target (E*, ν*) of `model::sppm_calibration` that
    /// makes the body show the scene's (E, ν); `false` fits the scene's own (E, ν), which is
    /// how that calibration is measured.
    pub calibrated: bool,
}

impl Default for RandomPlane {
    fn default() -> Self {
        RandomPlane { calibrated: true }
    }
}

impl Generator<2, { random::SLOTS_2D }> for RandomPlane {
    const KIND: Discretisation = Discretisation::RandomPlane;

    fn model(
        &self,
        scene: &Scene,
        stage: &dyn Fn(&str),
    ) -> Result<Model<{ random::SLOTS_2D }, 2>, RunError> {
        let d = &scene.discretisation;
        let m = &scene.material;
        let shape = begin(scene, stage);
        let recipe = RandomParticles::of_scene(scene);
        let (particles, cells, generation) = random::fill::<{ random::SLOTS_2D }>(&shape, &recipe)
            .map_err(|e| {
                RunError::Setup(format!(
                    "discretisation.spacing = {} (lattice = \"random\", min_distance = {}): {e}",
                    d.spacing, recipe.min_distance
                ))
            })?;
        assemble_plane(
            scene,
            stage,
            &shape,
            particles,
            true,
            |particles, dmat, a, b, _| {
                // every particle's own least-squares constants (docs/model.md §3, (3.20))
                let target = if self.calibrated {
                    let (e, nu) = crate::model::sppm_calibration::fit_target(
                        m.youngs_modulus(),
                        m.nu,
                        m.plane(),
                        generation.min_distance,
                    )
                    .map_err(|allowed| nu_outside_calibration(m.nu, allowed))?;
                    micro_modulus::elasticity_matrix(e, nu, m.plane())
                } else {
                    *dmat
                };
                stage("micro-moduli of every particle (least squares)");
                let moduli = fit_moduli(particles, &target, a, b);
                Ok(Some(RandomBody {
                    cells,
                    generation,
                    moduli,
                }))
            },
        )
    }
}
