//! Throughput of the bond-based kernel (`model::bond_based::kernel`) on a cube of N³ points
//! of a cubic grid with the horizon π·Δx (122 bonds a point inside), in bond-updates per
//! second: one bond-update is one point's computation of one of its bonds, as LAMMPS's
//! peri/pmb counts them (benchmarks/lammps_pmb.sh runs LAMMPS on the same grid). Each step
//! is the whole explicit step: the forces, the velocity and the position update. Set-up is
//! excluded: two runs of different lengths, the difference timed.
//!
//! cargo run --release --example bond_kernel -- [N, default 100] [threads, default 1]

use nalgebra::Vector3;
use sppm::model::bond_based::body::{BodySettings, BondBody};
use sppm::model::bond_based::family::CubicGrid;
use sppm::model::bond_based::micromodulus::{micromodulus, Body, Influence};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(100);
    let threads: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(1);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let (dx, e, rho) = (0.005, 37e9, 2346.0);
    let delta = std::f64::consts::PI * dx;
    let x0 = CubicGrid { n: [n, n, n], dx }.points();
    let settings = BodySettings {
        delta,
        dx,
        c: micromodulus(e, delta, Body::Solid, Influence::Constant),
        influence: Influence::Constant,
        surface_correction: false,
        critical_stretch_correction: false,
        law: None,
        compressive: None,
        contact: false,
    };
    let cell = dx * dx * dx;
    let built = Instant::now();
    let mut body = pool.install(|| {
        BondBody::new(x0.clone(), vec![cell; x0.len()], settings, None, &|_, _| {
            true
        })
    });
    let half_bonds = body.neighbour.len();
    eprintln!(
        "{} points, {:.2} bonds a point, built in {:.1} s",
        body.len(),
        half_bonds as f64 / body.len() as f64,
        built.elapsed().as_secs_f64()
    );
    let mass: Vec<f64> = body.volume.iter().map(|v| rho * v).collect();
    let dt = 1e-7;
    // a small random velocity, as LAMMPS's deck starts from
    let mut seed: u64 = 12345;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut v: Vec<Vector3<f64>> = (0..body.len())
        .map(|_| Vector3::new(rnd(), rnd(), rnd()) * 1e-3)
        .collect();
    let mut x = x0;
    let mut f = vec![Vector3::zeros(); body.len()];
    let mut run = |steps: usize| {
        let t = Instant::now();
        pool.install(|| {
            for _ in 0..steps {
                body.forces(&x, &mut f);
                for ((xi, vi), (fi, m)) in x.iter_mut().zip(v.iter_mut()).zip(f.iter().zip(&mass)) {
                    *vi += fi * (dt / m);
                    *xi += *vi * dt;
                }
            }
        });
        t.elapsed().as_secs_f64()
    };
    let (short, long) = (5, 25);
    let t1 = run(short);
    let t2 = run(long);
    let per_step = (t2 - t1) / (long - short) as f64;
    println!(
        "sppm bond-based: {} points, {:.2} bonds a point, {threads} thread(s): {:.3} s a step, {:.3e} point-steps/s, {:.3e} bond-updates/s ({:.3e} per thread)",
        body.len(),
        half_bonds as f64 / body.len() as f64,
        per_step,
        body.len() as f64 / per_step,
        half_bonds as f64 / per_step,
        half_bonds as f64 / per_step / threads as f64
    );
}
