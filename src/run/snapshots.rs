//! The time series of a run (`output.snapshots = N`): N frames spread evenly over the load
//! path, each a copy of the particles' displacement, stress and damage.
//!
//! Frame j of N (j = 1 … N − 1) is taken at the first state whose load fraction reaches
//! j/N: the first step of an explicit run whose load time reaches j/N of t_end, the first
//! converged increment of a relaxation or quasi-static run whose ramp time reaches j/N (the
//! increment's k/increments; the quasi-static solver's cut-back increments at their own
//! time). Frame N is the state the run ends in: at t_end, after the last increment, at the
//! stop after the peak or at a failure. A state that passes several fractions at once is
//! one frame, so a run with fewer increments than N, or one that stops early, has fewer
//! than N frames. Taking a frame recovers the stress as at the end of the run and copies the
//! arrays once: the cost is proportional to N, and a run without snapshots only tests an
//! `Option` per step.

use super::arrays::point3;
use super::prepare::Prepared;
use super::recover::Recovered;
use crate::solver::inelastic::ParticleDamage;
use crate::solver::{Probe, Simulation};

pub use super::model::FRAME_BYTES_PER_PARTICLE;

/// One frame of a run's time series.
#[derive(Clone, Debug)]
pub struct Snapshot {
    /// The fraction of the load path the frame is at (0 … 1): the load time over t_end
    /// (explicit), the ramp's time of the increment (relaxation, quasi-static).
    pub load_fraction: f64,
    /// The probe group's mean displacement along its loaded component (m; 0 without a
    /// probe group).
    pub probe_displacement_m: f64,
    /// Each particle's displacement (m; z is 0 in 2D).
    pub displacement: Vec<[f64; 3]>,
    /// Each particle's stress, Voigt [xx, yy, zz, yz, xz, xy] (Pa), as `Outcome::stress`.
    pub stress: Vec<[f64; 6]>,
    /// Each particle's tensile and compressive damage [w_t, w_c] (scenes with `[concrete]`).
    pub damage: Option<Vec<[f64; 2]>>,
}

impl Snapshot {
    /// Particles counted as cracked (w_t ≥ 0.99, as summary.json and the crack map count
    /// them); 0 without damage.
    pub fn cracked(&self) -> usize {
        self.damage.as_ref().map_or(0, |d| {
            d.iter()
                .filter(|w| w[0] >= crate::model::damage_law::CRACKED_WT)
                .count()
        })
    }
}

/// The two damages of each particle as a frame keeps them.
fn damages(d: &[ParticleDamage]) -> Vec<[f64; 2]> {
    d.iter().map(|p| [p.wt, p.wc]).collect()
}

/// Takes the frames of a run as it goes (see the module doc).
pub struct Recorder<'a, const K: usize, const D: usize> {
    frames: usize,
    /// The next frame's index j (frame j is due at load fraction j/frames).
    next: usize,
    /// The load fraction of the latest state observed.
    last: f64,
    taken: Vec<Snapshot>,
    p: &'a Prepared<K, D>,
    probe: &'a Probe,
    recover: &'a dyn Fn(&Prepared<K, D>, &Simulation<D, K>) -> Recovered,
}

impl<'a, const K: usize, const D: usize> Recorder<'a, K, D> {
    /// The recorder of a run, `None` when the scene asks for no snapshots.
    pub fn of(
        p: &'a Prepared<K, D>,
        probe: &'a Probe,
        recover: &'a dyn Fn(&Prepared<K, D>, &Simulation<D, K>) -> Recovered,
    ) -> Option<Self> {
        let frames = p.model.scene.output.snapshots?;
        Some(Recorder {
            frames,
            next: 1,
            last: 0.0,
            taken: Vec::with_capacity(frames),
            p,
            probe,
            recover,
        })
    }

    /// Is a frame due at load fraction `fraction`? (Frames 1 … N − 1; frame N is the end.)
    pub fn due(&self, fraction: f64) -> bool {
        self.next < self.frames && fraction >= self.next as f64 / self.frames as f64
    }

    /// Take a frame of `sim` if one is due at load fraction `fraction`.
    pub fn observe(&mut self, sim: &Simulation<D, K>, fraction: f64) {
        self.last = fraction;
        if !self.due(fraction) {
            return;
        }
        let (stress, damage) = (self.recover)(self.p, sim);
        self.take(sim, fraction, stress, damage.as_deref());
        while self.due(fraction) {
            self.next += 1;
        }
    }

    fn take(
        &mut self,
        sim: &Simulation<D, K>,
        fraction: f64,
        stress: Vec<[f64; 6]>,
        damage: Option<&[ParticleDamage]>,
    ) {
        let probe = self.probe;
        let probe_displacement_m = if probe.members.is_empty() {
            0.0
        } else {
            probe
                .members
                .iter()
                .map(|&i| {
                    sim.state.x[i as usize][probe.component] - sim.x0[i as usize][probe.component]
                })
                .sum::<f64>()
                / probe.members.len() as f64
        };
        self.taken.push(Snapshot {
            load_fraction: fraction.clamp(0.0, 1.0),
            probe_displacement_m,
            displacement: sim
                .state
                .x
                .iter()
                .zip(&sim.x0)
                .map(|(a, b)| point3(&(a - b)))
                .collect(),
            stress,
            damage: damage.map(damages),
        });
    }

    /// The frames with the last one, the state the run ends in at the latest load fraction
    /// observed (its stress and damage as the end of the run recovered them); it replaces a
    /// frame taken at that same fraction (a run that stopped there).
    pub fn finish(
        mut self,
        sim: &Simulation<D, K>,
        stress: &[[f64; 6]],
        damage: Option<&[ParticleDamage]>,
    ) -> Vec<Snapshot> {
        let fraction = self.last.clamp(0.0, 1.0);
        if self
            .taken
            .last()
            .is_some_and(|f| f.load_fraction >= fraction)
        {
            self.taken.pop();
        }
        self.take(sim, fraction, stress.to_vec(), damage);
        self.taken
    }
}
