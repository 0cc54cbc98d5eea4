//! The explicit integration of a bond-based body: Euler–Cromer (the velocity from the forces
//! at the old positions, the positions from the new velocity; Hobbs 2021, §4.6) with the
//! displacement loading of the scene's groups and velocity damping of the fundamental mode
//! (`damping.external`, c = 2·ξ·ω1), recording the probe, the energies and the gauges.

use super::{ramp_at, unstable_at, BondFinished};
use crate::model::bond_based::body::BondBody;
use crate::run::gauges::gauges_of;
use crate::run::load_test::{applied_forces, watch, LoadTestReport};
use crate::run::prepare::Prepared;
use crate::solver::failure::Observation;
use crate::solver::gauge::{readings, Gauge};
use crate::solver::loading::{AppliedForce, Prescribed};
use crate::solver::{Probe, Record};
use nalgebra::SVector;
use rayon::prelude::*;
use std::time::Instant;

/// Points per chunk of the sums taken in parallel (each chunk summed, the chunks in order).
const SUM_CHUNK: usize = 4096;

/// The state of a bond-based run and what it integrates.
pub struct Stepper<const D: usize> {
    pub body: BondBody<D>,
    pub x: Vec<SVector<f64, D>>,
    pub v: Vec<SVector<f64, D>>,
    /// The internal forces at `x` (N).
    pub f: Vec<SVector<f64, D>>,
    pub mass: Vec<f64>,
    prescribed: Vec<Prescribed>,
    /// Force-controlled loads (`load.force`), and their velocity components before a step.
    applied: Vec<AppliedForce>,
    applied_v: Vec<f64>,
    /// Per point and component: integrated (not prescribed).
    free: Vec<[bool; D]>,
    /// c = 2·ξ_ex·ω1 (1/s).
    damping: f64,
    gauges: Vec<Gauge<D>>,
    external_work: f64,
    damping_work: f64,
}

impl<const D: usize> Stepper<D> {
    pub fn new<const K: usize>(p: &Prepared<K, D>, body: BondBody<D>, mass: Vec<f64>) -> Self {
        let n = body.len();
        let omega1 = p.fundamental.eigenvalue.sqrt();
        Stepper {
            x: body.x0.clone(),
            v: vec![SVector::zeros(); n],
            f: vec![SVector::zeros(); n],
            mass,
            prescribed: p.model.prescribed.clone(),
            applied: applied_forces(&p.model.scene, &p.model.groups, &body.volume),
            applied_v: Vec::new(),
            free: p
                .model
                .constrained
                .iter()
                .map(|c| c.map(|held| !held))
                .collect(),
            damping: 2.0 * p.model.scene.damping.external * omega1,
            gauges: gauges_of(&p.model),
            external_work: 0.0,
            damping_work: 0.0,
            body,
        }
    }

    /// One step from t to t + Δt: the forces at the current positions (kept in `f`), then
    /// the free components' velocities and positions, then the applied forces' share, then
    /// the prescribed components.
    fn step(&mut self, t: f64, dt: f64, scene: &crate::scene::Scene, t_end: f64) {
        self.body.forces(&self.x, &mut self.f);
        self.applied_v.clear();
        for a in &self.applied {
            self.applied_v
                .push(self.v[a.particle as usize][a.component as usize]);
        }
        let h = 0.5 * self.damping * dt;
        let damping = self.damping;
        // per fixed chunk of points, summed in order: the same bits on any number of threads
        let work: Vec<f64> = self
            .x
            .par_chunks_mut(SUM_CHUNK)
            .zip(self.v.par_chunks_mut(SUM_CHUNK))
            .zip(
                self.f
                    .par_chunks(SUM_CHUNK)
                    .zip(self.mass.par_chunks(SUM_CHUNK)),
            )
            .zip(self.free.par_chunks(SUM_CHUNK))
            .map(|(((xs, vs), (fs, ms)), frees)| {
                let mut w = 0.0;
                for ((x, v), ((f, m), free)) in xs
                    .iter_mut()
                    .zip(vs.iter_mut())
                    .zip(fs.iter().zip(ms).zip(frees))
                {
                    for c in 0..D {
                        if free[c] {
                            let vn = ((1.0 - h) * v[c] + dt * f[c] / m) / (1.0 + h);
                            let mid = 0.5 * (vn + v[c]);
                            w += damping * m * mid * mid * dt;
                            v[c] = vn;
                            x[c] += dt * vn;
                        }
                    }
                }
                w
            })
            .collect();
        let work: f64 = work.iter().sum();
        self.damping_work += work;
        self.apply_forces(ramp_at(scene, t, t_end), dt);
        let load = ramp_at(scene, t + dt, t_end);
        for pr in &self.prescribed {
            let (i, c) = (pr.particle as usize, pr.component as usize);
            let target = self.body.x0[i][c] + pr.amplitude * load;
            let du = target - self.x[i][c];
            self.external_work -= self.f[i][c] * du;
            self.v[i][c] = du / dt;
            self.x[i][c] = target;
        }
    }

    /// The force-controlled loads b = ramp·P_i added to the step taken from the internal
    /// forces (Euler–Cromer is linear in the force): Δv = Δt·b/(m·(1 + h)), with the
    /// damper's work booked again for the new mid-step velocity and the loads' work
    /// b·(x^{n+1} − x^n).
    fn apply_forces(&mut self, ramp: f64, dt: f64) {
        let h = 0.5 * self.damping * dt;
        for (a, &v0) in self.applied.iter().zip(&self.applied_v) {
            let (i, c) = (a.particle as usize, a.component as usize);
            let b = a.amplitude * ramp;
            let m = self.mass[i];
            let dv = dt * b / (m * (1.0 + h));
            let v1 = self.v[i][c];
            let (mid, mid_new) = (0.5 * (v0 + v1), 0.5 * (v0 + v1 + dv));
            self.damping_work += self.damping * m * (mid_new * mid_new - mid * mid) * dt;
            self.v[i][c] = v1 + dv;
            self.x[i][c] += dt * dv;
            self.external_work += b * dt * (v1 + dv);
        }
    }

