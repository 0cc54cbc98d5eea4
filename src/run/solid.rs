//! The body and model of a 3D scene (`discretisation.lattice = "fcc"`): the FCC
//! lattice in the scene's solid, its boundary treatment and micro-moduli, its groups and
//! supports ([`prepare_model_solid`]), then the same dynamics as 2D ([`prepare_solid`]).
//! `[concrete]` runs the same damage kernel as 2D (`solver::concrete`, with the FCC
//! second-neighbour modulus c); random fields in 3D are refused (they are sampled in the
//! plane).

use super::prepare::{
    check_size, dynamics, estimated_particles, supports, Model, Prepared, RandomBody,
    SurfaceCorrection,
};
use super::RunError;
use crate::discretise::fcc::{cell_volume, FccLattice, SECOND, SLOTS, STEPS};
use crate::discretise::groups;
use crate::discretise::NONE;
use crate::discretise::{random3, voronoi3, Particles};
use crate::geometry::Shape3;
use crate::model::dimension::{Dim, Dimension};
use crate::model::micro_modulus::{fit_fcc_weighted, fit_weighted_3d, FccBond, FccModuli};
use crate::scene::Plane;
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
    check_size(scene)?;
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

/// The assembled elastic model of a 3D scene (FCC, 18 slots): body, groups, supports,
/// micro-moduli.
pub fn prepare_model_solid(
    scene: &Scene,
    stage: &dyn Fn(&str),
) -> Result<Model<SLOTS, 3>, RunError> {
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
    assemble(scene, particles, bulk, surface, None)
}

/// Random fields are sampled in the plane: a 3D scene refuses them.
fn refuse_fields(scene: &Scene) -> Result<(), RunError> {
    if scene.random_field.is_empty() {
        return Ok(());
    }
    Err(RunError::Scene(crate::scene::SceneError::Invalid {
        key: "random_field".into(),
        value: format!("{} random fields", scene.random_field.len()),
        allowed: "absent in 3D for now (the fields are sampled in the plane)".into(),
    }))
}

/// The groups, supports and mechanics of a 3D body with its micro-moduli set.
fn assemble<const K: usize>(
    scene: &Scene,
    particles: Particles<3, K>,
    bulk: crate::model::dimension::MicroModuli,
    surface: SurfaceCorrection,
    random: Option<RandomBody>,
) -> Result<Model<K, 3>, RunError> {
    let solid = scene.solid().ok_or_else(|| {
        RunError::Setup(format!(
            "discretisation.lattice = \"{}\" in 3D needs a solid body (box, cylinder or prism)",
            scene.discretisation.lattice
        ))
    })?;
    let section = scene.section_along_z();
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
    let mech = crate::solver::mechanics::Mechanics::new(
        &particles,
        &vec![scene.material.rho; particles.len()],
    );
    Ok(Model {
        scene: scene.clone(),
        particles,
        groups,
        prescribed,
        constrained,
        mech,
        bulk,
        surface,
        fields: Vec::new(),
        random,
    })
}

/// The assembled elastic model of a 3D scene of random particles (SPPM, `lattice =
/// "random"` in a solid; [`random3::SLOTS_3D`] slots): the particles, their clipped Voronoi
/// volumes and bonds (`discretise::random3`), each particle's least-squares (a_i, b_i)
/// against the isotropic D (3.20) of the calibrated pair (E*, ν*) that makes the body show the
/// scene's (E, ν) (`model::sppm_calibration::fit_target_3d`), with the weighted dilatation;
/// groups and supports. Particles no fit can serve (too few or coplanar bonds) take the
/// median fitted moduli per unit volume times their own volume, and are counted
/// (`surface_correction.kept_bulk`).
pub fn prepare_model_random_solid(
    scene: &Scene,
    stage: &dyn Fn(&str),
) -> Result<Model<{ random3::SLOTS_3D }, 3>, RunError> {
    refuse_fields(scene)?;
    check_size(scene)?;
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
    .map_err(|allowed| crate::run::prepare::nu_outside_calibration(m.nu, allowed))?;
    let d = <Dim<3> as Dimension<3>>::elasticity(e_fit, nu_fit, Plane::Stress);
    let n = particles.len();
    let (mut a, mut b) = (vec![f64::NAN; n], vec![f64::NAN; n]);
    let moduli = crate::run::prepare::fit_moduli_3d(&particles, &d, &mut a, &mut b);
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
    assemble(scene, particles, bulk, surface, Some(random))
}

/// Discretise and assemble a 3D scene of random particles, compute T1 and the time step.
pub fn prepare_random_solid(
    scene: &Scene,
    stage: &dyn Fn(&str),
) -> Result<Prepared<{ random3::SLOTS_3D }, 3>, RunError> {
    dynamics(prepare_model_random_solid(scene, stage)?, stage)
}

