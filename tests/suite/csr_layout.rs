//! The CSR bond layout (`discretise::csr`) and its elastic step kernel
//! (`solver::csr_kernel`) against the slot layout and the slot kernel.

use nalgebra::{SVector, Vector2};
use sppm::bench::{bench, Layout};
use sppm::discretise::csr::Csr;
use sppm::discretise::hex::HexLattice;
use sppm::discretise::{Particles, NONE};
use sppm::geometry::Shape2;
use sppm::solver::kernel::{self, State};
use sppm::solver::mechanics::Mechanics;
use sppm::solver::{csr_kernel, KernelSet};

/// Deterministic pseudo-random numbers in [0, 1) (ChaCha20: the same stream everywhere).
struct Lcg(rand::rngs::ChaCha20Rng);
impl Lcg {
    fn new(seed: u64) -> Self {
        use rand::SeedableRng;
        Lcg(rand::rngs::ChaCha20Rng::seed_from_u64(seed))
    }
    fn next(&mut self) -> f64 {
        use rand::Rng;
        (self.0.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A notched block of hexagonal lattice (boundary particles with empty slots, bonds cut by
/// the notch), ~3,000 particles.
fn block() -> Particles<2, 6> {
    let lat = HexLattice {
        spacing: 1e-3,
        rotation_deg: 10.0,
        offset: Vector2::new(0.2e-3, 0.1e-3),
        thickness: 0.1,
    };
    lat.fill(&Shape2::NotchedBeam {
        length: 0.07,
        depth: 0.045,
        notch_depth: 0.015,
        notch_width: 0.002,
    })
}

/// Concrete-like micro-moduli (docs/model.md §3, 2D plane stress) varied per particle by ±10%,
/// with bond dampers (ξ_in = 0.2) and particle dampers (ξ_ex, none on every fifth particle),
/// so that any mix-up of i and j or of bonds shows.
fn mechanics(p: &Particles<2, 6>) -> Mechanics<2, 6> {
    let (e, nu, l0, t) = (30e9, 0.2, p.spacing, 0.1);
    let s3 = 3f64.sqrt();
    let a = 2.0 * e * l0 * t / (s3 * (1.0 + nu));
    let b = e * l0 * t * (1.0 - 3.0 * nu) / (6.0 * s3 * (nu * nu - 1.0));
    let n = p.len();
    let mut r = Lcg::new(7);
    let mut vary = |s: f64| {
        (0..n)
            .map(|_| s * (0.9 + 0.2 * r.next()))
            .collect::<Vec<_>>()
    };
    let (av, bv, rho) = (vary(a), vary(b), vary(2400.0));
    let mut body = p.clone();
    body.a = av;
    body.b = bv;
    let mut m = Mechanics::new(&body, &rho);
    let omega = sppm::material::particle_frequency(e, nu, 2400.0, l0);
    for i in 0..n {
        m.c_in[i] = 2.0 * m.mass[i] * 0.2 * omega * (0.9 + 0.2 * r.next());
        m.c_ex[i] = if i % 5 == 0 {
            0.0
        } else {
            2.0 * m.mass[i] * 0.05 * omega * r.next()
        };
    }
    m
}

/// A homogeneous strain with a random perturbation of the positions, random velocities and
/// a random previous force (for reading A): free vibration from there.
fn start(p: &Particles<2, 6>) -> State<2> {
    let mut r = Lcg::new(99);
    let mut st = State::at_rest(&p.x0);
    let l0 = p.spacing;
    for i in 0..p.len() {
        let jitter = Vector2::new(r.next() - 0.5, r.next() - 0.5) * (2e-5 * l0);
        st.x[i] = p.x0[i] * (1.0 + 1e-4) + jitter;
        st.v[i] = Vector2::new(r.next() - 0.5, r.next() - 0.5) * 1e-3;
        st.force_prev[i] = Vector2::new(r.next() - 0.5, r.next() - 0.5);
    }
    st
}

fn bits(v: &[SVector<f64, 2>]) -> Vec<u64> {
    v.iter()
        .flat_map(|p| p.iter().map(|c| c.to_bits()))
        .collect()
}

fn sbits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|c| c.to_bits()).collect()
}

/// Steps `steps` times with `one` (which leaves x^{n+1}, v^{n+½} in x_next, v_next).
fn run(st: &mut State<2>, steps: usize, mut one: impl FnMut(&mut State<2>)) {
    for _ in 0..steps {
        one(st);
        std::mem::swap(&mut st.x, &mut st.x_next);
        std::mem::swap(&mut st.v, &mut st.v_next);
        std::mem::swap(&mut st.force, &mut st.force_prev);
    }
}

/// Slot and CSR kernels over `steps` steps from the same start, on 1 and 2 threads: the same
/// positions, velocities, forces, bθ and damper work, bit for bit.
fn compare<const LAG: bool, const DAMP: bool>(steps: usize) {
    let p = block();
    let m = mechanics(&p);
    let csr = Csr::from_slots(&p).unwrap();
    let dt = 0.9 * sppm::solver::time_step::stable_step(&m, &p.x0).dt_stable;
    let st0 = start(&p);
    let pool = |t| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .unwrap()
    };
    let mut slots = st0.clone();
    pool(2).install(|| {
        run(&mut slots, steps, |st| {
            kernel::step::<2, 6, LAG, DAMP>(&m, st, dt)
        })
    });
    // the motion is not trivial: positions moved by much more than rounding
    let moved = slots
        .x
        .iter()
        .zip(st0.x.iter())
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(moved > 1e-3 * p.spacing, "moved {moved}");
    assert!(slots.x.iter().all(|x| x.iter().all(|c| c.is_finite())));
    for threads in [1, 2] {
        let mut c = st0.clone();
        pool(threads).install(|| {
            run(&mut c, steps, |st| {
                csr_kernel::step::<2, 6, LAG, DAMP>(&csr, &m, st, dt)
            })
        });
        assert_eq!(bits(&c.x), bits(&slots.x), "positions, {threads} threads");
        assert_eq!(bits(&c.v), bits(&slots.v), "velocities, {threads} threads");
        assert_eq!(bits(&c.force_prev), bits(&slots.force_prev), "forces");
        assert_eq!(sbits(&c.b_theta), sbits(&slots.b_theta), "bθ");
        assert_eq!(
            sbits(&c.damping_work),
            sbits(&slots.damping_work),
            "damper work"
        );
    }
}

/// Built from slots, the CSR layout sums each particle's bonds in slot order and every bond
/// performs the slot kernel's IEEE operations in the same order (the force law through
/// `model::force_state`, no FMA), so 1,000 steps agree bit for bit.
#[test]
fn csr_kernel_matches_slot_kernel_bit_for_bit() {
    compare::<false, true>(1000);
    compare::<false, false>(300);
    compare::<true, true>(300);
}

/// The CSR of a body with boundary: each particle's bonds are its occupied slots in slot
/// order, with 1/L0 = 1/l0 and reverse positions that land on the reverse slot.
#[test]
fn csr_from_slots_of_a_body_with_boundary() {
    let p = block();
    let csr = Csr::from_slots(&p).unwrap();
    csr.check_topology().unwrap();
    assert_eq!(csr.len(), p.len());
    assert_eq!(csr.bonds(), p.bonds());
    let boundary = (0..p.len()).filter(|&i| p.bond_count(i) < 6).count();
    assert!(boundary > 100, "{boundary} boundary particles");
    for i in 0..p.len() {
        assert_eq!(csr.bond_count(i), p.bond_count(i));
        let occupied: Vec<usize> = (0..6).filter(|&k| p.neighbours[i][k] != NONE).collect();
        for (b, &k) in csr.range(i).zip(&occupied) {
            let j = p.neighbours[i][k];
            assert_eq!(csr.neighbours()[b], j);
            assert_eq!(csr.inv_l0()[b].to_bits(), (1.0 / p.l0[i][k]).to_bits());
            let rb = csr.reverse()[b] as usize;
            // position rb is slot reverse[i][k] among j's occupied slots
            let r = p.reverse[i][k] as usize;
            let rank = (0..r)
                .filter(|&s| p.neighbours[j as usize][s] != NONE)
                .count();
            assert_eq!(rb, csr.range(j as usize).start + rank);
            assert_eq!(csr.reverse()[rb] as usize, b);
        }
    }
    // inconsistent slots are refused
    let mut bad = p.clone();
    let i = (0..p.len()).find(|&i| p.bond_count(i) == 6).unwrap();
    bad.reverse[i][0] = 1;
    assert!(Csr::from_slots(&bad).unwrap_err().contains("no reverse"));
    let mut bad = p.clone();
    bad.neighbours[i][2] = p.len() as u32;
    assert!(Csr::from_slots(&bad)
        .unwrap_err()
        .contains("no such particle"));
}

/// Random particles bonded where either end lists the other among its 6 nearest (docs/model.md
/// §1): the pairs come in both orders and twice; the CSR has one bond per pair, reverse of
/// reverse is the identity, L0 is symmetric bit for bit and each row is sorted.
#[test]
fn csr_from_pairs_topology() {
    let mut r = Lcg::new(2024);
    let n = 1500;
    let x0: Vec<Vector2<f64>> = (0..n).map(|_| Vector2::new(r.next(), r.next())).collect();
    let mut pairs = Vec::new();
    for i in 0..n {
        let mut d: Vec<(f64, usize)> = (0..n)
            .filter(|&j| j != i)
            .map(|j| ((x0[j] - x0[i]).norm(), j))
            .collect();
        d.sort_by(|a, b| a.partial_cmp(b).unwrap());
        for &(_, j) in &d[..6] {
            pairs.push((i as u32, j as u32));
        }
    }
    let mut unique: Vec<(u32, u32)> = pairs.iter().map(|&(i, j)| (i.min(j), i.max(j))).collect();
    unique.sort_unstable();
    unique.dedup();
    assert!(
        unique.len() < pairs.len(),
        "some pairs are listed from both ends"
    );
    let csr = Csr::from_pairs(&x0, &pairs).unwrap();
    csr.check_topology().unwrap();
    assert_eq!(csr.len(), n);
    assert_eq!(csr.bonds(), unique.len());
    let (nb, rev, il) = (csr.neighbours(), csr.reverse(), csr.inv_l0());
    let mut seen = 0;
    for i in 0..n {
        let row = &nb[csr.range(i)];
        assert!(
            row.windows(2).all(|w| w[0] < w[1]),
            "row {i} sorted, no repeats"
        );
        assert!(
            csr.bond_count(i) >= 6,
            "every particle keeps its own 6 nearest"
        );
        for b in csr.range(i) {
            let j = nb[b] as usize;
            let rb = rev[b] as usize;
            assert_eq!(rev[rb] as usize, b, "reverse of reverse");
            assert!(csr.range(j).contains(&rb));
            assert_eq!(nb[rb] as usize, i);
            assert_eq!(il[b].to_bits(), il[rb].to_bits(), "L0 symmetric");
            let l0 = (x0[j] - x0[i]).norm();
            assert!((il[b] * l0 - 1.0).abs() < 1e-15);
            if i < j {
                assert!(unique.binary_search(&(i as u32, j as u32)).is_ok());
                seen += 1;
            }
        }
    }
    assert_eq!(seen, unique.len());
    // bad pairs are refused
    assert!(Csr::from_pairs(&x0, &[(3, 3)])
        .unwrap_err()
        .contains("itself"));
    assert!(Csr::from_pairs(&x0, &[(0, n as u32)])
        .unwrap_err()
        .contains("no particle"));
    let twins = [Vector2::new(0.0, 0.0), Vector2::new(0.0, 0.0)];
    assert!(Csr::from_pairs(&twins, &[(0, 1)])
        .unwrap_err()
        .contains("distance"));
    // particles without bonds have empty rows
    let csr = Csr::from_pairs(&x0[..4], &[(2, 0)]).unwrap();
    assert_eq!(csr.offsets(), &[0, 1, 1, 2, 2]);
    csr.check_topology().unwrap();
}

/// `sppm bench --layout csr` runs the elastic kernel only and says so.
#[test]
fn bench_csr_layout_is_elastic_only() {
    let r = bench(
        2000,
        5,
        1,
        KernelSet::Elastic,
        Layout::Csr,
        "hexagonal",
        true,
    )
    .unwrap();
    assert_eq!(r.layout, "csr");
    let e = bench(
        2000,
        5,
        1,
        KernelSet::Tension,
        Layout::Csr,
        "hexagonal",
        true,
    )
    .unwrap_err();
    let msg = format!("{e:#}");
    assert!(
        msg.contains("--layout csr") && msg.contains("elastic"),
        "{msg}"
    );
}