    /// What the failure criteria read after a step (docs/failure.md): the loaded points'
    /// speeds and out-of-balance forces, the power of the loads at `ramp`, and the share of
    /// bonds broken.
    fn failure_observation(&self, ramp: f64) -> Observation {
        Observation::of_loads(
            &self.applied,
            ramp,
            (&self.x, &self.body.x0),
            &self.v,
            &self.f,
            self.body.broken_bonds() as f64 / self.body.bonds().max(1) as f64,
        )
    }

    /// `n` steps from rest (for timing), without records.
    pub fn steps<const K: usize>(&mut self, p: &Prepared<K, D>, n: usize) {
        for k in 0..n {
            self.step(k as f64 * p.dt, p.dt, &p.model.scene, p.t_end);
        }
    }

    /// The record at step n (time t), the forces `f` at the current positions.
    fn record(&self, n: usize, t: f64, probe: &Probe, load: f64) -> Record {
        let kinetic: f64 = self
            .v
            .iter()
            .zip(&self.mass)
            .map(|(v, m)| 0.5 * m * v.norm_squared())
            .sum();
        let (displacement_m, force_n) = probe.reading(load, &self.x, &self.body.x0, &self.f);
        Record {
            step: n,
            time_s: t,
            displacement_m,
            force_n,
            kinetic_j: kinetic,
            internal_j: self.body.elastic_energy(&self.x),
            external_work_j: self.external_work,
            damping_j: self.damping_work,
            gauges: readings(&self.gauges, &self.x, &self.body.x0),
        }
    }

    /// Run to t_end with `output.records` records, stopping at an instability or after the
    /// peak (`loading.stop_after_peak`: the force below the fraction of its peak once a bond
    /// has broken).
    pub fn run<const K: usize>(&mut self, p: &Prepared<K, D>, start: Instant) -> BondFinished {
        let scene = &p.model.scene;
        let empty = Probe::empty();
        let probe = p.probe.as_ref().map(|(_, pr)| pr).unwrap_or(&empty);
        let sign = probe.sign();
        let every = (p.steps / (scene.output.records - 1)).max(1);
        let mut out = BondFinished {
            records: Vec::with_capacity(scene.output.records + 1),
            wall_s: Vec::new(),
            steps_done: 0,
            failure: None,
            stopped_after_peak: false,
            load_test: None,
        };
        let mut peak = 0.0f64;
        let mut watch = watch(scene, p.t_end, p.dt);
        let mut decision = None;
        let t_ramp = scene.loading.ramp_fraction * p.t_end;
        for n in 0..p.steps {
            let t = n as f64 * p.dt;
            self.step(t, p.dt, scene, p.t_end);
            out.steps_done = n + 1;
            if n % 64 == 0 || n + 1 == p.steps {
                if let Some(e) = unstable_at(&self.x, &self.body.x0, n + 1, t + p.dt) {
                    out.failure = Some(e);
                    break;
                }
            }
            if n % every == 0 || n + 1 == p.steps {
                // the forces of this step were taken at time t
                let r = self.record(n, t, probe, ramp_at(scene, t, p.t_end));
                out.records.push(r);
                out.wall_s.push(start.elapsed().as_secs_f64());
                let f = sign * r.force_n;
                peak = peak.max(f);
                if let Some(fraction) = scene.loading.stop_after_peak {
                    if peak > 0.0 && f < fraction * peak && self.body.broken_bonds() > 0 {
                        out.stopped_after_peak = true;
                        break;
                    }
                }
            }
            if let Some(w) = watch.as_mut().filter(|w| w.due(n + 1)) {
                let o = self.failure_observation(ramp_at(scene, t, p.t_end));
                decision = w.observe(n + 1, t + p.dt > t_ramp, &o);
                if decision.is_some() {
                    break;
                }
            }
        }
        out.load_test = watch
            .filter(|_| out.failure.is_none())
            .map(|w| LoadTestReport::of(scene, &w, decision, out.steps_done, p.dt));
        out
    }

    /// Each point's stress (Voigt [σxx, σyy, σzz, σyz, σxz, σxy], Pa): (1/(2ΔV_i))·Σ f_b ⊗ y_b
    /// over its bonds at the final positions.
    pub fn stresses(&mut self) -> Vec<[f64; 6]> {
        let body = &self.body;
        let x = &self.x;
        (0..body.len())
            .into_par_iter()
            .map(|i| {
                let mut s = nalgebra::SMatrix::<f64, D, D>::zeros();
                for b in body.start[i] as usize..body.start[i + 1] as usize {
                    let sm = body.s_max[b];
                    if sm.is_infinite() {
                        continue;
                    }
                    let j = body.neighbour[b] as usize;
                    let y = x[j] - x[i];
                    let len = y.norm();
                    let st = len * body.inv_xi[b] - 1.0;
                    let d = if st > 0.0 { body.bond_damage(b) } else { 0.0 };
                    let f = y * (body.stiffness[b] as f64 * st * (1.0 - d) / len);
                    s += f * y.transpose();
                }
                s /= 2.0 * body.volume[i];
                crate::run::arrays::voigt6(&s)
            })
            .collect()
    }
}
