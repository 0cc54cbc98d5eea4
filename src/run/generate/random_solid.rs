//! Random Voronoi-weighted particles in a solid (3D SPPM; docs/model.md §1, §3; docs/sppm.md).

use super::moduli::fit_moduli_3d;
use super::solid::{assemble_solid, refuse_fields};
use super::Generator;
use crate::discretise::fcc::cell_volume;
use crate::discretise::random3;
use crate::model::dimension::{Dim, Dimension};
use crate::run::model::{nu_outside_calibration, Model, RandomBody, SurfaceCorrection};
use crate::run::RunError;
use crate::scene::{Discretisation, Plane, Scene, Surface};

/// Random particles in a solid: [`random3::SLOTS_3D`] bond slots.
#[derive(Clone, Copy, Debug, Default)]
pub struct RandomSolid;

impl Generator<3, { random3::SLOTS_3D }> for RandomSolid {
    const KIND: Discretisation = Discretisation::RandomSolid;

    /// The assembled elastic model of a 3D scene of random particles (SPPM, `lattice =
    /// "random"` in a solid; [`random3::SLOTS_3D`] slots): the particles, their clipped Voronoi
    /// volumes and bonds (`discretise::random3`), each particle's least-squares (a_i, b_i)
    /// against the isotropic D (3.20) of the calibrated pair (E*, ν*) that makes the body show the
    /// scene's (E, ν) (`model::sppm_calibration::fit_target_3d`), with the weighted dilatation;
    /// groups and supports. Particles no fit can serve (too few or coplanar bonds) take the
    /// median fitted moduli per unit volume times their own volume, and are counted
    /// (`surface_correction.kept_bulk`).
    fn model(
        &self,
        scene: &Scene,
        stage: &dyn Fn(&str),
    ) -> Result<Model<{ random3::SLOTS_3D }, 3>, RunError> {
        refuse_fields(scene)?;
        let solid = scene.solid().ok_or_else(|| {
            RunError::Setup("discretisation.lattice = \"random\" in 3D needs a solid body".into())
        })?;
        let recipe = random3::RandomSolid::of_scene(scene);
        stage(&format!(
            "placing {} random particles, their clipped Voronoi cells and bonds",
            random3::target_count(&solid, recipe.spacing)
        ));
        let (mut particles, generation) = random3::fill::<{ random3::SLOTS_3D }>(&solid, &recipe)
            .map_err(|e| {
            RunError::Setup(format!(
                "discretisation.spacing = {} (lattice = \"random\", min_distance = {}): {e}",
                recipe.spacing, recipe.min_distance
            ))
        })?;
        stage("micro-moduli of every particle (least squares)");
        let m = &scene.material;
        let (e_fit, nu_fit) = crate::model::sppm_calibration::fit_target_3d(
            m.youngs_modulus(),
            m.nu,
            recipe.min_distance,
        )
        .map_err(|allowed| nu_outside_calibration(m.nu, allowed))?;
        let d = <Dim<3> as Dimension<3>>::elasticity(e_fit, nu_fit, Plane::Stress);
        let n = particles.len();
        let (mut a, mut b) = (vec![f64::NAN; n], vec![f64::NAN; n]);
        let moduli = fit_moduli_3d(&particles, &d, &mut a, &mut b);
        let per_volume = |v: &[f64]| {
            let mut q: Vec<f64> = (0..n)
                .filter(|&i| v[i].is_finite())
                .map(|i| v[i] / particles.volume[i])
                .collect();
            q.sort_by(f64::total_cmp);
            q.get(q.len() / 2).copied()
        };
        let (Some(a_bulk), Some(b_bulk)) = (per_volume(&a), per_volume(&b)) else {
            return Err(RunError::Setup(format!(
            "discretisation.spacing = {}: no random particle's bonds carry a fit of the micro-moduli (too few or coplanar bonds); use a smaller spacing",
            recipe.spacing
        )));
        };
        for i in 0..n {
            if !a[i].is_finite() {
                a[i] = a_bulk * particles.volume[i];
                b[i] = b_bulk * particles.volume[i];
            }
        }
        particles.a = a;
        particles.b = b;
        let surface = SurfaceCorrection {
            method: Surface::VoronoiFit.name(),
            enabled: true,
            boundary_particles: generation.outline_particles,
            corrected: n - moduli.unfitted,
            kept_bulk: moduli.unfitted,
            max_residual: moduli.residual_max,
            body_volume: solid.volume(),
            particle_volume: particles.volume.iter().sum(),
        };
        // the bulk constants reported: the median particle's, at the FCC cell volume of L0
        let cell = cell_volume(recipe.spacing);
        let bulk = crate::model::dimension::MicroModuli {
            a: a_bulk * cell,
            b: b_bulk * cell,
        };
        let random = RandomBody {
            cells: Vec::new(),
            generation,
            moduli,
        };
        assemble_solid(scene, particles, bulk, surface, Some(random))
    }
}
