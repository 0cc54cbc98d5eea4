//! Stage 1 of a run: discretise a scene and assemble its model (body, groups, supports,
//! micro-moduli, random fields), then T1, the dampers and the stable time step.

use super::RunError;
use crate::discretise::random::{self, Generation, RandomParticles};
use crate::discretise::{bytes_per_particle, groups, hex::HexLattice, voronoi, Particles};
use crate::limits::available_memory;
use crate::material;
use crate::material::properties::{self, SampledField};
use crate::model::micro_modulus::{self, MicroModuli};
use crate::scene::{Scene, Surface};
use crate::solver::loading::Prescribed;
use crate::solver::mechanics::Mechanics;
use crate::solver::time_step::{stable_step, StableStep};
use crate::solver::{modal, Probe};
use nalgebra::Vector2;
use serde::Serialize;

/// How the lattice's boundary particles were weighted (`discretisation.surface`; docs/model.md §1,
/// §3): their count, the fits, and the body's volume against the particles'.
#[derive(Clone, Debug, Serialize)]
pub struct SurfaceCorrection {
    /// `discretisation.surface` ("voronoi_fit", "voronoi", "lattice", "lattice_fit";
    /// "voronoi_fit" for random particles, which fit every particle).
    pub method: &'static str,
    /// Whether boundary particles got fitted micro-moduli.
    pub enabled: bool,
    /// Particles with fewer than six bonds or a clipped cell.
    pub boundary_particles: usize,
    /// Boundary particles given fitted constants.
    pub corrected: usize,
    /// Boundary particles whose bonds cannot carry a fit (kept at bulk constants, scaled by
    /// their volume fraction under a "voronoi" method).
    pub kept_bulk: usize,
    /// Largest ‖a·A + b·B − D‖/‖D‖ among the corrected particles.
    pub max_residual: f64,
    /// The body's volume (area × thickness, m³) and the particles' total ΔV.
    pub body_volume: f64,
    pub particle_volume: f64,
}

/// What a random body (SPPM) adds to the model: its Voronoi cells, what generation
/// measured, and how well each particle's fitted micro-moduli reproduce D.
#[derive(Clone, Debug)]
pub struct RandomBody {
    /// Each particle's Voronoi cell clipped to the body (counter-clockwise polygon, m).
    pub cells: Vec<Vec<Vector2<f64>>>,
    pub generation: Generation,
    pub moduli: ModuliFit,
}

/// The per-particle least-squares micro-moduli of a random body (docs/model.md §3, (3.20)).
#[derive(Clone, Debug, Serialize)]
pub struct ModuliFit {
    /// ‖a_i·A_i + b_i·B_i − D‖/‖D‖ of each particle (NaN where no fit exists).
    #[serde(skip)]
    pub residual: Vec<f64>,
    pub residual_mean: f64,
    pub residual_p99: f64,
    pub residual_max: f64,
    /// Particles whose bonds cannot carry a fit (too few, or too nearly collinear, or a fit
    /// with a ≤ 0): they keep the hexagonal lattice's constants at their own length.
    pub unfitted: usize,
}

/// A discretised, assembled specimen ready to run: the model plus its dynamics.
pub struct Prepared<const K: usize = 6, const D: usize = 2> {
    pub model: Model<K, D>,
    pub fundamental: modal::Fundamental,
    pub stable: StableStep,
    pub dt: f64,
    pub t_end: f64,
    pub steps: usize,
    pub probe: Option<(String, Probe)>,
}

/// Particles the body will hold (area / cell area; in 3D volume / cell volume), known
/// before anything is allocated.
pub fn estimated_particles(scene: &Scene) -> f64 {
    let l0 = scene.discretisation.spacing;
    if let Some(solid) = scene.solid() {
        return solid.volume() / crate::discretise::fcc::cell_volume(l0);
    }
    scene.shape().area() / (0.5 * 3f64.sqrt() * l0 * l0)
}

