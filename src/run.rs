//! `run(scene) -> Outcome`: the whole pipeline of one specimen (ARCHITECTURE.md): scene →
//! body → lattice and groups → micro-moduli → model → stable step and fundamental period →
//! explicit run with probes → outcome. The CLI and the studies are thin callers.

use crate::discretise::{bytes_per_particle, groups, hex::HexLattice, Particles};
use crate::material;
use crate::material::properties::{self, FieldReport, SampledField};
use crate::model::force_state::{dilatation_term, force_state};
use crate::model::micro_modulus::{self, MicroModuli};
use crate::model::stress::StressSum;
use crate::model::stretch::total_stretch;
use crate::model::two_spring::TwoSpring;
use crate::scene::{Scene, SceneError, SolverMethod};
use crate::solver::concrete::{Concrete, ParticleDamage};
use crate::solver::loading::Prescribed;
use crate::solver::mechanics::Mechanics;
use crate::solver::time_step::{stable_step, StableStep};
use crate::solver::{modal, relaxation, Integration, PeakStop, Probe, Record, Simulation};
use nalgebra::{Matrix2, Vector2};
use serde::Serialize;
use std::time::Instant;

/// Everything that stops a run.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("{0}")]
    Setup(String),
    #[error(transparent)]
    Modal(#[from] modal::ModalError),
}

/// Run options that are not part of the scene.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Show a progress bar on runs longer than about a second.
    pub progress: bool,
    /// Override the scene's thread count.
    pub threads: Option<usize>,
}

/// Statistics of the surface correction (MODEL.md §3).
#[derive(Clone, Debug, Serialize)]
pub struct SurfaceCorrection {
    pub enabled: bool,
    /// Particles with fewer than six bonds.
    pub boundary_particles: usize,
    /// Boundary particles given fitted constants.
    pub corrected: usize,
    /// Boundary particles whose bonds cannot carry a fit (kept at bulk constants).
    pub kept_bulk: usize,
    /// Largest ‖a·A + b·B − D‖/‖D‖ among the corrected particles.
    pub max_residual: f64,
}

/// A discretised, assembled specimen ready to run: the model plus its dynamics.
pub struct Prepared {
    pub model: Model,
    pub fundamental: modal::Fundamental,
    pub stable: StableStep,
    pub dt: f64,
    pub t_end: f64,
    pub steps: usize,
    pub probe: Option<(String, Probe)>,
}

pub use crate::limits::available_memory;

/// Particles the body will hold (area / cell area), known before anything is allocated.
pub fn estimated_particles(scene: &Scene) -> f64 {
    let l0 = scene.discretisation.spacing;
    scene.shape().area() / (0.5 * 3f64.sqrt() * l0 * l0)
}

/// Estimated bytes a run allocates.
pub fn estimated_memory(scene: &Scene) -> f64 {
    estimated_particles(scene) * bytes_per_particle(2, 6) as f64
}

/// The assembled elastic model of a scene, before any dynamics (T1, dampers, time step).
pub struct Model {
    pub scene: Scene,
    pub particles: Particles<2, 6>,
    pub groups: Vec<groups::Group>,
    pub prescribed: Vec<Prescribed>,
    pub constrained: Vec<[bool; 2]>,
    pub mech: Mechanics<2, 6>,
    pub bulk: MicroModuli,
    pub surface: SurfaceCorrection,
    /// The scene's random fields sampled at the particles (MODEL.md §12).
    pub fields: Vec<SampledField>,
}

/// Discretise a scene and assemble its model: lattice, groups, supports, micro-moduli.
pub fn prepare_model(scene: &Scene) -> Result<Model, RunError> {
    prepare_model_with(scene, &|_| {})
}

