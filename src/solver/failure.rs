//! The failure criteria of a force-controlled load (docs/failure.md): checked every few steps
//! once the load is fully applied, each decides whether the specimen holds the load or has
//! failed; a load not judged held by the end of the run has failed (Ness 2019, §4.3).

use super::loading::AppliedForce;
use crate::scene::failure::{Criterion, FailureSpec};
use nalgebra::SVector;
use serde::Serialize;

/// What a check reads from the run, over the force-loaded particles B.
#[derive(Clone, Copy, Debug, Default)]
pub struct Observation {
    /// (F.1): (1/|B|)·Σ_B |v_i| (m/s).
    pub mean_speed: f64,
    /// (F.2): (1/|B|)·Σ_B |f_i + b_i| / |b_i|, f_i the internal force.
    pub out_of_balance: f64,
    /// The damaged share of the body: broken bonds over bonds (bond-based), the
    /// volume-weighted mean of max(w_t, w_c) (SPLM/SPPM).
    pub damage: f64,
    /// Σ_B v_i·b_i (W): positive while the loaded particles move with the load.
    pub power: f64,
    /// (1/|B|)·Σ_B |u_i| (m): how far the loaded particles have moved.
    pub mean_displacement: f64,
}

impl Observation {
    /// The observation over the force-loaded particles `applied` at `ramp` × their load:
    /// positions `x` (reference `x0`), velocities `v`, internal forces `f`; with the body's
    /// damaged share `damage`.
    pub fn of_loads<const D: usize>(
        applied: &[AppliedForce],
        ramp: f64,
        (x, x0): (&[SVector<f64, D>], &[SVector<f64, D>]),
        v: &[SVector<f64, D>],
        f: &[SVector<f64, D>],
        damage: f64,
    ) -> Self {
        let (mut speed, mut ratio, mut power, mut moved) = (0.0, 0.0, 0.0, 0.0);
        for a in applied {
            let (i, c) = (a.particle as usize, a.component as usize);
            let b = a.amplitude * ramp;
            speed += v[i].norm();
            moved += (x[i] - x0[i]).norm();
            power += v[i][c] * b;
            let mut out = f[i];
            out[c] += b;
            ratio += out.norm() / b.abs().max(f64::MIN_POSITIVE);
        }
        let n = applied.len().max(1) as f64;
        Observation {
            mean_speed: speed / n,
            out_of_balance: ratio / n,
            damage,
            power,
            mean_displacement: moved / n,
        }
    }
}

/// The share of the body's smallest dimension beyond which loaded particles that have moved
/// that far on average have failed, under any criterion: no specimen of concrete carries a
/// load at such a deflection (a tenth of the depth is some 50 times a beam's deflection at
/// its peak), and a run that goes on only follows the broken pieces.
pub const RUNAWAY_SHARE: f64 = 0.1;

/// The verdict on a load.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    Holds,
    Fails,
}

/// A verdict, when it was reached and why.
#[derive(Clone, Debug, Serialize)]
pub struct Decision {
    pub verdict: Verdict,
    pub step: usize,
    pub reason: String,
}

/// The criterion's tolerances, resolved for a run.
#[derive(Clone, Copy, Debug)]
pub struct Tolerances {
    pub criterion: Criterion,
    /// τ_u (m/s).
    pub speed: f64,
    /// β.
    pub out_of_balance: f64,
    /// τ_D.
    pub damage: f64,
    /// S* (steps).
    pub stable_steps: usize,
    /// F* (steps).
    pub failing_steps: usize,
    pub check_every: usize,
    /// The mean displacement of the loaded particles that fails the load (m).
    pub runaway: f64,
}

