//! Tests of the damage kernel: SIMD passes bit-identical to scalar, the secant stiffness, the
//! increments and the neighbourhood mean.
use super::passes::*;
use super::*;
use crate::aligned::CollectAligned;
use crate::discretise::hex::HexLattice;
use crate::discretise::random::{self, RandomParticles};
use crate::geometry::Shape2;
use crate::model::damage::ConcreteLaw;
use crate::model::stretch::total_stretch;
use crate::solver::kernel::{use_avx, LANES};
use crate::solver::test_rng::Lcg;
use nalgebra::{Matrix2, Vector2};

/// The bench's concrete law, with or without the compressive branch and plasticity.
fn law<const D: usize>(full: bool) -> TwoSpring<D>
where
    Dim<D>: Dimension<D>,
{
    TwoSpring::new(ConcreteLaw::table1(full), None)
}

/// A block strained by up to ±2·f't/E per bond, with every kind of committed state:
/// intact, initiated, partly damaged in tension and compression, fully damaged (w = 1,
/// where the series factor is 0/0), plastic stretch in every bond.
/// With 18 slots the particles also get FCC second-neighbour moduli c (about −0.65·a, in
/// slots 12..18).
fn damaged<const D: usize, const K: usize>(
    p: &Particles<D, K>,
    full: bool,
    seed: u64,
) -> (Mechanics<D, K>, DamageKernel<D, K>, Vec<SVector<f64, D>>)
where
    Dim<D>: Dimension<D>,
{
    let n = p.len();
    let mut r = Lcg(seed);
    let mut m = Mechanics::new(p, &vec![2400.0; n]);
    for i in 0..n {
        m.a[i] = 3e6 * (1.0 + 0.1 * r.next());
        m.b[i] = -1e6 * (1.0 + 0.1 * r.next());
        m.c_in[i] = 5.0 * (1.0 + r.next());
        m.c_ex[i] = if i % 3 == 0 { 0.0 } else { 2.0 * r.next() };
    }
    if let Some(first_slot) = crate::solver::mechanics::first_second_slot(K) {
        let c = (0..n)
            .map(|i| -0.65 * m.a[i] * (1.0 + 0.05 * r.next()))
            .collect_aligned();
        m.second = Some(crate::solver::mechanics::SecondNeighbours { c, first_slot });
    }
    let mut c = DamageKernel::new(law(full), p);
    let mut w = || match (r.next() * 10.0) as u32 {
        0..=4 => 0.0,
        5..=7 => r.next(),
        8 => 1.0,
        _ => 1.0 + r.next(),
    };
    for s in c.committed.iter_mut() {
        s.wt = w();
        s.wc = if full { w() } else { 0.0 };
        s.initiated = s.wt > 0.0;
        s.eps_init = 8e-5;
    }
    let mut r = Lcg(seed + 1);
    for (i, s) in c.sps.iter_mut().enumerate() {
        for (k, s) in s.iter_mut().enumerate() {
            if full && p.neighbours[i][k] != NONE {
                *s = 2e-4 * (r.next() - 0.5);
            }
        }
    }
    let eps = 2.0 * 2.6168e6 / 30e9;
    let x =
        p.x0.iter()
            .map(|x0| {
                let shift = SVector::<f64, D>::from_fn(|c, _| r.next() - [0.3, 0.5, 0.4][c]);
                x0 + shift * eps * 40.0 * p.spacing
            })
            .map(|x| x * (1.0 + 0.5 * eps))
            .collect();
    (m, c, x)
}

