//! The stress a run reports of each particle at its end, in its dimension: 2D recovers
//! D_i·ε_i (run::stress_recovery), 3D takes D·ε_i of each particle's least-squares strain.

use super::arrays::voigt6;
use super::prepare::Prepared;
use super::stress_recovery;
use crate::model::dimension::Dim;
use crate::solver::inelastic::ParticleDamage;
use crate::solver::Simulation;

/// What a run shows of each particle at its end: the stress (6 Voigt components) and, with
/// damage, each particle's damage.
pub type Recovered = (Vec<[f64; 6]>, Option<Vec<ParticleDamage>>);

/// The end-of-run stress recovery of a dimension.
pub trait Recover<const D: usize> {
    fn recover<const K: usize>(p: &Prepared<K, D>, sim: &Simulation<D, K>) -> Recovered;
}

impl Recover<2> for Dim<2> {
    fn recover<const K: usize>(p: &Prepared<K, 2>, sim: &Simulation<2, K>) -> Recovered {
        stress_2d(p, sim)
    }
}

impl Recover<3> for Dim<3> {
    fn recover<const K: usize>(p: &Prepared<K, 3>, sim: &Simulation<3, K>) -> Recovered {
        stress_3d(p, sim)
    }
}

/// The recovered stress D_i·ε_i of a 2D run (run::stress_recovery), not (3.18).
fn stress_2d<const K: usize>(p: &Prepared<K>, sim: &Simulation<2, K>) -> Recovered {
    let x = &sim.state.x;
    let (stress, damage) = match &sim.inelastic {
        Some(model) => {
            let damage = model.damage();
            let intact = |j: usize| {
                let d = &damage[j];
                d.wt == 0.0 && d.wc == 0.0 && !d.yielded
            };
            let strain = stress_recovery::recovered_strain(
                &p.model,
                x,
                model.particle_strain(&sim.mech, x),
                &intact,
            );
            (
                stress_recovery::recovered_stress(&p.model, &strain),
                Some(damage),
            )
        }
        None => (stress_recovery::elastic_stress(&p.model, x), None),
    };
    (stress.iter().map(voigt6).collect(), damage)
}

/// The stress of a 3D run: D·ε_i with ε_i each particle's least-squares strain of its own
/// (damaged elastic) bond stretches (docs/model.md §7, §13), as in the bulk of 2D; with damage,
/// each particle's damage.
fn stress_3d<const K: usize>(p: &Prepared<K, 3>, sim: &Simulation<3, K>) -> Recovered {
    let x = &sim.state.x;
    let (strain, damage) = match &sim.inelastic {
        Some(model) => (model.particle_strain(&sim.mech, x), Some(model.damage())),
        None => (stress_recovery::elastic_strain(&p.model, x), None),
    };
    (
        stress_recovery::stress_3d(&p.model, &strain)
            .iter()
            .map(voigt6)
            .collect(),
        damage,
    )
}
