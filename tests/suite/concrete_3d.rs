//! The concrete kernel and the two-spring law run in 3D from the same source as in 2D
//! (dimension as a type): on a small 3D body under a uniform uniaxial strain
//! ε_xx, Rankine initiation happens exactly where the 3D isotropic stress
//! σ_xx = E(1−ν)/((1+ν)(1−2ν))·ε_xx reaches f't, and the initiation strain recorded is ε_xx.
//!
//! The body is a 4×4×4 simple-cubic block with 18 slots per particle (6 nearest neighbours
//! and 12 face diagonals), built here: the test needs only a body whose bonds span 3D.
//!
//! On the FCC lattice the damage kernel carries the second-neighbour modulus
//! a + c (docs/model.md §3 erratum) and the weighted dilatation: undamaged, its forces are the
//! elastic kernel's; damaged, its energy is the potential of its forces.

use nalgebra::Vector3;
use sppm::discretise::{Particles, NONE};
use sppm::model::damage::ConcreteLaw;
use sppm::model::two_spring::TwoSpring;
use sppm::scene::{CrackOpening, Initiation, Plane};
use sppm::solver::inelastic::{self, DamageKernel};
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
        softening_stress: sppm::scene::SofteningStress::Strain,
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
        let mut c: DamageKernel<3, 18> = DamageKernel::new(TwoSpring::new(l, None), &p);
        inelastic::internal_forces(&m, &mut c, &x);
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

/// An FCC block (18 slots, second neighbours in 12..18 with modulus a + c, weighted
/// dilatation) with clipped cells and fitted boundary moduli, as `sppm run` builds it.
fn fcc_block() -> (Particles<3, 18>, Mechanics<3, 18>) {
    use sppm::discretise::fcc::FccLattice;
    use sppm::geometry::Shape3;
    let shape = Shape3::Box {
        origin: Vector3::zeros(),
        size: Vector3::new(0.05, 0.045, 0.055),
    };
    let mut p = FccLattice {
        spacing: L0,
        rotation_deg: [25.0, 15.0, 5.0],
        offset: Vector3::new(0.001, 0.002, 0.0),
    }
    .fill(&shape);
    p.volume = sppm::discretise::voronoi3::fcc_clipped_volumes(&p, &shape);
    sppm::run::generate::moduli::assign_moduli(&mut p, law().e, law().nu);
    let m = Mechanics::new(&p, &vec![2400.0; p.len()]);
    assert!(m.second.is_some() && m.dilatation_weight.is_some());
    (p, m)
}

