//! Time integration of a discretised specimen: the step kernel, displacement loading,
//! probes (reaction force, energies) and the stability guard (docs/architecture.md, "Solver").

pub mod bearing;
pub mod failure;
pub mod friction;
pub mod gauge;
pub mod inelastic;
pub mod kernel;
pub mod lanczos;
pub mod linear;
pub mod loading;
pub mod mass_scaling;
pub mod mechanics;
pub mod modal;
pub mod pace;
pub mod relaxation;
pub mod secant;
pub mod time_step;

/// Deterministic pseudo-random numbers for the kernels' unit tests.
#[cfg(test)]
pub(crate) mod test_rng {
    /// A linear congruential generator, numbers in [0, 1).
    pub struct Lcg(pub u64);
    impl Lcg {
        pub fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }
}

use kernel::State;
use loading::{ramp_fraction, AppliedForce, Prescribed};
use mechanics::Mechanics;
use nalgebra::SVector;

use crate::scene::Ramp;

/// The step kernel a run uses, chosen once before the loop from the features the scene turns
/// on (docs/architecture.md, "skip what the scene does not need"): the elastic kernel (no
/// `[concrete]`), the tension kernel (tensile damage only: no plastic stretch, no w_c, no
/// yield test), or the full kernel (compressive damage and/or plasticity).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum KernelSet {
    Elastic,
    Tension,
    Full,
    /// The bond-based family's kernel (`model::bond_based::kernel`).
    #[serde(rename = "bond_based")]
    BondBased,
}

impl KernelSet {
    pub fn name(self) -> &'static str {
        match self {
            KernelSet::Elastic => "elastic",
            KernelSet::Tension => "tension",
            KernelSet::Full => "full",
            KernelSet::BondBased => "bond_based",
        }
    }
}

/// How the run integrates.
#[derive(Clone, Copy, Debug)]
pub struct Integration {
    pub dt: f64,
    /// Reading (A) of docs/model.md §4 when true.
    pub lagged_forces: bool,
    pub ramp: Ramp,
    pub t_ramp: f64,
}

/// One sample of the probes.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct Record {
    pub step: usize,
    pub time_s: f64,
    /// Prescribed displacement of the probe group (m); for a force-controlled group, its
    /// members' mean displacement.
    pub displacement_m: f64,
    /// Reaction of the probe group along its component (N); for a force-controlled group,
    /// the force applied to it.
    pub force_n: f64,
    pub kinetic_j: f64,
    pub internal_j: f64,
    pub external_work_j: f64,
    pub damping_j: f64,
    /// The readings of the run's gauges (m), in the scene's order (`[[gauges]]`).
    pub gauges: [f64; gauge::MAX_GAUGES],
}

/// The probe: a group and the component along which its reaction is summed.
#[derive(Clone, Debug)]
pub struct Probe {
    pub members: Vec<u32>,
    pub component: usize,
    /// Δmax of the group along the component (0 for a support or a force-controlled group).
    pub amplitude: f64,
    /// P (N) of a force-controlled group (`load.force`), `None` otherwise.
    pub force: Option<f64>,
}

impl Probe {
    /// A probe that reads nothing (a scene without groups).
    pub fn empty() -> Self {
        Probe {
            members: vec![],
            component: 1,
            amplitude: 0.0,
            force: None,
        }
    }

    /// +1, or −1 when the group is pushed in the negative direction (its displacement or
    /// force is negative).
    pub fn sign(&self) -> f64 {
        if self.amplitude < 0.0 || self.force.is_some_and(|p| p < 0.0) {
            -1.0
        } else {
            1.0
        }
    }

