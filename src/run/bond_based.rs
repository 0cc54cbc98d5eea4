//! A run of the bond-based family (`model.family = "bond_based"`; docs/bond_based.md): the
//! scene's generator fills the body (the cubic grid, or the particles of any other
//! discretisation), the points get their families within the horizon, and the explicit
//! Euler–Cromer integration drives the displacement loading to the same records, summary
//! and outputs as a lattice run.

use super::generate::Generator;
use super::model::Model;
use super::prepare::{checked_steps, loading_time, prepare_model, probe_of, time_step, Prepared};
pub use super::summary::BondReport;
use super::summary::{point3, summarise, Finished, Outcome, SolverReport};
use super::RunError;
use crate::model::bond_based::body::{BodySettings, BondBody};
use crate::model::bond_based::micromodulus::{micromodulus, Body, Influence};
use crate::model::bond_based::softening::{Fit, Softening};
use crate::model::damage_law::ParticleDamage;
use crate::scene::model_family::{InfluenceKind, SofteningKind};
use crate::scene::{Plane, Scene};
use crate::solver::loading::ramp_fraction;
use crate::solver::modal::{self, Fundamental};
use crate::solver::time_step::StableStep;
use crate::solver::{Location, Record, Unstable};
use nalgebra::SVector;
use std::time::Instant;

mod integrate;
pub use integrate::Stepper;

/// The bond-based body of a model's points, with the scene's `[model]` choices and, with
/// `[concrete]`, its softening law; and the run's report of it.
pub fn bond_body<const K: usize, const D: usize>(
    model: &Model<K, D>,
) -> Result<(BondBody<D>, BondReport), RunError> {
    let scene = &model.scene;
    let spec = &scene.model;
    let p = &model.particles;
    let t = scene.material.thickness();
    let mean = p.volume.iter().sum::<f64>() / p.len() as f64;
    let dx = if scene.discretisation.lattice == crate::scene::Lattice::Cubic {
        scene.discretisation.spacing
    } else if D == 3 {
        mean.cbrt()
    } else {
        (mean / t).sqrt()
    };
    let delta = spec.horizon() * dx;
    let (body, nu) = match (D, scene.material.plane()) {
        (3, _) => (Body::Solid, 0.25),
        (_, Plane::Stress) => (Body::PlaneStress { t }, 1.0 / 3.0),
        (_, Plane::Strain) => (Body::PlaneStrain { t }, 0.25),
    };
    let influence = match spec.influence() {
        InfluenceKind::Constant => Influence::Constant,
        InfluenceKind::Conical => Influence::Conical,
    };
    let e = scene.material.youngs_modulus();
    let c = micromodulus(e, delta, body, influence);
    let law = scene.concrete.as_ref().map(|conc| {
        let fit = Fit {
            e,
            ft: conc.ft.unwrap_or(f64::NAN),
            gf: conc.gf.unwrap_or(f64::NAN),
            delta,
            // the laws are fitted to the constant micromodulus of the same stiffness
            c: micromodulus(e, delta, body, Influence::Constant),
            thickness: (D == 2).then_some(t),
        };
        match spec.softening() {
            SofteningKind::Linear => Softening::linear(&fit),
            SofteningKind::Bilinear => Softening::bilinear(&fit, BILINEAR_RATIO),
            SofteningKind::Trilinear => Softening::trilinear(&fit, TRILINEAR_BETA),
            SofteningKind::NonLinear => {
                Softening::non_linear(&fit, NON_LINEAR_RATE, NON_LINEAR_RESIDUAL)
            }
        }
    });
    let settings = BodySettings {
        delta,
        dx,
        c,
        influence,
        surface_correction: spec.surface_correction(),
        critical_stretch_correction: spec.critical_stretch_correction(),
        law,
        compressive: spec.compressive_stretch,
        contact: spec.contact(),
    };
    let admits = admission(scene);
    let x0 = p.x0.clone();
    let body = BondBody::new(x0.clone(), p.volume.clone(), settings, None, &|i, j| {
        admits(&x0[i], &x0[j])
    });
    let report = BondReport {
        horizon_m: delta,
        horizon_ratio: spec.horizon(),
        cell_size_m: dx,
        micromodulus: c,
        influence: spec.influence(),
        poisson_ratio_of_the_model: nu,
        softening: law.map(|_| spec.softening()),
        s0: law.map(|l| l.elastic_limit()),
        critical_stretch: law.map(|l| l.critical_stretch()),
        compressive_stretch: spec.compressive_stretch,
        surface_correction: spec.surface_correction(),
        critical_stretch_correction: spec.critical_stretch_correction(),
        contact: spec.contact(),
        bonds: body.bonds(),
        bonds_per_point: body.neighbour.len() as f64 / body.len() as f64,
        broken_bonds: 0,
        max_point_damage: 0.0,
        points_half_damaged: 0,
    };
    Ok((body, report))
}