/// A deterministic pseudo-random number in [0, 1) (no test depends on its quality).
fn hash01(i: usize, k: usize) -> f64 {
    let mut z = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (k as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z ^= z >> 31;
    z = z.wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 29;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// Positions under a strain of about f't/E with a random part, so that bonds are stretched
/// and shortened.
fn strained(p: &Particles<3, 18>) -> Vec<Vector3<f64>> {
    let eps = 1e-4;
    p.x0.iter()
        .enumerate()
        .map(|(i, x)| {
            let r = Vector3::new(hash01(i, 0), hash01(i, 1), hash01(i, 2)) - Vector3::repeat(0.5);
            Vector3::new(
                x.x * (1.0 + eps),
                x.y * (1.0 - 0.3 * eps),
                x.z * (1.0 + 0.5 * eps),
            ) + r * (eps * L0)
        })
        .collect()
}

/// docs/model.md §3 erratum in the damage kernel: without damage its forces on the FCC lattice are
/// the elastic kernel's (second-neighbour bonds at a + c), to round-off; with damage fixed,
/// its energy is the potential of its forces (−∂U/∂x_i = f_i by central differences), so the
/// energy balance of a 3D run closes.
#[test]
fn fcc_damage_kernel_carries_the_second_neighbour_modulus() {
    use sppm::solver::kernel::{particle_force, pass_dilatation};
    let (p, m) = fcc_block();
    let n = p.len();
    let x = strained(&p);
    let mut strong = law();
    (strong.ft, strong.fc) = (1e12, 1e13);
    let mut c: DamageKernel<3, 18> = DamageKernel::new(TwoSpring::new(strong, None), &p);
    let f = inelastic::internal_forces(&m, &mut c, &x);
    let mut bt = vec![0.0; n];
    pass_dilatation(&m, &x, &mut bt);
    let v = vec![Vector3::zeros(); n];
    let scale = f.iter().map(|f| f.norm()).fold(0.0, f64::max);
    assert!(scale > 0.0);
    for (i, fi) in f.iter().enumerate() {
        let fe = particle_force::<3, 18, false>(&m, &x, &v, &bt, i).0;
        assert!(
            (fi - fe).norm() <= 1e-12 * scale,
            "particle {i}: damage kernel {fi:?}, elastic kernel {fe:?}"
        );
    }
    // with c left out the forces differ: the test sees the modulus
    let mut without = m.clone();
    without.second = None;
    let mut c0: DamageKernel<3, 18> = DamageKernel::new(TwoSpring::new(strong, None), &p);
    let f0 = inelastic::internal_forces(&without, &mut c0, &x);
    let diff = f
        .iter()
        .zip(&f0)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(diff > 0.1 * scale, "{diff} against {scale}");

    // damage of every kind, fixed: the energy is the potential of the force
    let mut c: DamageKernel<3, 18> = DamageKernel::new(TwoSpring::new(law(), None), &p);
    for (i, s) in c.committed.iter_mut().enumerate() {
        s.wt = match i % 5 {
            0 | 1 => 0.0,
            2 => 1.0,
            _ => hash01(i, 7),
        };
        s.initiated = s.wt > 0.0;
        s.eps_init = 1e-4;
    }
    assert!(c.committed.iter().any(|s| s.wt > 0.0 && s.wt < 1.0));
    let f = inelastic::internal_forces(&m, &mut c, &x);
    let energy = |xs: &[Vector3<f64>]| inelastic::internal_energy(&m, &c, xs);
    // A bond's factor switches where its stretch changes sign (w_t acts only in tension), and
    // there a broken bond's force jumps: leave out particles with a bond within 100·h/L0 of
    // zero stretch.
    let h = 1e-11;
    let near_zero = |i: usize| {
        (0..18).any(|k| {
            let j = p.neighbours[i][k];
            j != NONE && ((x[j as usize] - x[i]).norm() / p.l0[i][k] - 1.0).abs() < 100.0 * h / L0
        })
    };
    let mut checked = 0;
    for i in (0..n).step_by(n / 13).filter(|&i| !near_zero(i)) {
        for k in 0..3 {
            let (mut xp, mut xm) = (x.clone(), x.clone());
            xp[i][k] += h;
            xm[i][k] -= h;
            let du = (energy(&xp) - energy(&xm)) / (2.0 * h);
            assert!(
                (du + f[i][k]).abs() <= 1e-5 * f[i].norm().max(1e-3 * scale),
                "particle {i} component {k}: −dU/dx = {} against f = {}",
                -du,
                f[i][k]
            );
        }
        checked += 1;
    }
    assert!(checked >= 11);
}

/// docs/model.md §9, (S.21): on the FCC lattice the plastic flow moves a bulk particle's bond
/// stretches as a plastic strain would, n·Δε_p·n on every bond, nearest and second neighbours
/// alike, with Δε_p deviatoric and along the deviatoric strain (von Mises' normal). Under a
/// homogeneous uniaxial compression past the yield stress, one kernel pass gives each bulk
/// particle 18 plastic stretch increments that a single symmetric tensor fits to the
/// stretches' second order (a relative O(e), e = 1.2e-3 the strain).
/// The force states' deviator (3.44) would give the second neighbours, whose modulus is a + c
/// ≈ 0.35·a, about 0.35 × the plastic stretch of a nearest neighbour at the same strain.
#[test]
fn fcc_plastic_flow_is_a_plastic_strain_on_both_bond_families() {
    use nalgebra::Matrix3;
    use sppm::model::dimension::{Dim, Dimension};
    let (p, m) = fcc_block();
    let mut l = law();
    (l.tensile_damage, l.compressive_damage, l.plasticity) = (false, false, true);
    let e = 1.2e-3; // σ_zz = −E·e = −36 MPa, past F_eff ≈ 27 MPa
    let eps = Matrix3::from_diagonal(&Vector3::new(l.nu * e, l.nu * e, -e));
    let x: Vec<Vector3<f64>> = p.x0.iter().map(|x0| x0 + eps * x0).collect();
    let mut c: DamageKernel<3, 18> = DamageKernel::new(TwoSpring::new(l, None), &p);
    inelastic::internal_forces(&m, &mut c, &x);
    c.commit();
    let dev = eps - Matrix3::identity() * (eps.trace() / 3.0);
    // a bond's stretch is n·ε·n to first order in e: relative departures of O(e)
    let tol = 4.0 * e;
    let mut checked = 0;
    for i in (0..p.len()).filter(|&i| p.bond_count(i) == 18) {
        // the kernel's own least-squares strain fit (S.11) of the 18 increments
        let ep = Dim::<3>::strain_tensor(&c.fit[i], &c.sps[i]);
        let (mut residual, mut norm) = (0.0, 0.0);
        for k in 0..18 {
            let n = (p.x0[p.neighbours[i][k] as usize] - p.x0[i]).normalize();
            residual += (n.dot(&(ep * n)) - c.sps[i][k]).powi(2);
            norm += c.sps[i][k].powi(2);
        }
        let (residual, norm) = (residual.sqrt(), norm.sqrt());
        assert!(norm > 1e-6, "particle {i} did not flow: {norm}");
        assert!(
            residual <= tol * norm,
            "particle {i}: residual {residual} of {norm}"
        );
        assert!(
            ep.trace().abs() <= tol * ep.norm(),
            "particle {i}: tr Δε_p = {}",
            ep.trace()
        );
        // along the deviatoric strain, and shortening along the load
        let cos = (ep.component_mul(&dev)).sum() / (ep.norm() * dev.norm());
        assert!(
            cos > 1.0 - tol * tol && ep[(2, 2)] < 0.0,
            "particle {i}: cos {cos}, {ep}"
        );
        checked += 1;
    }
    assert!(checked >= 20, "{checked} bulk particles");
}

/// The acceptance for 3D concrete on the shipped tension prism (150 × 150 × 300 mm,
/// Table 1 concrete) at L0 = 15 mm: the peak within ±5% of f't·A, the dissipated energy
/// within ±10% of G_f·A (the FCC crack band is calibrated on this prism at 10 and 15 mm,
/// benchmarks/RESULTS.md "The effective stress as the 3D default"), kinetic/internal energy
/// ≤ 5% up to the peak, and one crack normal to the load across the whole section, in the
/// middle 60% of the height.
#[test]
#[cfg_attr(
    not(feature = "validation"),
    ignore = "validation: cargo test --release --features validation"
)]
fn tension_prism_reaches_ft_dissipates_gf_and_cracks_across() {
    use sppm::run::{run, RunOptions};
    let scene = sppm::Scene::from_file(
        std::path::Path::new("lattices/tension_prism_3d.toml"),
        &["discretisation.spacing=0.015".to_string()],
    )
    .unwrap();
    let out = run(&scene, &RunOptions::default()).unwrap();
    let s = &out.summary;
    let v = |k: &str| {
        s.material_values
            .iter()
            .find(|d| d.key == k)
            .unwrap_or_else(|| panic!("{k}"))
            .value
    };
    let area = 0.15 * 0.15;
    let peak = s.peak_force_n / (v("ft") * area);
    let energy = s.dissipated_energy_j / (v("Gf") * area);
    println!("FCC tension prism 15 mm: peak {peak:.4} × f't·A, energy {energy:.4} × G_f·A");
    assert!((0.95..=1.05).contains(&peak), "peak {peak} × f't·A");
    assert!((0.90..=1.10).contains(&energy), "energy {energy} × G_f·A");
    assert!(
        s.max_kinetic_to_internal_energy <= 0.05,
        "K/U {}",
        s.max_kinetic_to_internal_energy
    );
    // the broken particles: one band normal to z, across the whole section
    let damage = out.damage.as_ref().unwrap();
    let broken: Vec<[f64; 3]> = (0..damage.len())
        .filter(|&i| damage[i].wt >= 0.99)
        .map(|i| out.x0[i])
        .collect();
    assert!(!broken.is_empty());
    let range = |d: usize| {
        let lo = broken.iter().map(|x| x[d]).fold(f64::INFINITY, f64::min);
        let hi = broken
            .iter()
            .map(|x| x[d])
            .fold(f64::NEG_INFINITY, f64::max);
        hi - lo
    };
    let l0 = 0.015;
    assert!(
        range(2) <= 3.0 * l0,
        "the crack band spans {} m in z",
        range(2)
    );
    for d in 0..2 {
        assert!(
            range(d) >= 0.15 - 2.0 * l0,
            "the crack spans {} m of 0.15 m",
            range(d)
        );
    }
    // as the objectivity study counts cracks across the load axis: one, in the middle 60% of
    // the height, away from the platens (a test that breaks at a platen is discarded)
    let wt: Vec<f64> = damage.iter().map(|p| p.wt).collect();
    let bands = sppm::study::crack_bands::crack_bands(
        &out.x0,
        &wt,
        sppm::study::crack_path::CRACK_PATH_DAMAGE,
        2,
        l0,
    );
    let across: Vec<_> = bands.iter().filter(|b| b.crosses()).collect();
    assert_eq!(across.len(), 1, "{bands:?}");
    let (lo, hi) = sppm::study::objectivity::MIDDLE_SHARE;
    assert!(
        (lo..=hi).contains(&across[0].share),
        "the crack at {} of the height",
        across[0].share
    );
}

