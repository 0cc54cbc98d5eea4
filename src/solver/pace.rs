//! Adaptive loading pace (docs/model.md §10, "Adaptive pace"): the ramp is read at a load
//! time τ that runs faster than time on the post-peak tail, and at the ramp's own pace
//! (dτ/dt = 1) up to and through the peak.
//!
//! The pace factor f = dτ/dt aims at `max` once a particle has failed and the probe force has
//! fallen below [`PACE_TAIL`] × the peak, unless the kinetic energy exceeds [`PACE_KINETIC`] ×
//! the largest elastic energy so far; elsewhere it aims at 1. f moves towards its aim by at most
//! (max − 1)·Δt/T_1 a step, so that a change of pace takes one fundamental period and does
//! not jolt the specimen.

use super::Record;

/// The share of the peak force below which the post-peak tail runs fast: half the peak, where
/// the crack has formed and softening is well under way.
pub const PACE_TAIL: f64 = 0.5;

/// The kinetic-to-elastic energy ratio above which the tail's pace falls back to the ramp's.
/// The tail rings with the elastic energy the crack released (its kinetic energy reached
/// 1–4% of the largest elastic energy in the FCC tension prism at the ramp's own pace), so the
/// limit sits above that ringing and below a tail the pace itself shakes:
/// benchmarks/RESULTS.md, "Adaptive pace".
pub const PACE_KINETIC: f64 = 0.05;

/// The controller's settings.
#[derive(Clone, Copy, Debug)]
pub struct PaceSettings {
    /// The largest pace factor (`loading.max_pace`).
    pub max: f64,
    /// T_1 (s).
    pub period: f64,
}

/// The state of the controller over a run.
#[derive(Clone, Debug)]
pub struct Pacer {
    settings: PaceSettings,
    /// +1 or −1: the probe's loading direction.
    sign: f64,
    peak: f64,
    largest_elastic: f64,
    aim: f64,
    factor: f64,
}

/// What the controller reads of the run at a record.
#[derive(Clone, Copy, Debug)]
pub struct Observed<'a> {
    pub record: &'a Record,
    /// Whether some particle has failed.
    pub failed: bool,
}

impl Pacer {
    /// A controller for a probe loaded in the direction of `sign` (±1).
    pub fn new(settings: PaceSettings, sign: f64) -> Self {
        Pacer {
            settings,
            sign,
            peak: 0.0,
            largest_elastic: 0.0,
            aim: 1.0,
            factor: 1.0,
        }
    }

    /// Set the aim from a record.
    pub fn observe(&mut self, o: Observed<'_>) {
        let f = self.sign * o.record.force_n;
        self.peak = self.peak.max(f);
        self.largest_elastic = self.largest_elastic.max(o.record.internal_j);
        let calm = o.record.kinetic_j <= PACE_KINETIC * self.largest_elastic;
        let tail = o.failed && self.peak > 0.0 && f < PACE_TAIL * self.peak;
        self.aim = if calm && tail { self.settings.max } else { 1.0 };
    }

    /// The pace factor of the next step of length `dt`, moved towards the aim.
    pub fn next(&mut self, dt: f64) -> f64 {
        let s = &self.settings;
        let most = (s.max - 1.0) * dt / s.period;
        self.factor += (self.aim - self.factor).clamp(-most, most);
        self.factor
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(force: f64, kinetic: f64, internal: f64) -> Record {
        Record {
            force_n: force,
            kinetic_j: kinetic,
            internal_j: internal,
            ..Default::default()
        }
    }

    fn settings() -> PaceSettings {
        PaceSettings {
            max: 5.0,
            period: 1.0,
        }
    }

    fn see(p: &mut Pacer, force: f64, kinetic: f64, failed: bool) {
        p.observe(Observed {
            record: &record(force, kinetic, 1.0),
            failed,
        })
    }

    /// The ramp's pace up to and through the peak, fast on the tail once a particle has
    /// failed and the force is below half the peak; each change takes one period:
    /// (max − 1)·Δt/T_1 a step.
    #[test]
    fn pace_is_the_ramps_until_the_tail_and_changes_over_one_period() {
        let mut p = Pacer::new(settings(), 1.0);
        see(&mut p, 10.0, 0.0, false);
        see(&mut p, 20.0, 0.0, false);
        assert_eq!(p.next(0.1), 1.0);
        // past the peak but above half of it, or below it without a failed particle: slow
        see(&mut p, 11.0, 0.0, true);
        assert_eq!(p.next(0.1), 1.0);
        see(&mut p, 9.0, 0.0, false);
        assert_eq!(p.next(0.1), 1.0);
        // on the tail: 0.1 T_1 a step, 0.4 a step, 1 → 5 in 10 steps
        see(&mut p, 9.0, 0.0, true);
        let factors: Vec<f64> = (0..12).map(|_| p.next(0.1)).collect();
        assert!((factors[0] - 1.4).abs() < 1e-12);
        assert!((factors[9] - 5.0).abs() < 1e-12 && factors[11] == 5.0);
        // ringing above the limit: back to 1 over a period
        see(&mut p, 9.0, 0.06, true);
        let last = (0..10).map(|_| p.next(0.1)).last().unwrap();
        assert!((last - 1.0).abs() < 1e-12);
    }

    /// A compressive probe (negative forces) finds its peak and tail the same way.
    #[test]
    fn the_sign_is_the_probes() {
        let mut p = Pacer::new(settings(), -1.0);
        see(&mut p, -10.0, 0.0, false);
        see(&mut p, -4.0, 0.0, true);
        assert!(p.next(0.1) > 1.0);
        let mut q = Pacer::new(settings(), 1.0);
        see(&mut q, -10.0, 0.0, false);
        see(&mut q, -4.0, 0.0, true);
        assert_eq!(q.next(0.1), 1.0);
    }
}
