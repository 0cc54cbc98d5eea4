//! The body and model of a 3D scene (`discretisation.lattice = "fcc"`, issue "3D"): the FCC
//! lattice in the scene's solid, its boundary treatment and micro-moduli, its groups and
//! supports ([`prepare_model_solid`]), then the same dynamics as 2D ([`prepare_solid`]).
//! Elastic scenes run; `[concrete]` and random fields in 3D are refused until the concrete
//! kernels carry the second-neighbour modulus c.

use super::prepare::{dynamics, supports, Model, Prepared, SurfaceCorrection};
use super::RunError;
use crate::discretise::fcc::{assign_moduli, FccLattice, ModuliReport, SLOTS};
use crate::discretise::groups;
use crate::discretise::{bytes_per_particle, voronoi3, Particles};
use crate::geometry::Shape3;
use crate::limits::available_memory;
use crate::model::micro_modulus::fcc_volume;
use crate::scene::{Scene, Surface};
use nalgebra::Vector3;
use serde::Serialize;

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

/// Particles an FCC body of the scene holds (volume / cell volume), before anything is
/// allocated.
pub fn estimated_particles(scene: &Scene, solid: &Shape3) -> f64 {
    solid.volume() / fcc_volume(scene.discretisation.spacing)
}

/// Estimated bytes a 3D run allocates.
pub fn estimated_memory(scene: &Scene, solid: &Shape3) -> f64 {
    estimated_particles(scene, solid) * bytes_per_particle(3, SLOTS) as f64
}