    /// The probe's (displacement, force) with the ramp at `ramp` × its full value: the
    /// prescribed displacement and the reaction (−Σ `f` on the members), or, for a
    /// force-controlled group, its members' mean displacement and the applied force.
    pub fn reading<const D: usize>(
        &self,
        ramp: f64,
        x: &[SVector<f64, D>],
        x0: &[SVector<f64, D>],
        f: &[SVector<f64, D>],
    ) -> (f64, f64) {
        match self.force {
            None => (self.amplitude * ramp, self.reaction(f)),
            Some(p) => {
                let c = self.component;
                let sum: f64 = self
                    .members
                    .iter()
                    .map(|&i| x[i as usize][c] - x0[i as usize][c])
                    .sum();
                (sum / self.members.len().max(1) as f64, p * ramp)
            }
        }
    }

    /// The reaction of the group along its component: −Σ of the internal forces `f` on its
    /// members.
    pub fn reaction<const D: usize>(&self, f: &[SVector<f64, D>]) -> f64 {
        -self
            .members
            .iter()
            .map(|&i| f[i as usize][self.component])
            .sum::<f64>()
    }
}

/// Stops a run once it has passed its peak (`loading.stop_after_peak`): the probe force,
/// taken along the loading direction, has fallen below `fraction` × its largest value, and
/// (explicit runs) a particle has failed. The failed particle keeps the early ramp of an
/// explicit run, where the force is near zero and dynamic ripples can dip below any fraction
/// of it, from stopping the run. Relaxation records are converged (quasi-static) states with
/// no ripples, so they stop on the force alone: a fine lattice whose particles need a large
/// strain to fail (COD_c/(crack_band·L0)) would otherwise run long after the peak (dog-bone
/// A at L0 = 1 mm: peak at 1.1 s, stop at 6.9 s). Records up to the stop are those of the full
/// run, so its peak is the same bit for bit.
#[derive(Clone, Copy, Debug)]
pub struct PeakStop {
    fraction: Option<f64>,
    /// +1 or −1: the loading direction of the probe.
    sign: f64,
    peak: f64,
    /// Also wait for a failed particle (explicit runs).
    need_failure: bool,
}

impl PeakStop {
    /// For an explicit run (waits for a failed particle).
    pub fn new(fraction: Option<f64>, probe: &Probe) -> Self {
        PeakStop {
            fraction,
            sign: probe.sign(),
            peak: 0.0,
            need_failure: true,
        }
    }

    /// For a relaxation run (the force alone decides).
    pub fn quasi_static(fraction: Option<f64>, probe: &Probe) -> Self {
        PeakStop {
            need_failure: false,
            ..Self::new(fraction, probe)
        }
    }

    /// Whether the run may stop after this record.
    pub fn reached<const D: usize, const K: usize>(
        &mut self,
        rec: &Record,
        sim: &Simulation<D, K>,
    ) -> bool {
        let Some(fraction) = self.fraction else {
            return false;
        };
        let f = self.sign * rec.force_n;
        self.peak = self.peak.max(f);
        self.peak > 0.0
            && f < fraction * self.peak
            && (!self.need_failure || sim.has_failed_particle())
    }
}

/// A run that went unstable, or whose quasi-static solve broke down.
#[derive(Debug)]
pub struct Unstable {
    /// Where it happened.
    pub at: Location,
    pub what: String,
}

/// Where a run stopped: an explicit step at a particle, or a quasi-static increment.
#[derive(Debug, Clone, PartialEq)]
pub enum Location {
    /// The explicit step just taken and the particle found failing, with its reference
    /// position.
    Step {
        step: usize,
        /// The time (s).
        time: f64,
        particle: usize,
        position: String,
    },
    /// The quasi-static solver's increment (1-based) that could not be solved: the failure
    /// is the whole stiffness's (or the gauge's), so no particle is named.
    Increment {
        increment: usize,
        load_factor: f64,
        /// The Newton iteration counted over the run.
        iteration: usize,
        /// What to change.
        remedy: &'static str,
    },
}

