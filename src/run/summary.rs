//! Stage 3 of a run: what it measured (summary.json) and the dimension-erased outcome handed
//! to `output` and `study`.

use super::model::{ModuliFit, SurfaceCorrection};
use super::prepare::Prepared;
use crate::discretise::groups;
use crate::material::properties::{FieldReport, SampledField};
use crate::scene::{Scene, SolverMethod, DEFAULT_END_PERIODS, KINETIC_LIMIT};
use crate::solver::inelastic::ParticleDamage;
use crate::solver::Record;
use serde::Serialize;

/// The summary of a run (summary.json; the keys docs/architecture.md names, and more).
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
    /// Relaxation: increments that stopped at solver.max_iterations().
    pub unconverged_increments: Option<usize>,
    /// Relaxation: largest out-of-balance force norm / reaction norm at the end of an
    /// increment.
    pub max_final_residual: Option<f64>,
    /// Quasi-static: state commits (secant iterations) of all increments.
    pub commits: Option<usize>,
    /// Quasi-static with damage: Cholesky factorisations of the held stiffness (one per
    /// state-changing commit and per NEWTON_PER_FACTOR Newton iterations of a held state).
    pub factorisations: Option<usize>,
    /// Quasi-static with damage: increments undone and taken again in half the step because
    /// damage jumped in them (their iterations are counted in `iterations`).
    pub cutbacks: Option<usize>,
    /// Quasi-static with indirect control: the gauge (`solver.control`: plus, minus,
    /// component, opening in m); the increments' openings are in increments.csv.
    pub control: Option<crate::scene::ControlSpec>,
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
    /// The probe group is pushed in the negative direction (compression): peak_force_N and
    /// final_force_N are its reaction with the sign turned, so positive while it resists
    /// (force_displacement.svg turns both axes and says so); the displacements keep their
    /// sign.
    pub sign_turned: bool,
    /// Each gauge (`[[gauges]]`): its opening at the peak, at the end and its largest.
    pub gauges: Vec<GaugeReport>,
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
    /// The same over the records up to the peak: what the loading pace and any added mass
    /// can change. After the peak a crack that runs unstably is kinetic at any pace.
    pub max_kinetic_to_internal_energy_to_peak: f64,
    /// The same over the whole run (after complete failure the elastic energy vanishes and
    /// this ratio says little).
    pub max_kinetic_to_internal_energy_whole_run: f64,
    /// Largest tensile damage w_t (scenes with `[concrete]`).
    pub max_damage: Option<f64>,
    pub max_compressive_damage: Option<f64>,
    /// Particles with w_t ≥ 0.99 (`ParticleDamage::cracked`, as the crack map counts them).
    pub cracked_particles: Option<usize>,
    /// Particles with w_c ≥ 0.99 that are not cracked (`ParticleDamage::crushed`, the crack
    /// map's ×).
    pub crushed_particles: Option<usize>,
    /// Particles that yielded at least once.
    pub yielded_particles: Option<usize>,
    /// The concrete law used (every value resolved).
    pub concrete: Option<crate::model::damage::ConcreteLaw>,
    /// The strain the concrete criteria read (docs/model.md §7): "neighbourhood" or "own".
    pub criteria_strain: Option<crate::scene::CriteriaStrain>,
    /// Material values and where each came from (scene, preset or correlation).
    pub material_values: Vec<crate::scene::concrete::Derived>,
    pub force_lag: crate::scene::ForceLag,
    /// The step kernel chosen for the scene's features: elastic, tension or full.
    pub kernel: crate::solver::KernelSet,
    pub surface_correction: SurfaceCorrection,
    /// The bond-based family (`model.family = "bond_based"`): its horizon, micromodulus,
    /// law and bonds; absent for the state-based lattice.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bond_based: Option<BondReport>,
    /// A force-controlled load judged by `[failure]` (docs/failure.md): held or failed.
    pub load_test: Option<super::load_test::LoadTestReport>,
    /// Random particles (SPPM): generation (count, distances, bond histogram, times), the
    /// minimum distance, and the micro-moduli residual statistics; absent for lattices.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub random_particles: Option<RandomReport>,
    pub micro_modulus_a_bulk: f64,
    pub micro_modulus_b_bulk: f64,
    pub spacing_m: f64,
    pub rotation_deg: crate::scene::Rotation,
    pub offset_m: Vec<f64>,
    pub omega_max_rad_s: f64,
    pub omega_max_bound_rad_s: f64,
    /// How the bond dampers were integrated (docs/model.md §5): `explicit` or
    /// `semi_implicit`.
    pub bond_damper_scheme: crate::scene::BondScheme,
    /// The bond dampers' damping ratio ζ at ω_max.
    pub bond_damping_ratio_at_omega_max: f64,
    /// σ of (S.17): the share of the bond dampers taken implicitly (0: explicit).
    pub bond_damper_implicit_share: f64,
    /// How the explicit run read the ramp (`loading.pace`): `fixed` or `adaptive`; `null`
    /// for the relaxation and quasi-static solvers.
    pub pace: Option<crate::scene::Pace>,
    /// What selective mass scaling added (docs/model.md §5, (S.18)); `null` without it.
    pub mass_scaling: Option<crate::solver::mass_scaling::MassScaling>,
    /// What the run did that may have changed its result, e.g. added mass with a kinetic
    /// energy above the quasi-static limit; empty when nothing did.
    pub warnings: Vec<String>,
    /// The scene's seed (`Scene::effective_seed`), `None` when it makes no random choice.
    pub seed: Option<u64>,
    /// Each random field: its parameters, seed and the statistics of the particles' values.
    pub random_fields: Vec<FieldReport>,
    pub sppm_version: String,
}