/// k_r of the bilinear law (Zaccariotto et al.; Hobbs 2021).
pub const BILINEAR_RATIO: f64 = 25.0;
/// β of the trilinear law (Yang et al. 2018; Hobbs 2021).
pub const TRILINEAR_BETA: f64 = 0.25;
/// k and α of the non-linear law (Hobbs 2021).
pub const NON_LINEAR_RATE: f64 = 25.0;
pub const NON_LINEAR_RESIDUAL: f64 = 0.25;

/// The test of whether a bond between two points stays in the body.
type Admission<const D: usize> = Box<dyn Fn(&SVector<f64, D>, &SVector<f64, D>) -> bool + Sync>;

/// Whether a bond between two points stays in the scene's body: it crosses no notch, slit or
/// hole and does not leave a non-convex outline (the body's own test of a lattice bond,
/// with the outline sampled at eight points along the bond). A bond that only touches a
/// notch, at its tip or along a face, is cut: the test's tolerance is negative, so the
/// boundary belongs to the notch (docs/bond_based.md, "Notches": on a regular grid a notch
/// tip midway between two rows lies on bonds, and Hobbs's own intersection test of a bond
/// against a notch counts a touch as a cut).
fn admission<const D: usize>(scene: &Scene) -> Admission<D> {
    let tol = -1e-9 * scene.discretisation.spacing;
    if D == 3 {
        let solid = scene.solid();
        Box::new(move |a, b| {
            let (a, b) = (
                nalgebra::Vector3::new(a[0], a[1], a[2]),
                nalgebra::Vector3::new(b[0], b[1], b[2]),
            );
            solid
                .as_ref()
                .map(|s| s.segment_in_body(&a, &b, tol, 8))
                .unwrap_or(true)
        })
    } else {
        let shape = scene.shape();
        Box::new(move |a, b| {
            shape.segment_in_body(
                &nalgebra::Vector2::new(a[0], a[1]),
                &nalgebra::Vector2::new(b[0], b[1]),
                tol,
                8,
            )
        })
    }
}

/// The lowest mode of the bond-based body held by its supports (Lanczos on the linearised
/// forces), and the stable step of the explicit integration, Δt ≤ √(2·m_i/Σ k/ξ) (the
/// Gershgorin bound of the highest frequency; Silling & Askari 2005).
fn dynamics<const D: usize>(
    body: &BondBody<D>,
    mass: &[f64],
    constrained: &[[bool; D]],
) -> Result<(Fundamental, StableStep), RunError> {
    let fundamental =
        modal::lowest_mode(&body.x0, mass, constrained, LANCZOS_STEPS, |u, out| {
            body.linear_forces(u, out)
        })
        .map_err(|e| {
            RunError::Setup(format!(
                "{e}: T1 of the bond-based body is the lowest mode held by its supports (groups.*.fix, groups.*.load); they may leave a mechanism"
            ))
        })?;
    let dt_stable = body
        .stiffness_sums()
        .iter()
        .zip(mass)
        .filter(|(k, _)| **k > 0.0)
        .map(|(k, m)| (2.0 * m / k).sqrt())
        .fold(f64::INFINITY, f64::min);
    let stable = StableStep {
        omega_max: 2.0 / dt_stable,
        omega_max_bound: 2.0 / dt_stable,
        zeta: 0.0,
        implicit_share: 0.0,
        dt_stable,
    };
    Ok((fundamental, stable))
}

/// A bond-based scene ready to run: its model (points, groups, supports) with T1, the time
/// step and the probe; the body; its report; the points' masses.
pub struct BondPrepared<const K: usize, const D: usize> {
    pub p: Prepared<K, D>,
    pub body: BondBody<D>,
    pub report: BondReport,
    pub mass: Vec<f64>,
}

/// Fill the scene's body with its generator's points, bond them and find T1 and the step.
pub fn prepare_bond_based<G, const D: usize, const K: usize>(
    scene: &Scene,
    generator: G,
) -> Result<BondPrepared<K, D>, RunError>
where
    G: Generator<D, K>,
{
    let model = prepare_model(scene, generator)?;
    let (body, report) = bond_body(&model)?;
    let mass: Vec<f64> = body.volume.iter().map(|v| scene.material.rho * v).collect();
    let (fundamental, stable) = dynamics(&body, &mass, &model.constrained)?;
    let dt = time_step(scene, stable.dt_stable)?;
    let t_end = loading_time(scene, fundamental.period);
    let steps = checked_steps(t_end, dt, body.len())?;
    crate::run::load_test::check_judgeable(scene, t_end, dt)?;
    let probe = probe_of(scene, &model.groups);
    let p = Prepared {
        model,
        fundamental,
        stable,
        mass_scaling: None,
        dt,
        t_end,
        steps,
        probe,
        bearings: Vec::new(),
    };
    Ok(BondPrepared {
        p,
        body,
        report,
        mass,
    })
}