/// Pass 1 through the SIMD blocks and through the scalar chunks, on 1 and 2 threads,
/// against `update_state` particle by particle: the same bits in bθ, the trial state, the
/// plastic stretch states, the slot cache and the neighbourhood's strains.
fn check_pass_state<const D: usize, const K: usize, const FULL: bool>(p: &Particles<D, K>, nb: bool)
where
    Dim<D>: Dimension<D>,
{
    let (m, mut c, x) = damaged(p, FULL, 99);
    if nb {
        c = c.with_neighbourhood_criteria(p);
        let mut r = Lcg(5);
        for e in c.neighbourhood.as_mut().unwrap().strain.iter_mut() {
            let t = Tensor::<D>::from_fn(|_, _| r.next() - 0.5);
            *e = (t + t.transpose()) * 1.5e-3;
        }
    }
    let n = p.len();
    let mut want = c.clone();
    let mut want_bt = vec![0.0; n];
    let mut own = vec![Tensor::<D>::zeros(); n];
    for i in 0..n {
        want_bt[i] = update_state::<D, K, TwoSpring<D>, FULL>(
            &m,
            &c,
            &x,
            i,
            &mut want.trial[i],
            &mut want.sps_trial[i],
            &mut want.cache,
            i,
            nb.then_some(&mut own[i]),
        );
    }
    let bits = |v: &[f64]| v.iter().map(|c| c.to_bits()).collect::<Vec<_>>();
    let state = |c: &DamageKernel<D, K>| {
        let mut v = Vec::new();
        for s in c.trial.iter() {
            v.extend([
                s.wt,
                s.wc,
                s.eps_init,
                s.initiated as u8 as f64,
                s.yielded as u8 as f64,
            ]);
        }
        v.extend(c.sps_trial.iter().flatten());
        v.extend(c.cache.iter());
        if let Some(nb) = &c.neighbourhood {
            v.extend(nb.strain_trial.iter().flat_map(|e| e.iter().copied()));
        }
        bits(&v)
    };
    if let Some(w) = want.neighbourhood.as_mut() {
        w.strain_trial = own;
    }
    let expect = state(&want);
    // damage of every kind reached the kernel
    let d: Vec<f64> = (0..n)
        .flat_map(|i| (0..K).map(move |k| (i, k)))
        .map(|(i, k)| SlotCache::read(&want.cache, slot_cache_at(i, k, K)).d)
        .collect();
    assert!(d.contains(&1.0) && d.iter().any(|&d| d > 0.0 && d < 1.0));
    assert!(d.iter().filter(|&&d| d == 0.0).count() > n);
    // and every branch of the law: initiation, and with FULL plastic flow
    assert!(want
        .trial
        .iter()
        .zip(c.committed.iter())
        .any(|(t, s)| t.initiated && !s.initiated));
    assert!(!FULL || want.trial.iter().filter(|s| s.yielded).count() > n / 20);
    for simd in [true, false] {
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut got = c.clone();
            got.simd = simd;
            let mut bt = vec![0.0; n];
            pool.install(|| pass_state::<D, K, TwoSpring<D>, FULL>(&m, &mut got, &x, &mut bt));
            assert_eq!(
                bits(&bt),
                bits(&want_bt),
                "bθ, simd {simd}, {threads} threads"
            );
            assert!(
                state(&got) == expect,
                "state, simd {simd}, {threads} threads"
            );
        }
    }
    // whole steps (both passes, the law's commits) through the SIMD and the scalar paths
    let mut st = crate::solver::kernel::State::at_rest(&p.x0);
    let mut r = Lcg(17);
    st.x.copy_from_slice(&x);
    for (v, f) in st.v.iter_mut().zip(st.force_prev.iter_mut()) {
        *v = SVector::<f64, D>::from_fn(|_, _| r.next() - 0.5) * 1e-2;
        *f = SVector::<f64, D>::from_fn(|_, _| r.next() - 0.5) * 1e3;
    }
    check_steps::<D, K, FULL, false, true>(&m, &c, &st);
    check_steps::<D, K, FULL, true, false>(&m, &c, &st);
}

/// Three steps with and without the SIMD blocks: the same bits in every output.
fn check_steps<
    const D: usize,
    const K: usize,
    const FULL: bool,
    const LAG: bool,
    const DAMP: bool,
>(
    m: &Mechanics<D, K>,
    c: &DamageKernel<D, K>,
    st0: &crate::solver::kernel::State<D>,
) where
    Dim<D>: Dimension<D>,
{
    let run = |simd: bool| {
        let (mut c, mut st) = (c.clone(), st0.clone());
        c.simd = simd;
        for _ in 0..3 {
            step::<D, K, TwoSpring<D>, LAG, DAMP, FULL>(m, &mut c, &mut st, 1e-8);
            std::mem::swap(&mut st.x, &mut st.x_next);
            std::mem::swap(&mut st.v, &mut st.v_next);
        }
        let mut v: Vec<u64> = [&st.x, &st.v, &st.force]
            .iter()
            .flat_map(|a| a.iter().flat_map(|p| p.iter().map(|c| c.to_bits())))
            .collect();
        v.extend(
            st.damping_work
                .iter()
                .chain(st.b_theta.iter())
                .map(|c| c.to_bits()),
        );
        for s in c.committed.iter() {
            v.extend([s.wt, s.wc, s.eps_init].map(f64::to_bits));
        }
        v
    };
    assert!(
        run(true) == run(false),
        "steps, LAG {LAG}, DAMP {DAMP}, FULL {FULL}"
    );
}