/// `sets` particle sets of a shipped scene on random particles (the scene's seed and the
/// study's further realisations, as `sppm study objectivity --offsets` draws them), with
/// semi-implicit bond dampers (docs/model.md §5) to keep the runs to minutes: the resolved
/// scene, the study's report and its folder (each run's outputs in `a0_o<k>/`; the caller
/// removes it).
fn random_sets(
    scene: &str,
    overrides: &[&str],
    sets: usize,
) -> (
    sppm::Scene,
    sppm::study::objectivity::ObjectivityReport,
    std::path::PathBuf,
) {
    use sppm::study::objectivity::{objectivity, ObjectivityArgs};
    let overrides: Vec<String> = [
        "discretisation.lattice=random",
        "damping.bond_scheme=semi_implicit",
    ]
    .iter()
    .chain(overrides)
    .map(|s| s.to_string())
    .collect();
    let scene_file = std::path::PathBuf::from(scene);
    let resolved = sppm::Scene::from_file(&scene_file, &overrides).unwrap();
    let dir = std::env::temp_dir().join(format!(
        "sppm-sets-{}-{}",
        resolved.name(),
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    let report = objectivity(&ObjectivityArgs {
        scene: scene_file,
        angles_deg: vec![0.0],
        axis: 'z',
        offsets: sets - 1,
        seed: sppm::study::objectivity::DEFAULT_SEED,
        crack_damage: sppm::study::crack_path::CRACK_PATH_DAMAGE,
        overrides,
        out: Some(dir.clone()),
        jobs: 2,
        progress: false,
    })
    .unwrap();
    assert_eq!(report.completed, sets);
    (resolved, report, dir)
}

/// The mean of `f` over a study's rows.
fn mean_of(
    report: &sppm::study::objectivity::ObjectivityReport,
    f: impl Fn(&sppm::study::RunRow) -> f64,
) -> f64 {
    report.rows.iter().map(f).sum::<f64>() / report.rows.len() as f64
}

/// The direct-tension acceptance on random particles: the shipped tension prism (150 × 150 ×
/// 300 mm, Table 1 concrete) at L0 = 15 mm in ten particle sets. The mean peak within ±5% of
/// f't·A, the mean dissipated energy within ±10% of G_f·A, and at least nine of the ten
/// broken by one crack across the section in the middle 60% of the height (a test that
/// breaks nearer a platen is discarded); the study counts the cracks (`study::crack_bands`).
#[test]
#[cfg_attr(
    not(feature = "validation"),
    ignore = "validation: cargo test --release --features validation"
)]
fn random_tension_prisms_break_once_in_the_middle_at_ft_and_gf() {
    use sppm::study::objectivity::{CRACK_COLUMNS, MIDDLE_SHARE};
    let (scene, report, dir) = random_sets(
        "lattices/tension_prism_3d.toml",
        &["discretisation.spacing=0.015"],
        10,
    );
    let _ = std::fs::remove_dir_all(&dir);
    let v = |k: &str| scene.derived.iter().find(|d| d.key == k).unwrap().value;
    let area = 0.15 * 0.15;
    let peak = mean_of(&report, |r| r.peak_force_n) / (v("ft") * area);
    let energy = mean_of(&report, |r| r.dissipated_energy_j) / (v("Gf") * area);
    println!("random tension prisms: mean peak {peak:.4} × f't·A, energy {energy:.4} × G_f·A");
    assert!((0.95..=1.05).contains(&peak), "mean peak {peak} × f't·A");
    assert!(
        (0.90..=1.10).contains(&energy),
        "mean energy {energy} × G_f·A"
    );
    let col = |name: &str| CRACK_COLUMNS.iter().position(|c| *c == name).unwrap();
    let (n, share) = (col("cracks_across"), col("crack_across_share"));
    let once_in_the_middle = report
        .rows
        .iter()
        .filter(|r| {
            r.metrics[n] == 1.0 && (MIDDLE_SHARE.0..=MIDDLE_SHARE.1).contains(&r.metrics[share])
        })
        .count();
    assert!(
        once_in_the_middle >= 9,
        "{once_in_the_middle} of 10 with one crack in the middle: {:?}",
        report
            .rows
            .iter()
            .map(|r| (r.metrics[n], r.metrics[share]))
            .collect::<Vec<_>>()
    );
}