/// Estimated bytes a run allocates (2D or 3D; with `[concrete]`, the damage kernel's too).
pub fn estimated_memory(scene: &Scene) -> f64 {
    let dim = scene.dim();
    let slots = if dim == 3 && scene.discretisation.is_random() {
        crate::discretise::random3::SLOTS_3D
    } else if dim == 3 {
        crate::discretise::fcc::SLOTS
    } else {
        slots_of(scene)
    };
    let damage = if scene.concrete.is_some() {
        crate::solver::concrete::bytes_per_particle(dim, slots)
    } else {
        0
    };
    estimated_particles(scene) * (bytes_per_particle(dim, slots) + damage) as f64
}

/// Refuse a scene whose body would not fit this machine's memory (80% of what is available)
/// or that has more particles than a run can index, before anything is allocated.
pub(crate) fn check_size(scene: &Scene) -> Result<(), RunError> {
    let d = &scene.discretisation;
    let need = estimated_memory(scene);
    if let Some(avail) = available_memory() {
        if need > 0.8 * avail as f64 {
            return Err(RunError::Setup(format!(
                "discretisation.spacing = {}: the body would hold about {:.3e} particles needing about {:.1} GiB, more than this machine has available ({:.1} GiB); use a larger spacing",
                d.spacing,
                estimated_particles(scene),
                need / 2f64.powi(30),
                avail as f64 / 2f64.powi(30)
            )));
        }
    }
    if estimated_particles(scene) > u32::MAX as f64 / 2.0 {
        return Err(RunError::Setup(format!(
            "discretisation.spacing = {}: about {:.3e} particles, more than the 2.1e9 a run can index",
            d.spacing,
            estimated_particles(scene)
        )));
    }
    Ok(())
}

/// The assembled elastic model of a scene, before any dynamics (T1, dampers, time step), in
/// `K` bond slots (6: the hexagonal lattice; [`random::SLOTS_2D`]: random particles).
pub struct Model<const K: usize = 6, const D: usize = 2> {
    pub scene: Scene,
    pub particles: Particles<D, K>,
    pub groups: Vec<groups::Group>,
    pub prescribed: Vec<Prescribed>,
    pub constrained: Vec<[bool; D]>,
    pub mech: Mechanics<D, K>,
    pub bulk: MicroModuli,
    pub surface: SurfaceCorrection,
    /// The scene's random fields sampled at the particles (docs/model.md §12).
    pub fields: Vec<SampledField>,
    /// Random particles only: cells, generation, fitted moduli.
    pub random: Option<RandomBody>,
}

/// Bond slots the scene's discretisation needs: 6 for the hexagonal lattice,
/// [`random::SLOTS_2D`] for random particles.
pub fn slots_of(scene: &Scene) -> usize {
    if scene.discretisation.is_random() {
        random::SLOTS_2D
    } else {
        6
    }
}

/// Discretise a scene and assemble its model: lattice, groups, supports, micro-moduli.
pub fn prepare_model(scene: &Scene) -> Result<Model, RunError> {
    prepare_model_with(scene, &|_| {})
}

/// [`prepare_model`] for a scene of random particles.
pub fn prepare_model_random(scene: &Scene) -> Result<Model<{ random::SLOTS_2D }>, RunError> {
    prepare_model_with(scene, &|_| {})
}

/// [`prepare_model_random`] with the moduli fitted to the scene's own (E, ν), without the
/// elastic calibration of `model::sppm_calibration`: how that calibration is measured.
pub fn prepare_model_random_uncalibrated(
    scene: &Scene,
) -> Result<Model<{ random::SLOTS_2D }>, RunError> {
    assemble(scene, &|_| {}, false)
}