/// A hexagonal block of 1,843 particles (not a multiple of 4) and a random one.
fn bodies() -> (Particles<2, 6>, Particles<2, { random::SLOTS_2D }>) {
    let shape = Shape2::Rectangle {
        origin: Vector2::zeros(),
        width: 0.0405,
        height: 0.0405,
    };
    let hex = HexLattice {
        spacing: 1e-3,
        rotation_deg: 10.0,
        offset: Vector2::zeros(),
        thickness: 0.1,
    }
    .fill(&shape);
    let recipe = RandomParticles {
        spacing: 2e-3,
        min_distance: random::DEFAULT_MIN_DISTANCE,
        seed: 3,
        rotation_deg: 0.0,
        thickness: 0.1,
    };
    let (rnd, _, _) = random::fill::<{ random::SLOTS_2D }>(&shape, &recipe).unwrap();
    (hex, rnd)
}

/// The memory estimate counts what [`DamageKernel::new`] allocates per particle.
#[test]
fn damage_kernel_bytes_per_particle_count_its_arrays() {
    fn count<const D: usize, const K: usize>() -> usize
    where
        Dim<D>: Dimension<D>,
    {
        std::mem::size_of::<<Dim<D> as Dimension<D>>::StrainFit<K>>()
            + 2 * std::mem::size_of::<[f64; K]>()
            + slot_cache_len(4096, K) * 8 / 4096
            + std::mem::size_of::<[u8; K]>()
            + 2 * std::mem::size_of::<ParticleDamage>()
            + std::mem::size_of::<f64>()
    }
    assert_eq!(bytes_per_particle(2, 6), count::<2, 6>());
    assert_eq!(bytes_per_particle(3, 18), count::<3, 18>());
    assert_eq!(
        (bytes_per_particle(2, 6), bytes_per_particle(3, 18)),
        (414, 1530)
    );
}

/// The secant stiffness is the derivative of the kernel's force with the state held:
/// K·v against the central difference −(F(x + hv) − F(x − hv))/2h, on damaged bodies with
/// every kind of state (held at x, branches included). The stiffness leaves out only the
/// geometric term, whose relative size is the bonds' stretch: the positions are scaled to
/// stretches below 2e-4, and the test allows 1e-3 (measured 2.5e-5–1.2e-4).
fn check_stiffness<const D: usize, const K: usize>(p: &Particles<D, K>, full: bool)
where
    Dim<D>: Dimension<D>,
{
    let (m, mut c, x) = damaged::<D, K>(p, full, 11);
    let x: Vec<SVector<f64, D>> = x
        .iter()
        .zip(&p.x0)
        .map(|(x, x0)| x0 + (x - x0) * 0.01)
        .collect();
    let largest_stretch = (0..p.len())
        .flat_map(|i| m.bonds(i).map(move |(_, j, il)| (i, j, il)))
        .map(|(i, j, il)| total_stretch((x[j] - x[i]).norm(), il).abs())
        .fold(0.0, f64::max);
    assert!(largest_stretch < 2e-4, "{largest_stretch}");
    c.freeze(true, &m, &x);
    let t = secant_stiffness(&m, &c, &x);
    let mut r = Lcg(5);
    let v: Vec<SVector<f64, D>> = (0..p.len())
        .map(|_| SVector::<f64, D>::from_fn(|_, _| r.next() - 0.5))
        .collect();
    let mut kv = vec![0.0; D * p.len()];
    for &(row, col, val) in &t {
        kv[row] += val * v[col / D][col % D];
    }
    let h = 1e-9 * p.spacing;
    let shifted = |sign: f64| -> Vec<SVector<f64, D>> {
        x.iter().zip(&v).map(|(x, v)| x + v * (sign * h)).collect()
    };
    let (fp, fm) = (
        internal_forces(&m, &mut c, &shifted(1.0)),
        internal_forces(&m, &mut c, &shifted(-1.0)),
    );
    let (mut err, mut norm) = (0.0f64, 0.0f64);
    for i in 0..p.len() {
        for d in 0..D {
            let fd = -(fp[i][d] - fm[i][d]) / (2.0 * h);
            err = err.max((kv[D * i + d] - fd).abs());
            norm = norm.max(fd.abs());
        }
    }
    println!(
        "K = {K}, full {full}: |K·v − FD| ≤ {:.2e} of |FD|",
        err / norm
    );
    assert!(err <= 1e-3 * norm, "{err:e} against {norm:e}");
}

