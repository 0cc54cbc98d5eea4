//! Stage 1 of a run: a scene's generator fills the body and assembles its model
//! (`run::generate`), then T1, the dampers and the stable time step ([`Prepared`]). The
//! functions here are generic over the generator; `run::dispatch` picks it for a scene.

use super::generate::Generator;
use super::model::{check_size, Model};
use super::RunError;
use crate::material;
use crate::scene::{BondScheme, Scene};
use crate::solver::bearing::{largest_rate, Bearing};
use crate::solver::mass_scaling::{scale_masses, MassScaling, MAX_ADDED_MASS};
use crate::solver::time_step::{split_bond_dampers, stable_step, StableStep};
use crate::solver::{modal, Probe};

/// A discretised, assembled specimen ready to run: the model plus its dynamics.
pub struct Prepared<const K: usize = 6, const D: usize = 2> {
    pub model: Model<K, D>,
    pub fundamental: modal::Fundamental,
    pub stable: StableStep,
    /// What selective mass scaling added (`solver.mass_scaling`), `None` without it.
    pub mass_scaling: Option<MassScaling>,
    pub dt: f64,
    pub t_end: f64,
    pub steps: usize,
    pub probe: Option<(String, Probe)>,
    /// The members pressed through bearing strips (`groups.<name>.bearing`), whose stiffness
    /// the stable step takes.
    pub bearings: Vec<Bearing>,
}

/// Discretise a scene with `generator` and assemble its model (body, groups, supports,
/// micro-moduli).
pub fn prepare_model<G, const D: usize, const K: usize>(
    scene: &Scene,
    generator: G,
) -> Result<Model<K, D>, RunError>
where
    G: Generator<D, K>,
{
    prepare_model_with(scene, generator, &|_| {})
}

/// [`prepare_model`], telling `stage` what it starts (for `sppm check` of large bodies).
pub fn prepare_model_with<G, const D: usize, const K: usize>(
    scene: &Scene,
    generator: G,
    stage: &dyn Fn(&str),
) -> Result<Model<K, D>, RunError>
where
    G: Generator<D, K>,
{
    let kind = scene.discretisation();
    if kind != G::KIND {
        return Err(RunError::Setup(format!(
            "discretisation.lattice = \"{}\" in this body is the {kind:?} discretisation, not the {:?} one it was prepared with (run::dispatch picks a scene's own)",
            scene.discretisation.lattice.name(),
            G::KIND
        )));
    }
    check_size(scene, K)?;
    generator.model(scene, stage)
}

/// Discretise and assemble a scene with `generator`, compute T1 and the time step.
pub fn prepare<G, const D: usize, const K: usize>(
    scene: &Scene,
    generator: G,
) -> Result<Prepared<K, D>, RunError>
where
    G: Generator<D, K>,
{
    prepare_with(scene, generator, &|_| {})
}