/// The body of a scene in K slots: the hexagonal lattice or random particles (with their
/// cells and generation report).
#[allow(clippy::type_complexity)]
fn discretise<const K: usize>(
    scene: &Scene,
    shape: &crate::geometry::Shape2,
) -> Result<
    (
        Particles<2, K>,
        Option<(Vec<Vec<Vector2<f64>>>, Generation)>,
    ),
    RunError,
> {
    let d = &scene.discretisation;
    if K != slots_of(scene) {
        return Err(RunError::Setup(format!(
            "discretisation.lattice = {:?} runs in {} bond slots, not {K} (use run::prepare_model{})",
            d.lattice,
            slots_of(scene),
            if d.is_random() { "_random" } else { "" }
        )));
    }
    if d.is_random() {
        let recipe = RandomParticles::of_scene(scene);
        let (p, cells, generation) = random::fill::<K>(shape, &recipe).map_err(|e| {
            RunError::Setup(format!(
                "discretisation.spacing = {} (lattice = \"random\", min_distance = {}): {e}",
                d.spacing, recipe.min_distance
            ))
        })?;
        return Ok((p, Some((cells, generation))));
    }
    let lattice = HexLattice {
        spacing: d.spacing,
        rotation_deg: d.rotation_deg.angle(),
        offset: Vector2::from(d.offset2()),
        thickness: scene.material.thickness(),
    };
    Ok((lattice.fill_slots(shape), None))
}

/// [`prepare_model`], telling `stage` what it starts (for `sppm check` of large bodies).
pub fn prepare_model_with<const K: usize>(
    scene: &Scene,
    stage: &dyn Fn(&str),
) -> Result<Model<K>, RunError> {
    assemble(scene, stage, true)
}

/// The error of a ν outside the range random particles' elastic calibration covers
/// (`allowed` names the range).
pub(crate) fn nu_outside_calibration(nu: f64, allowed: String) -> RunError {
    RunError::Scene(crate::scene::SceneError::Invalid {
        key: "material.nu".into(),
        value: nu.to_string(),
        allowed,
    })
}

