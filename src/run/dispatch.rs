//! The one place a scene becomes a typed run: its [`Discretisation`] picks the generator,
//! and with it the dimension `D` and the bond slots `K` that every later stage is compiled
//! for. Adding a discretisation is a generator module (`run::generate`), an arm of
//! [`Discretisation`] and one line here.

use super::generate::{CubicGrid, Fcc, Generator, Hexagonal, RandomPlane, RandomSolid, SquareGrid};
use super::model::memory_in_slots;
use super::recover::Recover;
use crate::model::dimension::{Dim, Dimension};
use crate::scene::{Discretisation, Scene};

/// Work to do on a scene once its generator (and so `D` and `K`) is known.
pub trait TypedRun {
    type Output;

    /// Do the work with the scene's generator.
    fn run<G, const D: usize, const K: usize>(self, scene: &Scene, generator: G) -> Self::Output
    where
        G: Generator<D, K>,
        Dim<D>: Dimension<D> + Recover<D>;
}

/// Run `work` with the generator of the scene's discretisation.
pub fn dispatch<T: TypedRun>(scene: &Scene, work: T) -> T::Output {
    match scene.discretisation() {
        Discretisation::Hexagonal => work.run(scene, Hexagonal),
        Discretisation::RandomPlane => work.run(scene, RandomPlane::default()),
        Discretisation::Fcc => work.run(scene, Fcc),
        Discretisation::RandomSolid => work.run(scene, RandomSolid),
        Discretisation::CubicGrid => work.run(scene, CubicGrid),
        Discretisation::SquareGrid => work.run(scene, SquareGrid),
    }
}

/// The bond slots of a scene's discretisation.
pub fn slots(scene: &Scene) -> usize {
    struct Slots;
    impl TypedRun for Slots {
        type Output = usize;
        fn run<G, const D: usize, const K: usize>(self, _: &Scene, _: G) -> usize
        where
            G: Generator<D, K>,
            Dim<D>: Dimension<D> + Recover<D>,
        {
            K
        }
    }
    dispatch(scene, Slots)
}

/// Estimated bytes a run of the scene allocates (2D or 3D; with `[concrete]`, the damage
/// kernel's too), known before anything is allocated.
pub fn estimated_memory(scene: &Scene) -> f64 {
    memory_in_slots(scene, slots(scene))
}
