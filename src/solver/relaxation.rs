//! Adaptive dynamic relaxation (Kilic & Madenci 2010, "An adaptive dynamic relaxation method
//! for quasi-static simulations using the peridynamic theory", Theor. Appl. Fract. Mech. 53):
//! the quasi-static answer of a displacement-controlled scene found as the steady state of a
//! critically damped pseudo-dynamics, one load increment at a time.
//!
//! **Update.** Kilic–Madenci's step (their Eqs. 17–18),
//!   v^{n+½} = ((2 − c^n·Δt)·v^{n−½} + 2Δt·F^n/λ)/(2 + c^n·Δt),   u^{n+1} = u^n + Δt·v^{n+½},
//! is exactly the central difference of the explicit kernel (`kernel::central_difference`,
//! v^{n+½} = ((1 − h)·v^{n−½} + Δt·F^n/m)/(1 + h) with h = ½Δt·C_ex,i/m_i) when the particle
//! damper is C_ex,i = c^n·m_i, λ = m and the bond dampers are off. So the relaxation drives
//! the existing kernels through [`Simulation::advance`] (damage and plasticity update in every
//! iteration, irreversibly, through the concrete kernel) and only sets C_ex between steps.
//!
//! **Fictitious mass.** Kilic–Madenci take Δt = 1 and λ_ii ≥ ¼·Δt²·Σ_j|K_ij| (a Gershgorin
//! bound on each row). Any diagonal λ and Δt with Δt ≤ 2/ω_max(λ⁻¹K) is stable; the
//! convergence rate is set by ω_min/ω_max of λ⁻¹K. The lattice's masses are proportional to
//! the particle volumes, which are equal, and the row stiffnesses differ only at the
//! surface, so λ = m changes ω_min/ω_max little, while the Lanczos estimate of ω_max
//! (`time_step`) is about 1.5² tighter than the Gershgorin bound (a Δt about 1.5× longer in
//! the same units). Hence: λ = the real masses, Δt = solver.safety × the computed stable
//! limit of the undamped model (dampers off). Damage only lowers stiffness, so the limit
//! of the undamaged model holds throughout.
//!
//! **Adaptive damping** (their Eqs. 19–20): c^n = 2·sqrt(uᵀ·¹K^n·u / uᵀu) with the local
//! diagonal stiffness ¹K^n_ii = −(F_i^n − F_i^{n−1})/(λ_ii·Δt·v_i^{n−½}), over the free
//! components (terms with zero velocity skipped), c = 0 when the quotient is not positive,
//! and c·Δt ≤ 2. Since the kernel computes F^n and the update in one pass, the damper of step
//! n+1 uses c^n (a lag of one step; the Rayleigh quotient changes slowly, and the
//! semi-implicit damper is stable for any c ≥ 0).
//!
//! **Increments.** Increment k of N holds the prescribed displacements at r(k/N)·Δmax, r the
//! scene's ramp shape, so the load path is the explicit run's. It has converged when the
//! out-of-balance force on the free components satisfies ‖F_free‖₂ ≤ tolerance × the reaction
//! norm ‖F_prescribed‖₂ (supports and loaded groups; the current one, or the largest at the
//! end of an earlier converged increment if that is larger, so that the test stays
//! meaningful when the specimen has failed and carries nothing), or stops after
//! max_iterations. One [`Record`] is taken per increment, at the converged state.
//!
//! The iteration loop allocates nothing; its reductions run in fixed chunks summed in order,
//! so results do not depend on the thread count.

use super::loading::ramp_fraction;
use super::mechanics::Mechanics;
use super::time_step::{stable_step, StableStep};
use super::{PeakStop, Probe, Record, Simulation, Unstable};
use crate::scene::Ramp;
use nalgebra::SVector;
use rayon::prelude::*;
use std::time::Instant;

/// Particles per chunk of the parallel reductions (fixed: the summation order does not
/// depend on the thread count).
const CHUNK: usize = 2048;