/// What summary.json reports of a bond-based run (`bond_based`).
#[derive(Clone, Debug, Serialize)]
pub struct BondReport {
    /// Horizon δ (m) and its ratio m = δ/Δx.
    pub horizon_m: f64,
    pub horizon_ratio: f64,
    /// Δx of the partial volumes (m): the grid spacing, or the mean cell's edge.
    pub cell_size_m: f64,
    /// Micromodulus c (constant influence) or c0 (conical), N/m⁶ (N/m⁵ in a plate).
    pub micromodulus: f64,
    pub influence: crate::scene::model_family::InfluenceKind,
    pub poisson_ratio_of_the_model: f64,
    pub softening: Option<crate::scene::model_family::SofteningKind>,
    /// The bulk law's stretches: where softening starts and where the bond breaks.
    pub s0: Option<f64>,
    pub critical_stretch: Option<f64>,
    pub compressive_stretch: Option<f64>,
    pub surface_correction: bool,
    pub critical_stretch_correction: bool,
    pub contact: bool,
    /// Bonds (each counted once), their mean per point, and how many broke.
    pub bonds: usize,
    pub bonds_per_point: f64,
    pub broken_bonds: usize,
    /// The largest point damage φ (the share of a point's bond stiffness lost) and the
    /// points with φ ≥ 0.5.
    pub max_point_damage: f64,
    pub points_half_damaged: usize,
}

/// The kinetic-to-elastic energy ratio around the peak below which a run counts as
/// quasi-static where the result might otherwise depend on inertia the specimen does not
/// have (added mass).
pub const QUASI_STATIC_LIMIT: f64 = 0.01;

/// What the run did that may have changed its result: the scene's inputs outside their
/// usual range, a load too fast ([`loading_warning`], on `ratio` around the peak), added
/// mass with a kinetic energy above the quasi-static limit up to the peak (`to_peak`: a
/// crack that runs unstably after the peak is kinetic with or without the added mass).
fn run_warnings<const K: usize, const D: usize>(
    p: &Prepared<K, D>,
    method: SolverMethod,
    ratio: f64,
    to_peak: f64,
) -> Vec<String> {
    let mass = p.mass_scaling.filter(|_| to_peak > QUASI_STATIC_LIMIT).map(|m| {
        format!(
            "solver.mass_scaling added {:.2}% of the mass and the kinetic energy reached {to_peak:.3e} × the elastic energy up to the peak, above the quasi-static {QUASI_STATIC_LIMIT}: the added mass may have changed the result; lower solver.mass_scaling or leave it out",
            100.0 * m.added_mass_fraction
        )
    });
    let scene = p.model.scene.warnings.iter().cloned();
    scene
        .chain(loading_warning(p, method, ratio))
        .chain(mass)
        .collect()
}

