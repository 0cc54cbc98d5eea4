//! One force law: the SPLM bond force, energy and stress of random configurations,
//! computed through every caller's path, agree.
//!
//! Paths: the elastic step kernel (`kernel::particle_force` after `pass_dilatation`), the
//! concrete kernel with no damage (`inelastic::internal_forces`), the linearised operator
//! (`LinearOperator::internal_forces`), the energies (`Simulation::internal_energy_now`,
//! `inelastic::internal_energy`) and the stress recovery (`run::particle_stress`,
//! `inelastic::particle_stress`).
//!
//! Expected agreement: the elastic and the undamaged concrete kernel evaluate the same force
//! state with the additions grouped differently (½((a_i+a_j)S + bθ_i + bθ_j) against
//! ½(1·(a_i+a_j)S + 1·(bθ_i + bθ_j))), so they agree to a few ulps of the bond force, not bit
//! for bit; the stresses are the same sums and agree to round-off; the energy's gradient
//! is the force (U = ¼ΣΣ L0·S·F_s is a potential of F_b on a lattice of equal bonds); the
//! linearised operator agrees with the kernel to first order in the displacement.

use crate::common;

use nalgebra::Vector2;
use rand::rngs::ChaCha20Rng;
use rand::{Rng, SeedableRng};
use sppm::model::damage::ConcreteLaw;
use sppm::model::two_spring::TwoSpring;
use sppm::run::{build_simulation, particle_stress, prepare};
use sppm::solver::inelastic::{self, DamageKernel};
use sppm::solver::kernel::{particle_force, pass_dilatation};
use sppm::solver::linear::LinearOperator;

/// A concrete tension block (a few hundred particles with boundaries, rotated lattice) and a
/// random displacement of relative size `strain` per bond.
fn configuration(seed: u64, strain: f64) -> (sppm::run::Prepared, Vec<Vector2<f64>>) {
    let scene = common::tension_block(0.1, 0.01, &["discretisation.rotation_deg=17"]);
    let p = prepare(&scene, sppm::run::Hexagonal).unwrap();
    let mut rng = ChaCha20Rng::seed_from_u64(seed);
    // uniform in [−1, 1)
    let mut draw = || (rng.next_u64() >> 11) as f64 / (1u64 << 52) as f64 - 1.0;
    let l0 = 0.01;
    let u: Vec<Vector2<f64>> = (0..p.model.particles.len())
        .map(|_| Vector2::new(draw(), draw()) * strain * l0)
        .collect();
    (p, u)
}

fn close(a: f64, b: f64, scale: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * scale
}

#[test]
fn kernel_concrete_kernel_and_linear_operator_give_the_same_forces() {
    for seed in 0..4 {
        let (p, u) = configuration(seed, 1e-4);
        let m = &p.model.mech;
        let x0 = &p.model.particles.x0;
        let x: Vec<_> = x0.iter().zip(&u).map(|(a, b)| a + b).collect();
        let n = x.len();
        // the elastic kernel
        let mut bt = vec![0.0; n];
        pass_dilatation(m, &x, &mut bt);
        let v = vec![Vector2::zeros(); n];
        let f_kernel: Vec<_> = (0..n)
            .map(|i| particle_force::<2, 6, false>(m, &x, &v, &bt, i).0)
            .collect();
        // the concrete kernel, undamaged
        let law = ConcreteLaw::from_scene(&p.model.scene).unwrap();
        let mut c: DamageKernel<2, 6> =
            DamageKernel::new(TwoSpring::new(law, None), &p.model.particles);
        let f_concrete = inelastic::internal_forces(m, &mut c, &x);
        let scale = f_kernel.iter().map(|f| f.norm()).fold(0.0, f64::max);
        for i in 0..n {
            for k in 0..2 {
                assert!(
                    close(f_kernel[i][k], f_concrete[i][k], scale, 1e-13),
                    "particle {i}: kernel {} concrete {}",
                    f_kernel[i][k],
                    f_concrete[i][k]
                );
            }
        }
        // the linear operator at a displacement 1e-3 × smaller (strains ~1e-7): first order
        // agreement
        let small: Vec<_> = u.iter().map(|d| d * 1e-3).collect();
        let xs: Vec<_> = x0.iter().zip(&small).map(|(a, b)| a + b).collect();
        pass_dilatation(m, &xs, &mut bt);
        let mut f_lin = vec![Vector2::zeros(); n];
        LinearOperator::new(m, x0).internal_forces(&small, &mut f_lin);
        let f_small: Vec<_> = (0..n)
            .map(|i| particle_force::<2, 6, false>(m, &xs, &v, &bt, i).0)
            .collect();
        let scale = f_lin.iter().map(|f| f.norm()).fold(0.0, f64::max);
        assert!(scale > 0.0);
        let worst = (0..n)
            .map(|i| (f_small[i] - f_lin[i]).norm() / scale)
            .fold(0.0, f64::max);
        println!(
            "seed {seed}: kernel against linear operator, worst {worst:.2e} of the largest force"
        );
        for i in 0..n {
            // second-order terms: ~ the strain, 1e-7 of the force (times the rotation of
            // the bonds, of the same order); the kernel's round-off in the stretch
            // L/L0 − 1: ε·|x|/L0 ≈ 1e-15 against strains of 1e-7, 1e-8 of it
            assert!(
                (f_small[i] - f_lin[i]).norm() <= 1e-6 * scale,
                "particle {i}: kernel {:?} linear {:?}",
                f_small[i],
                f_lin[i]
            );
        }
    }
}