/// [`prepare_model`], telling `stage` what it starts (for `sppm check` of large bodies).
pub fn prepare_model_with(scene: &Scene, stage: &dyn Fn(&str)) -> Result<Model, RunError> {
    let d = &scene.discretisation;
    let m = &scene.material;
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
    let shape = scene.shape();
    let lattice = HexLattice {
        spacing: d.spacing,
        rotation_deg: d.rotation_deg,
        offset: Vector2::new(d.offset[0], d.offset[1]),
        thickness: m.thickness,
    };
    stage(&format!(
        "filling the body with about {:.3e} particles",
        estimated_particles(scene)
    ));
    let particles = lattice.fill(&shape);
    if particles.len() < 2 {
        return Err(RunError::Setup(format!(
            "discretisation.spacing = {}: the body holds {} bonded particles at this spacing, rotation and offset; at least 2 are needed (use a smaller spacing)",
            d.spacing,
            particles.len()
        )));
    }

    // Groups, supports and loading.
    let n = particles.len();
    let mut groups = Vec::new();
    let mut constrained = vec![[false; 2]; n];
    let mut amplitude: Vec<[Option<(f64, String)>; 2]> = vec![[None, None]; n];
    let (body_lo, body_hi) = shape.bounding_box();
    for g in &scene.groups {
        let members = groups::select(&g.select, &particles, &shape);
        if members.is_empty() {
            return Err(RunError::Scene(crate::scene::SceneError::Invalid {
                key: format!("groups.{}.select", g.name),
                value: g.select.scene_text(),
                allowed: format!(
                    "a selection that contains at least one particle; the body spans x ∈ [{:.6}, {:.6}] m, y ∈ [{:.6}, {:.6}] m",
                    body_lo.x, body_hi.x, body_lo.y, body_hi.y
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
            (0..2).filter_map(move |c| {
                a[c].as_ref().map(|(amp, _)| Prescribed {
                    particle: i as u32,
                    component: c as u8,
                    amplitude: *amp,
                })
            })
        })
        .collect();

    // Micro-moduli, with the surface correction of particles that miss bonds.
    stage("micro-moduli and the surface correction");
    // Bulk constants (4.5), (4.6) of each particle's own spacing; reported at the nominal one.
    let bulk = micro_modulus::hexagonal(m.youngs_modulus(), m.nu, d.spacing, m.thickness, m.plane);
    let dmat = micro_modulus::elasticity_matrix(m.youngs_modulus(), m.nu, m.plane);
    let own: Vec<MicroModuli> = (0..n)
        .map(|i| {
            micro_modulus::hexagonal(
                m.youngs_modulus(),
                m.nu,
                particles.length[i],
                m.thickness,
                m.plane,
            )
        })
        .collect();
    let mut a: Vec<f64> = own.iter().map(|mm| mm.a).collect();
    let mut b: Vec<f64> = own.iter().map(|mm| mm.b).collect();
    let mut surface = SurfaceCorrection {
        enabled: d.surface_correction,
        boundary_particles: 0,
        corrected: 0,
        kept_bulk: 0,
        max_residual: 0.0,
    };
    for i in 0..n {
        if particles.bond_count(i) == 6 {
            continue;
        }
        surface.boundary_particles += 1;
        if !d.surface_correction {
            continue;
        }
        let bonds: Vec<(Vector2<f64>, f64)> = (0..6)
            .filter(|&k| particles.neighbours[i][k] != crate::discretise::NONE)
            .map(|k| {
                let j = particles.neighbours[i][k] as usize;
                (
                    (particles.x0[j] - particles.x0[i]).normalize(),
                    particles.l0[i][k],
                )
            })
            .collect();
        match micro_modulus::fit(&bonds, particles.volume[i], &dmat) {
            Some(f) => {
                a[i] = f.moduli.a;
                b[i] = f.moduli.b;
                surface.corrected += 1;
                surface.max_residual = surface.max_residual.max(f.residual);
            }
            None => surface.kept_bulk += 1,
        }
    }
    if !scene.random_field.is_empty() {
        stage("random fields");
    }
    // Random fields (MODEL.md §12), over the body's box: E scales the micro-moduli here, the
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
    let mut particles = particles;
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
    })
}

/// A failed modal analysis, with the scene keys T1 depends on.
fn modal_failure(model: &Model, e: modal::ModalError) -> RunError {
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
        m.nu, m.plane
    ))
}

