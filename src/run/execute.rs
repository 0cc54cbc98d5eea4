//! Stage 2 of a run: the explicit or relaxation solver on a prepared model, with probes, to
//! a dimension-erased [`Outcome`].

use super::dispatch::{dispatch, TypedRun};
use super::generate::Generator;
use super::load_test::LoadTestReport;
use super::model::Model;
use super::prepare::{prepare, Prepared};
use super::recover::{Recover, Recovered};
use super::snapshots::Recorder;
use super::summary::{point3, summarise, Finished, Outcome, SolverReport};
use super::{RunError, RunOptions};
use crate::material::properties;
use crate::model::dimension::{Dim, Dimension};
use crate::model::force_state::{dilatation_term, force_state};
use crate::model::stress::StressSum;
use crate::model::stretch::total_stretch;
use crate::model::two_spring::TwoSpring;
use crate::scene::{CriteriaStrain, Pace, Scene, SolverMethod};
use crate::solver::inelastic::DamageKernel;
use crate::solver::mechanics::{weighted, Mechanics};
use crate::solver::pace::{Observed, PaceSettings, Pacer};
use crate::solver::{relaxation, Integration, PeakStop, Probe, Record, Simulation};
use nalgebra::{SMatrix, SVector};
use std::time::Instant;

/// Particle stresses (3.18) at positions x, in D dimensions: σ_i = (1/(2ΔV_i))·Σ_j
/// L0,ij·F_s,ij·(e_ij ⊗ e_ij) with F_s,ij = a_i·S_ij + b_i·θ_i (a_i + c_i in an FCC
/// second-neighbour slot, docs/model.md §3 erratum; θ_i = Σ_m w_im·S_im, `Mechanics::weights`)
/// and e_ij the current bond direction.
pub fn particle_stress<const D: usize, const K: usize>(
    mech: &Mechanics<D, K>,
    volume: &[f64],
    x: &[SVector<f64, D>],
) -> Vec<SMatrix<f64, D, D>> {
    (0..x.len())
        .map(|i| {
            let mut theta = 0.0;
            let w = mech.weights(i);
            for (k, j, il) in mech.bonds(i) {
                theta += weighted(w, k, total_stretch((x[j] - x[i]).norm(), il));
            }
            let mut acc = StressSum::<D>::default();
            for (k, j, il) in mech.bonds(i) {
                let d = x[j] - x[i];
                let len = d.norm();
                let s = total_stretch(len, il);
                acc.add(
                    &(d / len),
                    1.0 / il,
                    force_state(
                        mech.slot_modulus(i, k),
                        s,
                        dilatation_term(mech.b[i], theta),
                    ),
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
    pool.install(|| dispatch(scene, Execute { opts, threads }))
}

/// A run of a scene with its generator: the family of `[model]` decides how the points are
/// bonded and integrated.
struct Execute<'a> {
    opts: &'a RunOptions,
    threads: usize,
}

impl TypedRun for Execute<'_> {
    type Output = Result<Outcome, RunError>;

    fn run<G, const D: usize, const K: usize>(self, scene: &Scene, generator: G) -> Self::Output
    where
        G: Generator<D, K>,
        Dim<D>: Dimension<D> + Recover<D>,
    {
        if scene.model.is_bond_based() {
            return super::bond_based::run_bond_based(scene, generator, self.threads);
        }
        let p = prepare(scene, generator)?;
        run_prepared(
            p,
            self.opts,
            self.threads,
            &build_simulation,
            &Dim::<D>::recover,
        )
    }
}

/// The simulation of a prepared scene (2D or 3D), at rest, taking over the model's arrays (no
/// copy); with `[concrete]`, the damage and plasticity kernel is on.
pub fn build_simulation<const K: usize, const D: usize>(p: &mut Prepared<K, D>) -> Simulation<D, K>
where
    Dim<D>: Dimension<D>,
{
    let mut sim = simulation_of(p);
    if let Some(c) = damage_kernel(&p.model) {
        sim.inelastic = Some(Box::new(c));
    }
    sim
}

/// The damage kernel of a model with `[concrete]`: the two-spring law with each particle's
/// local properties (docs/model.md §12), its criteria read over each particle's neighbourhood
/// (S.16) or on its own strain ([`Scene::criteria_strain`]).
/// `None` without `[concrete]`.
pub fn damage_kernel<const K: usize, const D: usize>(
    model: &Model<K, D>,
) -> Option<DamageKernel<D, K>>
where
    Dim<D>: Dimension<D>,
{
    let law = crate::model::damage::ConcreteLaw::from_scene(&model.scene)?;
    let local = properties::local_properties(&model.fields, &law, model.particles.len());
    let c = DamageKernel::new(TwoSpring::new(law, local), &model.particles);
    Some(match model.scene.criteria_strain()? {
        CriteriaStrain::Own => c,
        CriteriaStrain::Neighbourhood => c.with_neighbourhood_criteria(&model.particles),
        CriteriaStrain::Surface => c.with_surface_criteria(&model.particles),
    })
}

/// The elastic simulation of a prepared scene (2D or 3D), at rest, taking over the model's
/// arrays.
pub fn simulation_of<const K: usize, const D: usize>(p: &mut Prepared<K, D>) -> Simulation<D, K> {
    let integration = Integration {
        dt: p.dt,
        lagged_forces: p.model.scene.solver.force_lag == crate::scene::ForceLag::Previous,
        ramp: p.model.scene.loading.ramp,
        t_ramp: p.model.scene.loading.ramp_fraction * p.t_end,
    };
    let bearings = std::mem::take(&mut p.bearings);
    let prescribed =
        super::platens::without_bearings(std::mem::take(&mut p.model.prescribed), &bearings);
    let mut sim = Simulation::new(
        p.model.particles.x0.clone(),
        std::mem::take(&mut p.model.mech),
        prescribed,
        integration,
    );
    sim.bearings = bearings;
    sim.gauges = super::gauges::gauges_of(&p.model);
    sim.applied = super::load_test::applied_forces(
        &p.model.scene,
        &p.model.groups,
        &p.model.particles.volume,
    );
    sim.friction = super::platens::contacts(&p.model);
    sim
}

/// The settings of a relaxation or quasi-static run: the scene's increments and tolerances,
/// and with `solver.control` the gauge's weights on the free displacements (refused where a
/// group prescribes one of them).
fn incremental_settings<const K: usize, const D: usize>(
    p: &Prepared<K, D>,
    sim: &Simulation<D, K>,
) -> Result<relaxation::Settings, RunError> {
    let s = &p.model.scene.solver;
    let quasi_static = s.method == SolverMethod::QuasiStatic;
    let settings = relaxation::Settings {
        increments: s.increments,
        tolerance: s.tolerance,
        max_iterations: s.max_iterations(),
        ramp: p.model.scene.loading.ramp,
        stop_after_peak: p.model.scene.loading.stop_after_peak,
        stop_unconverged: quasi_static.then(|| s.max_residual.unwrap_or(s.tolerance)),
        control: s.control.as_ref().map(|c| {
            let mut gauge = Vec::new();
            for (name, sign) in [(&c.plus, 1.0), (&c.minus, -1.0)] {
                let members = &p
                    .model
                    .groups
                    .iter()
                    .find(|g| &g.name == name)
                    .expect("solver.control names a group (validated)")
                    .members;
                let w = sign / members.len() as f64;
                gauge.extend(
                    members
                        .iter()
                        .map(|&i| (D * i as usize + c.component.index(), w)),
                );
            }
            relaxation::Control {
                gauge,
                opening: c.opening,
            }
        }),
    };
    if let Some(c) = &settings.control {
        for p in &sim.prescribed {
            let d = D * p.particle as usize + p.component as usize;
            if c.gauge.iter().any(|&(g, _)| g == d) {
                return Err(RunError::Setup(format!(
                    "solver.control: the gauge's particle {} (at {:?}) has its {} displacement prescribed by a group; the gauge must measure free displacements: choose its groups (solver.control.plus, solver.control.minus) away from the supports and the loaded rows",
                    p.particle,
                    sim.x0[p.particle as usize].as_slice(),
                    ["x", "y", "z"][p.component as usize]
                )));
            }
        }
    }
    Ok(settings)
}

fn run_prepared<const K: usize, const D: usize>(
    mut p: Prepared<K, D>,
    opts: &RunOptions,
    threads: usize,
    simulate: &dyn Fn(&mut Prepared<K, D>) -> Simulation<D, K>,
    recover: &dyn Fn(&Prepared<K, D>, &Simulation<D, K>) -> Recovered,
) -> Result<Outcome, RunError> {
    let start = Instant::now();
    let method = p.model.scene.solver.method;
    if method.is_incremental() {
        // Dampers off; the step of the undamped model (see solver::relaxation).
        p.stable = relaxation::undamped(&mut p.model.mech, &p.model.particles.x0);
        p.dt = p
            .model
            .scene
            .solver
            .dt
            .unwrap_or(p.model.scene.solver.safety * p.stable.dt_stable);
    }
    let mut sim = simulate(&mut p);
    let empty_probe = Probe::empty();
    let probe = p.probe.as_ref().map(|(_, pr)| pr).unwrap_or(&empty_probe);
    let mut recorder = Recorder::of(&p, probe, recover);
    let mut increments = Vec::new();
    let mut load_test = None;
    let (records, wall_s, failure, report) = match method {
        SolverMethod::Explicit => {
            let run = run_explicit(&mut sim, &p, probe, opts, start, recorder.as_mut());
            let report = SolverReport {
                stopped_after_peak: run.stopped,
                ..Default::default()
            };
            load_test = run.load_test;
            (run.records, run.wall_s, run.failure, report)
        }
        SolverMethod::Relaxation | SolverMethod::QuasiStatic => {
            let s = &p.model.scene.solver;
            let quasi_static = method == SolverMethod::QuasiStatic;
            let settings = incremental_settings(&p, &sim)?;
            // scenes with damage: the implicit secant solver; elastic scenes have no state
            // to hold, and relax (docs/quasi_static.md)
            let implicit = quasi_static && sim.inelastic.is_some();
            let mut observe = |sim: &Simulation<D, K>, fraction: f64| {
                if let Some(r) = recorder.as_mut() {
                    r.observe(sim, fraction)
                }
            };
            let r = if implicit {
                crate::solver::secant::solve(&mut sim, probe, &settings, start, &mut observe)
            } else {
                relaxation::relax(&mut sim, probe, &settings, start, &mut observe)
            };
            let report = SolverReport {
                iterations: Some(r.iterations),
                increments: Some(r.increments.len().max(s.increments)),
                unconverged_increments: Some(r.unconverged_increments),
                max_final_residual: Some(r.max_final_residual),
                stopped_after_peak: r.stopped_after_peak,
                commits: quasi_static.then(|| r.increments.iter().map(|i| i.commits).sum()),
                factorisations: implicit.then_some(r.factorisations),
                cutbacks: implicit.then_some(r.cutbacks),
                stopped_unconverged: r.stopped_unconverged,
            };
            increments = r.increments;
            (r.records, r.wall_s, r.failure, report)
        }
    };
    let wall = start.elapsed().as_secs_f64();
    let displacement: Vec<[f64; 3]> = sim
        .state
        .x
        .iter()
        .zip(&p.model.particles.x0)
        .map(|(a, b)| point3(&(a - b)))
        .collect();
    let (stress, damage) = recover(&p, &sim);
    let snapshots = recorder
        .map(|r| r.finish(&sim, &stress, damage.as_deref()))
        .unwrap_or_default();
    let mut summary = summarise(
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
    summary.load_test = load_test;
    let outcome = Outcome {
        summary,
        cells: p
            .model
            .random
            .as_ref()
            .filter(|r| !r.cells.is_empty())
            .map(|r| {
                r.cells
                    .iter()
                    .map(|c| c.iter().map(|v| [v.x, v.y]).collect())
                    .collect()
            }),
        moduli_residual: p.model.random.as_ref().map(|r| r.moduli.residual.clone()),
        records,
        increments,
        dim: D,
        x0: p.model.particles.x0.iter().map(point3).collect(),
        volume: p.model.particles.volume.clone(),
        displacement,
        stress,
        damage,
        groups: p.model.groups.clone(),
        scene: p.model.scene.clone(),
        fields: p.model.fields.clone(),
        axes: ["x", "y"],
        snapshots: std::sync::Arc::new(snapshots),
    };
    Ok(outcome)
}

/// What an explicit run hands to its summary.
struct ExplicitRun {
    records: Vec<Record>,
    wall_s: Vec<f64>,
    failure: Option<crate::solver::Unstable>,
    /// Stopped after the peak (`loading.stop_after_peak`).
    stopped: bool,
    /// The verdict of `[failure]` on a force-controlled load.
    load_test: Option<LoadTestReport>,
}

/// The explicit run to t_end with probe records (and the wall time at each), stopping at an
/// instability, after the peak with `loading.stop_after_peak`, or at the verdict of a
/// `[failure]` criterion on a force-controlled load (docs/failure.md). With an
/// adaptive pace (`loading.pace`) the records are spread over the load time τ and the run
/// ends when τ reaches t_end. With `snapshots`, the frames due at each step's load time
/// τ/t_end are taken (`run::snapshots`).
fn run_explicit<const K: usize, const D: usize>(
    sim: &mut Simulation<D, K>,
    p: &Prepared<K, D>,
    probe: &Probe,
    opts: &RunOptions,
    start: Instant,
    mut snapshots: Option<&mut Recorder<K, D>>,
) -> ExplicitRun {
    let scene = &p.model.scene;
    let mut stop = PeakStop::new(scene.loading.stop_after_peak, probe);
    let mut watch = super::load_test::watch(scene, p.t_end, sim.integration.dt);
    let mut decision = None;
    let t_ramp = sim.integration.t_ramp;
    let mut stopped = false;
    let wanted = scene.output.records;
    let every = (p.steps / (wanted - 1)).max(1);
    let mut pacer = pacer(p, probe);
    // adaptive pace: a record every `every` steps' worth of load time, at the fixed ramp's
    // steps while the pace is 1
    let gap = every as f64 * sim.integration.dt;
    let mut next_record = 0.0;
    let bar = progress_bar(p, opts);
    let mut records = Vec::with_capacity(wanted + 1);
    let mut wall_s = Vec::with_capacity(wanted + 1);
    let mut failure = None;
    let dt = sim.integration.dt;
    for n in 0..p.steps {
        let (want, last) = match &mut pacer {
            None => (n % every == 0 || n + 1 == p.steps, n + 1 == p.steps),
            Some(pc) => {
                let f = pc.next(dt);
                sim.set_pace(f);
                let tau = sim.load_time();
                let last = tau + f * dt >= p.t_end || n + 1 == p.steps;
                (tau + 0.5 * dt >= next_record || last, last)
            }
        };
        let rec = sim.advance(if want { Some(probe) } else { None });
        if let Some(s) = snapshots.as_deref_mut() {
            s.observe(sim, sim.load_time() / p.t_end);
        }
        if let Some(r) = rec {
            records.push(r);
            wall_s.push(start.elapsed().as_secs_f64());
            while next_record <= sim.load_time() - 0.5 * dt {
                next_record += gap;
            }
            if let Some(pc) = &mut pacer {
                pc.observe(Observed {
                    record: &r,
                    failed: sim.has_failed_particle(),
                });
            }
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
        if let Some(w) = watch.as_mut().filter(|w| w.due(sim.step)) {
            decision = w.observe(sim.step, sim.time() > t_ramp, &sim.failure_observation());
            if decision.is_some() {
                break;
            }
        }
        if let Some(b) = &bar {
            if n % 256 == 0 {
                b.set_position(n as u64);
            }
        }
        if last {
            break;
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let load_test = watch
        .filter(|_| failure.is_none())
        .map(|w| LoadTestReport::of(scene, &w, decision, sim.step, sim.integration.dt));
    ExplicitRun {
        records,
        wall_s,
        failure,
        stopped,
        load_test,
    }
}

/// The controller of an adaptive pace (`loading.pace = "adaptive"`), `None` for the fixed
/// ramp (docs/model.md §10).
fn pacer<const K: usize, const D: usize>(p: &Prepared<K, D>, probe: &Probe) -> Option<Pacer> {
    let l = &p.model.scene.loading;
    (p.model.scene.pace() == Some(Pace::Adaptive)).then(|| {
        Pacer::new(
            PaceSettings {
                max: l.max_pace,
                period: p.fundamental.period,
            },
            probe.sign(),
        )
    })
}

/// The progress bar of a long run (more than 2e7 particle-steps), `None` otherwise.
fn progress_bar<const K: usize, const D: usize>(
    p: &Prepared<K, D>,
    opts: &RunOptions,
) -> Option<indicatif::ProgressBar> {
    if !(opts.progress && (p.steps as f64 * p.model.particles.len() as f64) > 2e7) {
        return None;
    }
    let b = indicatif::ProgressBar::new(p.steps as u64);
    b.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} {wide_bar} {pos}/{len} steps  {elapsed_precise} ETA {eta}",
        )
        .unwrap(),
    );
    Some(b)
}