/// A rotated FCC block with weighted dilatations, not a multiple of 4 particles.
fn fcc_body() -> Particles<3, 18> {
    crate::discretise::fcc::FccLattice {
        spacing: 2e-3,
        rotation_deg: [20.0, 10.0, 5.0],
        offset: nalgebra::Vector3::zeros(),
    }
    .fill(&crate::geometry::solid::Shape3::Box {
        origin: nalgebra::Vector3::zeros(),
        size: nalgebra::Vector3::new(0.0133, 0.011, 0.015),
    })
}

#[test]
fn secant_stiffness_is_the_held_forces_derivative() {
    let (hex, rnd) = bodies();
    for full in [false, true] {
        check_stiffness::<2, 6>(&hex, full);
        check_stiffness::<2, 12>(&rnd, full);
    }
    let fcc = fcc_body();
    check_stiffness::<3, 18>(&fcc, true);
}

/// A broken bond whose two particles have met (a separated piece pushed onto its
/// neighbour) has no direction: its stiffness entries are zeros, not NaN, and the
/// triplets are the same ones as before (the quasi-static solver's pattern is built once).
#[test]
fn broken_bond_with_coincident_ends_adds_zeros_to_the_stiffness() {
    let (hex, _) = bodies();
    let (m, mut c, mut x) = damaged::<2, 6>(&hex, false, 11);
    c.freeze(true, &m, &x);
    // a bond held on the tensile branch (the tension kernel has no compressive damage)
    let i = hex.len() / 2;
    let (k, j) = (0..6)
        .map(|k| (k, hex.neighbours[i][k]))
        .find(|&(k, j)| j != NONE && (c.shortened[i] >> k) & 1 == 0)
        .expect("an interior particle has a lengthened bond");
    let j = j as usize;
    c.committed[i].wt = 1.0;
    c.committed[j].wt = 1.0;
    let before = secant_stiffness(&m, &c, &x);
    x[j] = x[i];
    let s = slot::<2, 6, TwoSpring<2>, false>(&m, &c, &x, i, k).unwrap();
    assert!(
        s.d == 0.0 && s.sd == 0.0 && !s.e.x.is_finite(),
        "{} {} {}",
        s.d,
        s.sd,
        s.e
    );
    let after = secant_stiffness(&m, &c, &x);
    assert!(after.iter().all(|t| t.2.is_finite()));
    assert!(before
        .iter()
        .zip(&after)
        .all(|(a, b)| (a.0, a.1) == (b.0, b.1)));
    assert_eq!(before.len(), after.len());
}

/// An undone increment leaves the committed state, plastic stretch, branches and
/// criteria strains as they were at its start, and its growth is the largest change of
/// w_t or w_c since then.
#[test]
fn undo_increment_restores_the_start_and_growth_measures_from_it() {
    let (_, rnd) = bodies();
    let (m, c, x) = damaged::<2, 12>(&rnd, true, 7);
    let mut c = c.with_neighbourhood_criteria(&rnd);
    c.freeze(true, &m, &x);
    c.begin_increment();
    let (state, sps) = (c.committed.to_vec(), c.sps.to_vec());
    let shortened = c.shortened.clone();
    let strain = c.neighbourhood.as_ref().unwrap().strain.clone();
    assert_eq!(c.growth(), 0.0);
    // a strained step: the trial state differs from the start
    let far: Vec<_> = x
        .iter()
        .zip(&rnd.x0)
        .map(|(x, x0)| x0 + (x - x0) * 3.0)
        .collect();
    internal_forces(&m, &mut c, &far);
    let (dw, _) = c.commit_at(&m, &far);
    assert!(dw > 0.0);
    let g = c.growth();
    assert!(g >= dw && g > 0.0, "{g} {dw}");
    c.undo_increment();
    assert!(c.committed.iter().zip(&state).all(|(a, b)| a == b));
    assert!(c.sps.iter().zip(&sps).all(|(a, b)| a == b));
    assert_eq!(c.shortened, shortened);
    assert_eq!(c.neighbourhood.as_ref().unwrap().strain, strain);
    assert_eq!(c.growth(), 0.0);
}