/// The relaxation keys of a scene (`[solver]`).
#[derive(Clone, Debug)]
pub struct Settings {
    pub increments: usize,
    pub tolerance: f64,
    pub max_iterations: usize,
    pub ramp: Ramp,
    /// `loading.stop_after_peak` (see [`PeakStop`]).
    pub stop_after_peak: Option<f64>,
    /// Stop at the first increment that ends above this out-of-balance ratio (quasi-static
    /// runs: `solver.max_residual`, else `tolerance`); `None` runs on (the relaxation).
    pub stop_unconverged: Option<f64>,
    /// Indirect displacement control (`solver.control`; the quasi-static solver only).
    pub control: Option<Control>,
}

/// A gauge opening as the load path (`solver.control`, `solver::secant`).
#[derive(Clone, Debug, Default)]
pub struct Control {
    /// The gauge as weights on degrees of freedom D·i + component: the opening is
    /// Σ w·(x − x0) over them.
    pub gauge: Vec<(usize, f64)>,
    /// The opening at the end of the run (m).
    pub opening: f64,
}

/// How one load increment ended (`increments.csv`).
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct IncrementReport {
    /// 1-based.
    pub increment: usize,
    /// Fraction of Δmax held.
    pub load_factor: f64,
    /// Kernel steps of the increment.
    pub iterations: usize,
    /// State commits of the increment (`solver::secant`; 0 for the relaxation).
    pub commits: usize,
    /// ‖F_free‖₂ / ‖R‖₂ at its end.
    pub residual: f64,
    /// The gauge opening held (m), with `solver.control`.
    pub opening_m: Option<f64>,
    pub converged: bool,
}

/// What a relaxation run produced.
#[derive(Debug, Default)]
pub struct Relaxed {
    /// One record per increment (at its start, i.e. the previous increment converged) and
    /// one at the end.
    pub records: Vec<Record>,
    /// Wall time (s since `start`) at each record.
    pub wall_s: Vec<f64>,
    /// Kernel steps, all increments together.
    pub iterations: usize,
    /// Increments that stopped at max_iterations.
    pub unconverged_increments: usize,
    /// Largest ‖F_free‖/scale at the end of an increment.
    pub max_final_residual: f64,
    pub failure: Option<Unstable>,
    /// Stopped after the peak (`loading.stop_after_peak`).
    pub stopped_after_peak: bool,
    /// Every increment run, in order.
    pub increments: Vec<IncrementReport>,
    /// The increment the run stopped at because it did not converge
    /// ([`Settings::stop_unconverged`]).
    pub stopped_unconverged: Option<IncrementReport>,
    /// Cholesky factorisations of the held stiffness (`solver::secant`; 0 here).
    pub factorisations: usize,
    /// Increments undone and taken again in half the step (`solver::secant`; 0 here).
    pub cutbacks: usize,
}

/// Switch the dampers off and compute the stable limit of the undamped model.
pub fn undamped<const D: usize, const K: usize>(
    mech: &mut Mechanics<D, K>,
    x0: &[SVector<f64, D>],
) -> StableStep {
    mech.c_in.iter_mut().for_each(|c| *c = 0.0);
    mech.c_ex.iter_mut().for_each(|c| *c = 0.0);
    mech.c_implicit.iter_mut().for_each(|c| *c = 0.0);
    stable_step(mech, x0)
}

/// Norms of one iteration.
#[derive(Clone, Copy, Debug, Default)]
struct Norms {
    /// ‖F‖² over the free components.
    residual2: f64,
    /// ‖F‖² over the prescribed components (the reactions).
    reaction2: f64,
    /// Σ u_i·¹K_ii·u_i over the free components.
    rayleigh_num: f64,
    /// Σ u_i² over the free components.
    rayleigh_den: f64,
}