/// The warning of an explicit run whose kinetic energy around the peak exceeded
/// [`KINETIC_LIMIT`] × the internal energy, with the loading time that brings it to half the
/// limit: the ratio falls as the square of the loading time (benchmarks/RESULTS.md,
/// "Loading rate").
fn loading_warning<const K: usize, const D: usize>(
    p: &Prepared<K, D>,
    method: SolverMethod,
    ratio: f64,
) -> Option<String> {
    if method != SolverMethod::Explicit || ratio.is_nan() || ratio <= KINETIC_LIMIT {
        return None;
    }
    let factor = (ratio / (0.5 * KINETIC_LIMIT)).sqrt();
    let l = &p.model.scene.loading;
    let fix = match l.end_s {
        Some(s) => format!("loading.end_s = {:.3e}", s * factor),
        None => format!(
            "loading.end_periods = {:.0}",
            (l.end_periods.unwrap_or(DEFAULT_END_PERIODS) * factor).ceil()
        ),
    };
    Some(format!(
        "the kinetic energy reached {ratio:.3} × the internal energy around the peak, above the quasi-static {KINETIC_LIMIT}: inertia may have raised the peak; load more slowly, e.g. {fix}"
    ))
}

/// A gauge's readings in summary.json (m).
#[derive(Clone, Debug, Serialize)]
pub struct GaugeReport {
    pub name: String,
    /// At the record of the peak force.
    pub at_peak_m: f64,
    #[serde(rename = "final_m")]
    pub last_m: f64,
    /// The largest reading of the run.
    pub max_m: f64,
}

/// The reports of the scene's gauges over `records`, with the peak record `peak`.
fn gauge_reports(
    scene: &crate::scene::Scene,
    records: &[Record],
    peak: Option<&Record>,
) -> Vec<GaugeReport> {
    scene
        .gauges
        .iter()
        .enumerate()
        .map(|(k, g)| GaugeReport {
            name: g.name.clone(),
            at_peak_m: peak.map(|r| r.gauges[k]).unwrap_or(0.0),
            last_m: records.last().map(|r| r.gauges[k]).unwrap_or(0.0),
            max_m: records.iter().map(|r| r.gauges[k]).fold(0.0, f64::max),
        })
        .collect()
}

/// What a random body reports in summary.json.
#[derive(Clone, Debug, Serialize)]
pub struct RandomReport {
    pub generation: crate::discretise::random::Generation,
    pub micro_moduli: ModuliFit,
}

/// What a run produces, dimension-erased: points and displacements as 3-vectors (z = 0 in
/// 2D), stresses as 6 Voigt components [σxx, σyy, σzz, σyz, σxz, σxy] (in 2D the
/// out-of-plane components are 0, as the 2D reports always showed them), so that `output`
/// and `study` serve every dimension from one copy.
#[derive(Clone)]
pub struct Outcome {
    pub summary: Summary,
    /// Random particles: each particle's Voronoi cell clipped to the body (reference
    /// polygon, m), for the maps; `None` for lattices.
    pub cells: Option<Vec<Vec<[f64; 2]>>>,
    /// Random particles: each particle's micro-moduli residual ‖a·A + b·B − D‖/‖D‖ (NaN
    /// where no fit exists), for the VTK file.
    pub moduli_residual: Option<Vec<f64>>,
    pub records: Vec<Record>,
    /// How each load increment ended (relaxation and quasi-static runs; empty for the
    /// explicit solver): `increments.csv`.
    pub increments: Vec<crate::solver::relaxation::IncrementReport>,
    /// Spatial dimension of the run (2 or 3).
    pub dim: usize,
    pub x0: Vec<[f64; 3]>,
    /// Each particle's volume ΔV (m³; in 2D its cell's area × the thickness, clipped to the
    /// body at a surface).
    pub volume: Vec<f64>,
    pub displacement: Vec<[f64; 3]>,
    pub stress: Vec<[f64; 6]>,
    /// Damage and plasticity state of each particle at the end (scenes with `[concrete]`).
    pub damage: Option<Vec<ParticleDamage>>,
    pub groups: Vec<groups::Group>,
    pub scene: Scene,
    /// The random fields' values at each particle (docs/model.md §12).
    pub fields: Vec<SampledField>,
    /// The names of the maps' horizontal and vertical axes: "x", "y" in 2D; a section of a
    /// 3D run (`output::section`) names its own.
    pub axes: [&'static str; 2],
    /// The frames of the run's time series (`output.snapshots`; empty without), shared by
    /// the views of the outcome.
    pub snapshots: std::sync::Arc<Vec<super::snapshots::Snapshot>>,
}

impl Outcome {
    pub fn failed(&self) -> bool {
        self.summary.status != "completed"
    }

