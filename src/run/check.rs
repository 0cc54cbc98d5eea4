//! `sppm check`: a scene's body, groups, T1, time step, memory and the run time from a few
//! timed steps of the real kernel, printed for the user, without running it.

use super::dispatch::{dispatch, estimated_memory, TypedRun};
use super::execute::build_simulation;
use super::generate::Generator;
use super::prepare::{prepare_with, Prepared};
use super::recover::Recover;
use super::RunError;
use crate::model::dimension::{Dim, Dimension};
use crate::say;
use crate::scene::{Scene, SolverMethod};

/// Bytes of a frame's `.vtu` file per particle (base64 of 16 Float64 values of point data
/// and position, the Int32 id and the cell arrays, measured: 237 on the tension block with
/// damage).
const FRAME_DISK_BYTES: f64 = 240.0;

/// Check `scene` and print what a run of it would be; `stage` is told what starts (large
/// bodies take minutes to set up).
pub fn check(scene: &Scene, stage: &dyn Fn(&str)) -> Result<(), RunError> {
    let mem = estimated_memory(scene);
    dispatch(scene, Check { mem, stage })
}

/// `sppm check` of a scene with its generator: the body, groups, T1, time step, memory and
/// the run time from a few timed steps of the real kernel.
struct Check<'a> {
    mem: f64,
    stage: &'a dyn Fn(&str),
}

impl TypedRun for Check<'_> {
    type Output = Result<(), RunError>;

    fn run<G, const D: usize, const K: usize>(self, sc: &Scene, generator: G) -> Self::Output
    where
        G: Generator<D, K>,
        Dim<D>: Dimension<D> + Recover<D>,
    {
        if sc.model.is_bond_based() {
            return bond_report(sc, self.mem, self.stage, generator);
        }
        let p = prepare_with(sc, generator, self.stage)?;
        report(sc, self.mem, self.stage, p)
    }
}

/// `sppm check` of a prepared scene (2D, or 3D: FCC or random particles).
fn report<const K: usize, const D: usize>(
    sc: &Scene,
    mem: f64,
    stage: &dyn Fn(&str),
    mut p: Prepared<K, D>,
) -> Result<(), RunError>
where
    Dim<D>: Dimension<D>,
{
    stage("timing a few steps of the kernel");
    // calibrate the run time with a few steps of the real kernel (with damage and
    // plasticity where the scene has them)
    let mut sim = build_simulation(&mut p);
    let calib = 20.min(p.steps.max(1));
    let t = std::time::Instant::now();
    for _ in 0..calib {
        sim.advance(None);
    }
    let per_step = t.elapsed().as_secs_f64() / calib as f64;
    say!("scene            {}", sc.name());
    for w in &sc.warnings {
        eprintln!("warning: {w}");
    }
    if D == 3 {
        say!(
            "lattice          {} (3D), rotation {:?}°",
            if sc.discretisation.is_random() {
                "random particles"
            } else {
                "fcc"
            },
            sc.discretisation.rotation_deg.angles()
        );
    }
    say!("particles        {}", p.model.particles.len());
    say!("bonds            {}", p.model.particles.bonds());
    say_groups_and_step(&p);
    say_fast_options(sc, &p);
    let threads = rayon::current_num_threads();
    let solver = &sc.solver;
    if solver.method == SolverMethod::QuasiStatic && sc.concrete.is_some() {
        say!(
            "solver           quasi_static: {} increments along the ramp (smaller while damage grows), at most {} iterations each (tolerance {:e}); each iteration evaluates the forces, each change of state refactorises the sparse stiffness (docs/quasi_static.md)",
            solver.increments, solver.max_iterations(), solver.tolerance
        );
        say!(
            "memory (est.)    {:.1} MiB, and the sparse factor",
            mem / 2f64.powi(20)
        );
        say!("run time (est.)  none: it depends on how the crack grows");
    } else if solver.method.is_incremental() {
        // the iterations per increment are known only once it has converged
        let most = solver.increments * solver.max_iterations();
        say!(
            "solver           {}: {} increments of at most {} iterations (tolerance {:e}); its step is solver.safety × the undamped limit, not the dt above",
            solver.method.name(), solver.increments, solver.max_iterations(), solver.tolerance
        );
        say!("memory (est.)    {:.1} MiB", mem / 2f64.powi(20));
        say!(
            "run time (est.)  at most {:.1} s on {threads} threads ({most} iterations); elastic increments converge in 1–10",
            per_step * most as f64
        );
    } else {
        let l = &sc.loading;
        let default = if l.end_periods.is_none() && l.end_s.is_none() {
            " (the default loading time, loading.end_periods)"
        } else {
            ""
        };
        say!(
            "t_end            {:.6e} s = {:.1} T1{default}",
            p.t_end,
            p.t_end / p.fundamental.period
        );
        say!("steps            {}", p.steps);
        say!("memory (est.)    {:.1} MiB", mem / 2f64.powi(20));
        say!(
            "run time (est.)  {:.1} s on {threads} threads",
            per_step * p.steps as f64
        );
    }
    let sf = &p.model.surface;
    say!(
        "surface          {}: {} boundary particles, {} fitted; largest residual {:.4}; particles' volume {:+.2e} of the body's",
        sf.method,
        sf.boundary_particles,
        sf.corrected,
        sf.max_residual,
        sf.particle_volume / sf.body_volume - 1.0
    );
    if let Some(n) = sc.output.snapshots {
        say!(
            "snapshots        {n} frames: {:.1} MiB of the memory above, about {:.1} MiB on disk",
            super::model::frames_memory(sc) / 2f64.powi(20),
            (n * p.model.particles.len()) as f64 * FRAME_DISK_BYTES / 2f64.powi(20)
        );
    }
    for d in &sc.derived {
        say!("{:<16} {:<12.6e} {}", d.key, d.value, d.source);
    }
    if let Some(r) = &p.model.random {
        let g = &r.generation;
        say!(
            "random particles {} ({} on the boundary; the lattice's density: {})",
            g.particles,
            g.outline_particles,
            g.target
        );
        say!(
            "nearest distance min {:.3} / mean {:.3} / max {:.3} × spacing",
            g.nearest_min,
            g.nearest_mean,
            g.nearest_max
        );
        say!("bonds a particle {:?} (histogram from 0)", g.bond_histogram);
        say!(
            "generation       {:.3} s placing, {:.3} s Voronoi cells, {:.3} s bonds",
            g.seconds_placing,
            g.seconds_voronoi,
            g.seconds_bonding
        );
        let m = &r.moduli;
        say!(
            "moduli residual  mean {:.4} / p99 {:.4} / max {:.4}; {} particle(s) without a fit",
            m.residual_mean,
            m.residual_p99,
            m.residual_max,
            m.unfitted
        );
    }
    Ok(())
}

