//! A second damage law, written outside the crate against the `DamageLaw` trait alone, runs
//! through the unchanged concrete kernel (laws are addable without touching the
//! kernel or the pipeline).
//!
//! The law is the simplest bond-based one of Hobbs's (2021) family: brittle failure at a critical
//! stretch s_c. A particle remembers whether any of its bonds has stretched beyond s_c; a bond
//! whose particle has failed carries nothing (d = 0). On a block pulled apart uniformly the
//! force must then follow the elastic line up to the stretch s_c and drop to zero after it.

use crate::common;

use sppm::model::damage_law::{DamageLaw, Kernel, ParticleBonds, ParticleDamage};
use sppm::run::{build_simulation, prepare};
use sppm::solver::inelastic::DamageKernel;

/// Brittle failure of a particle once any of its bonds stretches beyond `critical`.
struct Brittle {
    critical: f64,
}

impl<const K: usize> DamageLaw<2, K> for Brittle {
    type State = bool;

    fn kernel(&self) -> Kernel {
        Kernel::Tension
    }

    fn bond_factor<const FULL: bool>(&self, i: &bool, j: &bool, _se: f64) -> (f64, f64) {
        if *i || *j {
            (0.0, 0.0)
        } else {
            (1.0, 1.0)
        }
    }

    fn update<const FULL: bool>(
        &self,
        b: &ParticleBonds<'_, 2, K>,
        failed: &mut bool,
        _: &mut [f64; K],
    ) {
        *failed |= (0..K).any(|k| b.used[k] && b.total[k] > self.critical);
    }

    fn view(&self, failed: &bool) -> ParticleDamage {
        ParticleDamage {
            wt: if *failed { 1.0 } else { 0.0 },
            ..Default::default()
        }
    }
}

#[test]
fn a_brittle_bond_law_runs_through_the_concrete_kernel() {
    // an elastic tension block (no [concrete]); the law is put in by hand
    let scene = common::scene(&common::plate_toml(
        0.1, 0.1, 0.01, 0.0, "stress", false, 0.2,
    ));
    let mut p = prepare(&scene, sppm::run::Hexagonal).unwrap();
    let mut sim = build_simulation(&mut p);
    assert!(sim.inelastic.is_none());
    // the plate is pulled to a strain of 1e-4: fail bonds at 0.5e-4
    let critical = 0.5e-4;
    let law: DamageKernel<2, 6, Brittle> =
        DamageKernel::new(Brittle { critical }, &p.model.particles);
    sim.inelastic = Some(Box::new(law));
    let probe = p.probe.as_ref().unwrap().1.clone();
    let mut peak: f64 = 0.0;
    let mut last = 0.0;
    for n in 0..p.steps {
        if let Some(r) = sim.advance(Some(&probe)) {
            peak = peak.max(r.force_n.abs());
            last = r.force_n;
        }
        sim.check_stability(None, false).unwrap();
        let _ = n;
    }
    let failed = sim
        .inelastic
        .as_ref()
        .unwrap()
        .damage()
        .iter()
        .filter(|d| d.wt == 1.0)
        .count();
    // the plate carried load before it broke, and after every particle of a row failed it
    // carries nothing: a row of failed particles separates top from bottom
    assert!(peak > 0.0);
    assert!(failed > 0, "no particle failed");
    assert!(sim.has_failed_particle());
    assert!(
        last.abs() < 1e-6 * peak,
        "force {last} N after failure, peak {peak} N"
    );
}