impl Unstable {
    /// The explicit step, or the quasi-static solver's Newton iteration counted over the run.
    pub fn step(&self) -> usize {
        match self.at {
            Location::Step { step, .. } => step,
            Location::Increment { iteration, .. } => iteration,
        }
    }
}

/// The remedy of a held stiffness that cannot be factorised.
pub const STIFFNESS_REMEDY: &str =
    "raise solver.increments (less damage grows in each), or run solver.method = \"explicit\"";

impl std::fmt::Display for Unstable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.at {
            Location::Step {
                step,
                time,
                particle,
                position,
            } => write!(
                f,
                "the run went unstable at step {step} (t = {time:.6e} s): {} at particle {particle} (reference position {position}); reduce solver.safety or solver.dt, or check the material and the loading",
                self.what
            ),
            Location::Increment {
                increment,
                load_factor,
                iteration,
                remedy,
            } => write!(
                f,
                "the quasi-static solver stopped at increment {increment} (load factor {load_factor:.6}, iteration {iteration} of the run): {}; {remedy}",
                self.what
            ),
        }
    }
}

impl std::error::Error for Unstable {}

/// How much energy beyond what was put in (in units of the energy put in) the stability guard
/// tolerates before it stops a run ([`Simulation::check_stability`]): 10, the margin of the
/// blow-up test before the dampers were counted. A load ramped over a few steps is
/// integrated with a balance error of the order of the energy put in (the central rule's
/// work against the dampers' booking: a generated scene ramped over 2 steps measured 1.04×),
/// which is no instability; a run that blows up passes any such margin within a few steps.
pub const ENERGY_CREATED_LIMIT: f64 = 10.0;

/// The share of the load's energy scale below which the energy balance is not judged.
pub const BALANCE_FLOOR: f64 = 1e-9;

/// A simulation in progress.
pub struct Simulation<const D: usize, const K: usize> {
    pub x0: Vec<SVector<f64, D>>,
    pub mech: Mechanics<D, K>,
    pub state: State<D>,
    pub prescribed: Vec<Prescribed>,
    /// Force-controlled loads (`load.force`), ramped like the displacements.
    pub applied: Vec<AppliedForce>,
    /// Members of platens with friction (`groups.<name>.friction`).
    pub friction: Vec<friction::Contact>,
    /// Members pressed through bearing strips (`groups.<name>.bearing`).
    pub bearings: Vec<bearing::Bearing>,
    pub integration: Integration,
    pub step: usize,
    external_work: f64,
    /// Initial energy E0 (the round-off elastic energy at rest, or a free-vibration start),
    /// for the blow-up test.
    energy_scale: f64,
    /// Elastic energy of the round-off in the positions, below which energies are noise.
    energy_floor: f64,
    /// A scale of the energy the prescribed displacements can put in,
    /// ½·Σ_prescribed (a_i·Σ_j 1/L0,ij)·Δmax²: [`BALANCE_FLOOR`] of it is the energy below
    /// which the balance test of [`Self::check_stability`] does not judge (bookkeeping
    /// round-off in the first steps of a ramp).
    load_energy: f64,
    /// Whether the kernel with bond dampers runs (decided once, before the loop).
    bond_dampers: bool,
    /// Damage and plasticity; `None` runs the elastic kernel.
    pub inelastic: Option<Box<dyn inelastic::Inelastic<D, K>>>,
    /// Load factor held instead of the time ramp (dynamic relaxation), see [`Self::hold_load`].
    held: Option<HeldLoad>,
    /// The load clock of an adaptive pace (`pace`), `None` for the fixed ramp in time.
    clock: Option<LoadClock>,
    /// The gauges each record reads (`[[gauges]]`).
    pub gauges: Vec<gauge::Gauge<D>>,
}

/// The load time τ of an adaptive pace: the ramp is read at τ = t + lead, and the lead grows
/// by (factor − 1)·Δt a step (docs/model.md §10, "Adaptive pace"). While the factor is 1 the
/// ramp is read at the fixed ramp's times, bit for bit.
#[derive(Clone, Copy, Debug)]
struct LoadClock {
    /// The lead at the previous step.
    before: f64,
    /// The lead at this step.
    now: f64,
    /// dτ/dt of this step.
    factor: f64,
}