/// `sppm check` of a bond-based scene: the points, the bonds and the law, T1, the time step,
/// memory and the run time from a few timed steps.
fn bond_report<G, const D: usize, const K: usize>(
    sc: &Scene,
    mem: f64,
    stage: &dyn Fn(&str),
    generator: G,
) -> Result<(), RunError>
where
    G: Generator<D, K>,
{
    stage("bonding the points and finding T1");
    let b = super::bond_based::prepare_bond_based(sc, generator)?;
    let (p, r) = (&b.p, &b.report);
    stage("timing a few steps of the kernel");
    let calib = 20.min(p.steps.max(1));
    let mut stepper = super::bond_based::Stepper::new(p, b.body.clone(), b.mass.clone());
    let t = std::time::Instant::now();
    stepper.steps(p, calib);
    let per_step = t.elapsed().as_secs_f64() / calib as f64;
    say!("scene            {}", sc.name());
    for w in &sc.warnings {
        eprintln!("warning: {w}");
    }
    say!(
        "model            bond_based ({D}D), on {} points",
        sc.discretisation.lattice.name()
    );
    say!("points           {}", p.model.particles.len());
    say!(
        "bonds            {} ({:.1} a point)",
        r.bonds,
        r.bonds_per_point
    );
    say!(
        "horizon          {:.6e} m = {} × Δx ({:.6e} m)",
        r.horizon_m,
        r.horizon_ratio,
        r.cell_size_m
    );
    say!(
        "micromodulus     {:.6e} ({:?} influence)",
        r.micromodulus,
        r.influence
    );
    if let (Some(law), Some(s0), Some(sc_)) = (r.softening, r.s0, r.critical_stretch) {
        say!(
            "softening        {}: s0 = {s0:.4e}, s_c = {sc_:.4e}",
            law.name()
        );
    }
    say_groups_and_step(p);
    say!(
        "t_end            {:.6e} s = {:.1} T1",
        p.t_end,
        p.t_end / p.fundamental.period
    );
    say!("steps            {}", p.steps);
    say!("memory (est.)    {:.1} MiB", mem / 2f64.powi(20));
    say!(
        "run time (est.)  {:.1} s on {} threads",
        per_step * p.steps as f64,
        rayon::current_num_threads()
    );
    Ok(())
}

/// The groups with their sizes, T1, the stable step and the step of a prepared scene.
fn say_groups_and_step<const K: usize, const D: usize>(p: &Prepared<K, D>) {
    say!(
        "groups           {}",
        p.model
            .groups
            .iter()
            .map(|g| format!("{} ({})", g.name, g.members.len()))
            .collect::<Vec<_>>()
            .join(", ")
    );
    say!("fundamental T1   {:.6e} s", p.fundamental.period);
    say!("stable dt        {:.6e} s", p.stable.dt_stable);
    say!("time step dt     {:.6e} s", p.dt);
}

/// What `sppm check` says of the fast options a scene turned on: the semi-implicit bond
/// dampers (S.17), the pace (docs/model.md §10) and selective mass scaling (S.18).
fn say_fast_options<const K: usize, const D: usize>(sc: &Scene, p: &Prepared<K, D>) {
    if p.stable.implicit_share > 0.0 {
        let z = p.stable.zeta;
        say!(
            "bond dampers     semi_implicit, σ = {:.3} (S.17); ζ = {z:.2} at ω_max, which would need dt ≤ {:.6e} s explicit",
            p.stable.implicit_share,
            p.stable.dt_stable * ((1.0 + z * z).sqrt() - z)
        );
    }
    if let Some(pace) = sc.pace() {
        say!(
            "pace             {}{}",
            pace.name(),
            if pace == crate::scene::Pace::Adaptive {
                format!(
                    ": up to {}× on the post-peak tail, so fewer steps than below",
                    sc.loading.max_pace
                )
            } else {
                String::new()
            }
        );
    }
    if let Some(m) = &p.mass_scaling {
        say!(
            "mass scaling     {} particles raised to {} × the median particle's step: {:.3}% of the mass added, the largest factor {:.2}",
            m.particles,
            m.fraction_of_median_step,
            100.0 * m.added_mass_fraction,
            m.largest_factor
        );
    }
}
