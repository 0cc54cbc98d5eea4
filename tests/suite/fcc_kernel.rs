//! The FCC second-neighbour modulus in the elastic kernels (docs/model.md §3 with its
//! erratum: F_s,ij = (a_i + c_i·[j ∈ N_II])·S_ij + b_i·θ_i).
//!
//! The linear patch test on a small FCC block built here by hand (integer points (i, j, k)
//! with i+j+k even, at (i, j, k)·L0/√2; 12 nearest-neighbour slots, then 6 second-neighbour
//! slots; the reverse of slot k is k ^ 1; bulk volume and moduli everywhere): under a
//! homogeneous strain with shear, (b) every particle whose neighbours all have their 18 bonds
//! feels no force to round-off, and its stress (3.18) is D·ε with the isotropic 3D D to
//! 1e-10; (c) the same with c = 0 misses D·ε by far, so the kernels use c. (The AVX path
//! against the scalar one, bit for bit, is `solver::kernel`'s test
//! `fcc_block_with_second_neighbours_matches_scalar_reference_bitwise`.)

use nalgebra::{Matrix3, Vector3};
use sppm::discretise::{Particles, NONE};
use sppm::model::dimension::{Dim, Dimension};
use sppm::model::micro_modulus::{fcc, fcc_volume};
use sppm::model::stress::StressSum;
use sppm::run::particle_stress;
use sppm::scene::Plane;
use sppm::solver::linear::LinearOperator;
use sppm::solver::mechanics::Mechanics;

const L0: f64 = 0.01;
const E: f64 = 30e9;
const NU: f64 = 0.2;
/// Half-cells per side: points 0..=SIDE in each direction.
const SIDE: i64 = 12;

/// The FCC offsets in half-cells: nearest (±1, ±1, 0) and permutations, then (±2, 0, 0) and
/// permutations; opposites adjacent.
fn offsets() -> Vec<[i64; 3]> {
    let mut near = Vec::new();
    for (p, q) in [(0, 1), (0, 2), (1, 2)] {
        for (s, t) in [(1, 1), (1, -1)] {
            for sign in [1, -1] {
                let mut o = [0i64; 3];
                o[p] = sign * s;
                o[q] = sign * t;
                near.push(o);
            }
        }
    }
    let mut second = Vec::new();
    for p in 0..3 {
        for sign in [2, -2] {
            let mut o = [0i64; 3];
            o[p] = sign;
            second.push(o);
        }
    }
    near.extend(second);
    near
}

/// The block with bulk moduli and volume everywhere; `with_c = false` sets c = 0.
fn block(with_c: bool) -> Particles<3, 18> {
    let offs = offsets();
    assert_eq!(offs.len(), 18);
    for k in 0..18 {
        let (o, r) = (offs[k], offs[k ^ 1]);
        assert_eq!([o[0] + r[0], o[1] + r[1], o[2] + r[2]], [0, 0, 0]);
    }
    let h = L0 / 2f64.sqrt();
    let mut cells = Vec::new();
    for i in 0..=SIDE {
        for j in 0..=SIDE {
            for k in 0..=SIDE {
                if (i + j + k) % 2 == 0 {
                    cells.push([i, j, k]);
                }
            }
        }
    }
    let at: std::collections::HashMap<[i64; 3], usize> =
        cells.iter().enumerate().map(|(p, &c)| (c, p)).collect();
    let index = |c: [i64; 3]| at.get(&c).copied();
    let n = cells.len();
    let mut x0 = Vec::with_capacity(n);
    let mut neighbours = vec![[NONE; 18]; n];
    let mut reverse = vec![[0u8; 18]; n];
    let mut l0 = vec![[0.0; 18]; n];
    for (p, c) in cells.iter().enumerate() {
        x0.push(Vector3::new(c[0] as f64, c[1] as f64, c[2] as f64) * h);
        for (k, o) in offs.iter().enumerate() {
            if let Some(q) = index([c[0] + o[0], c[1] + o[1], c[2] + o[2]]) {
                neighbours[p][k] = q as u32;
                reverse[p][k] = (k ^ 1) as u8;
                l0[p][k] = if k < 12 { L0 } else { L0 * 2f64.sqrt() };
            }
        }
    }
    let mut p = Particles::new(x0, vec![fcc_volume(L0); n], neighbours, reverse, l0, L0);
    p.check_topology().unwrap();
    let m = fcc(E, NU, L0);
    p.a = vec![m.a; n];
    p.b = vec![m.b; n];
    p.c = vec![if with_c { m.c } else { 0.0 }; n];
    p
}