/// A load factor held from a given step on (the factor `before` applies to earlier steps).
#[derive(Clone, Copy, Debug)]
struct HeldLoad {
    from_step: usize,
    before: f64,
    after: f64,
}

impl<const D: usize, const K: usize> Simulation<D, K> {
    pub fn new(
        x0: Vec<SVector<f64, D>>,
        mech: Mechanics<D, K>,
        prescribed: Vec<Prescribed>,
        integration: Integration,
    ) -> Self {
        let state = State::at_rest(&x0);
        let bond_dampers = mech.has_bond_dampers();
        let mut sim = Simulation {
            x0,
            mech,
            state,
            prescribed,
            applied: Vec::new(),
            friction: Vec::new(),
            bearings: Vec::new(),
            integration,
            step: 0,
            external_work: 0.0,
            energy_scale: 0.0,
            energy_floor: 0.0,
            load_energy: 0.0,
            bond_dampers,
            inelastic: None,
            held: None,
            clock: None,
            gauges: Vec::new(),
        };
        // The elastic energy at rest is not zero to round-off (positions far from the origin
        // or offset by many cells, rotated lattices): it is initial energy, part of E0.
        sim.energy_scale = sim.internal_energy_now();
        sim.energy_floor = sim.round_off_energy();
        sim.load_energy = sim
            .prescribed
            .iter()
            .map(|p| {
                let i = p.particle as usize;
                let k: f64 = sim
                    .mech
                    .bonds(i)
                    .map(|(_, _, il)| sim.mech.a[i].abs() * il)
                    .sum();
                0.5 * k * p.amplitude * p.amplitude
            })
            .sum();
        sim
    }

    /// Elastic energy of a uniform bond stretch s_r = 1000·ε·max(1, max|x0|/L0), the size
    /// of the stretch errors that rounding the positions makes (ε the machine epsilon):
    /// U = ¼·s_r²·Σ_i |a_i + n_i·b_i|·Σ_j L0,ij for S_ij = s_r (n_i bonds of particle i).
    /// A loaded specimen stores 1e8 times more; an unloaded one only this noise.
    fn round_off_energy(&self) -> f64 {
        let m = &self.mech;
        let mut reach: f64 = 1.0;
        let mut sum = 0.0;
        for i in 0..self.x0.len() {
            let (mut n, mut lengths) = (0.0, 0.0);
            for (_, _, il) in m.bonds(i) {
                n += 1.0;
                lengths += 1.0 / il;
                reach = reach.max(self.x0[i].norm() * il);
            }
            let c = m.second.as_ref().map_or(0.0, |c| c.c[i].abs());
            sum += ((m.a[i] + n * m.b[i]).abs() + c) * lengths;
        }
        let s = 1000.0 * f64::EPSILON * reach;
        0.25 * s * s * sum
    }

    /// Whether some particle has failed (w_t or w_c ≥ 0.99); never for the elastic kernel.
    pub fn has_failed_particle(&self) -> bool {
        self.inelastic
            .as_ref()
            .is_some_and(|m| m.has_failed_particle())
    }

    /// The step kernel this simulation runs.
    pub fn kernel(&self) -> KernelSet {
        match &self.inelastic {
            Some(model) => model.kernel(),
            None => KernelSet::Elastic,
        }
    }

    pub fn time(&self) -> f64 {
        self.step as f64 * self.integration.dt
    }

    /// Fraction of Δmax applied at time t.
    fn ramp_at(&self, t: f64) -> f64 {
        if let Some(h) = self.held {
            let step = (t / self.integration.dt).round();
            return if step >= h.from_step as f64 {
                h.after
            } else {
                h.before
            };
        }
        ramp_fraction(self.integration.ramp, t, self.integration.t_ramp)
    }