/// The splitting acceptance on random particles: the shipped split cylinder (D = 150 mm,
/// L = 300 mm, Table 5 concrete, 10 mm) with bearing strips b = D/12 (ASTM C496 and EN
/// 12390-6 use strips of about that width) in five particle sets. The mean peak over
/// π·L·D·f't/2 within [0.95, 1.25] (splitting tests give 0.95–1.28 times the direct tensile
/// strength; EC2 and Model Code 1990 take f_ct = 0.9·f_ct,sp, a ratio of 1.11), and in each
/// set the crack on the loaded diameter: the particles with w_t ≥ 0.9 away from the strips
/// (within 50 mm of the axis, of the 75 mm radius) lie within one spacing of the plane x = 0
/// (RMS).
#[test]
#[cfg_attr(
    not(feature = "validation"),
    ignore = "validation: cargo test --release --features validation"
)]
fn random_split_cylinders_split_on_the_loaded_diameter_at_ft() {
    let (scene, report, dir) = random_sets(
        "lattices/split_cylinder_3d.toml",
        &[
            "groups.bottom_strip.select.width=0.0125",
            "groups.top_strip.select.width=0.0125",
        ],
        5,
    );
    let ft = scene.derived.iter().find(|d| d.key == "ft").unwrap().value;
    let ratio =
        mean_of(&report, |r| r.peak_force_n) / (std::f64::consts::PI * 0.3 * 0.15 * ft / 2.0);
    let spacing = scene.discretisation.spacing;
    let mut rms = vec![];
    for k in 0..5 {
        let mut reader =
            csv::Reader::from_path(dir.join(format!("a0_o{k}/particles.csv"))).unwrap();
        let h = reader.headers().unwrap().clone();
        let col = |name: &str| h.iter().position(|c| c == name).unwrap();
        let (x, y, wt) = (col("x_m"), col("y_m"), col("tensile_damage"));
        let xs: Vec<f64> = reader
            .records()
            .map(|r| r.unwrap())
            .map(|r| {
                [
                    r[x].parse::<f64>().unwrap(),
                    r[y].parse().unwrap(),
                    r[wt].parse().unwrap(),
                ]
            })
            .filter(|p| p[2] >= sppm::study::crack_path::CRACK_PATH_DAMAGE && p[1].abs() < 0.05)
            .map(|p| p[0])
            .collect();
        assert!(!xs.is_empty(), "set {k}: no crack");
        rms.push((xs.iter().map(|x| x * x).sum::<f64>() / xs.len() as f64).sqrt());
    }
    let _ = std::fs::remove_dir_all(&dir);
    println!("random split cylinders: mean peak {ratio:.4} × π·L·D·f't/2, crack RMS {rms:?} m");
    assert!(
        (0.95..=1.25).contains(&ratio),
        "mean peak {ratio} × π·L·D·f't/2"
    );
    assert!(
        rms.iter().all(|&r| r <= spacing),
        "RMS distance of the crack from the loaded diameter: {rms:?} m"
    );
}

