use super::*;
use crate::aligned::CollectAligned;
use crate::discretise::NONE;
use crate::solver::mechanics::uniform_inv_l0;

use crate::solver::test_rng::Lcg;

/// A random model with some empty slots and a random state, n not a multiple of the
/// chunk or block size.
fn model<const D: usize, const K: usize>(n: usize) -> (Mechanics<D, K>, State<D>) {
    let mut r = Lcg(12345);
    let x0: Vec<SVector<f64, D>> = (0..n)
        .map(|i| SVector::from_fn(|c, _| i as f64 * 1e-3 * (c + 1) as f64 + 1e-4 * r.next()))
        .collect();
    let mut neighbours = vec![[NONE; K]; n];
    let mut inv_l0 = vec![[0.0; K]; n];
    for i in 0..n {
        for k in 0..K {
            if r.next() < 0.8 {
                let mut j = (i + 1 + (r.next() * 40.0) as usize) % n;
                if j == i {
                    j = (i + 1) % n;
                }
                neighbours[i][k] = j as u32;
                inv_l0[i][k] = 1.0 / ((x0[j] - x0[i]).norm() * (1.0 + 0.01 * r.next()));
            }
        }
    }
    let mut v = |s: f64| (0..n).map(|_| s * (1.0 + r.next())).collect_aligned();
    let (a, b, mass, c_in, mut c_ex) = (v(3e6), v(-1e5), v(1e-3), v(10.0), v(1.0));
    // some particles without a particle damper (h = 0)
    for c in c_ex.iter_mut().step_by(3) {
        *c = 0.0;
    }
    // some with an implicit share of the bond dampers (g ≠ 0)
    let c_implicit = (0..n)
        .map(|i| if i % 2 == 0 { 0.0 } else { 5.0 * r.next() })
        .collect_aligned();
    let slot_end = crate::solver::mechanics::slot_end(&neighbours);
    let mech = Mechanics {
        neighbours: copied(&neighbours),
        slot_inv_l0: uniform_inv_l0(&neighbours, &inv_l0),
        inv_l0: copied(&inv_l0),
        a,
        b,
        second: None,
        inv_mass: mass.iter().map(|m| 1.0 / m).collect_aligned(),
        mass,
        c_in,
        c_ex,
        c_implicit,
        dilatation_weight: None,
        slot_weight: None,
        slot_end,
    };
    let mut st = State::at_rest(&x0);
    for i in 0..n {
        st.v[i] = SVector::from_fn(|_, _| r.next() - 0.5);
        st.force_prev[i] = SVector::from_fn(|_, _| r.next() - 0.5);
        st.damping_work[i] = r.next();
    }
    (mech, st)
}

/// The kernel against the plain per-particle code, bit for bit, on 1 and 2 threads, with
/// a reference length per bond and with one per slot (a lattice: the AVX blocks
/// broadcast [`Mechanics::slot_inv_l0`]); with 18 slots also with FCC second-neighbour
/// moduli c in slots 12..18.
fn check<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>() {
    check_weighted::<D, K, LAG, DAMP>(false, false);
    check_weighted::<D, K, LAG, DAMP>(false, true);
    if K == 18 {
        let n = 2 * CHUNK + 4 * 37 + 3;
        let (mut m, st0) = model::<D, K>(n);
        with_second(&mut m);
        check_model::<D, K, LAG, DAMP>(&m, &st0);
    }
}

/// Random second-neighbour moduli c (about −0.65·a, as FCC's) in slots 12..K.
fn with_second<const D: usize, const K: usize>(m: &mut Mechanics<D, K>) {
    let mut r = Lcg(99);
    let c =
        m.a.iter()
            .map(|a| -0.65 * a * (1.0 + 0.1 * r.next()))
            .collect_aligned();
    m.second = Some(crate::solver::mechanics::SecondNeighbours { c, first_slot: 12 });
}

/// [`check`]; with `weighted`, the body weighs its dilatations (random particles); with
/// `per_slot`, every bond in slot k has the same reference length.
fn check_weighted<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>(
    weighted: bool,
    per_slot: bool,
) {
    let n = 2 * CHUNK + 4 * 37 + 3;
    let (mut m, st0) = model::<D, K>(n);
    assert!(m.slot_inv_l0.is_none());
    if per_slot {
        let u: [f64; K] = std::array::from_fn(|k| 1.0 / (3e-3 * (1.0 + 0.1 * k as f64)));
        for (s, l) in m.neighbours.iter().zip(m.inv_l0.iter_mut()) {
            for k in 0..K {
                if s[k] != NONE {
                    l[k] = u[k];
                }
            }
        }
        m.slot_inv_l0 = uniform_inv_l0(&m.neighbours, &m.inv_l0);
        assert_eq!(m.slot_inv_l0, Some(u));
    }
    if weighted {
        // L0,ik/ℓ_i of random particles lies about 0.6–1.6
        let mut r = Lcg(7);
        m.dilatation_weight = Some(
            (0..n)
                .map(|i| {
                    std::array::from_fn(|k| {
                        let w = 0.6 + r.next();
                        if m.neighbours[i][k] == NONE {
                            0.0
                        } else {
                            w
                        }
                    })
                })
                .collect_aligned(),
        );
    }
    check_model::<D, K, LAG, DAMP>(&m, &st0);
}