    /// From the next step on, hold the prescribed displacements at `factor` × Δmax instead
    /// of following the time ramp (load increments of dynamic relaxation). The positions the
    /// current step computes, x^{n+1}, carry the new factor; the work of the jump is booked
    /// by the central rule like any other motion of the supports.
    pub fn hold_load(&mut self, factor: f64) {
        let before = self.ramp_at(self.time());
        self.held = Some(HeldLoad {
            from_step: self.step + 1,
            before,
            after: factor,
        });
    }

    /// Read the ramp at a load time that advances `factor` times as fast as time from this
    /// step on (adaptive pace, [`pace`]).
    pub fn set_pace(&mut self, factor: f64) {
        let clock = self.clock.get_or_insert(LoadClock {
            before: 0.0,
            now: 0.0,
            factor,
        });
        clock.factor = factor;
    }

    /// The load time τ: the time for the fixed ramp, time plus the load clock's lead for an
    /// adaptive pace.
    pub fn load_time(&self) -> f64 {
        self.time() + self.clock.map_or(0.0, |c| c.now)
    }

    /// Book work done on the specimen outside the kernel (the displacement predictor of
    /// dynamic relaxation moves free particles between steps).
    pub fn add_external_work(&mut self, work: f64) {
        self.external_work += work;
    }

    /// Start from a given displacement field and velocity (free-vibration tests).
    pub fn set_initial(&mut self, u: &[SVector<f64, D>], v: &[SVector<f64, D>]) {
        for i in 0..self.x0.len() {
            self.state.x[i] = self.x0[i] + u[i];
            self.state.v[i] = v[i];
        }
        let (k, u_int) = (self.kinetic_energy(), self.internal_energy_now());
        self.energy_scale = k + u_int;
    }

    /// Advance one step. Returns the probe record when `record` is given.
    pub fn advance(&mut self, record: Option<&Probe>) -> Option<Record> {
        let dt = self.integration.dt;
        if let Some(model) = self.inelastic.as_mut() {
            model.step(
                &self.mech,
                &mut self.state,
                dt,
                self.integration.lagged_forces,
                self.bond_dampers,
            );
        } else {
            self.step_elastic(dt);
        }
        self.finish_step(record)
    }

    fn step_elastic(&mut self, dt: f64) {
        match (self.integration.lagged_forces, self.bond_dampers) {
            (false, false) => kernel::step::<D, K, false, false>(&self.mech, &mut self.state, dt),
            (false, true) => kernel::step::<D, K, false, true>(&self.mech, &mut self.state, dt),
            (true, false) => kernel::step::<D, K, true, false>(&self.mech, &mut self.state, dt),
            (true, true) => kernel::step::<D, K, true, true>(&self.mech, &mut self.state, dt),
        }
    }