/// [`prepare_model_with`]; `calibrate`: random particles are fitted to the calibrated target
/// (E*, ν*) of `model::sppm_calibration` rather than to the scene's (E, ν).
fn assemble<const K: usize>(
    scene: &Scene,
    stage: &dyn Fn(&str),
    calibrate: bool,
) -> Result<Model<K>, RunError> {
    let d = &scene.discretisation;
    let m = &scene.material;
    if scene.dim() == 3 {
        return Err(RunError::Setup(format!(
            "discretisation.lattice = \"fcc\" (body.shape = \"{}\") is a 3D scene: its model is assembled by run::solid::prepare_model_solid / prepare_solid, not by the 2D assembly",
            scene.body.name()
        )));
    }
    check_size(scene)?;
    let shape = scene.shape();
    stage(&format!(
        "filling the body with about {:.3e} particles",
        estimated_particles(scene)
    ));
    let (particles, random_body) = discretise::<K>(scene, &shape)?;
    if particles.len() < 2 {
        return Err(RunError::Setup(format!(
            "discretisation.spacing = {}: the body holds {} bonded particles at this spacing, rotation and offset; at least 2 are needed (use a smaller spacing)",
            d.spacing,
            particles.len()
        )));
    }

    // Groups, supports and loading.
    let n = particles.len();
    let (body_lo, body_hi) = shape.bounding_box();
    let extent = format!(
        "x ∈ [{:.6}, {:.6}] m, y ∈ [{:.6}, {:.6}] m",
        body_lo.x, body_hi.x, body_lo.y, body_hi.y
    );
    let (groups, constrained, prescribed) = supports(
        scene,
        &particles,
        &|sel| groups::select(sel, &particles, &shape),
        &extent,
    )?;

    // Micro-moduli, with the surface treatment of particles that miss bonds.
    stage("micro-moduli and the surface correction");
    let mut particles = particles;
    // Bulk constants (4.5), (4.6) of each particle's own spacing; reported at the nominal one.
    let bulk = micro_modulus::hexagonal(
        m.youngs_modulus(),
        m.nu,
        d.spacing,
        m.thickness(),
        m.plane(),
    );
    let dmat = micro_modulus::elasticity_matrix(m.youngs_modulus(), m.nu, m.plane());
    let own: Vec<MicroModuli> = (0..n)
        .map(|i| {
            micro_modulus::hexagonal(
                m.youngs_modulus(),
                m.nu,
                particles.length[i],
                m.thickness(),
                m.plane(),
            )
        })
        .collect();
    let mut a: Vec<f64> = own.iter().map(|mm| mm.a).collect();
    let mut b: Vec<f64> = own.iter().map(|mm| mm.b).collect();
    let is_random = random_body.is_some();
    let method = d.surface();
    let mut surface = SurfaceCorrection {
        method: method.name(),
        enabled: is_random || matches!(method, Surface::VoronoiFit | Surface::LatticeFit),
        boundary_particles: 0,
        corrected: 0,
        kept_bulk: 0,
        max_residual: 0.0,
        body_volume: shape.area() * m.thickness(),
        particle_volume: 0.0,
    };
    if !is_random {
        stage("boundary particles: clipped Voronoi cells and fitted moduli");
        surface_treatment(
            &mut particles,
            m.thickness(),
            &shape,
            method,
            &dmat,
            &mut a,
            &mut b,
            &mut surface,
        )?;
    }
    // Random particles: every particle's own least-squares constants (docs/model.md §3, (3.20)).
    let target = match (&random_body, calibrate) {
        (Some((_, generation)), true) => {
            let md = generation.min_distance;
            let (e, nu) =
                crate::model::sppm_calibration::fit_target(m.youngs_modulus(), m.nu, m.plane(), md)
                    .map_err(|allowed| nu_outside_calibration(m.nu, allowed))?;
            micro_modulus::elasticity_matrix(e, nu, m.plane())
        }
        _ => dmat,
    };
    let random = random_body.map(|(cells, generation)| {
        stage("micro-moduli of every particle (least squares)");
        let moduli = fit_moduli(&particles, &target, &mut a, &mut b);
        RandomBody {
            cells,
            generation,
            moduli,
        }
    });
    if !scene.random_field.is_empty() {
        stage("random fields");
    }
    // Random fields (docs/model.md §12), over the body's box: E scales the micro-moduli here, the
    // concrete values go to the damage kernel (`build_simulation`).
    // The box is widened by a margin that does not depend on the spacing (particles may sit
    // on the outline within the lattice fill's tolerance, 1e-9·size).
    let pad = Vector2::repeat(1e-6 * shape.size().max(1.0));
    let fields = properties::sample(scene, body_lo - pad, body_hi + pad, &particles.x0)?;
    properties::check_strengths(scene, &fields)?;
    if let Some(f) = properties::stiffness_factors(&fields, m.youngs_modulus()) {
        for i in 0..n {
            a[i] *= f[i];
            b[i] *= f[i];
        }
    }
    surface.particle_volume = particles.volume.iter().sum();
    particles.a = a;
    particles.b = b;
    let rho = vec![m.rho; n];
    let mech = Mechanics::new(&particles, &rho);
    Ok(Model {
        scene: scene.clone(),
        particles,
        groups,
        prescribed,
        constrained,
        mech,
        bulk,
        surface,
        fields,
        random,
    })
}