/// The compression acceptance on random particles: the shipped compression prism (150 × 150 ×
/// 300 mm, Table 1 concrete, 10 mm) in three particle sets between sliding platens reaches
/// f'c·A within ±10% on average (a prism with h/b = 2 reaches about f'c), and between
/// gripping platens (both ends also held in x and y) carries more (they confine the ends).
#[test]
#[cfg_attr(
    not(feature = "validation"),
    ignore = "validation: cargo test --release --features validation"
)]
fn random_compression_prisms_reach_fc_and_gripping_platens_carry_more() {
    let (scene, sliding, dir) = random_sets("lattices/compression_prism_3d.toml", &[], 3);
    let _ = std::fs::remove_dir_all(&dir);
    let (_, gripping, dir) = random_sets(
        "lattices/compression_prism_3d.toml",
        &[
            r#"groups.bottom.fix=["x","y","z"]"#,
            r#"groups.top.fix=["x","y"]"#,
        ],
        3,
    );
    let _ = std::fs::remove_dir_all(&dir);
    let fc = scene.derived.iter().find(|d| d.key == "fc").unwrap().value;
    let reference = fc * 0.15 * 0.15;
    let slide = mean_of(&sliding, |r| r.peak_force_n) / reference;
    let grip = mean_of(&gripping, |r| r.peak_force_n) / reference;
    println!("random compression prisms: sliding {slide:.4}, gripping {grip:.4} × f'c·A");
    assert!(
        (0.9..=1.1).contains(&slide),
        "sliding platens: {slide} × f'c·A"
    );
    assert!(
        grip > slide,
        "gripping {grip} against sliding {slide} × f'c·A"
    );
}