/// A general homogeneous strain (normal and shear components).
fn strain() -> Matrix3<f64> {
    Matrix3::new(
        1.0e-4, 0.3e-4, -0.2e-4, 0.3e-4, -0.5e-4, 0.4e-4, -0.2e-4, 0.4e-4, 0.7e-4,
    )
}

/// Particles whose every neighbour has all 18 bonds (so θ_j = θ_i for every neighbour j).
fn deep_bulk(p: &Particles<3, 18>) -> Vec<usize> {
    let full = |i: usize| p.bond_count(i) == 18;
    (0..p.len())
        .filter(|&i| full(i) && p.neighbours[i].iter().all(|&j| full(j as usize)))
        .collect()
}

/// For each deep-bulk particle: |f_i| over its round-off bound, and the relative error of
/// its stress (3.18) against D·ε, from the linearised operator (and the stress from the
/// kernels' force states at x0 + εx0, whose finite-strain error is O(|ε|)).
fn patch(with_c: bool) -> (f64, f64, f64) {
    let p = block(with_c);
    let mech = Mechanics::new(&p, &vec![2400.0; p.len()]);
    assert_eq!(mech.second.is_some(), with_c);
    let eps = strain();
    let u: Vec<Vector3<f64>> = p.x0.iter().map(|x| eps * x).collect();
    let mut op = LinearOperator::new(&mech, &p.x0);
    let mut f = vec![Vector3::zeros(); p.len()];
    op.internal_forces(&u, &mut f);
    let d = <Dim<3> as Dimension<3>>::elasticity(E, NU, Plane::Stress);
    let want = <Dim<3> as Dimension<3>>::stress_of_strain(&d, &eps);
    let m = fcc(E, NU, L0);
    // Round-off bound of a particle's force: 18 bond forces, each at most
    // (|a| + |c| + 18·|b|)·max|S| with max|S| ≤ ‖ε‖, each formed with about 16 roundings
    // of relative size ε_mach, and the stretches n·(u_j − u_i)/L0 from displacements up to
    // ‖ε‖·max|x| (their difference loses max|x|/L0 in relative accuracy).
    let norm = eps.norm();
    let reach = p.x0.iter().map(|x| x.norm()).fold(0.0, f64::max) / L0;
    let bound = 18.0
        * 16.0
        * f64::EPSILON
        * (m.a.abs() + m.c.abs() + 18.0 * m.b.abs())
        * norm
        * (1.0 + reach);
    let x: Vec<Vector3<f64>> = p.x0.iter().zip(&u).map(|(x, u)| x + u).collect();
    let nonlinear = particle_stress(&mech, &p.volume, &x);
    let bulk = deep_bulk(&p);
    assert!(bulk.len() >= 20, "{} deep-bulk particles", bulk.len());
    let (mut force, mut stress, mut finite) = (0.0f64, 0.0f64, 0.0f64);
    for &i in &bulk {
        force = force.max(f[i].norm() / bound);
        let mut acc = StressSum::<3>::default();
        for (n, l0, fs) in op.force_states(&u, i) {
            acc.add(&n, l0, fs);
        }
        let sigma = acc.finish(p.volume[i]);
        stress = stress.max((sigma - want).norm() / want.norm());
        finite = finite.max((nonlinear[i] - want).norm() / want.norm());
    }
    (force, stress, finite)
}

/// (b) The linear patch test with the second-neighbour modulus.
#[test]
fn fcc_patch_test_reproduces_isotropic_stress() {
    let (force, stress, finite) = patch(true);
    eprintln!("with c: |f|/bound {force:.3e}, stress error {stress:.3e}, finite {finite:.3e}");
    assert!(force <= 1.0, "force {force} × its round-off bound");
    assert!(stress <= 1e-10, "stress off D·ε by {stress}");
    // the kernels' own force states at finite strain: off by O(‖ε‖) ~ 1e-4
    assert!(finite <= 1e-3, "finite-strain stress off D·ε by {finite}");
}

/// (c) Without c the same block is in equilibrium (symmetry) but its stress is not D·ε:
/// the test above sees c.
#[test]
fn fcc_patch_test_fails_without_c() {
    let (force, stress, _) = patch(false);
    eprintln!("without c: |f|/bound {force:.3e}, stress error {stress:.3e}");
    assert!(force <= 1.0, "force {force} × its round-off bound");
    assert!(stress > 1e-2, "stress off D·ε by only {stress} without c");
}