/// The scene's groups on a body, its supports (`constrained`) and its prescribed
/// displacements; `select` picks a selection's members, `extent` describes the body for the
/// message of a selection that picks nothing.
#[allow(clippy::type_complexity)]
pub(crate) fn supports<const D: usize, const K: usize>(
    scene: &Scene,
    particles: &Particles<D, K>,
    select: &dyn Fn(&crate::scene::Selection) -> Vec<u32>,
    extent: &str,
) -> Result<(Vec<groups::Group>, Vec<[bool; D]>, Vec<Prescribed>), RunError> {
    let n = particles.len();
    let mut groups = Vec::new();
    let mut constrained = vec![[false; D]; n];
    let mut amplitude: Vec<[Option<(f64, String)>; D]> = vec![std::array::from_fn(|_| None); n];
    for g in &scene.groups {
        let members = select(&g.select);
        if members.is_empty() {
            return Err(RunError::Scene(crate::scene::SceneError::Invalid {
                key: format!("groups.{}.select", g.name),
                value: g.select.scene_text(),
                allowed: format!(
                    "a selection that contains at least one particle; the body spans {extent}"
                ),
            }));
        }
        let mut entries: Vec<(usize, f64)> = g.fix.iter().map(|a| (a.index(), 0.0)).collect();
        if let Some(l) = &g.load {
            entries.push((l.component.index(), l.delta()));
        }
        for &i in &members {
            for &(c, amp) in &entries {
                let slot = &mut amplitude[i as usize][c];
                match slot {
                    Some((prev, other)) if *prev != amp => {
                        return Err(RunError::Scene(crate::scene::SceneError::Invalid {
                            key: format!("groups.{}", g.name),
                            value: format!("particle {i} at {:?}", particles.x0[i as usize].as_slice()),
                            allowed: format!(
                                "groups that overlap must prescribe the same displacement: groups.{other} already prescribes {prev} m in component {c}, this group {amp} m"
                            ),
                        }))
                    }
                    _ => *slot = Some((amp, g.name.clone())),
                }
                constrained[i as usize][c] = true;
            }
        }
        groups.push(groups::Group {
            name: g.name.clone(),
            members,
        });
    }
    let prescribed: Vec<Prescribed> = (0..n)
        .flat_map(|i| {
            let a = amplitude[i].clone();
            (0..D).filter_map(move |c| {
                a[c].as_ref().map(|(amp, _)| Prescribed {
                    particle: i as u32,
                    component: c as u8,
                    amplitude: *amp,
                })
            })
        })
        .collect();
    Ok((groups, constrained, prescribed))
}

/// The boundary treatment of a lattice body (`discretisation.surface`, docs/model.md §1, §3) into
/// `particles.volume` and the micro-moduli `a`, `b` (which hold each particle's bulk
/// constants on entry).
///
/// - `voronoi_fit`, `voronoi`: each particle's volume is its Voronoi cell clipped to the body
///   (`discretise::voronoi`), so the particles carry the body's mass at any rotation and
///   offset. A particle with all six bonds and an unclipped cell keeps the lattice cell
///   (bit for bit). Any other particle gets, under `voronoi_fit`, the least-squares (a, b) of
///   its own bonds and clipped volume against D (3.20), which for a particle with six bonds
///   is exactly the bulk constants times its volume fraction; under `voronoi` (and where a
///   fit does not exist) the bulk constants times its volume fraction.
/// - `lattice`: the source's full cells and bulk constants.
/// - `lattice_fit`: full cells; particles missing bonds get the least-squares fit.
#[allow(clippy::too_many_arguments)]
fn surface_treatment<const K: usize>(
    particles: &mut Particles<2, K>,
    thickness: f64,
    shape: &crate::geometry::Shape2,
    method: Surface,
    dmat: &nalgebra::Matrix3<f64>,
    a: &mut [f64],
    b: &mut [f64],
    report: &mut SurfaceCorrection,
) -> Result<(), RunError> {
    let n = particles.len();
    let clipped = match method {
        Surface::VoronoiFit | Surface::Voronoi => Some(
            voronoi::clipped_cells(&particles.x0, shape).map_err(|e| {
                RunError::Setup(format!(
                    "discretisation.surface = \"{}\": the clipped Voronoi cells of the lattice failed: {e}",
                    method.name()
                ))
            })?,
        ),
        Surface::Lattice | Surface::LatticeFit => None,
    };
    for i in 0..n {
        let cell = particles.volume[i];
        let full_bonds = particles.bond_count(i) == 6;
        let volume = match &clipped {
            Some(c) => {
                let v = c[i].1 * thickness;
                if full_bonds && (v - cell).abs() <= 1e-12 * cell {
                    cell
                } else {
                    v
                }
            }
            None => cell,
        };
        if full_bonds && volume == cell {
            continue;
        }
        report.boundary_particles += 1;
        let volume = quantised(volume, cell, 28);
        particles.volume[i] = volume;
        let fraction = volume / cell;
        let fit = match method {
            Surface::VoronoiFit | Surface::LatticeFit => {
                micro_modulus::fit(&particles.reference_bonds(i), volume, dmat)
            }
            Surface::Voronoi | Surface::Lattice => None,
        };
        match fit {
            Some(f) => {
                let scale = a[i];
                a[i] = quantised(f.moduli.a, scale, 20);
                b[i] = quantised(f.moduli.b, scale, 20);
                report.corrected += 1;
                report.max_residual = report.max_residual.max(f.residual);
            }
            None => {
                a[i] *= fraction;
                b[i] *= fraction;
                if report.enabled {
                    report.kept_bulk += 1;
                }
            }
        }
    }
    Ok(())
}