impl Tolerances {
    /// From `[failure]`, with S* and F* defaulting to twice the ramp's `ramp_steps`, for a
    /// body whose smallest dimension is `body_size`.
    pub fn of(spec: &FailureSpec, ramp_steps: usize, body_size: f64) -> Self {
        Tolerances {
            runaway: RUNAWAY_SHARE * body_size,
            criterion: spec.criterion,
            speed: spec.velocity_tolerance.unwrap_or(f64::INFINITY),
            out_of_balance: spec.force_tolerance,
            damage: spec.damage_tolerance,
            stable_steps: spec.stable_steps.unwrap_or(2 * ramp_steps.max(1)),
            failing_steps: spec.failing_steps.unwrap_or(2 * ramp_steps.max(1)),
            check_every: spec.check_every,
        }
    }
}

/// The criterion's state through a run.
#[derive(Clone, Debug)]
pub struct FailureWatch {
    pub tolerances: Tolerances,
    /// Steps over which damage has grown less than τ_D per check (S).
    stable: usize,
    /// Steps the loaded particles have moved with the load since damage was stable (F).
    failing: usize,
    last: Option<(usize, f64)>,
}

impl FailureWatch {
    pub fn new(tolerances: Tolerances) -> Self {
        FailureWatch {
            tolerances,
            stable: 0,
            failing: 0,
            last: None,
        }
    }

    /// Whether `step` is a check.
    pub fn due(&self, step: usize) -> bool {
        step.is_multiple_of(self.tolerances.check_every)
    }

    /// A check at `step`; `loaded`: the ramp has ended, so a verdict may be given.
    pub fn observe(&mut self, step: usize, loaded: bool, o: &Observation) -> Option<Decision> {
        let t = self.tolerances;
        let (elapsed, growth) = match self.last {
            Some((s, d)) => (step - s, o.damage - d),
            None => (step, o.damage),
        };
        self.last = Some((step, o.damage));
        let decide = |verdict, reason: String| {
            Some(Decision {
                verdict,
                step,
                reason,
            })
        };
        if o.mean_displacement > t.runaway {
            return decide(
                Verdict::Fails,
                format!("the loaded particles moved {:.3e} m on average, beyond {RUNAWAY_SHARE} of the body's smallest dimension ({:.3e} m)", o.mean_displacement, t.runaway),
            );
        }
        match t.criterion {
            Criterion::VelocityDecay if loaded && o.mean_speed < t.speed => decide(
                Verdict::Holds,
                format!(
                    "mean speed of the loaded particles {:.3e} m/s < {:.3e} m/s",
                    o.mean_speed, t.speed
                ),
            ),
            Criterion::ForceDecay if loaded && o.out_of_balance < t.out_of_balance => decide(
                Verdict::Holds,
                format!(
                    "mean out-of-balance ratio {:.3e} < {:.3e}",
                    o.out_of_balance, t.out_of_balance
                ),
            ),
            Criterion::BondDamage => {
                self.stable = if growth < t.damage {
                    self.stable + elapsed
                } else {
                    0
                };
                if self.stable < t.stable_steps || !loaded {
                    return None;
                }
                if o.power < 0.0 {
                    self.failing = 0;
                    if o.mean_speed < t.speed {
                        return decide(
                            Verdict::Holds,
                            format!("damage stable for {} steps; the loaded particles move against the load at a mean {:.3e} m/s < {:.3e} m/s", self.stable, o.mean_speed, t.speed),
                        );
                    }
                } else {
                    self.failing += elapsed;
                }
                (self.failing >= t.failing_steps).then(|| Decision {
                    verdict: Verdict::Fails,
                    step,
                    reason: format!(
                        "damage stable, but the loaded particles moved with the load for {} steps",
                        self.failing
                    ),
                })
            }
            _ => None,
        }
    }