/// Lanczos steps allowed for the bond-based body's T1.
const LANCZOS_STEPS: usize = 20_000;

/// Run a scene of the bond-based family with its generator's points.
pub fn run_bond_based<G, const D: usize, const K: usize>(
    scene: &Scene,
    generator: G,
    threads: usize,
) -> Result<Outcome, RunError>
where
    G: Generator<D, K>,
{
    let start = Instant::now();
    let BondPrepared {
        p,
        body,
        mut report,
        mass,
    } = prepare_bond_based(scene, generator)?;
    let mut stepper = Stepper::new(&p, body, mass);
    let finished = stepper.run(&p, start);
    let body = &stepper.body;
    let phi = body.damage();
    report.broken_bonds = body.broken_bonds();
    report.max_point_damage = phi.iter().cloned().fold(0.0, f64::max);
    report.points_half_damaged = phi.iter().filter(|&&f| f >= 0.5).count();
    let damage: Vec<ParticleDamage> = phi
        .iter()
        .map(|&f| ParticleDamage {
            wt: f,
            ..Default::default()
        })
        .collect();
    let wall = start.elapsed().as_secs_f64();
    let mut summary = summarise(
        &p,
        &Finished {
            kernel: crate::solver::KernelSet::BondBased,
            method: scene.solver.method,
            report: SolverReport {
                stopped_after_peak: finished.stopped_after_peak,
                ..Default::default()
            },
            records: &finished.records,
            wall_s: &finished.wall_s,
            wall,
            threads,
            steps_done: finished.steps_done,
            failure: finished.failure.as_ref().map(|e| e.to_string()),
        },
        scene.concrete.as_ref().map(|_| &damage[..]),
    );
    summary.bonds = report.bonds;
    summary.cracked_particles = None;
    summary.crushed_particles = None;
    summary.yielded_particles = None;
    summary.max_compressive_damage = None;
    summary.micro_modulus_a_bulk = 0.0;
    summary.micro_modulus_b_bulk = 0.0;
    if (scene.material.nu - report.poisson_ratio_of_the_model).abs() > 1e-3 {
        summary.warnings.push(format!(
            "material.nu = {}: the bond-based model fixes Poisson's ratio at {:.4} in this body ({}); the run uses material.E and not material.nu",
            scene.material.nu,
            report.poisson_ratio_of_the_model,
            if D == 3 { "3D" } else { "a plate" }
        ));
    }
    summary.bond_based = Some(report);
    summary.load_test = finished.load_test;
    let x0 = &p.model.particles.x0;
    let stress = stepper.stresses();
    Ok(Outcome {
        summary,
        cells: None,
        moduli_residual: None,
        records: finished.records,
        increments: Vec::new(),
        dim: D,
        x0: x0.iter().map(point3).collect(),
        volume: p.model.particles.volume.clone(),
        displacement: stepper
            .x
            .iter()
            .zip(x0)
            .map(|(a, b)| point3(&(a - b)))
            .collect(),
        stress,
        damage: scene.concrete.as_ref().map(|_| damage),
        groups: p.model.groups.clone(),
        scene: p.model.scene.clone(),
        fields: Vec::new(),
        axes: ["x", "y"],
        snapshots: std::sync::Arc::new(Vec::new()),
    })
}

/// What a finished bond-based run hands to its summary.
pub struct BondFinished {
    pub records: Vec<Record>,
    pub wall_s: Vec<f64>,
    pub steps_done: usize,
    pub failure: Option<Unstable>,
    pub stopped_after_peak: bool,
    /// The verdict of `[failure]` on a force-controlled load.
    pub load_test: Option<crate::run::load_test::LoadTestReport>,
}

/// The instability of a step: the first point whose position is not finite.
fn unstable_at<const D: usize>(
    x: &[SVector<f64, D>],
    x0: &[SVector<f64, D>],
    step: usize,
    time: f64,
) -> Option<Unstable> {
    let i = x.iter().position(|p| !p.iter().all(|c| c.is_finite()))?;
    Some(Unstable {
        at: Location::Step {
            step,
            time,
            particle: i,
            position: format!("{:?}", x0[i].as_slice()),
        },
        what: "the position is not a finite number".into(),
    })
}

/// The fraction of Δmax the ramp applies at time t.
fn ramp_at(scene: &Scene, t: f64, t_end: f64) -> f64 {
    ramp_fraction(scene.loading.ramp, t, scene.loading.ramp_fraction * t_end)
}