/// `value` rounded to a multiple of 2⁻ᵇⁱᵗˢ·|scale|.
///
/// The clipped cells and the fits of two particles that are mirror images of each other come
/// out equal only to round-off (6e-14 relative for the volumes on the split cylinder, more
/// for b, a small difference of large terms), because their cells and bonds are visited in
/// a different order; a crack then grows from that difference and a symmetric specimen
/// cracks asymmetrically. Rounding to a grid far coarser than the round-off and far finer
/// than anything physical makes the pairs equal bit for bit: volumes to 2⁻²⁸ of the cell
/// (3.7e-9; the body's mass stays exact to 1e-9), a and b to 2⁻²⁰ of the bulk a (9.5e-7 of
/// a, 2.4e-5 of b).
fn quantised(value: f64, scale: f64, bits: i32) -> f64 {
    let q = scale.abs() * 2f64.powi(-bits);
    (value / q).round() * q
}

/// Each random particle's least-squares (a_i, b_i) against the elasticity matrix `d` from its
/// own bonds, with weighted dilatation ((3.20), docs/sppm.md), written into `a` and `b`;
/// particles without a fit keep their entries. Returns the residual statistics.
pub fn fit_moduli<const K: usize>(
    particles: &Particles<2, K>,
    d: &nalgebra::Matrix3<f64>,
    a: &mut [f64],
    b: &mut [f64],
) -> ModuliFit {
    fit_moduli_with(
        particles,
        |bonds, volume, ell| crate::model::dimension::fit_weighted_2d(bonds, volume, ell, d),
        a,
        b,
    )
}

/// [`fit_moduli`] in 3D (random particles in a solid): against the isotropic 6×6 `d`
/// (3.20), with the weighted dilatation.
pub fn fit_moduli_3d<const K: usize>(
    particles: &Particles<3, K>,
    d: &nalgebra::Matrix6<f64>,
    a: &mut [f64],
    b: &mut [f64],
) -> ModuliFit {
    fit_moduli_with(
        particles,
        |bonds, volume, ell| crate::model::micro_modulus::fit_weighted_3d(bonds, volume, ell, d),
        a,
        b,
    )
}