/// [`prepare`], telling `stage` what it starts.
pub fn prepare_with<G, const D: usize, const K: usize>(
    scene: &Scene,
    generator: G,
    stage: &dyn Fn(&str),
) -> Result<Prepared<K, D>, RunError>
where
    G: Generator<D, K>,
{
    dynamics(prepare_model_with(scene, generator, stage)?, stage)
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

/// T1, the dampers, the time step, the run's length and its probe of an assembled model (2D
/// or 3D).
pub(crate) fn dynamics<const K: usize, const D: usize>(
    mut model: Model<K, D>,
    stage: &dyn Fn(&str),
) -> Result<Prepared<K, D>, RunError> {
    let scene = &model.scene.clone();
    // A free particle with one bond has no stiffness across it: a zero-frequency mode that
    // Lanczos may or may not report (with clipped cells it found ω² ≈ 3e-5 rad²/s² and
    // T1 = 1e3 s for the spike of tests/suite/proptest_scenes.rs); refuse it before.
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
    let share = match scene.damping.bond_scheme {
        BondScheme::Explicit => 0.0,
        BondScheme::SemiImplicit => split_bond_dampers(&mut model.mech, &model.particles.x0),
    };
    let mass_scaling = match scene.solver.mass_scaling {
        Some(q) => Some(scaled(&mut model.mech, &model.particles.x0, q)?),
        None => None,
    };
    stage("stable time step (largest frequency, Lanczos)");
    let mut stable = stable_step(&model.mech, &model.particles.x0);
    stable.implicit_share = share;
    let bearings = super::platens::bearings(&model);
    if !bearings.is_empty() {
        stable.add_stiffness(largest_rate(&bearings, &model.mech.mass));
    }
    let dt = time_step(scene, stable.dt_stable)?;
    let t_end = loading_time(scene, fundamental.period);
    let steps = checked_steps(t_end, dt, n)?;
    super::load_test::check_judgeable(scene, t_end, dt)?;
    let probe = probe_of(scene, &model.groups);

    Ok(Prepared {
        model,
        fundamental,
        stable,
        mass_scaling,
        dt,
        t_end,
        steps,
        probe,
        bearings,
    })
}

/// Selective mass scaling to `q` × the median particle's step (docs/model.md §5, (S.18)),
/// refused where it adds more than [`MAX_ADDED_MASS`] of the specimen's mass.
fn scaled<const K: usize, const D: usize>(
    mech: &mut crate::solver::mechanics::Mechanics<D, K>,
    x0: &[nalgebra::SVector<f64, D>],
    q: f64,
) -> Result<MassScaling, RunError> {
    let r = scale_masses(mech, x0, q);
    if r.added_mass_fraction > MAX_ADDED_MASS {
        return Err(RunError::Scene(crate::scene::SceneError::Invalid {
            key: "solver.mass_scaling".into(),
            value: format!("{q}"),
            allowed: format!(
                "a fraction that adds at most {:.0}% of the specimen's mass; {q} adds {:.1}% ({} particles raised, the largest {:.1}×): lower solver.mass_scaling",
                100.0 * MAX_ADDED_MASS,
                100.0 * r.added_mass_fraction,
                r.particles,
                r.largest_factor
            ),
        }));
    }
    Ok(r)
}

/// The run's end t_end (s): `loading.end_periods` × T1, or `loading.end_s`, or
/// [`crate::scene::DEFAULT_END_PERIODS`] × T1.
pub(crate) fn loading_time(scene: &Scene, period: f64) -> f64 {
    match (scene.loading.end_periods, scene.loading.end_s) {
        (Some(p), _) => p * period,
        (None, Some(s)) => s,
        (None, None) => crate::scene::DEFAULT_END_PERIODS * period,
    }
}

/// The steps of Δt to t_end, refused beyond 1e14 particle-steps of `n` particles.
pub(crate) fn checked_steps(t_end: f64, dt: f64, n: usize) -> Result<usize, RunError> {
    let steps = (t_end / dt).ceil() as usize;
    if steps as f64 * n as f64 > 1e14 {
        return Err(RunError::Setup(format!(
            "loading: t_end = {t_end:.3e} s needs {steps} steps of {n} particles, beyond 1e14 particle-steps; shorten loading.end_periods or coarsen discretisation.spacing"
        )));
    }
    Ok(steps)
}

/// The probe of a run: `output.probe_group`, else the first loaded group, with the component
/// and Δmax along which its reaction is read.
pub(crate) fn probe_of(
    scene: &Scene,
    groups: &[crate::discretise::groups::Group],
) -> Option<(String, Probe)> {
    let name = scene.output.probe_group.clone().or_else(|| {
        scene
            .groups
            .iter()
            .find(|g| g.load.is_some())
            .map(|g| g.name.clone())
    })?;
    let spec = scene.groups.iter().find(|g| g.name == name)?;
    let members = groups.iter().find(|g| g.name == name)?.members.clone();
    let (component, amplitude, force) = match &spec.load {
        Some(l) if l.force.is_some() => (l.component.index(), 0.0, l.force),
        Some(l) => (l.component.index(), l.delta(), None),
        None => (spec.fix[0].index(), 0.0, None),
    };
    Some((
        name,
        Probe {
            members,
            component,
            amplitude,
            force,
        },
    ))
}

/// The run's Δt: `solver.dt`, refused above the stable limit, or `solver.safety` × the limit.
pub(crate) fn time_step(scene: &Scene, dt_stable: f64) -> Result<f64, RunError> {
    match scene.solver.dt {
        Some(dt) if dt > dt_stable => Err(RunError::Scene(crate::scene::SceneError::Invalid {
            key: "solver.dt".into(),
            value: format!("{dt:e}"),
            allowed: format!(
                "at most the stable limit {dt_stable:.6e} s computed from the stiffness, masses and damping (or leave solver.dt out to use solver.safety × the limit)"
            ),
        })),
        Some(dt) => Ok(dt),
        None => Ok(scene.solver.safety * dt_stable),
    }
}