/// The kernel's step of model `m` from state `st0` against the plain per-particle code.
fn check_model<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>(
    m: &Mechanics<D, K>,
    st0: &State<D>,
) {
    let n = m.len();
    let dt = 1e-7;
    let mut want = st0.clone();
    for i in 0..n {
        want.b_theta[i] = dilatation_one(m, &st0.x, i);
    }
    for i in 0..n {
        let (f, p) = particle_force::<D, K, DAMP>(m, &st0.x, &st0.v, &want.b_theta, i);
        want.force[i] = f;
        let (mut xn, mut vn, mut dw) = (st0.x_next[i], st0.v_next[i], st0.damping_work[i]);
        let inp = Inputs {
            m,
            x: &st0.x,
            v: &st0.v,
            b_theta: &want.b_theta,
            force_prev: &st0.force_prev,
            dt,
        };
        update_one::<D, K, LAG, DAMP>(inp, i, f, p, &mut xn, &mut vn, &mut dw);
        (want.x_next[i], want.v_next[i], want.damping_work[i]) = (xn, vn, dw);
    }
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let mut st = st0.clone();
        pool.install(|| step::<D, K, LAG, DAMP>(m, &mut st, dt));
        let bits = |v: &[SVector<f64, D>]| {
            v.iter()
                .flat_map(|p| p.iter().map(|c| c.to_bits()).collect::<Vec<_>>())
                .collect::<Vec<_>>()
        };
        let sbits = |v: &[f64]| v.iter().map(|c| c.to_bits()).collect::<Vec<_>>();
        assert_eq!(sbits(&st.b_theta), sbits(&want.b_theta));
        assert_eq!(bits(&st.force), bits(&want.force));
        assert_eq!(bits(&st.x_next), bits(&want.x_next));
        assert_eq!(bits(&st.v_next), bits(&want.v_next));
        assert_eq!(sbits(&st.damping_work), sbits(&want.damping_work));
    }
}

/// (a) of the FCC kernel: on a randomly perturbed FCC block (`bench::fcc_block`: 18
/// slots, second neighbours in 12..18) with per-particle a, b and c ≠ 0, moving, the AVX
/// blocks and the scalar code agree bit for bit, and c changes the forces.
#[test]
fn fcc_block_with_second_neighbours_matches_scalar_reference_bitwise() {
    let l0 = 1e-3;
    let p = crate::bench::fcc_block(6, l0);
    p.check_topology().unwrap();
    let n = p.len();
    assert!(
        !n.is_multiple_of(LANES) && n > 1000,
        "{n}: tails on the scalar path"
    );
    let mut m = Mechanics::new(&p, &vec![2400.0; n]);
    let mut r = Lcg(2026);
    for i in 0..n {
        m.a[i] *= 1.0 + 0.1 * r.next();
        m.b[i] *= 1.0 + 0.1 * r.next();
        m.c_in[i] = 2.0 * m.mass[i] * 0.2 * 1e6 * r.next();
        m.c_ex[i] = if i % 3 == 0 { 0.0 } else { m.mass[i] * 1e3 };
    }
    let sec = m.second.as_mut().expect("FCC moduli have c ≠ 0");
    assert_eq!(sec.first_slot, 12);
    for c in sec.c.iter_mut() {
        *c *= 1.0 + 0.1 * r.next();
    }
    let mut st = State::at_rest(&p.x0);
    for i in 0..n {
        st.x[i] += SVector::from_fn(|_, _| 1e-3 * l0 * (r.next() - 0.5));
        st.v[i] = SVector::from_fn(|_, _| r.next() - 0.5);
        st.force_prev[i] = SVector::from_fn(|_, _| r.next() - 0.5);
    }
    check_model::<3, 18, false, true>(&m, &st);
    check_model::<3, 18, true, false>(&m, &st);
    check_model::<3, 18, false, false>(&m, &st);
    // c is used: the same step without it gives other forces
    let mut with = st.clone();
    step::<3, 18, false, false>(&m, &mut with, 1e-9);
    let mut without = st.clone();
    m.second = None;
    step::<3, 18, false, false>(&m, &mut without, 1e-9);
    let differ = (0..n)
        .filter(|&i| with.force[i] != without.force[i])
        .count();
    assert_eq!(differ, n);
}

#[test]
fn step_matches_scalar_reference_bitwise() {
    check::<2, 6, false, true>();
    check::<2, 6, false, false>();
    check::<2, 6, true, true>();
    check::<2, 6, true, false>();
    check::<3, 18, false, true>();
    check::<3, 18, true, false>();
    // weighted dilatation (random particles) on the AVX and scalar paths
    check_weighted::<2, 12, false, true>(true, false);
    check_weighted::<2, 12, true, false>(true, false);
}