/// Each particle's (a_i, b_i) from `fit` of its reference bonds, volume and length scale, and
/// the residual statistics ([`fit_moduli`], [`fit_moduli_3d`]).
fn fit_moduli_with<const D: usize, const K: usize>(
    particles: &Particles<D, K>,
    fit: impl Fn(&[(nalgebra::SVector<f64, D>, f64)], f64, f64) -> Option<crate::model::dimension::Fit>
        + Sync,
    a: &mut [f64],
    b: &mut [f64],
) -> ModuliFit {
    use rayon::prelude::*;
    let n = particles.len();
    let fits: Vec<Option<crate::model::dimension::Fit>> = (0..n)
        .into_par_iter()
        .map(|i| {
            fit(
                &particles.reference_bonds(i),
                particles.volume[i],
                particles.length[i],
            )
        })
        .collect();
    let mut residual = vec![f64::NAN; n];
    let mut unfitted = 0;
    for (i, f) in fits.into_iter().enumerate() {
        match f {
            Some(f) => {
                a[i] = f.moduli.a;
                b[i] = f.moduli.b;
                residual[i] = f.residual;
            }
            None => unfitted += 1,
        }
    }
    let mut fitted: Vec<f64> = residual.iter().copied().filter(|r| r.is_finite()).collect();
    fitted.sort_by(f64::total_cmp);
    let pick = |q: f64| {
        if fitted.is_empty() {
            f64::NAN
        } else {
            fitted[((q * (fitted.len() - 1) as f64).round() as usize).min(fitted.len() - 1)]
        }
    };
    ModuliFit {
        residual_mean: fitted.iter().sum::<f64>() / fitted.len().max(1) as f64,
        residual_p99: pick(0.99),
        residual_max: pick(1.0),
        residual,
        unfitted,
    }
}

/// A failed modal analysis, with the scene keys T1 depends on.
fn modal_failure<const K: usize, const D: usize>(
    model: &Model<K, D>,
    e: modal::ModalError,
) -> RunError {
    let text = e.to_string();
    if text.contains("every particle is constrained") {
        return RunError::Setup(format!("{text}: groups fix or load every component of every particle, so nothing is left to move; free some components (groups.*.fix, groups.*.load)"));
    }
    // A particle with one bond has no stiffness across it: a zero-frequency mode.
    let p = &model.particles;
    let single: Vec<usize> = (0..p.len()).filter(|&i| p.bond_count(i) == 1).collect();
    let hanging = match single.first() {
        Some(&i) => format!(
            " {} particle(s) hang by a single bond and swing freely across it (e.g. particle {i} at {:?}): change discretisation.spacing, discretisation.rotation_deg or discretisation.offset, or the body's sharp corners.",
            single.len(),
            p.x0[i].as_slice()
        ),
        None => String::new(),
    };
    let m = &model.scene.material;
    RunError::Setup(format!(
        "{text}. T1 is the lowest mode of the lattice held by its supports (groups.*.fix, groups.*.load); it cannot be found when the supports leave a mechanism, or when material.nu = {} is so close to -1 or 0.5 that the stiffness is too ill-conditioned ({:?} plane).{hanging}",
        m.nu, m.plane()
    ))
}

/// Discretise and assemble a scene, compute T1 and the time step.
pub fn prepare(scene: &Scene) -> Result<Prepared, RunError> {
    prepare_with(scene, &|_| {})
}

/// [`prepare`] for a scene of random particles.
pub fn prepare_random(scene: &Scene) -> Result<Prepared<{ random::SLOTS_2D }>, RunError> {
    prepare_with(scene, &|_| {})
}

/// [`prepare`], telling `stage` what it starts (for `sppm check` of large bodies).
pub fn prepare_with<const K: usize>(
    scene: &Scene,
    stage: &dyn Fn(&str),
) -> Result<Prepared<K>, RunError> {
    dynamics(prepare_model_with(scene, stage)?, stage)
}