    /// The in-plane reference position of particle i (x, y).
    pub fn point2(&self, i: usize) -> nalgebra::Vector2<f64> {
        nalgebra::Vector2::new(self.x0[i][0], self.x0[i][1])
    }

    /// The in-plane stress tensor of particle i (σxx, σyy, σxy).
    pub fn stress2(&self, i: usize) -> nalgebra::Matrix2<f64> {
        let s = &self.stress[i];
        nalgebra::Matrix2::new(s[0], s[5], s[5], s[1])
    }
}

pub use super::arrays::{point3, voigt6};

/// What the relaxation solver adds to the summary (`None` for the explicit one).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct SolverReport {
    pub iterations: Option<usize>,
    pub increments: Option<usize>,
    pub unconverged_increments: Option<usize>,
    pub max_final_residual: Option<f64>,
    pub stopped_after_peak: bool,
    /// Quasi-static: state commits of all increments.
    pub commits: Option<usize>,
    /// Quasi-static with damage: Cholesky factorisations.
    pub factorisations: Option<usize>,
    /// Quasi-static with damage: increments undone and taken again in half the step.
    pub cutbacks: Option<usize>,
    /// Quasi-static: the increment the run stopped at because it did not converge.
    pub stopped_unconverged: Option<crate::solver::relaxation::IncrementReport>,
}

/// What a finished run hands to its summary.
pub(super) struct Finished<'a> {
    pub kernel: crate::solver::KernelSet,
    pub method: SolverMethod,
    pub report: SolverReport,
    pub records: &'a [Record],
    /// Wall time (s since the start) at each record.
    pub wall_s: &'a [f64],
    pub wall: f64,
    pub threads: usize,
    /// Kernel steps taken (the step an unstable run stopped at, not only the last record).
    pub steps_done: usize,
    pub failure: Option<String>,
}

/// Why an incremental run's forces are not the quasi-static answer, if they are not: an
/// increment that stopped the run unconverged, or increments left above the accepted residual.
fn unconverged_message(s: &crate::scene::SolverSpec, report: &SolverReport) -> Option<String> {
    let accepted = s.max_residual.unwrap_or(s.tolerance);
    match (report.unconverged_increments, report.max_final_residual) {
        _ if report.stopped_unconverged.is_some() => report.stopped_unconverged.map(|inc| format!(
            "load increment {} of {} (load factor {:.4}) did not converge: after solver.max_iterations = {} iterations and {} state commits its out-of-balance force is {:.3e} × the reactions, above {} = {accepted:e}; the run stopped there, and its curve ends at the last converged increment. Raise solver.max_iterations (a crack that runs at a held displacement needs more iterations), or solver.increments, or accept the residual with solver.max_residual ≥ {:.2e}",
            inc.increment,
            report.increments.unwrap_or(0),
            inc.load_factor,
            inc.iterations,
            inc.commits,
            inc.residual,
            if s.max_residual.is_some() { "solver.max_residual" } else { "solver.tolerance" },
            inc.residual,
        )),
        (Some(k), Some(r)) if k > 0 && r > accepted => Some(format!(
            "{k} of {} load increments stopped at solver.max_iterations = {} with an out-of-balance force up to {r:.3e} × the reactions, above {} = {accepted:e}: the forces and the crack path are not the quasi-static answer. Raise solver.max_iterations or solver.increments, or accept the residual with solver.max_residual ≥ {r:.2e}",
            report.increments.unwrap_or(0),
            s.max_iterations(),
            if s.max_residual.is_some() { "solver.max_residual" } else { "solver.tolerance" },
        )),
        _ => None,
    }
}