    /// Supports, loading, probes and the swap to the next step, after the kernel.
    fn finish_step(&mut self, record: Option<&Probe>) -> Option<Record> {
        let dt = self.integration.dt;
        let t = self.time();
        // The ramp at n−1, n and n+1, once for every prescribed component.
        let (r_prev, r_now, r_next) = match self.clock {
            None => {
                let r_prev = if self.step == 0 {
                    0.0
                } else {
                    self.ramp_at(t - dt)
                };
                (r_prev, self.ramp_at(t), self.ramp_at(t + dt))
            }
            Some(c) => {
                let at = |tau| ramp_fraction(self.integration.ramp, tau, self.integration.t_ramp);
                let r_prev = if self.step == 0 {
                    0.0
                } else {
                    at(t - dt + c.before)
                };
                let lead = c.now + (c.factor - 1.0) * dt;
                (r_prev, at(t + c.now), at(t + dt + lead))
            }
        };
        if let Some(c) = &mut self.clock {
            c.before = c.now;
            c.now += (c.factor - 1.0) * dt;
        }
        // Force loading, then supports and displacement loading; work of the applied
        // forces and of the reactions (central rule).
        let (mut work, mut work_half) = self.apply_forces(r_now);
        let (w, w_half) = bearing::apply(
            &self.bearings,
            &self.mech,
            &self.x0,
            &mut self.state,
            r_now,
            dt,
        );
        work += w;
        work_half += w_half;
        for p in &self.prescribed {
            let (i, c) = (p.particle as usize, p.component as usize);
            let u_next = p.amplitude * r_next;
            // The kernel integrated this component freely and booked its particle-damper
            // work; no particle damper acts on a prescribed component: take that work back.
            let c_ex = self.mech.c_ex[i];
            if c_ex != 0.0 {
                let vm = 0.5 * (self.state.v[i][c] + self.state.v_next[i][c]);
                self.state.damping_work[i] -= dt * c_ex * vm * vm;
            }
            // ... nor the implicit share of the bond dampers (S.17)
            let c_im = self.mech.c_implicit[i];
            if c_im != 0.0 {
                let (v0, v1) = (self.state.v[i][c], self.state.v_next[i][c]);
                self.state.damping_work[i] -= dt * c_im * (v1 - v0) * 0.5 * (v0 + v1);
            }
            self.state.x_next[i][c] = self.x0[i][c] + u_next;
            self.state.v_next[i][c] = (self.state.x_next[i][c] - self.state.x[i][c]) / dt;
            if p.amplitude != 0.0 {
                let reaction = -self.state.force[i][c];
                let u_prev = p.amplitude * r_prev;
                work += reaction * 0.5 * (u_next - u_prev);
                work_half += reaction * 0.5 * (p.amplitude * r_now - u_prev);
            }
        }
        friction::apply(&self.friction, &self.mech, &mut self.state, dt);
        let rec = record.map(|probe| {
            let kinetic = self.kinetic_energy_mid();
            let (displacement_m, force_n) =
                probe.reading(r_now, &self.state.x, &self.x0, &self.state.force);
            Record {
                step: self.step,
                time_s: t,
                displacement_m,
                force_n,
                kinetic_j: kinetic,
                internal_j: self.internal_energy_now(),
                external_work_j: self.external_work + work_half,
                damping_j: self.state.damping_work.iter().sum(),
                gauges: gauge::readings(&self.gauges, &self.state.x, &self.x0),
            }
        });
        self.external_work += work;
        if self.integration.lagged_forces {
            std::mem::swap(&mut self.state.force, &mut self.state.force_prev);
        }
        std::mem::swap(&mut self.state.x, &mut self.state.x_next);
        std::mem::swap(&mut self.state.v, &mut self.state.v_next);
        self.step += 1;
        rec
    }

    /// Adds the force-controlled loads b_i = ramp·P_i to the step the kernel took from the
    /// internal forces alone ([`loading::add_force`]). Returns the work of the loads over the
    /// step and up to step n.
    fn apply_forces(&mut self, ramp: f64) -> (f64, f64) {
        let dt = self.integration.dt;
        let (mut work, mut work_half) = (0.0, 0.0);
        for a in &self.applied {
            let at = (a.particle as usize, a.component as usize);
            let (w, w_half) =
                loading::add_force(&self.mech, &mut self.state, at, a.amplitude * ramp, dt);
            work += w;
            work_half += w_half;
        }
        (work, work_half)
    }

    /// What the failure criteria read after a step (docs/failure.md): the force-loaded
    /// particles' speeds v^{n+½}, their out-of-balance forces at x^n and the power of the
    /// loads, and the volume-weighted mean damage max(w_t, w_c) of the body.
    pub fn failure_observation(&self) -> failure::Observation {
        let damage = self
            .inelastic
            .as_ref()
            .map_or(0.0, |m| m.mean_damage(&self.mech.mass));
        failure::Observation::of_loads(
            &self.applied,
            self.ramp_at(self.time() - self.integration.dt),
            (&self.state.x, &self.x0),
            &self.state.v,
            &self.state.force,
            damage,
        )
    }