impl std::ops::Add for Norms {
    type Output = Norms;
    fn add(self, o: Norms) -> Norms {
        Norms {
            residual2: self.residual2 + o.residual2,
            reaction2: self.reaction2 + o.reaction2,
            rayleigh_num: self.rayleigh_num + o.rayleigh_num,
            rayleigh_den: self.rayleigh_den + o.rayleigh_den,
        }
    }
}

/// The adaptive damper: F^{n−1}, the free-component mask and the chunk partial sums,
/// allocated once.
struct AdaptiveDamping<const D: usize> {
    force_prev: Vec<SVector<f64, D>>,
    /// 1 on a free component, 0 on a prescribed one.
    free: Vec<SVector<f64, D>>,
    partial: Vec<Norms>,
    /// c^n (1/s).
    c: f64,
    /// The state was moved outside the kernel: the next update keeps c.
    restart: bool,
}

impl<const D: usize> AdaptiveDamping<D> {
    fn new<const K: usize>(sim: &Simulation<D, K>) -> Self {
        let n = sim.x0.len();
        let mut free = vec![SVector::<f64, D>::repeat(1.0); n];
        for p in &sim.prescribed {
            free[p.particle as usize][p.component as usize] = 0.0;
        }
        AdaptiveDamping {
            force_prev: vec![SVector::zeros(); n],
            free,
            partial: vec![Norms::default(); n.div_ceil(CHUNK)],
            c: 0.0,
            restart: false,
        }
    }

    /// After a step (x^n, v^{n−½} in `x_next`, `v_next`; F^n in `force`): the norms of
    /// F^n, the new c, C_ex = c·m for the next step, and F^n kept as F^{n−1}.
    fn update<const K: usize>(&mut self, sim: &mut Simulation<D, K>) -> Norms {
        let dt = sim.integration.dt;
        let st = &sim.state;
        let (x, v, f) = (&st.x_next, &st.v_next, &st.force);
        let (x0, inv_mass, free) = (&sim.x0, &sim.mech.inv_mass, &self.free);
        self.force_prev
            .par_chunks_mut(CHUNK)
            .zip(self.partial.par_iter_mut())
            .enumerate()
            .for_each(|(ci, (fp, out))| {
                let base = ci * CHUNK;
                let mut s = Norms::default();
                for (o, fpi) in fp.iter_mut().enumerate() {
                    let i = base + o;
                    let (fi, mask) = (f[i], free[i]);
                    for c in 0..D {
                        if mask[c] == 0.0 {
                            s.reaction2 += fi[c] * fi[c];
                            continue;
                        }
                        s.residual2 += fi[c] * fi[c];
                        let u = x[i][c] - x0[i][c];
                        s.rayleigh_den += u * u;
                        if v[i][c] != 0.0 {
                            let k = -(fi[c] - fpi[c]) * inv_mass[i] / (dt * v[i][c]);
                            s.rayleigh_num += u * u * k;
                        }
                    }
                    *fpi = fi;
                }
                *out = s;
            });
        let total = self.partial.iter().fold(Norms::default(), |a, &b| a + b);
        if std::mem::take(&mut self.restart) {
            return total;
        }
        self.c = if total.rayleigh_num > 0.0 && total.rayleigh_den > 0.0 {
            (2.0 * (total.rayleigh_num / total.rayleigh_den).sqrt()).min(2.0 / dt)
        } else {
            0.0
        };
        let c = self.c;
        let mech = &mut sim.mech;
        mech.c_ex
            .par_iter_mut()
            .zip(mech.mass.par_iter())
            .for_each(|(ce, &m)| *ce = c * m);
        total
    }
}