/// Discretise and assemble a scene, compute T1 and the time step.
pub fn prepare(scene: &Scene) -> Result<Prepared, RunError> {
    prepare_with(scene, &|_| {})
}

/// [`prepare`], telling `stage` what it starts (for `sppm check` of large bodies).
pub fn prepare_with(scene: &Scene, stage: &dyn Fn(&str)) -> Result<Prepared, RunError> {
    let mut model = prepare_model_with(scene, stage)?;
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

/// The summary of a run (summary.json; the keys ARCHITECTURE.md names, and more).
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub scene: String,
    pub description: Option<String>,
    pub status: String,
    pub message: Option<String>,
    pub particles: usize,
    pub bonds: usize,
    pub steps: usize,
    pub dt_s: f64,
    pub dt_stable_s: f64,
    pub safety: f64,
    pub fundamental_period_s: f64,
    pub t_end_s: f64,
    pub wall_time_s: f64,
    /// Wall time from the start of the run to the record of the peak force.
    pub wall_time_to_peak_s: f64,
    /// Step of the peak record.
    pub peak_step: usize,
    pub solver_method: SolverMethod,
    /// Relaxation: kernel steps of all increments.
    pub iterations: Option<usize>,
    /// Relaxation: load increments.
    pub increments: Option<usize>,
    /// Relaxation: increments that stopped at solver.max_iterations.
    pub unconverged_increments: Option<usize>,
    /// Relaxation: largest out-of-balance force norm / reaction norm at the end of an
    /// increment.
    pub max_final_residual: Option<f64>,
    /// The run stopped after its peak (`loading.stop_after_peak`), before t_end.
    pub stopped_after_peak: bool,
    pub threads: usize,
    pub probe_group: Option<String>,
    #[serde(rename = "peak_force_N")]
    pub peak_force_n: f64,
    pub displacement_at_peak_m: f64,
    pub final_displacement_m: f64,
    #[serde(rename = "final_force_N")]
    pub final_force_n: f64,
    /// External work not found in kinetic, elastic or damper energy (damage and plasticity;
    /// for an elastic scene a measure of the energy error).
    #[serde(rename = "dissipated_energy_J")]
    pub dissipated_energy_j: f64,
    #[serde(rename = "damping_energy_J")]
    pub damping_energy_j: f64,
    #[serde(rename = "external_work_J")]
    pub external_work_j: f64,
    #[serde(rename = "internal_energy_J")]
    pub internal_energy_j: f64,
    #[serde(rename = "kinetic_energy_J")]
    pub kinetic_energy_j: f64,
    /// Largest kinetic/internal energy ratio before and around the peak (the records up to
    /// the peak and after it while the force stays at 80% of the peak or more), over the records where the internal energy is
    /// at least 1% of its maximum (the quasi-static check).
    pub max_kinetic_to_internal_energy: f64,
    /// The same over the whole run (after complete failure the elastic energy vanishes and
    /// this ratio says little).
    pub max_kinetic_to_internal_energy_whole_run: f64,
    /// Largest tensile damage w_t (scenes with `[concrete]`).
    pub max_damage: Option<f64>,
    pub max_compressive_damage: Option<f64>,
    /// Particles with w_t ≥ 0.99.
    pub cracked_particles: Option<usize>,
    /// Particles with w_c ≥ 0.99.
    pub crushed_particles: Option<usize>,
    /// Particles that yielded at least once.
    pub yielded_particles: Option<usize>,
    /// The concrete law used (every value resolved).
    pub concrete: Option<crate::model::damage::ConcreteLaw>,
    /// Material values and where each came from (scene, preset or correlation).
    pub material_values: Vec<crate::scene::concrete::Derived>,
    pub force_lag: crate::scene::ForceLag,
    /// The step kernel chosen for the scene's features: elastic, tension or full.
    pub kernel: crate::solver::KernelSet,
    pub surface_correction: SurfaceCorrection,
    pub micro_modulus_a_bulk: f64,
    pub micro_modulus_b_bulk: f64,
    pub spacing_m: f64,
    pub rotation_deg: f64,
    pub offset_m: [f64; 2],
    pub omega_max_rad_s: f64,
    pub omega_max_bound_rad_s: f64,
    /// The scene's seed (`Scene::effective_seed`), `None` when it makes no random choice.
    pub seed: Option<u64>,
    /// Each random field: its parameters, seed and the statistics of the particles' values.
    pub random_fields: Vec<FieldReport>,
    pub sppm_version: String,
}