    /// Kinetic energy of the free components at step n, v^n = ½(v^{n−½} + v^{n+½})
    /// (before the swap).
    fn kinetic_energy_mid(&self) -> f64 {
        let st = &self.state;
        self.kinetic_energy_of(|i| (st.v[i] + st.v_next[i]) * 0.5)
    }

    /// Kinetic energy of the free components from v^{n−½}.
    pub fn kinetic_energy(&self) -> f64 {
        self.kinetic_energy_of(|i| self.state.v[i])
    }

    /// ½·Σ m·v² over the components that are not prescribed (the machine moves those),
    /// summed over the free components only: subtracting the prescribed ones from the total
    /// loses the free energy to cancellation when the machine moves fast (a loaded group
    /// of every particle: 1e4 J moved, 1e-20 J free).
    fn kinetic_energy_of(&self, v: impl Fn(usize) -> SVector<f64, D>) -> f64 {
        let mut held = vec![[false; D]; self.x0.len()];
        for p in &self.prescribed {
            held[p.particle as usize][p.component as usize] = true;
        }
        (0..self.x0.len())
            .map(|i| {
                let vi = v(i);
                let free: f64 = (0..D).filter(|&c| !held[i][c]).map(|c| vi[c] * vi[c]).sum();
                0.5 * self.mech.mass[i] * free
            })
            .sum()
    }

    /// Elastic energy stored in the bonds at the current positions,
    /// U = ¼·Σ_i Σ_j L0,ij·S_ij·F_s,ij (so that ∂U/∂L_ij = F_b,ij; see docs/model.md §7), with
    /// the FCC second-neighbour term ¼·c_i·Σ_{j∈N_II} L0,ij·S_ij² (docs/model.md §3 erratum).
    pub fn internal_energy_now(&self) -> f64 {
        if let Some(model) = &self.inelastic {
            return model.internal_energy(&self.mech, &self.state.x);
        }
        let x = &self.state.x;
        let m = &self.mech;
        (0..x.len())
            .map(|i| {
                let mut sum_s = 0.0;
                let mut sum_s2_l = 0.0;
                let mut sum_s_l = 0.0;
                // Σ over second-neighbour slots of S²·L0 (FCC: their modulus is a + c)
                let mut sum_s2_l_second = 0.0;
                let w = m.weights(i);
                for (k, j, il) in m.bonds(i) {
                    let s = crate::model::stretch::total_stretch((x[j] - x[i]).norm(), il);
                    sum_s += mechanics::weighted(w, k, s);
                    sum_s2_l += s * s / il;
                    sum_s_l += s / il;
                    if m.second.as_ref().is_some_and(|c| k >= c.first_slot) {
                        sum_s2_l_second += s * s / il;
                    }
                }
                let u = crate::model::force_state::particle_energy(
                    m.a[i], m.b[i], sum_s, sum_s2_l, sum_s_l,
                );
                match &m.second {
                    None => u,
                    Some(c) => u + 0.25 * c.c[i] * sum_s2_l_second,
                }
            })
            .sum()
    }