/// The start of an increment: the free components extrapolated from the last two converged
/// increments, u = u_{k−1} + α·(u_{k−1} − u_{k−2}) with α = (r_k − r_{k−1})/(r_{k−1} − r_{k−2})
/// (u_0 = 0, r_0 = 0; so increment 2 scales increment 1's field by r_2/r_1), at rest. Without
/// it, the prescribed rows jump by the whole increment while their neighbours stay, a strain
/// concentration of about (height/L0)× the increment's mean strain that cracks concrete next
/// to the grips long before the specimen's strength is reached (measured on the tension
/// block: peak 0.52–0.80 f't·A, crack at the loaded rows).
struct Predictor<const D: usize> {
    /// Free displacements at the last two converged increments.
    u1: Vec<SVector<f64, D>>,
    u2: Vec<SVector<f64, D>>,
    r1: f64,
    r2: f64,
    /// Converged increments seen (0, 1, 2 or more).
    seen: usize,
}

impl<const D: usize> Predictor<D> {
    fn new(n: usize) -> Self {
        Predictor {
            u1: vec![SVector::zeros(); n],
            u2: vec![SVector::zeros(); n],
            r1: 0.0,
            r2: 0.0,
            seen: 0,
        }
    }

    /// Called right after the step that moved the prescribed components to `r` (so that
    /// `x_next` holds the converged state of the previous increment, at load `r_prev`).
    fn apply<const K: usize>(
        &mut self,
        sim: &mut Simulation<D, K>,
        free: &[SVector<f64, D>],
        r_prev: f64,
        r: f64,
    ) {
        // Shift the history: u1 ← converged state at r_prev, u2 ← old u1.
        std::mem::swap(&mut self.u1, &mut self.u2);
        self.r2 = self.r1;
        self.r1 = r_prev;
        let x0 = &sim.x0;
        {
            let xc = &sim.state.x_next;
            self.u1
                .par_iter_mut()
                .enumerate()
                .for_each(|(i, u)| *u = xc[i] - x0[i]);
        }
        if r_prev > 0.0 {
            self.seen += 1;
        }
        if self.seen == 0 || self.r1 == self.r2 {
            return;
        }
        let alpha = (r - self.r1) / (self.r1 - self.r2);
        let (u1, u2) = (&self.u1, &self.u2);
        let mass = &sim.mech.mass;
        let st = &mut sim.state;
        // The kinetic energy taken out by the restart at rest counts as damping.
        st.x.par_iter_mut()
            .zip(st.v.par_iter_mut())
            .zip(st.damping_work.par_iter_mut())
            .enumerate()
            .with_min_len(CHUNK)
            .for_each(|(i, ((x, v), dw))| {
                for c in 0..D {
                    if free[i][c] != 0.0 {
                        x[c] = x0[i][c] + u1[i][c] + alpha * (u1[i][c] - u2[i][c]);
                        *dw += 0.5 * mass[i] * v[c] * v[c];
                        v[c] = 0.0;
                    }
                }
            });
    }
}

/// Σ over the prescribed components of reaction × (their displacement at `r` − at `r_prev`),
/// with the internal forces of the last step.
fn reaction_work<const D: usize, const K: usize>(
    sim: &Simulation<D, K>,
    r_prev: f64,
    r: f64,
) -> f64 {
    sim.prescribed
        .iter()
        .map(|p| {
            -sim.state.force[p.particle as usize][p.component as usize] * p.amplitude * (r - r_prev)
        })
        .sum()
}

/// Told of the state at the end of each load increment: the simulation and the ramp's time
/// reached (0 … 1), e.g. to take the frames of a time series (`run::snapshots`).
pub type Observer<'a, const D: usize, const K: usize> = &'a mut dyn FnMut(&Simulation<D, K>, f64);

