//! `sppm bench`: throughput of the step kernels (elastic; tension: tensile damage only; full:
//! two-spring damage and plasticity) on a square block of hexagonal lattice, in particle-steps
//! per second (set-up excluded), on the fixed bond slots of the lattice (`solver::kernel`).
//!
//! `--dim 3` times the same kernels on a cube of FCC lattice (18 slots: 12 nearest and 6
//! second neighbours with the modulus a + c, docs/model.md §3 with its erratum), built by
//! [`fcc_block`] here: the same block as LAMMPS's `lattice fcc a` with `region block 0 N`
//! (benchmarks/fcc_vs_lammps.sh); or, with `--lattice random`, on a cube of random particles
//! (36 slots, [`bench_random3`]).

use crate::discretise::hex::HexLattice;
use crate::discretise::random::{self, RandomParticles};
use crate::discretise::Particles;
use crate::geometry::Shape2;
use crate::model::micro_modulus;
use crate::scene::Plane;
use crate::solver::inelastic::Inelastic;
use crate::solver::kernel::{self, State};
use crate::solver::mechanics::Mechanics;
use crate::solver::KernelSet;
use nalgebra::{Vector2, Vector3};
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
    /// "hexagonal", "random" or "fcc".
    pub lattice: String,
    /// Bytes per particle the run's arrays take ([`bytes_per_particle`]).
    pub bytes_per_particle: usize,
    /// The damage kernels ran their AVX paths where the CPU has them (`false`: `--scalar`,
    /// the scalar path for a same-binary comparison).
    pub simd: bool,
    /// Random particles: the seconds their set-up took.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub setup: Option<Setup>,
}

/// Set-up of a random body (seconds): placement, Voronoi cells, bonds, least-squares moduli.
#[derive(Clone, Debug, Serialize)]
pub struct Setup {
    pub placing_s: f64,
    pub voronoi_s: f64,
    pub bonding_s: f64,
    pub moduli_s: f64,
}

/// Fit every random particle's micro-moduli with `fit` (2D or 3D), timed, and the set-up
/// times of generation `g` with it; an error where a particle has no fit.
fn fitted<const D: usize, const K: usize>(
    p: &mut crate::discretise::Particles<D, K>,
    g: &random::Generation,
    fit: impl Fn(
        &crate::discretise::Particles<D, K>,
        &mut [f64],
        &mut [f64],
    ) -> crate::run::model::ModuliFit,
) -> anyhow::Result<Setup> {
    let t = Instant::now();
    let (mut a, mut b) = (std::mem::take(&mut p.a), std::mem::take(&mut p.b));
    let report = fit(p, &mut a, &mut b);
    anyhow::ensure!(
        report.unfitted == 0,
        "{} particles have no moduli fit",
        report.unfitted
    );
    (p.a, p.b) = (a, b);
    Ok(Setup {
        placing_s: g.seconds_placing,
        voronoi_s: g.seconds_voronoi,
        bonding_s: g.seconds_bonding,
        moduli_s: t.elapsed().as_secs_f64(),
    })
}

/// Bytes per particle a benchmark of `kernel` in `dim` dimensions allocates: the run's arrays
/// ([`crate::discretise::bytes_per_particle`], with the lattice's slots) and, with damage,
/// the damage kernel's ([`crate::solver::inelastic::bytes_per_particle`]).
pub fn bytes_per_particle(kernel: KernelSet, dim: usize) -> usize {
    let base = crate::discretise::bytes_per_particle(dim, crate::discretise::slots(dim));
    match kernel {
        KernelSet::Elastic => base,
        _ => {
            base + crate::solver::inelastic::bytes_per_particle(dim, crate::discretise::slots(dim))
        }
    }
}