/// The FCC body of a 3D scene with its volumes and micro-moduli. `discretisation.surface`:
/// "voronoi_fit" (the default) clips each cell to the body (`discretise::voronoi3`) where
/// the body is a convex polyhedron (a box) and fits the boundary particles' (a, b, c); on a
/// cylinder or a prism the clipped cells are not available yet and the scene must say
/// `surface = "lattice_fit"` (full cells, fitted boundary moduli) or `"lattice"`.
pub fn fcc_body(scene: &Scene) -> Result<(Particles<3, SLOTS>, SolidBody), RunError> {
    let d = &scene.discretisation;
    let m = &scene.material;
    let solid = scene.solid().ok_or_else(|| {
        RunError::Setup(
            "discretisation.lattice = \"fcc\" needs a solid body (box, cylinder or prism)".into(),
        )
    })?;
    let need = estimated_memory(scene, &solid);
    if let Some(avail) = available_memory() {
        if need > 0.8 * avail as f64 {
            return Err(RunError::Setup(format!(
                "discretisation.spacing = {}: the FCC body would hold about {:.3e} particles needing about {:.1} GiB at {} bytes each, more than this machine has available ({:.1} GiB); use a larger spacing",
                d.spacing,
                estimated_particles(scene, &solid),
                need / 2f64.powi(30),
                bytes_per_particle(3, SLOTS),
                avail as f64 / 2f64.powi(30)
            )));
        }
    }
    if estimated_particles(scene, &solid) > u32::MAX as f64 / 2.0 {
        return Err(RunError::Setup(format!(
            "discretisation.spacing = {}: about {:.3e} particles, more than the 2.1e9 a run can index",
            d.spacing,
            estimated_particles(scene, &solid)
        )));
    }
    let method = d.surface();
    let clipped = match method {
        Surface::VoronoiFit => true,
        Surface::LatticeFit | Surface::Lattice => false,
        Surface::Voronoi => return Err(RunError::Scene(crate::scene::SceneError::Invalid {
            key: "discretisation.surface".into(),
            value: "\"voronoi\"".into(),
            allowed:
                "\"voronoi_fit\" (box bodies), \"lattice_fit\" or \"lattice\" for the FCC lattice"
                    .into(),
        })),
    };
    if clipped && solid.planes().is_none() {
        return Err(RunError::Scene(crate::scene::SceneError::Invalid {
            key: "discretisation.surface".into(),
            value: format!("\"voronoi_fit\" (the default) on body.shape = \"{}\"", scene.body.name()),
            allowed: "\"lattice_fit\" (full cells, fitted boundary moduli) or \"lattice\" (the source) on a cylinder or a prism: their clipped 3D Voronoi cells are not available yet (a box has them)".into(),
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
    if clipped {
        p.volume = voronoi3::fcc_clipped_volumes(&p, &solid).expect("a box has planes");
    }
    let e = m.youngs_modulus();
    let mut moduli = assign_moduli(&mut p, e, m.nu);
    if method == Surface::Lattice {
        let bulk = crate::discretise::fcc::bulk_moduli(e, m.nu, d.spacing);
        for i in 0..p.len() {
            (p.a[i], p.b[i], p.c[i]) = (bulk.a, bulk.b, bulk.c);
        }
        moduli = ModuliReport {
            bulk: p.len(),
            ..Default::default()
        };
    }
    let report = SolidBody {
        method: method.name(),
        body_volume: solid.volume(),
        particle_volume: p.volume.iter().sum(),
        moduli,
    };
    Ok((p, report))
}

/// The assembled elastic model of a 3D scene (FCC, 18 slots): body, groups, supports,
/// micro-moduli.
pub fn prepare_model_solid(
    scene: &Scene,
    stage: &dyn Fn(&str),
) -> Result<Model<SLOTS, 3>, RunError> {
    let refuse = |key: &str, value: String, allowed: &str| {
        RunError::Scene(crate::scene::SceneError::Invalid {
            key: key.into(),
            value,
            allowed: allowed.into(),
        })
    };
    if scene.concrete.is_some() {
        return Err(refuse(
            "concrete",
            "a [concrete] section".into(),
            "absent in 3D for now: the 3D run is elastic until the concrete kernels carry the FCC second-neighbour modulus (issue \"3D\")",
        ));
    }
    if !scene.random_field.is_empty() {
        return Err(refuse(
            "random_field",
            format!("{} random fields", scene.random_field.len()),
            "absent in 3D for now (the fields are sampled in the plane)",
        ));
    }
    stage(&format!(
        "filling the body with about {:.3e} FCC particles",
        scene
            .solid()
            .map_or(0.0, |solid| estimated_particles(scene, &solid))
    ));
    let (particles, body) = fcc_body(scene)?;
    let solid = scene.solid().expect("fcc_body checked the solid");
    let section = match (&scene.body, &solid) {
        (crate::scene::BodySpec::Prism { .. }, _) => Some(scene.shape()),
        (_, Shape3::Cylinder { axis, .. }) if axis.x.abs() < 1e-12 && axis.y.abs() < 1e-12 => {
            Some(scene.shape())
        }
        _ => None,
    };
    let (lo, hi) = solid.bounding_box();
    let extent = format!(
        "x ∈ [{:.6}, {:.6}] m, y ∈ [{:.6}, {:.6}] m, z ∈ [{:.6}, {:.6}] m",
        lo.x, hi.x, lo.y, hi.y, lo.z, hi.z
    );
    let (groups, constrained, prescribed) = supports(
        scene,
        &particles,
        &|sel| groups::select_3d(sel, &particles, &solid, section.as_ref()),
        &extent,
    )?;
    let m = &scene.material;
    let n = particles.len();
    let bulk =
        crate::discretise::fcc::bulk_moduli(m.youngs_modulus(), m.nu, scene.discretisation.spacing);
    let mech = crate::solver::mechanics::Mechanics::new(&particles, &vec![m.rho; n]);
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
    Ok(Model {
        scene: scene.clone(),
        particles,
        groups,
        prescribed,
        constrained,
        mech,
        bulk: crate::model::dimension::MicroModuli {
            a: bulk.a,
            b: bulk.b,
        },
        surface,
        fields: Vec::new(),
        random: None,
    })
}

/// Discretise and assemble a 3D scene, compute T1 and the time step.
pub fn prepare_solid(scene: &Scene, stage: &dyn Fn(&str)) -> Result<Prepared<SLOTS, 3>, RunError> {
    dynamics(prepare_model_solid(scene, stage)?, stage)
}