    /// The verdict at the end of the run when none was reached: the load was not held.
    pub fn at_end(&self, step: usize) -> Decision {
        Decision {
            verdict: Verdict::Fails,
            step,
            reason: format!(
                "not judged held by the end of the run ({}: {})",
                self.tolerances.criterion.name(),
                "a load that does not settle within t_end has failed"
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn watch(criterion: Criterion) -> FailureWatch {
        FailureWatch::new(Tolerances {
            criterion,
            speed: 0.5,
            out_of_balance: 0.5,
            damage: 1e-5,
            stable_steps: 100,
            failing_steps: 100,
            check_every: 50,
            runaway: 0.01,
        })
    }

    fn seen(speed: f64, ratio: f64, damage: f64, power: f64) -> Observation {
        Observation {
            mean_speed: speed,
            out_of_balance: ratio,
            damage,
            power,
            mean_displacement: 0.0,
        }
    }

    #[test]
    fn velocity_and_force_decay_judge_only_the_full_load() {
        let mut w = watch(Criterion::VelocityDecay);
        assert!(w.observe(50, false, &seen(0.1, 1.0, 0.0, 1.0)).is_none());
        assert!(w.observe(100, true, &seen(0.6, 1.0, 0.0, 1.0)).is_none());
        let d = w.observe(150, true, &seen(0.4, 1.0, 0.0, 1.0)).unwrap();
        assert_eq!((d.verdict, d.step), (Verdict::Holds, 150));
        let mut w = watch(Criterion::ForceDecay);
        assert!(w.observe(50, false, &seen(1.0, 0.1, 0.0, 1.0)).is_none());
        assert!(w.observe(100, true, &seen(0.0, 0.6, 0.0, 1.0)).is_none());
        assert_eq!(
            w.observe(150, true, &seen(0.0, 0.4, 0.0, 1.0))
                .unwrap()
                .verdict,
            Verdict::Holds
        );
    }

    #[test]
    fn bond_damage_waits_for_stable_damage_then_reads_the_motion() {
        let mut w = watch(Criterion::BondDamage);
        // damage still growing: no verdict, however slow
        assert!(w.observe(50, true, &seen(0.0, 0.0, 1e-3, -1.0)).is_none());
        assert!(w.observe(100, true, &seen(0.0, 0.0, 2e-3, -1.0)).is_none());
        // stable for 50, then 100 steps: at S* = 100 a slow recoil holds
        assert!(w.observe(150, true, &seen(0.0, 0.0, 2e-3, -1.0)).is_none());
        let d = w.observe(200, true, &seen(0.1, 0.0, 2e-3, -1.0)).unwrap();
        assert_eq!((d.verdict, d.step), (Verdict::Holds, 200));
        // stable damage, moving with the load for F* = 100 steps: failed
        let mut w = watch(Criterion::BondDamage);
        for s in [50, 100] {
            assert!(
                w.observe(s, true, &seen(1.0, 0.0, 0.0, 1.0)).is_none(),
                "{s}"
            );
        }
        assert_eq!(
            w.observe(150, true, &seen(1.0, 0.0, 0.0, 1.0))
                .unwrap()
                .verdict,
            Verdict::Fails
        );
        // a recoil resets F: moving with the load again must last F* anew
        let mut w = watch(Criterion::BondDamage);
        for (s, p) in [(50, 1.0), (100, 1.0), (150, -1.0), (200, 1.0)] {
            assert!(w.observe(s, true, &seen(1.0, 0.0, 0.0, p)).is_none(), "{s}");
        }
        assert_eq!(
            w.observe(250, true, &seen(1.0, 0.0, 0.0, 1.0))
                .unwrap()
                .verdict,
            Verdict::Fails
        );
    }

    #[test]
    fn an_unsettled_load_fails_at_the_end() {
        let w = watch(Criterion::VelocityDecay);
        assert_eq!(w.at_end(5000).verdict, Verdict::Fails);
    }

    #[test]
    fn a_runaway_fails_under_every_criterion_even_during_the_ramp() {
        for c in [
            Criterion::VelocityDecay,
            Criterion::ForceDecay,
            Criterion::BondDamage,
        ] {
            let mut w = watch(c);
            let mut o = seen(0.0, 0.0, 0.0, -1.0);
            o.mean_displacement = 0.011;
            assert_eq!(w.observe(50, false, &o).unwrap().verdict, Verdict::Fails);
        }
    }
}