/// The peak of `lattices/compression_prism_3d.toml` with `set`, over f'c·A (27.58 MPa on
/// 150 × 150 mm); the run must complete.
fn compression_prism_peak(set: &[&str]) -> f64 {
    use sppm::run::{run, RunOptions};
    let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
    let scene = sppm::Scene::from_file(
        std::path::Path::new("lattices/compression_prism_3d.toml"),
        &set,
    )
    .unwrap();
    let s = run(&scene, &RunOptions::default()).unwrap().summary;
    assert_eq!(s.status, "completed");
    s.peak_force_n.abs() / (27.58e6 * 0.15 * 0.15)
}

/// The compression prism (150 × 150 × 300 mm, Table 1 concrete) between platens free to
/// slide, its criteria read over the neighbourhood (`concrete.criteria_strain`, docs/model.md
/// §7): its peak at the shipped 10 mm and at 15 mm within 5% of each other (the acceptance
/// for 3D concrete), and platens that grip carry more than sliding ones (they confine the
/// ends; EC2's cube/cylinder ratio is about 1.2). With each particle's own criteria strain
/// (the lattices' default) the two spacings are 11% apart (0.875 and 0.784 × f'c·A), the
/// prism cracking from its edges; benchmarks/RESULTS.md, "Criteria over the neighbourhood on
/// lattices".
#[test]
#[cfg_attr(
    not(feature = "validation"),
    ignore = "validation: cargo test --release --features validation"
)]
fn compression_prism_converges_and_gripping_platens_carry_more() {
    let peak = |set: &[&str]| {
        let mut set: Vec<&str> = set.to_vec();
        set.push("concrete.criteria_strain=\"neighbourhood\"");
        compression_prism_peak(&set)
    };
    let coarse = ["discretisation.spacing=0.015"];
    let (p10, p15) = (peak(&[]), peak(&coarse));
    let gripped = peak(&[
        coarse[0],
        r#"groups.bottom.fix=["x","y","z"]"#,
        r#"groups.top.fix=["x","y"]"#,
    ]);
    println!("compression peaks / f'c·A: 10 mm {p10:.4}, 15 mm {p15:.4}, gripped {gripped:.4}");
    assert!((p15 / p10 - 1.0).abs() <= 0.05, "10 mm {p10}, 15 mm {p15}");
    assert!(gripped > p15, "gripped {gripped}, sliding {p15}");
}