/// Discretise and assemble a 3D scene, compute T1 and the time step.
pub fn prepare_solid(scene: &Scene, stage: &dyn Fn(&str)) -> Result<Prepared<SLOTS, 3>, RunError> {
    dynamics(prepare_model_solid(scene, stage)?, stage)
}

/// How the micro-moduli of an FCC body were set ([`assign_moduli`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ModuliReport {
    /// Particles with all 18 bonds: the bulk constants (4.8) with the erratum (× the volume
    /// fraction of a clipped cell).
    pub bulk: usize,
    /// Particles with missing bonds fitted (a, b, c) against D (3.20).
    pub fitted: usize,
    /// Particles with missing bonds whose (a, b, c) fit failed, fitted (a, b) with c = 0.
    pub fitted_without_c: usize,
    /// Particles no fit could serve (too few or coplanar bonds), given the bulk constants
    /// scaled by their volume fraction.
    pub unfitted: usize,
    /// Largest relative residual ‖D_i − D‖/‖D‖ of a fitted particle.
    pub max_residual: f64,
}

/// The bulk constants (a, b, c) of an FCC particle with nearest spacing `l0` under the
/// weighted dilatation the lattice runs with (docs/model.md §3 with its erratum; the closed forms
/// (4.8) hold for the source's unweighted θ, see [`fit_fcc_weighted`]): the exact fit of the
/// 18 bonds and the full cell to the isotropic D.
pub fn bulk_moduli(e: f64, nu: f64, l0: f64) -> FccModuli {
    let d = <Dim<3> as Dimension<3>>::elasticity(e, nu, Plane::Stress);
    let bonds: Vec<FccBond> = STEPS
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let v = Vector3::new(s[0] as f64, s[1] as f64, s[2] as f64);
            (v.normalize(), v.norm() * l0 / 2f64.sqrt(), k >= SECOND)
        })
        .collect();
    fit_fcc_weighted(&bonds, cell_volume(l0), l0, &d)
        .expect("the bulk FCC particle spans D")
        .moduli
}

/// Set a, b, c of every particle of an FCC body for the isotropic (E, ν) (docs/model.md §3 with
/// its erratum) and its volume `p.volume` (the full cell, or the cell clipped to the body,
/// `voronoi3::fcc_clipped_volumes`), for the weighted dilatation θ_i = Σ_m (L0,im/ℓ_i)·S_im
/// the lattice runs with ([`FccLattice::fill`](crate::discretise::fcc::FccLattice::fill) sets it): [`bulk_moduli`] scaled by the
/// particle's volume fraction for a particle with all 18 bonds; for one with missing bonds
/// the least-squares (a, b, c) of its own bonds and volume against D (3.20,
/// [`fit_fcc_weighted`]), or (a, b) with c = 0 where that fit fails, or the bulk constants
/// scaled by the volume fraction where no fit exists.
pub fn assign_moduli(p: &mut Particles<3, SLOTS>, e: f64, nu: f64) -> ModuliReport {
    let d = <Dim<3> as Dimension<3>>::elasticity(e, nu, Plane::Stress);
    let mut report = ModuliReport::default();
    let bulk = bulk_moduli(e, nu, p.spacing);
    for i in 0..p.len() {
        let ell = p.length[i];
        let fraction = p.volume[i] / cell_volume(p.spacing);
        let (mut a, mut b, mut c) = (bulk.a * fraction, bulk.b * fraction, bulk.c * fraction);
        if p.bond_count(i) == SLOTS {
            report.bulk += 1;
        } else {
            let bonds: Vec<FccBond> = (0..SLOTS)
                .filter(|&k| p.neighbours[i][k] != NONE)
                .map(|k| {
                    let j = p.neighbours[i][k] as usize;
                    ((p.x0[j] - p.x0[i]).normalize(), p.l0[i][k], k >= SECOND)
                })
                .collect();
            if let Some(f) = fit_fcc_weighted(&bonds, p.volume[i], ell, &d) {
                (a, b, c) = (f.moduli.a, f.moduli.b, f.moduli.c);
                report.fitted += 1;
                report.max_residual = report.max_residual.max(f.residual);
            } else {
                let plain: Vec<_> = bonds.iter().map(|&(n, l, _)| (n, l)).collect();
                if let Some(f) = fit_weighted_3d(&plain, p.volume[i], ell, &d) {
                    (a, b, c) = (f.moduli.a, f.moduli.b, 0.0);
                    report.fitted_without_c += 1;
                    report.max_residual = report.max_residual.max(f.residual);
                } else {
                    report.unfitted += 1;
                }
            }
        }
        p.a[i] = a;
        p.b[i] = b;
        p.c[i] = c;
    }
    report
}
