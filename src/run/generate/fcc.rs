//! The FCC lattice in a solid (3D SPLM; docs/model.md §1, §3; docs/fcc.md): the lattice in
//! the scene's body, its boundary treatment and micro-moduli, groups and supports.

use super::moduli::{assign_moduli, bulk_moduli, ModuliReport};
use super::solid::{assemble_solid, refuse_fields};
use super::Generator;
use crate::discretise::fcc::{FccLattice, SLOTS};
use crate::discretise::{voronoi3, Particles};
use crate::geometry::Shape3;
use crate::run::model::{estimated_particles, Model, SurfaceCorrection};
use crate::run::RunError;
use crate::scene::{Discretisation, Scene, Surface};
use nalgebra::Vector3;
use serde::Serialize;

/// The FCC lattice: 18 bond slots (12 nearest, 6 second neighbours).
#[derive(Clone, Copy, Debug, Default)]
pub struct Fcc;

impl Generator<3, SLOTS> for Fcc {
    const KIND: Discretisation = Discretisation::Fcc;

    fn model(&self, scene: &Scene, stage: &dyn Fn(&str)) -> Result<Model<SLOTS, 3>, RunError> {
        refuse_fields(scene)?;
        stage(&format!(
            "filling the body with about {:.3e} FCC particles",
            estimated_particles(scene)
        ));
        let (particles, body) = fcc_body(scene)?;
        let m = &scene.material;
        let n = particles.len();
        let bulk = bulk_moduli(m.youngs_modulus(), m.nu, scene.discretisation.spacing);
        let moduli = body.moduli;
        let surface = SurfaceCorrection {
            method: body.method,
            enabled: body.method != "lattice",
            boundary_particles: n - moduli.bulk,
            corrected: moduli.fitted + moduli.fitted_without_c,
            kept_bulk: moduli.unfitted,
            max_residual: moduli.max_residual,
            body_volume: body.body_volume,
            particle_volume: body.particle_volume,
        };
        let bulk = crate::model::dimension::MicroModuli {
            a: bulk.a,
            b: bulk.b,
        };
        assemble_solid(scene, particles, bulk, surface, None)
    }
}

/// What the boundary treatment of a 3D body did (`discretisation.surface`).
#[derive(Clone, Debug, Serialize)]
pub struct SolidBody {
    /// The treatment applied: "voronoi_fit" (cells clipped to the body), "lattice_fit" or
    /// "lattice" (full cells).
    pub method: &'static str,
    /// The body's volume (m³) and the particles' total ΔV.
    pub body_volume: f64,
    pub particle_volume: f64,
    pub moduli: ModuliReport,
}

/// The FCC body of a 3D scene with its volumes and micro-moduli. `discretisation.surface`:
/// "voronoi_fit" (the default) clips each cell to the body (`discretise::voronoi3`: box,
/// cylinder, prism) and fits the boundary particles' (a, b, c); `"lattice_fit"` keeps full
/// cells with fitted boundary moduli, `"lattice"` the source's full cells and bulk moduli.
pub fn fcc_body(scene: &Scene) -> Result<(Particles<3, SLOTS>, SolidBody), RunError> {
    let d = &scene.discretisation;
    let m = &scene.material;
    let solid = scene.solid().ok_or_else(|| {
        RunError::Setup(
            "discretisation.lattice = \"fcc\" needs a solid body (box, cylinder or prism)".into(),
        )
    })?;
    let method = d.surface();
    if method == Surface::Voronoi {
        return Err(RunError::Scene(crate::scene::SceneError::Invalid {
            key: "discretisation.surface".into(),
            value: "\"voronoi\"".into(),
            allowed: "\"voronoi_fit\", \"lattice_fit\" or \"lattice\" for the FCC lattice".into(),
        }));
    }
    let [ox, oy, oz] = d.offset3();
    let lattice = FccLattice {
        spacing: d.spacing,
        rotation_deg: d.rotation_deg.angles(),
        offset: Vector3::new(ox, oy, oz),
    };
    let mut p = lattice.fill(&solid);
    if p.len() < 2 {
        return Err(RunError::Setup(format!(
            "discretisation.spacing = {}: the body holds {} bonded particles at this spacing, rotation and offset; at least 2 are needed (use a smaller spacing)",
            d.spacing,
            p.len()
        )));
    }
    let report = surface_treatment(&mut p, &solid, method, m.youngs_modulus(), m.nu);
    Ok((p, report))
}

/// The boundary treatment `method` of an FCC body in `solid` (`discretisation.surface`;
/// "voronoi" is not offered in 3D) into its volumes and micro-moduli for (E, ν):
/// `voronoi_fit` clips every cell to the body and fits the boundary particles
/// ([`assign_moduli`]), `lattice_fit` fits them in full cells, `lattice` gives every particle
/// the full cell and the bulk constants.
pub fn surface_treatment(
    p: &mut Particles<3, SLOTS>,
    solid: &Shape3,
    method: Surface,
    e: f64,
    nu: f64,
) -> SolidBody {
    if method == Surface::VoronoiFit {
        p.volume = voronoi3::fcc_clipped_volumes(p, solid);
    }
    let moduli = if method == Surface::Lattice {
        let n = p.len();
        let bulk = bulk_moduli(e, nu, p.spacing);
        (p.a, p.b, p.c) = (vec![bulk.a; n], vec![bulk.b; n], vec![bulk.c; n]);
        ModuliReport {
            bulk: n,
            ..Default::default()
        }
    } else {
        assign_moduli(p, e, nu)
    };
    SolidBody {
        method: method.name(),
        body_volume: solid.volume(),
        particle_volume: p.volume.iter().sum(),
        moduli,
    }
}