/// The FCC compression prism with each particle's own criteria strain (the lattices'
/// default) and the 3D law's defaults, (4.14) softening the effective principal stress σ̃_I
/// at that stress's opening ((S.22), (S.23), docs/model.md §8): the edges still initiate
/// first, but a compressed particle no longer takes tensile damage from its Poisson expansion
/// alone, and the prism with sliding platens reaches the laboratory's f'c·A within ±10% at the
/// shipped 10 mm, and within 5% of that at 15 mm (measured 0.916 and 0.930). With (4.14) as
/// written it peaks at 0.875 and 0.784 (benchmarks/RESULTS.md, "The effective stress as the 3D
/// default").
#[test]
#[cfg_attr(
    not(feature = "validation"),
    ignore = "validation: cargo test --release --features validation"
)]
fn compression_prism_reaches_fc_between_sliding_platens() {
    let peak =
        |spacing: &str| compression_prism_peak(&[&format!("discretisation.spacing={spacing}")]);
    let (p10, p15) = (peak("0.01"), peak("0.015"));
    println!("compression peaks / f'c·A: 10 mm {p10:.4}, 15 mm {p15:.4}");
    assert!((p10 - 1.0).abs() <= 0.10, "10 mm {p10}");
    assert!((p15 / p10 - 1.0).abs() <= 0.05, "10 mm {p10}, 15 mm {p15}");
}

/// The interaction criterion in 3D on the FCC lattice (clipped cells, fitted boundary
/// moduli, second-neighbour modulus): under the homogeneous stress σ = diag(σ1, 0, σ3) with
/// σ1 = s·f't/2 and σ3 = −s·f'c/2, σ1/f't − σ3/f'c = s, so every particle initiates at s = 1
/// and none below (to the finite stretches' second order), and the recorded initiation strain
/// is the largest principal strain ε1 = (σ1 − ν·σ3)/E.
#[test]
fn interaction_initiation_on_the_fcc_lattice() {
    let (p, m) = fcc_block();
    let mut l = law();
    l.initiation = Initiation::Interaction;
    for (s, expect) in [(0.98, false), (1.02, true)] {
        let (s1, s3) = (0.5 * s * l.ft, -0.5 * s * l.fc);
        let e1 = (s1 - l.nu * s3) / l.e;
        let e2 = -l.nu * (s1 + s3) / l.e;
        let e3 = (s3 - l.nu * s1) / l.e;
        let x: Vec<_> =
            p.x0.iter()
                .map(|x| Vector3::new(x.x * (1.0 + e1), x.y * (1.0 + e2), x.z * (1.0 + e3)))
                .collect();
        let mut c: DamageKernel<3, 18> = DamageKernel::new(TwoSpring::new(l, None), &p);
        inelastic::internal_forces(&m, &mut c, &x);
        c.commit();
        for (i, d) in c.damage().iter().enumerate() {
            assert_eq!(d.initiated, expect, "particle {i} at s = {s}");
            if expect {
                assert!(
                    (d.eps_init - e1).abs() <= 5e-3 * e1,
                    "particle {i}: ε_init {} against {e1}",
                    d.eps_init
                );
            }
        }
    }
}