    /// Stop with the step and the particle if the state is not finite, or if the energy
    /// balance K + U + D = W + E0 (kinetic, elastic when given, damper energy, work of the
    /// supports, initial energy) is broken: the specimen holds more than
    /// [`ENERGY_CREATED_LIMIT`] × everything put into it (E0 + |W| + the round-off floor) on
    /// top of what was put in — energy from nowhere, which a stable run cannot make, whether
    /// it shows as motion, strain or heat in the dampers — or the dampers gave back more than
    /// that (negative damper work). The dissipated energy W + E0 − K − U − D may be positive
    /// (fracture); it is negative by that margin only when the balance is broken.
    ///
    /// `balance = false` skips the balance test and keeps the blow-up test of kinetic plus
    /// elastic energy against 10× the energy put in: dynamic relaxation is not a physical
    /// motion (its load jumps between increments and its dampers are fictitious), so its
    /// energies need not balance.
    pub fn check_stability(
        &mut self,
        internal: Option<f64>,
        balance: bool,
    ) -> Result<(), Unstable> {
        let v = &self.state.v;
        let x = &self.state.x;
        let bad = (0..v.len())
            .find(|&i| !(v[i].iter().all(|c| c.is_finite()) && x[i].iter().all(|c| c.is_finite())));
        let kinetic = self.kinetic_energy();
        let held = kinetic + internal.unwrap_or(0.0);
        let put_in = self.energy_scale + self.external_work;
        let reference = self.energy_scale + self.external_work.abs() + self.energy_floor;
        // what broke, if anything (`None`: the run is fine)
        let broken = if balance {
            let damping: f64 = self.state.damping_work.iter().sum();
            let judged = ENERGY_CREATED_LIMIT * (reference + BALANCE_FLOOR * self.load_energy);
            let dissipated = put_in - held - damping;
            if !(held.is_finite() && damping.is_finite()) {
                Some(format!("the energies are not finite (kinetic + elastic {held:.3e} J, dampers {damping:.3e} J)"))
            } else if -dissipated > judged || damping < -judged {
                Some(format!("the energy balance is broken: kinetic + elastic energy {held:.3e} J and damper energy {damping:.3e} J against {put_in:.3e} J put in (dissipated {dissipated:.3e} J < 0)"))
            } else {
                None
            }
        } else if !held.is_finite() || (reference > 0.0 && held > 10.0 * reference) {
            Some(format!("kinetic + elastic energy {held:.3e} J exceeds 10× the energy put in ({reference:.3e} J)"))
        } else {
            None
        };
        let (particle, what) = match (bad, broken) {
            (None, None) => return Ok(()),
            (Some(i), _) => (
                i,
                "the position or velocity is not a finite number".to_string(),
            ),
            (None, Some(what)) => {
                let i = (0..v.len())
                    .max_by(|&a, &b| {
                        v[a].norm()
                            .partial_cmp(&v[b].norm())
                            .unwrap_or(std::cmp::Ordering::Equal)
                    })
                    .unwrap_or(0);
                (i, format!("{what}, fastest"))
            }
        };
        Err(Unstable {
            at: Location::Step {
                step: self.step,
                time: self.time(),
                particle,
                position: format!("{:?}", self.x0[particle].as_slice()),
            },
            what,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::{Location, Unstable, STIFFNESS_REMEDY};

    /// A quasi-static breakdown names the increment and load factor and the keys that apply
    /// to that solver, not the explicit step's (solver.safety, solver.dt) nor a particle.
    #[test]
    fn quasi_static_breakdown_names_the_increment_and_its_remedy() {
        let e = Unstable {
            at: Location::Increment {
                increment: 57,
                load_factor: 0.4375,
                iteration: 812,
                remedy: STIFFNESS_REMEDY,
            },
            what: "the secant stiffness is not positive definite".into(),
        };
        let msg = e.to_string();
        assert!(
            msg.contains("increment 57") && msg.contains("load factor 0.437500"),
            "{msg}"
        );
        assert!(msg.contains("solver.increments") && msg.contains("not positive definite"));
        assert!(
            !msg.contains("solver.dt") && !msg.contains("particle"),
            "{msg}"
        );
        let explicit = Unstable {
            at: Location::Step {
                step: 812,
                time: 0.4375,
                particle: 0,
                position: "[0.0, 0.0]".into(),
            },
            ..e
        };
        let msg = explicit.to_string();
        assert!(
            msg.contains("step 812") && msg.contains("particle 0") && msg.contains("solver.dt")
        );
    }
}