/// T1, the dampers, the time step, the run's length and its probe of an assembled model (2D
/// or 3D).
pub(crate) fn dynamics<const K: usize, const D: usize>(
    mut model: Model<K, D>,
    stage: &dyn Fn(&str),
) -> Result<Prepared<K, D>, RunError> {
    let scene = &model.scene.clone();
    // A free particle with one bond has no stiffness across it: a zero-frequency mode that
    // Lanczos may or may not report (with clipped cells it found ω² ≈ 3e-5 rad²/s² and
    // T1 = 1e3 s for the spike of tests/proptest_scenes.rs); refuse it before.
    let p = &model.particles;
    let swings = |i: usize| {
        if p.bond_count(i) != 1 {
            return false;
        }
        // 2D: the direction across its one bond is free of every held component; 3D: it
        // swings unless every component is held
        if D != 2 {
            return model.constrained[i].iter().any(|&c| !c);
        }
        let (n, _) = p.reference_bonds(i)[0];
        let across = [-n[1], n[0]];
        (0..2).all(|c| !model.constrained[i][c] || across[c].abs() < 1e-9)
    };
    if (0..p.len()).any(swings) {
        return Err(modal_failure(
            &model,
            modal::ModalError::Failed("the lattice has a zero-frequency mode".into()),
        ));
    }
    stage("fundamental period T1 (Lanczos)");
    let m = &scene.material;
    let n = model.particles.len();
    let fundamental = modal::fundamental(&model.mech, &model.particles.x0, &model.constrained)
        .map_err(|e| modal_failure(&model, e))?;
    let omega_struct = 2.0 * std::f64::consts::PI / fundamental.period;
    let mech = &mut model.mech;
    for i in 0..n {
        // ω_i from the particle's own length scale (section 4.3)
        let omega_i = material::particle_frequency(
            m.youngs_modulus(),
            m.nu,
            m.rho,
            model.particles.length[i],
        );
        mech.c_in[i] = 2.0 * mech.mass[i] * scene.damping.internal * omega_i;
        mech.c_ex[i] = 2.0 * mech.mass[i] * scene.damping.external * omega_struct;
    }
    stage("stable time step (largest frequency, Lanczos)");
    let stable = stable_step(&model.mech, &model.particles.x0);
    let dt = match scene.solver.dt {
        Some(dt) if dt > stable.dt_stable => {
            return Err(RunError::Scene(crate::scene::SceneError::Invalid {
                key: "solver.dt".into(),
                value: format!("{dt:e}"),
                allowed: format!(
                    "at most the stable limit {:.6e} s computed from the stiffness, masses and damping (or leave solver.dt out to use solver.safety × the limit)",
                    stable.dt_stable
                ),
            }))
        }
        Some(dt) => dt,
        None => scene.solver.safety * stable.dt_stable,
    };
    let t_end = match (scene.loading.end_periods, scene.loading.end_s) {
        (Some(p), _) => p * fundamental.period,
        (None, Some(s)) => s,
        (None, None) => 10.0 * fundamental.period,
    };
    let steps = (t_end / dt).ceil() as usize;
    if steps as f64 * n as f64 > 1e14 {
        return Err(RunError::Setup(format!(
            "loading: t_end = {t_end:.3e} s needs {steps} steps of {n} particles, beyond 1e14 particle-steps; shorten loading.end_periods or coarsen discretisation.spacing"
        )));
    }

    let probe_name = scene.output.probe_group.clone().or_else(|| {
        scene
            .groups
            .iter()
            .find(|g| g.load.is_some())
            .map(|g| g.name.clone())
    });
    let probe = probe_name.map(|name| {
        let spec = scene.groups.iter().find(|g| g.name == name).unwrap();
        let members = model
            .groups
            .iter()
            .find(|g| g.name == name)
            .unwrap()
            .members
            .clone();
        let (component, amplitude) = match &spec.load {
            Some(l) => (l.component.index(), l.delta()),
            None => (spec.fix[0].index(), 0.0),
        };
        (
            name,
            Probe {
                members,
                component,
                amplitude,
            },
        )
    });

    Ok(Prepared {
        model,
        fundamental,
        stable,
        dt,
        t_end,
        steps,
        probe,
    })
}