pub(super) fn summarise<const K: usize, const D: usize>(
    p: &Prepared<K, D>,
    run: &Finished,
    damage: Option<&[ParticleDamage]>,
) -> Summary {
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
    let unconverged = unconverged_message(s, &report);
    let failure = run.failure.clone();
    let status = if failure.is_some() {
        "unstable"
    } else if unconverged.is_some() {
        "unconverged"
    } else {
        "completed"
    };
    let failure = failure.or(unconverged);
    let sign = p.probe.as_ref().map(|(_, pr)| pr.sign()).unwrap_or(1.0);
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
    let (to_peak_end, window_end) = match peak {
        Some(pk) => {
            let ipk = records.iter().position(|r| r.step == pk.step).unwrap_or(0);
            let drop = records[ipk..]
                .iter()
                .position(|r| sign * r.force_n < 0.8 * sign * pk.force_n);
            (ipk + 1, drop.map_or(records.len(), |o| ipk + o))
        }
        None => (records.len(), records.len()),
    };
    let ratio = ratio_over(&records[..window_end]);
    let ratio_to_peak = ratio_over(&records[..to_peak_end]);
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
        commits: report.commits,
        factorisations: report.factorisations,
        cutbacks: report.cutbacks,
        control: p.model.scene.solver.control.clone(),
        stopped_after_peak: report.stopped_after_peak,
        threads,
        probe_group: p.probe.as_ref().map(|(n, _)| n.clone()),
        peak_force_n: peak.map(|r| r.force_n * sign).unwrap_or(0.0),
        displacement_at_peak_m: peak.map(|r| r.displacement_m).unwrap_or(0.0),
        final_displacement_m: last.displacement_m,
        final_force_n: last.force_n * sign,
        sign_turned: sign < 0.0,
        gauges: gauge_reports(&p.model.scene, records, peak),
        dissipated_energy_j: last.external_work_j
            - last.kinetic_j
            - last.internal_j
            - last.damping_j,
        damping_energy_j: last.damping_j,
        external_work_j: last.external_work_j,
        internal_energy_j: last.internal_j,
        kinetic_energy_j: last.kinetic_j,
        max_kinetic_to_internal_energy: ratio,
        max_kinetic_to_internal_energy_to_peak: ratio_to_peak,
        max_kinetic_to_internal_energy_whole_run: ratio_whole,
        max_damage: damage.map(|d| d.iter().map(|p| p.wt).fold(0.0, f64::max)),
        max_compressive_damage: damage.map(|d| d.iter().map(|p| p.wc).fold(0.0, f64::max)),
        cracked_particles: damage.map(|d| d.iter().filter(|p| p.cracked()).count()),
        crushed_particles: damage.map(|d| d.iter().filter(|p| p.crushed()).count()),
        yielded_particles: damage.map(|d| d.iter().filter(|p| p.yielded).count()),
        concrete: crate::model::damage::ConcreteLaw::from_scene(&p.model.scene),
        criteria_strain: p.model.scene.criteria_strain(),
        material_values: p.model.scene.derived.clone(),
        force_lag: p.model.scene.solver.force_lag,
        kernel,
        surface_correction: p.model.surface.clone(),
        bond_based: None,
        load_test: None,
        random_particles: p.model.random.as_ref().map(|r| RandomReport {
            generation: r.generation.clone(),
            micro_moduli: r.moduli.clone(),
        }),
        micro_modulus_a_bulk: p.model.bulk.a,
        micro_modulus_b_bulk: p.model.bulk.b,
        spacing_m: d.spacing,
        rotation_deg: d.rotation_deg,
        offset_m: d.offset.clone(),
        omega_max_rad_s: p.stable.omega_max,
        omega_max_bound_rad_s: p.stable.omega_max_bound,
        bond_damper_scheme: p.model.scene.damping.bond_scheme,
        bond_damping_ratio_at_omega_max: p.stable.zeta,
        bond_damper_implicit_share: p.stable.implicit_share,
        mass_scaling: p.mass_scaling,
        warnings: run_warnings(p, method, ratio, ratio_to_peak),
        pace: p.model.scene.pace(),
        seed: p.model.scene.effective_seed(),
        random_fields: p.model.fields.iter().map(|f| f.report.clone()).collect(),
        sppm_version: env!("CARGO_PKG_VERSION").to_string(),
    }
}