/// What a run produces.
pub struct Outcome {
    pub summary: Summary,
    pub records: Vec<Record>,
    pub x0: Vec<Vector2<f64>>,
    pub displacement: Vec<Vector2<f64>>,
    pub stress: Vec<Matrix2<f64>>,
    /// Damage and plasticity state of each particle at the end (scenes with `[concrete]`).
    pub damage: Option<Vec<ParticleDamage>>,
    pub groups: Vec<groups::Group>,
    pub scene: Scene,
    /// The random fields' values at each particle (MODEL.md §12).
    pub fields: Vec<SampledField>,
}

impl Outcome {
    pub fn failed(&self) -> bool {
        self.summary.status != "completed"
    }
}

/// Particle stresses (3.18) at positions x: σ_i = (1/(2ΔV_i))·Σ_j L0,ij·F_s,ij·(e_ij ⊗ e_ij)
/// with F_s,ij = a_i·S_ij + b_i·Σ_m S_im and e_ij the current bond direction.
pub fn particle_stress(
    mech: &Mechanics<2, 6>,
    volume: &[f64],
    x: &[Vector2<f64>],
) -> Vec<Matrix2<f64>> {
    (0..x.len())
        .map(|i| {
            let mut theta = 0.0;
            for (_, j, il) in mech.bonds(i) {
                theta += total_stretch((x[j] - x[i]).norm(), il);
            }
            let mut acc = StressSum::default();
            for (_, j, il) in mech.bonds(i) {
                let d = x[j] - x[i];
                let len = d.norm();
                let s = total_stretch(len, il);
                acc.add(
                    &(d / len),
                    1.0 / il,
                    force_state(mech.a[i], s, dilatation_term(mech.b[i], theta)),
                );
            }
            acc.finish(volume[i])
        })
        .collect()
}

/// Run a scene to its end. A run that goes unstable stops there and its outcome says so
/// (`summary.status = "unstable"`, `summary.message` names the step and the particle).
pub fn run(scene: &Scene, opts: &RunOptions) -> Result<Outcome, RunError> {
    let threads = opts
        .threads
        .or(scene.solver.threads)
        .unwrap_or_else(rayon::current_num_threads);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| RunError::Setup(format!("cannot start {threads} threads: {e}")))?;
    pool.install(|| run_prepared(prepare(scene)?, opts, threads))
}

/// The simulation of a prepared scene, at rest, taking over the model's arrays (no copy);
/// with `[concrete]`, the damage and plasticity kernel is on.
pub fn build_simulation(p: &mut Prepared) -> Simulation<2, 6> {
    let integration = Integration {
        dt: p.dt,
        lagged_forces: p.model.scene.solver.force_lag == crate::scene::ForceLag::Previous,
        ramp: p.model.scene.loading.ramp,
        t_ramp: p.model.scene.loading.ramp_fraction * p.t_end,
    };
    let mut sim = Simulation::new(
        p.model.particles.x0.clone(),
        std::mem::take(&mut p.model.mech),
        std::mem::take(&mut p.model.prescribed),
        integration,
    );
    if let Some(law) = crate::model::damage::ConcreteLaw::from_scene(&p.model.scene) {
        let local = properties::local_properties(&p.model.fields, &law, p.model.particles.len());
        let c: Concrete<6> = Concrete::new(TwoSpring::new(law, local), &p.model.particles);
        sim.inelastic = Some(Box::new(c));
    }
    sim
}