#[test]
fn the_energy_is_the_potential_of_the_force() {
    let (mut p, u) = configuration(7, 1e-4);
    let x0 = p.model.particles.x0.clone();
    let mut sim = build_simulation(&mut p);
    let x: Vec<_> = x0.iter().zip(&u).map(|(a, b)| a + b).collect();
    let n = x.len();
    let energy = |sim: &mut sppm::solver::Simulation<2, 6>, x: &[Vector2<f64>]| {
        sim.state.x.copy_from_slice(x);
        sim.internal_energy_now()
    };
    // concrete (undamaged) and elastic energies agree
    let u_concrete = energy(&mut sim, &x);
    let inelastic = sim.inelastic.take();
    let u_elastic = energy(&mut sim, &x);
    assert!(
        close(u_concrete, u_elastic, u_elastic, 1e-12),
        "{u_concrete} vs {u_elastic}"
    );
    sim.inelastic = inelastic;
    // −∂U/∂x_i = f_i by central differences, for a few particles
    let m = &sim.mech.clone();
    let mut bt = vec![0.0; n];
    pass_dilatation(m, &x, &mut bt);
    let v = vec![Vector2::zeros(); n];
    let h = 1e-9;
    let mut checked = 0;
    for i in (0..n).step_by(n / 7) {
        let f = particle_force::<2, 6, false>(m, &x, &v, &bt, i).0;
        for k in 0..2 {
            let mut xp = x.clone();
            let mut xm = x.clone();
            xp[i][k] += h;
            xm[i][k] -= h;
            let du = (energy(&mut sim, &xp) - energy(&mut sim, &xm)) / (2.0 * h);
            assert!(
                (du + f[k]).abs() <= 1e-5 * f.norm().max(1e-3),
                "particle {i} component {k}: −dU/dx = {} against f = {}",
                -du,
                f[k]
            );
        }
        checked += 1;
    }
    assert!(checked >= 7);
}

#[test]
fn stress_recovery_is_the_same_through_both_paths() {
    let (p, u) = configuration(3, 1e-4);
    let m = &p.model.mech;
    let x0 = &p.model.particles.x0;
    let vol = &p.model.particles.volume;
    let x: Vec<_> = x0.iter().zip(&u).map(|(a, b)| a + b).collect();
    let elastic = particle_stress(m, vol, &x);
    let law = ConcreteLaw::from_scene(&p.model.scene).unwrap();
    let c: DamageKernel<2, 6> = DamageKernel::new(TwoSpring::new(law, None), &p.model.particles);
    let damaged = inelastic::particle_stress(m, &c, &x, vol);
    let scale = elastic.iter().map(|s| s.norm()).fold(0.0, f64::max);
    assert!(scale > 0.0);
    for i in 0..x.len() {
        assert!(
            (elastic[i] - damaged[i]).norm() <= 1e-13 * scale,
            "particle {i}: {:?} vs {:?}",
            elastic[i],
            damaged[i]
        );
    }
}
