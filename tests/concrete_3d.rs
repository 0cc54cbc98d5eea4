//! The concrete kernel and the two-spring law run in 3D from the same source as in 2D
//! (issue 12, dimension as a type): on a small 3D body under a uniform uniaxial strain
//! ε_xx, Rankine initiation happens exactly where the 3D isotropic stress
//! σ_xx = E(1−ν)/((1+ν)(1−2ν))·ε_xx reaches f't, and the initiation strain recorded is ε_xx.
//!
//! The body is a 4×4×4 simple-cubic block with 18 slots per particle (6 nearest neighbours
//! and 12 face diagonals), built here: the test needs only a body whose bonds span 3D.

use nalgebra::Vector3;
use sppm::discretise::{Particles, NONE};
use sppm::model::damage::ConcreteLaw;
use sppm::model::two_spring::TwoSpring;
use sppm::scene::{CrackOpening, Initiation, Plane};
use sppm::solver::concrete::{self, Concrete};
use sppm::solver::mechanics::Mechanics;

const N: i64 = 4;
const L0: f64 = 0.01;

fn directions() -> Vec<(i64, i64, i64)> {
    let mut d = Vec::new();
    for x in -1i64..=1 {
        for y in -1i64..=1 {
            for z in -1i64..=1 {
                let m = x.abs() + y.abs() + z.abs();
                if m == 1 || m == 2 {
                    d.push((x, y, z));
                }
            }
        }
    }
    d
}

fn block() -> Particles<3, 18> {
    let dirs = directions();
    assert_eq!(dirs.len(), 18);
    let index = |x: i64, y: i64, z: i64| (x * N * N + y * N + z) as usize;
    let inside = |c: i64| (0..N).contains(&c);
    let n = (N * N * N) as usize;
    let mut x0 = vec![Vector3::zeros(); n];
    let mut neighbours = vec![[NONE; 18]; n];
    let mut reverse = vec![[0u8; 18]; n];
    let mut l0 = vec![[0.0; 18]; n];
    for x in 0..N {
        for y in 0..N {
            for z in 0..N {
                let i = index(x, y, z);
                x0[i] = Vector3::new(x as f64, y as f64, z as f64) * L0;
                for (k, &(dx, dy, dz)) in dirs.iter().enumerate() {
                    let (a, b, c) = (x + dx, y + dy, z + dz);
                    if inside(a) && inside(b) && inside(c) {
                        neighbours[i][k] = index(a, b, c) as u32;
                        reverse[i][k] =
                            dirs.iter().position(|&d| d == (-dx, -dy, -dz)).unwrap() as u8;
                        l0[i][k] = L0 * ((dx * dx + dy * dy + dz * dz) as f64).sqrt();
                    }
                }
            }
        }
    }
    let mut p = Particles::new(x0, vec![L0 * L0 * L0; n], neighbours, reverse, l0, L0);
    p.a = vec![1e6; n];
    p.b = vec![0.0; n];
    p.check_topology().unwrap();
    p
}

fn law() -> ConcreteLaw {
    ConcreteLaw {
        e: 30e9,
        nu: 0.2,
        plane: Plane::Stress, // ignored in 3D
        fc: 30e6,
        ft: 3e6,
        fy: 25e6,
        fult: 30e6,
        gf: 100.0,
        cod_c: 2e-4,
        cod_1: 2e-5,
        gamma: 0.25,
        eps_ult: 0.0035,
        wt_cr: 1.0 / 3.0,
        wc_max: 1.0,
        initiation: Initiation::Rankine,
        crack_opening: CrackOpening::Total,
        tensile_damage: true,
        compressive_damage: false,
        plasticity: false,
        crack_band: 2.8,
    }
}

#[test]
fn rankine_initiation_in_3d_at_the_isotropic_stress() {
    let p = block();
    let m = Mechanics::new(&p, &vec![2400.0; p.len()]);
    let l = law();
    // σ_xx of a uniaxial strain in 3D
    let d11 = l.e * (1.0 - l.nu) / ((1.0 + l.nu) * (1.0 - 2.0 * l.nu));
    let eps_crit = l.ft / d11;
    for (factor, expect) in [(0.99, false), (1.01, true)] {
        let eps = factor * eps_crit;
        let x: Vec<_> =
            p.x0.iter()
                .map(|x| Vector3::new(x.x * (1.0 + eps), x.y, x.z))
                .collect();
        let mut c: Concrete<3, 18> = Concrete::new(TwoSpring::new(l, None), &p);
        concrete::internal_forces(&m, &mut c, &x);
        c.commit();
        for (i, d) in c.damage().iter().enumerate() {
            assert_eq!(d.initiated, expect, "particle {i} at ε = {factor}·f't/D11");
            if expect {
                // the recorded initiation strain is the largest principal strain, ε_xx, to
                // the second-order term of the finite stretches L/L0 − 1 (at most ε²/2 per
                // bond)
                assert!(
                    (d.eps_init - eps).abs() <= eps * eps,
                    "particle {i}: ε_init {} against {eps}",
                    d.eps_init
                );
                // just past initiation the particle is far from broken
                assert!((0.0..0.5).contains(&d.wt), "particle {i}: w_t = {}", d.wt);
            }
        }
    }
}