fn run_prepared(mut p: Prepared, opts: &RunOptions, threads: usize) -> Result<Outcome, RunError> {
    let start = Instant::now();
    let method = p.model.scene.solver.method;
    if method == SolverMethod::Relaxation {
        // Dampers off; the step of the undamped model (see solver::relaxation).
        p.stable = relaxation::undamped(&mut p.model.mech, &p.model.particles.x0);
        p.dt = p
            .model
            .scene
            .solver
            .dt
            .unwrap_or(p.model.scene.solver.safety * p.stable.dt_stable);
    }
    let mut sim = build_simulation(&mut p);
    let empty_probe = Probe {
        members: vec![],
        component: 1,
        amplitude: 0.0,
    };
    let probe = p.probe.as_ref().map(|(_, pr)| pr).unwrap_or(&empty_probe);
    let (records, wall_s, failure, report) = match method {
        SolverMethod::Explicit => {
            let (records, wall_s, failure, stopped) =
                run_explicit(&mut sim, &p, probe, opts, start);
            let report = SolverReport {
                stopped_after_peak: stopped,
                ..Default::default()
            };
            (records, wall_s, failure, report)
        }
        SolverMethod::Relaxation => {
            let s = &p.model.scene.solver;
            let settings = relaxation::Settings {
                increments: s.increments,
                tolerance: s.tolerance,
                max_iterations: s.max_iterations,
                ramp: p.model.scene.loading.ramp,
                stop_after_peak: p.model.scene.loading.stop_after_peak,
            };
            let r = relaxation::relax(&mut sim, probe, &settings, start);
            let report = SolverReport {
                iterations: Some(r.iterations),
                increments: Some(s.increments),
                unconverged_increments: Some(r.unconverged_increments),
                max_final_residual: Some(r.max_final_residual),
                stopped_after_peak: r.stopped_after_peak,
            };
            (r.records, r.wall_s, r.failure, report)
        }
    };
    let wall = start.elapsed().as_secs_f64();
    let x = sim.state.x.clone();
    let displacement: Vec<Vector2<f64>> = x
        .iter()
        .zip(&p.model.particles.x0)
        .map(|(a, b)| a - b)
        .collect();
    let (stress, damage) = match &sim.inelastic {
        Some(model) => (
            model.particle_stress(&sim.mech, &x, &p.model.particles.volume),
            Some(model.damage()),
        ),
        None => (
            particle_stress(&sim.mech, &p.model.particles.volume, &x),
            None,
        ),
    };
    let summary = summarise(
        &p,
        &Finished {
            kernel: sim.kernel(),
            method,
            report,
            records: &records,
            wall_s: &wall_s,
            wall,
            threads,
            steps_done: sim.step,
            failure: failure.as_ref().map(|e| e.to_string()),
        },
        damage.as_deref(),
    );
    let outcome = Outcome {
        summary,
        records,
        x0: p.model.particles.x0.clone(),
        displacement,
        stress,
        damage,
        groups: p.model.groups.clone(),
        scene: p.model.scene.clone(),
        fields: p.model.fields.clone(),
    };
    Ok(outcome)
}

/// What the relaxation solver adds to the summary (`None` for the explicit one).
#[derive(Clone, Copy, Debug, Default)]
struct SolverReport {
    iterations: Option<usize>,
    increments: Option<usize>,
    unconverged_increments: Option<usize>,
    max_final_residual: Option<f64>,
    stopped_after_peak: bool,
}