/// Run the increments on a simulation at rest whose dampers are off (see [`undamped`]).
/// Stops early, with `failure` set, if the state blows up, and with `stopped_unconverged`
/// set at the first increment above [`Settings::stop_unconverged`]. `observe` is told of the
/// state at the end of each increment k (ramp time k/increments).
///
/// (The same pseudo-dynamics with the state held and committed at its equilibria was measured
/// as the quasi-static solver's first design and dropped: docs/quasi_static.md.)
pub fn relax<const D: usize, const K: usize>(
    sim: &mut Simulation<D, K>,
    probe: &Probe,
    s: &Settings,
    start: Instant,
    observe: Observer<D, K>,
) -> Relaxed {
    let mut damping = AdaptiveDamping::new(sim);
    let mut predictor = Predictor::new(sim.x0.len());
    let mut stop = PeakStop::quasi_static(s.stop_after_peak, probe);
    let mut r_prev = 0.0;
    let mut out = Relaxed {
        records: Vec::with_capacity(s.increments + 1),
        wall_s: Vec::with_capacity(s.increments + 1),
        increments: Vec::with_capacity(s.increments),
        ..Default::default()
    };
    // Largest reaction norm² of the converged increments so far.
    let mut converged_reaction2: f64 = 0.0;
    let tol2 = s.tolerance * s.tolerance;
    'increments: for k in 1..=s.increments {
        let factor = ramp_fraction(s.ramp, k as f64 / s.increments as f64, 1.0);
        // The step that records the converged state of increment k − 1 also moves the
        // prescribed components to increment k.
        sim.hold_load(factor);
        let rec = sim.advance(Some(probe));
        out.records.extend(rec);
        out.wall_s.push(start.elapsed().as_secs_f64());
        out.iterations += 1;
        if rec.is_some_and(|r| stop.reached(&r, sim)) {
            out.stopped_after_peak = true;
            break 'increments;
        }
        // Energy: the kernel books the prescribed jump by the trapezoid rule with the
        // reactions before and after it; the path from the converged state to the
        // predicted one, at the committed damage, did U(x_pred) − U(x^n) of work. Book the
        // difference once the reaction after the jump is known.
        let u_converged = rec.map(|r| r.internal_j).unwrap_or(0.0);
        let work_before = reaction_work(sim, r_prev, factor);
        predictor.apply(sim, &damping.free, r_prev, factor);
        let u_predicted = sim.internal_energy_now();
        let r_jump = r_prev;
        r_prev = factor;
        // The first step from the predicted state has no velocity history: keep c.
        damping.restart = true;
        let mut report = IncrementReport {
            increment: k,
            load_factor: factor,
            ..Default::default()
        };
        loop {
            sim.advance(None);
            report.iterations += 1;
            let norms = damping.update(sim);
            if report.iterations == 1 {
                let booked = 0.5 * (work_before + reaction_work(sim, r_jump, factor));
                sim.add_external_work(u_predicted - u_converged - booked);
            }
            let scale = norms.reaction2.max(converged_reaction2);
            if scale > 0.0 {
                report.residual = (norms.residual2 / scale).sqrt();
            }
            let converged = norms.residual2 <= tol2 * scale;
            if converged || report.iterations >= s.max_iterations {
                report.converged = converged;
                if converged {
                    converged_reaction2 = converged_reaction2.max(norms.reaction2);
                } else {
                    out.unconverged_increments += 1;
                }
                out.max_final_residual = out.max_final_residual.max(report.residual);
                break;
            }
            if report.iterations.is_multiple_of(64) {
                if let Err(e) = sim.check_stability(None, false) {
                    out.failure = Some(e);
                    out.iterations += report.iterations;
                    out.increments.push(report);
                    break 'increments;
                }
            }
        }
        out.iterations += report.iterations;
        out.increments.push(report);
        if let Err(e) = sim.check_stability(None, false) {
            out.failure = Some(e);
            break;
        }
        observe(sim, k as f64 / s.increments as f64);
        if s.stop_unconverged
            .is_some_and(|limit| !report.converged && report.residual > limit)
        {
            out.stopped_unconverged = Some(report);
            break;
        }
    }
    if out.failure.is_none() && !out.stopped_after_peak && out.stopped_unconverged.is_none() {
        let rec = sim.advance(Some(probe));
        out.records.extend(rec);
        out.wall_s.push(start.elapsed().as_secs_f64());
        out.iterations += 1;
    }
    out
}
