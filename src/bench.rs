//! `sppm bench`: throughput of the elastic step kernel on a square block of hexagonal
//! lattice, in particle-steps per second (set-up excluded).

use crate::discretise::hex::HexLattice;
use crate::geometry::Shape2;
use crate::model::micro_modulus;
use crate::scene::Plane;
use crate::solver::kernel::{self, State};
use crate::solver::mechanics::Mechanics;
use nalgebra::Vector2;
use serde::Serialize;
use std::time::Instant;

/// One benchmark result (one JSON line).
#[derive(Clone, Debug, Serialize)]
pub struct BenchResult {
    pub particles: usize,
    pub steps: usize,
    pub threads: usize,
    pub model: String,
    pub particle_steps_per_s: f64,
    pub seconds: f64,
}

/// Time `steps` elastic steps (bond dampers on, as in the shipped scenes) of a square block
/// of about `particles` particles on `threads` threads.
pub fn bench_elastic(
    particles: usize,
    steps: usize,
    threads: usize,
) -> anyhow::Result<BenchResult> {
    let l0 = 1e-3;
    let side = (particles as f64 * 0.5 * 3f64.sqrt()).sqrt() * l0;
    let shape = Shape2::Rectangle {
        origin: Vector2::zeros(),
        width: side,
        height: side,
    };
    let lat = HexLattice {
        spacing: l0,
        rotation_deg: 0.0,
        offset: Vector2::zeros(),
        thickness: 0.1,
    };
    let p = lat.fill(&shape);
    let n = p.len();
    let mm = micro_modulus::hexagonal(30e9, 0.2, l0, 0.1, Plane::Stress);
    let mut mech = Mechanics::new(&p, vec![mm.a; n], vec![mm.b; n], &vec![2400.0; n]);
    let omega = crate::material::particle_frequency(30e9, 0.2, 2400.0, l0);
    for i in 0..n {
        mech.c_in[i] = 2.0 * mech.mass[i] * 0.2 * omega;
        mech.c_ex[i] = 2.0 * mech.mass[i] * 0.2 * 1e3;
    }
    let dt = 0.9 * crate::solver::time_step::stable_step(&mech, &p.x0).dt_stable;
    let mut st = State::at_rest(&p.x0);
    // a small homogeneous strain so that every bond works
    for (x, x0) in st.x.iter_mut().zip(&p.x0) {
        *x = x0 * (1.0 + 1e-4);
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let seconds = pool.install(|| {
        for _ in 0..2 {
            kernel::step::<2, 6, false, true>(&mech, &mut st, dt);
            std::mem::swap(&mut st.x, &mut st.x_next);
            std::mem::swap(&mut st.v, &mut st.v_next);
        }
        let t = Instant::now();
        for _ in 0..steps {
            kernel::step::<2, 6, false, true>(&mech, &mut st, dt);
            std::mem::swap(&mut st.x, &mut st.x_next);
            std::mem::swap(&mut st.v, &mut st.v_next);
        }
        t.elapsed().as_secs_f64()
    });
    Ok(BenchResult {
        particles: n,
        steps,
        threads,
        model: "elastic".into(),
        particle_steps_per_s: (n * steps) as f64 / seconds,
        seconds,
    })
}