/// The explicit run to t_end with probe records (and the wall time at each), stopping at an
/// instability, or after the peak with `loading.stop_after_peak` (then `true`).
fn run_explicit(
    sim: &mut Simulation<2, 6>,
    p: &Prepared,
    probe: &Probe,
    opts: &RunOptions,
    start: Instant,
) -> (Vec<Record>, Vec<f64>, Option<crate::solver::Unstable>, bool) {
    let mut stop = PeakStop::new(p.model.scene.loading.stop_after_peak, probe);
    let mut stopped = false;
    let every = (p.steps / (p.model.scene.output.records - 1)).max(1);
    let bar = if opts.progress && (p.steps as f64 * p.model.particles.len() as f64) > 2e7 {
        let b = indicatif::ProgressBar::new(p.steps as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} {wide_bar} {pos}/{len} steps  {elapsed_precise} ETA {eta}",
            )
            .unwrap(),
        );
        Some(b)
    } else {
        None
    };
    let mut records = Vec::with_capacity(p.model.scene.output.records + 1);
    let mut wall_s = Vec::with_capacity(p.model.scene.output.records + 1);
    let mut failure = None;
    for n in 0..p.steps {
        let want = n % every == 0 || n + 1 == p.steps;
        let rec = sim.advance(if want { Some(probe) } else { None });
        if let Some(r) = rec {
            records.push(r);
            wall_s.push(start.elapsed().as_secs_f64());
        }
        if want || n % 64 == 0 {
            let u = rec.map(|r| r.internal_j);
            if let Err(e) = sim.check_stability(u, true) {
                failure = Some(e);
                break;
            }
        }
        if rec.is_some_and(|r| stop.reached(&r, sim)) {
            stopped = true;
            break;
        }
        if let Some(b) = &bar {
            if n % 256 == 0 {
                b.set_position(n as u64);
            }
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    (records, wall_s, failure, stopped)
}

/// What a finished run hands to its summary.
struct Finished<'a> {
    kernel: crate::solver::KernelSet,
    method: SolverMethod,
    report: SolverReport,
    records: &'a [Record],
    /// Wall time (s since the start) at each record.
    wall_s: &'a [f64],
    wall: f64,
    threads: usize,
    /// Kernel steps taken (the step an unstable run stopped at, not only the last record).
    steps_done: usize,
    failure: Option<String>,
}