/// On a law without compressive damage and plasticity the tension kernel (docs/model.md §17,
/// "Kernel sets") gives the full kernel's states and forces bit for bit on the FCC lattice
/// through loading, unloading and reloading: its largest principal strain alone is the full
/// kernel's ε1, damage held while the strain falls and growing again past its maximum.
#[test]
fn tension_kernel_matches_the_full_kernel_in_3d_through_unloading() {
    use sppm::solver::KernelSet;
    let (p, m) = fcc_block();
    let strained = strained(&p);
    // multiples of the strain of `strained`: initiation near 0.86, softening, unloading,
    // reloading past the earlier maximum
    let path = [
        0.5, 1.0, 1.5, 2.0, 2.5, 2.0, 1.5, 1.8, 2.2, 2.5, 2.8, 2.0, 1.0,
    ];
    let mut runs = Vec::new();
    for force_full in [false, true] {
        let mut c: DamageKernel<3, 18> = DamageKernel::new(TwoSpring::new(law(), None), &p);
        c.force_full = force_full;
        let mut history = Vec::new();
        for s in path {
            let x: Vec<Vector3<f64>> =
                p.x0.iter()
                    .zip(&strained)
                    .map(|(x0, x1)| x0 + (x1 - x0) * s)
                    .collect();
            let f = inelastic::internal_forces(&m, &mut c, &x);
            c.commit();
            history.push((f, c.committed.to_vec()));
        }
        runs.push((c.kernel(), history));
    }
    assert_eq!(runs[0].0, KernelSet::Tension);
    assert_eq!(runs[1].0, KernelSet::Full);
    // damage grew while loading and held while unloading
    let damaged = |step: usize| {
        runs[0].1[step]
            .1
            .iter()
            .filter(|d| d.wt > 0.0 && d.wt < 1.0)
            .count()
    };
    assert!(damaged(4) > p.len() / 2, "{} of {}", damaged(4), p.len());
    assert_eq!(
        runs[0].1[4].1, runs[0].1[6].1,
        "unloading changes no damage"
    );
    assert_ne!(
        runs[0].1[6].1, runs[0].1[10].1,
        "reloading past the maximum does"
    );
    for (step, ((ft, st), (ff, sf))) in runs[0].1.iter().zip(&runs[1].1).enumerate() {
        assert_eq!(st, sf, "states at step {step}");
        for (a, b) in ft.iter().zip(ff) {
            assert_eq!(
                a.map(f64::to_bits),
                b.map(f64::to_bits),
                "forces at step {step}"
            );
        }
    }
}

/// One parameter set (docs/validation.md; docs/model.md §13): every shipped 3D concrete scene
/// sets only the concrete's own properties (strengths, fracture energy, aggregate size or a
/// preset of them); the law's constants (crack band, softening shape, damage coupling,
/// ultimate strain, criteria) are the defaults, calibrated once on the tension prism.
#[test]
fn shipped_3d_concrete_scenes_share_one_law() {
    const OWN: [&str; 8] = [
        "preset",
        "fc",
        "ft",
        "fy",
        "fult",
        "Gf",
        "Gf0",
        "max_aggregate",
    ];
    let mut checked = 0;
    for entry in std::fs::read_dir("lattices").unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        if !name.ends_with("_3d") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let value: toml::Value = toml::from_str(&text).unwrap();
        let Some(concrete) = value.get("concrete").and_then(|c| c.as_table()) else {
            continue;
        };
        for key in concrete.keys() {
            assert!(
                OWN.contains(&key.as_str()),
                "{name} sets concrete.{key}: a law constant, not the concrete's own property"
            );
        }
        checked += 1;
    }
    assert!(checked >= 8, "{checked} 3D concrete scenes");
}