/// Time `steps` steps of `kernel` (bond dampers on, as in the shipped scenes) on a square
/// block of about `particles` particles on `threads` threads. The tension and full kernels
/// run the Table 1 concrete of Nikravesh Kazeroni (2017) under an equibiaxial strain of 0.9e-4 (1.03·f't/E; the
/// principal stress E·ε/(1 − ν) is 1.29·f't), so every particle initiates in the first
/// step and then softens: each timed step evaluates every particle's tensile damage (and,
/// with the full kernel, compressive damage and the yield test) and every bond's damage
/// factor, the concrete kernels' heaviest path.
pub fn bench(
    particles: usize,
    steps: usize,
    threads: usize,
    kernel: KernelSet,
    lattice: &str,
    simd: bool,
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
    match lattice {
        "hexagonal" => {
            let mut p = lat.fill(&shape);
            let n = p.len();
            let mm = micro_modulus::hexagonal(30e9, 0.2, l0, 0.1, Plane::Stress);
            p.a = vec![mm.a; n];
            p.b = vec![mm.b; n];
            time_steps(p, steps, threads, kernel, None, simd)
        }
        "random" => {
            let recipe = RandomParticles {
                spacing: l0,
                min_distance: random::DEFAULT_MIN_DISTANCE,
                seed: 1,
                rotation_deg: 0.0,
                thickness: 0.1,
            };
            let (mut p, _, g) = random::fill::<{ random::SLOTS_2D }>(&shape, &recipe)
                .map_err(|e| anyhow::anyhow!("random particles: {e}"))?;
            let d = micro_modulus::elasticity_matrix(30e9, 0.2, Plane::Stress);
            let setup = fitted(&mut p, &g, |p, a, b| {
                crate::run::generate::moduli::fit_moduli(p, &d, a, b)
            })?;
            time_steps(p, steps, threads, kernel, Some(setup), simd)
        }
        other => anyhow::bail!("--lattice {other}: \"hexagonal\" or \"random\""),
    }
}

/// The bench's mechanics of a body (ρ = 2400 kg/m³, bond and particle dampers with ξ = 0.2
/// as in the shipped scenes) and its state under a small homogeneous strain so that every
/// bond works: 1e-4 for the elastic kernel, 0.9e-4 for a damage kernel (see [`bench`] and
/// [`bench_fcc`] for what it makes the particles do).
fn strained_model<const D: usize, const K: usize>(
    p: &crate::discretise::Particles<D, K>,
    kernel: KernelSet,
) -> (Mechanics<D, K>, State<D>) {
    let n = p.len();
    let mut mech = Mechanics::new(p, &vec![2400.0; n]);
    let omega = crate::material::particle_frequency(30e9, 0.2, 2400.0, p.spacing);
    for i in 0..n {
        mech.c_in[i] = 2.0 * mech.mass[i] * 0.2 * omega;
        mech.c_ex[i] = 2.0 * mech.mass[i] * 0.2 * 1e3;
    }
    let strain = if kernel == KernelSet::Elastic {
        1e-4
    } else {
        0.9e-4
    };
    let mut st = State::at_rest(&p.x0);
    for (x, x0) in st.x.iter_mut().zip(&p.x0) {
        *x = x0 * (1.0 + strain);
    }
    (mech, st)
}

/// The bench's damage model for `kernel` (Table 1 concrete of Nikravesh Kazeroni (2017); `None` for the elastic
/// kernel), checked to choose that kernel.
fn damage_model<const D: usize, const K: usize>(
    p: &crate::discretise::Particles<D, K>,
    kernel: KernelSet,
    simd: bool,
) -> anyhow::Result<Option<crate::solver::inelastic::DamageKernel<D, K>>>
where
    crate::model::dimension::Dim<D>: crate::model::dimension::Dimension<D>,
{
    let model = (kernel != KernelSet::Elastic).then(|| {
        let law = crate::model::damage::ConcreteLaw::table1(kernel == KernelSet::Full);
        let mut c = crate::solver::inelastic::DamageKernel::<D, K>::new(
            crate::model::two_spring::TwoSpring::new(law, None),
            p,
        );
        c.simd = simd;
        c
    });
    let chosen = model.as_ref().map_or(KernelSet::Elastic, |c| c.kernel());
    anyhow::ensure!(
        chosen == kernel,
        "the law chose the {chosen:?} kernel, not {kernel:?}"
    );
    Ok(model)
}