fn summarise(p: &Prepared, run: &Finished, damage: Option<&[ParticleDamage]>) -> Summary {
    let Finished {
        kernel,
        method,
        report,
        records,
        wall_s,
        wall,
        threads,
        ..
    } = *run;
    let s = &p.model.scene.solver;
    let accepted = s.max_residual.unwrap_or(s.tolerance);
    let unconverged = match (report.unconverged_increments, report.max_final_residual) {
        (Some(k), Some(r)) if k > 0 && r > accepted => Some(format!(
            "{k} of {} load increments stopped at solver.max_iterations = {} with an out-of-balance force up to {r:.3e} × the reactions, above {} = {accepted:e}: the forces and the crack path are not the quasi-static answer. Raise solver.max_iterations or solver.increments, or accept the residual with solver.max_residual ≥ {r:.2e}",
            report.increments.unwrap_or(0),
            s.max_iterations,
            if s.max_residual.is_some() { "solver.max_residual" } else { "solver.tolerance" },
        )),
        _ => None,
    };
    let failure = run.failure.clone();
    let status = if failure.is_some() {
        "unstable"
    } else if unconverged.is_some() {
        "unconverged"
    } else {
        "completed"
    };
    let failure = failure.or(unconverged);
    let sign = p
        .probe
        .as_ref()
        .map(|(_, pr)| if pr.amplitude < 0.0 { -1.0 } else { 1.0 })
        .unwrap_or(1.0);
    let peak = records.iter().max_by(|a, b| {
        (sign * a.force_n)
            .partial_cmp(&(sign * b.force_n))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let last = records.last().copied().unwrap_or_default();
    let umax = records.iter().map(|r| r.internal_j).fold(0.0, f64::max);
    let ratio_over = |rs: &[Record]| {
        rs.iter()
            .filter(|r| r.internal_j >= 0.01 * umax && umax > 0.0)
            .map(|r| r.kinetic_j / r.internal_j)
            .fold(0.0, f64::max)
    };
    // Before and around the peak: the records up to the peak and after it while the force
    // stays at 80% of the peak or more.
    let window_end = match peak {
        Some(pk) => {
            let ipk = records.iter().position(|r| r.step == pk.step).unwrap_or(0);
            records[ipk..]
                .iter()
                .position(|r| sign * r.force_n < 0.8 * sign * pk.force_n)
                .map(|o| ipk + o)
                .unwrap_or(records.len())
        }
        None => records.len(),
    };
    let ratio = ratio_over(&records[..window_end]);
    let ratio_whole = ratio_over(records);
    let d = &p.model.scene.discretisation;
    Summary {
        scene: p.model.scene.name().to_string(),
        description: p.model.scene.description.clone(),
        status: status.into(),
        message: failure,
        particles: p.model.particles.len(),
        bonds: p.model.particles.bonds(),
        steps: run.steps_done,
        dt_s: p.dt,
        dt_stable_s: p.stable.dt_stable,
        safety: p.dt / p.stable.dt_stable,
        fundamental_period_s: p.fundamental.period,
        t_end_s: p.t_end,
        wall_time_s: wall,
        wall_time_to_peak_s: peak
            .and_then(|pk| records.iter().position(|r| r.step == pk.step))
            .and_then(|i| wall_s.get(i).copied())
            .unwrap_or(wall),
        peak_step: peak.map(|r| r.step).unwrap_or(0),
        solver_method: method,
        iterations: report.iterations,
        increments: report.increments,
        unconverged_increments: report.unconverged_increments,
        max_final_residual: report.max_final_residual,
        stopped_after_peak: report.stopped_after_peak,
        threads,
        probe_group: p.probe.as_ref().map(|(n, _)| n.clone()),
        peak_force_n: peak.map(|r| r.force_n * sign).unwrap_or(0.0),
        displacement_at_peak_m: peak.map(|r| r.displacement_m).unwrap_or(0.0),
        final_displacement_m: last.displacement_m,
        final_force_n: last.force_n,
        dissipated_energy_j: last.external_work_j
            - last.kinetic_j
            - last.internal_j
            - last.damping_j,
        damping_energy_j: last.damping_j,
        external_work_j: last.external_work_j,
        internal_energy_j: last.internal_j,
        kinetic_energy_j: last.kinetic_j,
        max_kinetic_to_internal_energy: ratio,
        max_kinetic_to_internal_energy_whole_run: ratio_whole,
        max_damage: damage.map(|d| d.iter().map(|p| p.wt).fold(0.0, f64::max)),
        max_compressive_damage: damage.map(|d| d.iter().map(|p| p.wc).fold(0.0, f64::max)),
        cracked_particles: damage.map(|d| d.iter().filter(|p| p.wt >= 0.99).count()),
        crushed_particles: damage.map(|d| d.iter().filter(|p| p.wc >= 0.99).count()),
        yielded_particles: damage.map(|d| d.iter().filter(|p| p.yielded).count()),
        concrete: crate::model::damage::ConcreteLaw::from_scene(&p.model.scene),
        material_values: p.model.scene.derived.clone(),
        force_lag: p.model.scene.solver.force_lag,
        kernel,
        surface_correction: p.model.surface.clone(),
        micro_modulus_a_bulk: p.model.bulk.a,
        micro_modulus_b_bulk: p.model.bulk.b,
        spacing_m: d.spacing,
        rotation_deg: d.rotation_deg,
        offset_m: d.offset,
        omega_max_rad_s: p.stable.omega_max,
        omega_max_bound_rad_s: p.stable.omega_max_bound,
        seed: p.model.scene.effective_seed(),
        random_fields: p.model.fields.iter().map(|f| f.report.clone()).collect(),
        sppm_version: env!("CARGO_PKG_VERSION").to_string(),
    }
}