#[test]
fn pass_state_simd_matches_scalar_bitwise() {
    if !use_avx() {
        eprintln!("no AVX on this CPU: only the scalar chunks are compared");
    }
    let (hex, rnd) = bodies();
    assert!(hex.len() % LANES != 0, "{}", hex.len());
    check_pass_state::<2, 6, false>(&hex, false);
    check_pass_state::<2, 6, true>(&hex, false);
    check_pass_state::<2, 12, false>(&rnd, true);
    check_pass_state::<2, 12, true>(&rnd, true);
}

/// The same in 3D on an FCC block with second-neighbour moduli c and weighted
/// dilatations (slots 12..18 take a + c, docs/model.md §3 erratum), not a multiple of 4.
#[test]
fn fcc_pass_state_with_second_neighbours_simd_matches_scalar_bitwise() {
    let fcc = fcc_body();
    assert!(
        !fcc.len().is_multiple_of(LANES) && fcc.len() > 200,
        "{}",
        fcc.len()
    );
    assert!(fcc.weighted_dilatation);
    check_pass_state::<3, 18, false>(&fcc, false);
    check_pass_state::<3, 18, true>(&fcc, false);
}

/// Particle 0 with neighbours 1 and 2 (and an empty slot): the mean weighs each strain by
/// its volume, and a damaged neighbour drops out of both the sum and the volume.
#[test]
fn neighbourhood_mean_weighs_by_volume_and_leaves_out_damaged_neighbours() {
    let nb = Neighbourhood::<2> {
        volume: vec![1.0, 2.0, 3.0],
        strain: vec![
            Matrix2::new(1.0, 0.5, 0.5, -1.0),
            Matrix2::new(4.0, 0.0, 0.0, 2.0),
            Matrix2::new(-8.0, 1.0, 1.0, 6.0),
        ],
        strain_trial: vec![Matrix2::zeros(); 3],
        strain_start: Vec::new(),
        only: None,
    };
    let row = [1, NONE, 2];
    let all = nb.mean(0, &row, |_| false);
    // (1·ε0 + 2·ε1 + 3·ε2)/6
    let expect_all = Matrix2::new(
        (1.0 + 8.0 - 24.0) / 6.0,
        (0.5 + 3.0) / 6.0,
        (0.5 + 3.0) / 6.0,
        (-1.0 + 4.0 + 18.0) / 6.0,
    );
    assert!((all - expect_all).norm() < 1e-15, "{all} vs {expect_all}");
    let intact = nb.mean(0, &row, |j| j == 2);
    // (1·ε0 + 2·ε1)/3
    let expect_intact = Matrix2::new(3.0, 0.5 / 3.0, 0.5 / 3.0, 1.0);
    assert!(
        (intact - expect_intact).norm() < 1e-15,
        "{intact} vs {expect_intact}"
    );
    // a damaged particle's own strain still counts
    let own = nb.mean(0, &row, |j| j != 0);
    assert!((own - nb.strain[0]).norm() < 1e-15);
}

/// `criteria_strain = "surface"` reads the mean where a particle misses bonds: on an FCC box
/// those are exactly the particles within √2·L0 (the second neighbours' reach) of a face, and
/// every other particle has the bulk's 18 bonds and reads its own strain.
#[test]
fn surface_criteria_read_the_mean_at_particles_missing_bonds_only() {
    let l0 = 2e-3;
    let size = nalgebra::Vector3::new(0.0133, 0.011, 0.015);
    let p = crate::discretise::fcc::FccLattice {
        spacing: l0,
        rotation_deg: [0.0; 3],
        offset: nalgebra::Vector3::repeat(0.25 * l0),
    }
    .fill(&crate::geometry::solid::Shape3::Box {
        origin: nalgebra::Vector3::zeros(),
        size,
    });
    let c = DamageKernel::new(law::<3>(true), &p).with_surface_criteria(&p);
    let only = c.neighbourhood.as_ref().unwrap().only.as_ref().unwrap();
    let (lo, hi) = p.x0.iter().fold(
        (
            nalgebra::Vector3::repeat(f64::MAX),
            nalgebra::Vector3::repeat(f64::MIN),
        ),
        |(lo, hi), x| (lo.inf(x), hi.sup(x)),
    );
    let reach = 2f64.sqrt() * l0 * (1.0 - 1e-9);
    let mut surface = 0;
    for (i, x) in p.x0.iter().enumerate() {
        let near = (0..3).any(|d| x[d] - lo[d] < reach || hi[d] - x[d] < reach);
        assert_eq!(only[i], near, "particle {i} at {x:?}");
        surface += near as usize;
    }
    assert!(surface > 0 && surface < p.len(), "{surface} of {}", p.len());
}