/// Time the steps of a filled body with its micro-moduli.
fn time_steps<const K: usize>(
    p: crate::discretise::Particles<2, K>,
    steps: usize,
    threads: usize,
    kernel: KernelSet,
    setup: Option<Setup>,
    simd: bool,
) -> anyhow::Result<BenchResult> {
    let n = p.len();
    let (mech, mut st) = strained_model(&p, kernel);
    let dt = 0.9 * crate::solver::time_step::stable_step(&mech, &p.x0).dt_stable;
    let mut model = damage_model(&p, kernel, simd)?;
    let mut one_step = |st: &mut State<2>| {
        match model.as_mut() {
            Some(c) => c.step(&mech, st, dt, false, true),
            None => kernel::step::<2, K, false, true>(&mech, st, dt),
        }
        std::mem::swap(&mut st.x, &mut st.x_next);
        std::mem::swap(&mut st.v, &mut st.v_next);
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let seconds = pool.install(|| {
        for _ in 0..2 {
            one_step(&mut st);
        }
        let t = Instant::now();
        for _ in 0..steps {
            one_step(&mut st);
        }
        t.elapsed().as_secs_f64()
    });
    Ok(BenchResult {
        particles: n,
        steps,
        threads,
        model: kernel.name().into(),
        particle_steps_per_s: (n * steps) as f64 / seconds,
        seconds,
        lattice: if setup.is_some() {
            "random"
        } else {
            "hexagonal"
        }
        .into(),
        bytes_per_particle: bytes_per_particle(kernel, 2),
        simd,
        setup,
    })
}

/// Cells per side of the FCC cube [`fcc_block`] whose particle count is nearest `particles`.
pub fn fcc_cells(particles: usize) -> usize {
    let count = |n: usize| fcc_block_len(n) as f64;
    let guess = ((2.0 * particles as f64).cbrt() - 1.0) / 2.0;
    let lo = (guess.floor() as usize).max(1);
    let target = particles as f64;
    [lo, lo + 1]
        .into_iter()
        .min_by(|&a, &b| {
            (count(a) - target)
                .abs()
                .total_cmp(&(count(b) - target).abs())
        })
        .unwrap_or(1)
}

/// Particles of [`fcc_block`] with `cells` cells per side: ((2N+1)³ + 1)/2 = 4N³ + 6N² + 3N + 1
/// (4 per cubic cell and the faces').
pub const fn fcc_block_len(cells: usize) -> usize {
    let s = 2 * cells + 1;
    (s * s * s).div_ceil(2)
}

/// A cube of FCC lattice with nearest spacing `l0` and `cells` cubic cells (a = √2·L0) per
/// side, faces included: the points (i, j, k)·L0/√2 with i, j, k in 0..=2·cells and i+j+k
/// even, in x-fastest order (`discretise::fcc::FccLattice` unrotated in a cube of side
/// cells·a), with the weighted dilatation the lattice runs with; every particle the bulk
/// volume (√2/2)·L0³ and the bulk moduli of E = 30 GPa, ν = 0.2
/// (`discretise::fcc::bulk_moduli`).
pub fn fcc_block(cells: usize, l0: f64) -> Particles<3, 18> {
    use crate::discretise::fcc::FccLattice;
    use crate::run::generate::moduli::bulk_moduli;
    let side = cells as f64 * 2f64.sqrt() * l0;
    let mut p = FccLattice {
        spacing: l0,
        rotation_deg: [0.0; 3],
        offset: Vector3::zeros(),
    }
    .fill(&crate::geometry::Shape3::Box {
        origin: Vector3::zeros(),
        size: Vector3::repeat(side),
    });
    debug_assert_eq!(p.len(), fcc_block_len(cells));
    let n = p.len();
    let mm = bulk_moduli(30e9, 0.2, l0);
    p.a = vec![mm.a; n];
    p.b = vec![mm.b; n];
    p.c = vec![mm.c; n];
    p
}

/// `sppm bench --dim 3`: the elastic slot kernel (bond dampers on, as in 2D) on the FCC cube
/// of [`fcc_block`] nearest `particles` particles, under a homogeneous strain of 1e-4; or a
/// damage kernel (`tension`, `full`) with the Table 1 concrete of Nikravesh Kazeroni (2017) under a triaxial strain
/// of 0.9e-4 (the principal stress E·ε/(1 − 2ν) is 1.72·f't), so that, as in 2D, every
/// particle initiates in the first step and then softens.
pub fn bench_fcc(
    particles: usize,
    steps: usize,
    threads: usize,
    kernel: KernelSet,
    simd: bool,
) -> anyhow::Result<BenchResult> {
    let l0 = 1e-3;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let p = fcc_block(fcc_cells(particles), l0);
    let n = p.len();
    let (mech, mut st) = strained_model(&p, kernel);
    assert!(mech.second.is_some());
    let dt = 0.9 * pool.install(|| crate::solver::time_step::stable_step(&mech, &p.x0).dt_stable);
    let mut model = damage_model(&p, kernel, simd)?;
    drop(p);
    let seconds = timed(&pool, steps, || {
        match model.as_mut() {
            Some(c) => c.step(&mech, &mut st, dt, false, true),
            None => kernel::step::<3, 18, false, true>(&mech, &mut st, dt),
        }
        std::mem::swap(&mut st.x, &mut st.x_next);
        std::mem::swap(&mut st.v, &mut st.v_next);
    });
    Ok(BenchResult {
        particles: n,
        steps,
        threads,
        model: kernel.name().into(),
        particle_steps_per_s: (n * steps) as f64 / seconds,
        seconds,
        lattice: "fcc".into(),
        bytes_per_particle: bytes_per_particle(kernel, 3),
        simd,
        setup: None,
    })
}

/// `sppm bench --dim 3 --lattice random`: random particles (SPPM, `discretise::random3`) in a
/// cube of about `particles` particles at the FCC density (L0 = 1 mm, seed 1), with each
/// particle's least-squares (a, b) for E = 30 GPa, ν = 0.2; the elastic slot kernel (bond
/// dampers on) under a homogeneous strain of 1e-4, or a damage kernel (`tension`, `full`) set
/// up as [`bench_fcc`] sets it up (the Table 1 concrete under a triaxial strain of 0.9e-4, so
/// that every particle initiates in the first step; each particle's own criteria strain, not
/// the neighbourhood mean the random scenes read). The set-up's seconds (placement, clipped
/// Voronoi cells, bonds, moduli) are reported beside the throughput.
pub fn bench_random3(
    particles: usize,
    steps: usize,
    threads: usize,
    kernel: KernelSet,
    simd: bool,
) -> anyhow::Result<BenchResult> {
    use crate::discretise::random3::{self, RandomSolid, SLOTS_3D};
    let l0 = 1e-3;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let side = (particles as f64 * 0.5 * 2f64.sqrt()).cbrt() * l0;
    let shape = crate::geometry::Shape3::Box {
        origin: Vector3::zeros(),
        size: Vector3::repeat(side),
    };
    let recipe = RandomSolid {
        spacing: l0,
        min_distance: random::DEFAULT_MIN_DISTANCE,
        seed: 1,
        rotation_deg: [0.0; 3],
    };
    let (p, setup) = pool.install(|| -> anyhow::Result<_> {
        let (mut p, g) = random3::fill::<SLOTS_3D>(&shape, &recipe)
            .map_err(|e| anyhow::anyhow!("random particles: {e}"))?;
        let d =
            <crate::model::dimension::Dim<3> as crate::model::dimension::Dimension<3>>::elasticity(
                30e9,
                0.2,
                Plane::Stress,
            );
        let setup = fitted(&mut p, &g, |p, a, b| {
            crate::run::generate::moduli::fit_moduli_3d(p, &d, a, b)
        })?;
        Ok((p, setup))
    })?;
    let n = p.len();
    let (mech, mut st) = strained_model(&p, kernel);
    let dt = 0.9 * pool.install(|| crate::solver::time_step::stable_step(&mech, &p.x0).dt_stable);
    let mut model = damage_model(&p, kernel, simd)?;
    drop(p);
    let seconds = timed(&pool, steps, || {
        match model.as_mut() {
            Some(c) => c.step(&mech, &mut st, dt, false, true),
            None => kernel::step::<3, SLOTS_3D, false, true>(&mech, &mut st, dt),
        }
        std::mem::swap(&mut st.x, &mut st.x_next);
        std::mem::swap(&mut st.v, &mut st.v_next);
    });
    let damage_bytes = match kernel {
        KernelSet::Elastic => 0,
        _ => crate::solver::inelastic::bytes_per_particle(3, SLOTS_3D),
    };
    Ok(BenchResult {
        particles: n,
        steps,
        threads,
        model: kernel.name().into(),
        particle_steps_per_s: (n * steps) as f64 / seconds,
        seconds,
        lattice: "random".into(),
        bytes_per_particle: crate::discretise::bytes_per_particle(3, SLOTS_3D) + damage_bytes,
        simd,
        setup: Some(setup),
    })
}

/// Seconds `steps` calls of `one_step` take on `pool`, after two untimed ones.
fn timed(pool: &rayon::ThreadPool, steps: usize, mut one_step: impl FnMut() + Send) -> f64 {
    pool.install(|| {
        for _ in 0..2 {
            one_step();
        }
        let t = Instant::now();
        for _ in 0..steps {
            one_step();
        }
        t.elapsed().as_secs_f64()
    })
}
