//! Random-field material properties (docs/model.md §12): marginal moments, correlation at several
//! lags, seed reproducibility, independence of the lattice, white noise, parameter errors.
//!
//! Tolerances are 4 standard errors of the estimator from independent samples: one sample per
//! anchor point, anchors ≥ 6ℓ apart (exponential correlation ≤ e⁻⁶ = 0.0025 between anchors,
//! below 1/10 of a standard error), many realisations (seeds).

use nalgebra::Vector2;
use sppm::discretise::hex::HexLattice;
use sppm::geometry::Shape2;
use sppm::random_field::{
    weibull_cov, Correlation, FieldError, GaussianField, Marginal, NODES_PER_LENGTH,
};

const L: f64 = 0.016; // ℓ = 2·d_max for d_max = 8 mm

/// Mean and CoV of `x` with 4-standard-error tolerances: SE(mean) = s/√N and, by the delta
/// method, SE(CoV) ≈ CoV·√((m4/s⁴ − 1)/(4N) + CoV²/N) with m4 the fourth central moment.
fn check_moments(x: &[f64], mean: f64, cov: f64, what: &str) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0);
    let m4 = x.iter().map(|v| (v - m).powi(4)).sum::<f64>() / n;
    let s = var.sqrt();
    let c = s / m;
    let tol_mean = 4.0 * s / n.sqrt();
    let kurt = m4 / (var * var);
    let tol_cov = 4.0 * c * ((kurt - 1.0) / (4.0 * n) + c * c / n).sqrt();
    assert!(
        (m - mean).abs() < tol_mean,
        "{what}: mean {m} vs {mean} (tolerance {tol_mean})"
    );
    assert!(
        (c - cov).abs() < tol_cov,
        "{what}: CoV {c} vs {cov} (tolerance {tol_cov})"
    );
}

/// Independent standard normals: white noise (ℓ = 0) at distinct points.
fn white_normals(n: usize, seed: u64) -> Vec<f64> {
    let f =
        GaussianField::new(Correlation::Exponential, 0.0, [0.0, 0.0], [1.0, 1.0], seed).unwrap();
    (0..n)
        .map(|k| {
            let p = [(k % 1000) as f64 * 1e-3, (k / 1000) as f64 * 1e-3];
            f.value_at(p).unwrap()
        })
        .collect()
}

#[test]
fn white_noise_is_standard_normal() {
    // SE(mean) = 1/√N, SE(variance) = √(2/N) for a standard normal
    let g = white_normals(200_000, 7);
    let n = g.len() as f64;
    let m = g.iter().sum::<f64>() / n;
    let v = g.iter().map(|x| x * x).sum::<f64>() / n;
    assert!(m.abs() < 4.0 / n.sqrt(), "mean {m}");
    assert!((v - 1.0).abs() < 4.0 * (2.0 / n).sqrt(), "variance {v}");
}

#[test]
fn mapped_marginals_match_mean_and_cov() {
    let g = white_normals(200_000, 11);
    let (mean, cov) = (3.0e6, 0.2);
    let normal = Marginal::normal(mean, cov).unwrap();
    let x: Vec<f64> = g.iter().map(|&v| normal.map(v)).collect();
    check_moments(&x, mean, cov, "normal CoV 0.2");
    let ln = Marginal::lognormal(mean, 0.3).unwrap();
    let x: Vec<f64> = g.iter().map(|&v| ln.map(v)).collect();
    check_moments(&x, mean, 0.3, "lognormal CoV 0.3");
    let wb = Marginal::weibull(mean, 0.25).unwrap();
    let x: Vec<f64> = g.iter().map(|&v| wb.map(v)).collect();
    check_moments(&x, mean, 0.25, "Weibull CoV 0.25");
    let m = 12.0;
    let wm = Marginal::weibull_modulus(mean, m).unwrap();
    let x: Vec<f64> = g.iter().map(|&v| wm.map(v)).collect();
    check_moments(&x, mean, weibull_cov(m), "Weibull modulus 12");
}

#[test]
fn heavily_truncated_normal_is_nonnegative_with_the_truncated_mean() {
    // CoV 1: a = −1, Φ(a) = 0.159, truncated mean μ(1 + φ(1)/Φ(1)) = 1.2876·μ
    let g = white_normals(200_000, 13);
    let tn = Marginal::normal(1.0, 1.0).unwrap();
    let x: Vec<f64> = g.iter().map(|&v| tn.map(v)).collect();
    assert!(x.iter().all(|&v| v >= 0.0));
    let expected = Marginal::truncated_normal_mean(1.0, 1.0);
    assert!((expected - 1.287_600).abs() < 1e-5, "{expected}");
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let s = (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    assert!(
        (m - expected).abs() < 4.0 * s / n.sqrt(),
        "{m} vs {expected}"
    );
    // at CoV 0.3 the truncation shifts the mean by 4.6e-4 relative, as documented
    let shift = Marginal::truncated_normal_mean(1.0, 0.3) - 1.0;
    assert!((shift - 4.6e-4).abs() < 0.1e-4, "{shift}");
}

#[test]
fn weibull_modulus_from_cov_round_trips() {
    for m in [2.0, 5.0, 12.0, 30.0] {
        let c = weibull_cov(m);
        let Marginal::Weibull { modulus, .. } = Marginal::weibull(1.0, c).unwrap() else {
            panic!()
        };
        assert!((modulus - m).abs() < 1e-9 * m, "{modulus} vs {m}");
    }
    // modulus 2 is the Rayleigh distribution: CoV = √(4/π − 1) exactly
    let rayleigh = (4.0 / std::f64::consts::PI - 1.0).sqrt();
    assert!((weibull_cov(2.0) - rayleigh).abs() < 1e-12);
}

/// Empirical correlation at lags ℓ/2, ℓ, 2ℓ and unit variance at cell centres, both kernels.
/// Per realisation, 16 anchors on a 6ℓ lattice at grid-cell centres (where the interpolant's
/// variance is lowest) and, for each lag, one partner in a random direction. With known mean 0
/// and variance 1 the estimator r̂ = mean(X·Y) has SE √((1 + ρ²)/N); the variance estimator has
/// SE √(2/N); the paired difference of squares between a cell centre and its grid node is
/// sharper (SE from its sample spread). Also maps the anchors to a lognormal and checks its moments.
fn check_correlation(kernel: Correlation) {
    let realisations = 250u64;
    let lags = [0.5 * L, L, 2.0 * L];
    let h = L / NODES_PER_LENGTH as f64;
    let side = 24.0 * L;
    let mut prod = vec![Vec::new(); lags.len()];
    let mut anchors = Vec::new();
    let mut centre_minus_node = Vec::new();
    let mut pick = 0x1234_5678u64;
    let mut next = || {
        pick ^= pick << 13;
        pick ^= pick >> 7;
        pick ^= pick << 17;
        (pick >> 11) as f64 / (1u64 << 53) as f64
    };
    for seed in 0..realisations {
        let f = GaussianField::new(kernel, L, [0.0, 0.0], [side, side], 1000 + seed).unwrap();
        for a in 0..4 {
            for b in 0..4 {
                // cell centre near (3ℓ + 6ℓ·a, 3ℓ + 6ℓ·b)
                let p = [
                    ((3.0 + 6.0 * a as f64) * L / h).floor() * h + 0.5 * h,
                    ((3.0 + 6.0 * b as f64) * L / h).floor() * h + 0.5 * h,
                ];
                let x = f.value_at(p).unwrap();
                anchors.push(x);
                let node = [p[0] - 0.5 * h, p[1] - 0.5 * h];
                centre_minus_node.push(x * x - f.value_at(node).unwrap().powi(2));
                for (k, &r) in lags.iter().enumerate() {
                    let th = 2.0 * std::f64::consts::PI * next();
                    let q = [p[0] + r * th.cos(), p[1] + r * th.sin()];
                    prod[k].push(x * f.value_at(q).unwrap());
                }
            }
        }
    }
    let n = anchors.len() as f64;
    let mean = anchors.iter().sum::<f64>() / n;
    let var = anchors.iter().map(|v| v * v).sum::<f64>() / n;
    assert!(mean.abs() < 4.0 / n.sqrt(), "{kernel:?}: mean {mean}");
    assert!(
        (var - 1.0).abs() < 4.0 * (2.0 / n).sqrt(),
        "{kernel:?}: variance at cell centres {var}"
    );
    // paired: the cell centre has the variance of the adjacent grid node (whose value is the
    // embedded field itself); SE from the sample spread of the differences
    let d_mean = centre_minus_node.iter().sum::<f64>() / n;
    let d_sd = (centre_minus_node
        .iter()
        .map(|d| (d - d_mean).powi(2))
        .sum::<f64>()
        / (n - 1.0))
        .sqrt();
    assert!(
        d_mean.abs() < 4.0 * d_sd / n.sqrt(),
        "{kernel:?}: variance at cell centres minus at nodes {d_mean} (SE {})",
        d_sd / n.sqrt()
    );
    for (k, &r) in lags.iter().enumerate() {
        let rho = kernel.rho(r, L);
        let est = prod[k].iter().sum::<f64>() / n;
        let tol = 4.0 * ((1.0 + rho * rho) / n).sqrt();
        assert!(
            (est - rho).abs() < tol,
            "{kernel:?} lag {}ℓ: correlation {est} vs ρ = {rho} (tolerance {tol})",
            r / L
        );
    }
    let ln = Marginal::lognormal(40e-6, 0.2).unwrap();
    let x: Vec<f64> = anchors.iter().map(|&g| ln.map(g)).collect();
    check_moments(&x, 40e-6, 0.2, "lognormal over the correlated field");
}

#[test]
#[cfg_attr(
    not(feature = "validation"),
    ignore = "validation: cargo test --release --features validation"
)]
fn exponential_field_correlation_matches_at_several_lags() {
    check_correlation(Correlation::Exponential);
}

#[test]
#[cfg_attr(
    not(feature = "validation"),
    ignore = "validation: cargo test --release --features validation"
)]
fn squared_exponential_field_correlation_matches_at_several_lags() {
    check_correlation(Correlation::SquaredExponential);
}

#[test]
fn embedding_clips_a_negligible_share_of_the_spectrum() {
    for kernel in [Correlation::Exponential, Correlation::SquaredExponential] {
        for (w, hgt) in [(0.1, 0.15), (0.02, 0.02), (0.5, 0.3)] {
            let f = GaussianField::new(kernel, L, [0.0, 0.0], [w, hgt], 1).unwrap();
            let e = f.embedding().unwrap();
            assert!(
                e.clipped_fraction < 1e-6,
                "{kernel:?} {w}×{hgt}: clipped {e:?}"
            );
        }
    }
}

#[test]
fn same_seed_same_field_different_seed_different() {
    for kernel in [Correlation::Exponential, Correlation::SquaredExponential] {
        let b = ([0.0, 0.0], [0.1, 0.15]);
        let f1 = GaussianField::new(kernel, L, b.0, b.1, 42).unwrap();
        let f2 = GaussianField::new(kernel, L, b.0, b.1, 42).unwrap();
        let f3 = GaussianField::new(kernel, L, b.0, b.1, 43).unwrap();
        let pts: Vec<[f64; 2]> = (0..200)
            .map(|k| [0.0005 * k as f64, 0.15 - 0.0007 * k as f64])
            .collect();
        let (a, b2, c) = (
            f1.sample(&pts).unwrap(),
            f2.sample(&pts).unwrap(),
            f3.sample(&pts).unwrap(),
        );
        assert!(a.iter().zip(&b2).all(|(x, y)| x.to_bits() == y.to_bits()));
        assert!(a.iter().zip(&c).all(|(x, y)| x != y));
    }
}

fn lattice_points(spacing: f64, rotation_deg: f64, w: f64, h: f64) -> Vec<[f64; 2]> {
    let shape = Shape2::Rectangle {
        origin: Vector2::zeros(),
        width: w,
        height: h,
    };
    let lat = HexLattice {
        spacing,
        rotation_deg,
        offset: Vector2::new(0.3 * spacing, 0.1 * spacing),
        thickness: 0.1,
    };
    lat.fill(&shape).x0.iter().map(|x| [x[0], x[1]]).collect()
}

#[test]
fn value_at_a_point_does_not_depend_on_the_lattice() {
    // dog-bone-B-sized body; the field is built for the body's box, the lattice only samples it
    let (w, h) = (0.1, 0.15);
    let probe = [0.0371, 0.0823];
    for kernel in [Correlation::Exponential, Correlation::SquaredExponential] {
        let mut seen = Vec::new();
        for (spacing, rot) in [(4e-3, 0.0), (1e-3, 0.0), (2.5e-3, 30.0), (1.5e-3, 17.0)] {
            let mut pts = lattice_points(spacing, rot, w, h);
            assert!(pts.len() > 500);
            pts.insert(pts.len() / 2, probe);
            let f = GaussianField::new(kernel, L, [0.0, 0.0], [w, h], 99).unwrap();
            let v = f.sample(&pts).unwrap();
            seen.push(v[pts.len() / 2]);
        }
        assert!(
            seen.iter().all(|v| v.to_bits() == seen[0].to_bits()),
            "{seen:?}"
        );
    }
    // the grid depends on the box only through its snapped node range: boxes of the points of a
    // coarse and a fine lattice inside the body give the very same field
    let bbox = |p: &[[f64; 2]]| {
        p.iter().fold(
            ([f64::MAX, f64::MAX], [f64::MIN, f64::MIN]),
            |(lo, hi), q| {
                (
                    [lo[0].min(q[0]), lo[1].min(q[1])],
                    [hi[0].max(q[0]), hi[1].max(q[1])],
                )
            },
        )
    };
    let coarse = lattice_points(4e-3, 0.0, w, h);
    let fine = lattice_points(1e-3, 0.0, w, h);
    let inner = [0.05, 0.07];
    let vals: Vec<f64> = [bbox(&coarse), bbox(&fine), ([0.0, 0.0], [w, h])]
        .iter()
        .map(|b| {
            let f = GaussianField::new(Correlation::Exponential, L, b.0, b.1, 5).unwrap();
            f.value_at(inner).unwrap()
        })
        .collect();
    assert!(
        vals.iter().all(|v| v.to_bits() == vals[0].to_bits()),
        "{vals:?}"
    );
}

#[test]
fn white_noise_is_reproducible_at_a_point_and_uncorrelated() {
    let f = GaussianField::new(Correlation::Exponential, 0.0, [0.0, 0.0], [1.0, 1.0], 3).unwrap();
    let p = [0.123_456_789, 0.5];
    let a = f.value_at(p).unwrap();
    let fine = lattice_points(1e-3, 0.0, 0.05, 0.05);
    let v = f.sample(&[fine.clone(), vec![p]].concat()).unwrap();
    assert_eq!(a.to_bits(), v.last().unwrap().to_bits());
    // neighbours 1e-6 m apart: correlation 0 within 4/√N
    let n = 20_000;
    let prods: Vec<f64> = (0..n)
        .map(|k| {
            let x = [(k % 200) as f64 * 4e-3, (k / 200) as f64 * 4e-3];
            f.value_at(x).unwrap() * f.value_at([x[0] + 1e-6, x[1]]).unwrap()
        })
        .collect();
    let r = prods.iter().sum::<f64>() / n as f64;
    assert!(
        r.abs() < 4.0 / (n as f64).sqrt(),
        "white-noise correlation {r}"
    );
    let other =
        GaussianField::new(Correlation::Exponential, 0.0, [0.0, 0.0], [1.0, 1.0], 4).unwrap();
    assert_ne!(a, other.value_at(p).unwrap());
}

fn message(e: FieldError) -> String {
    e.to_string()
}

#[test]
fn bad_parameters_give_clear_errors() {
    let b = ([0.0, 0.0], [0.1, 0.1]);
    let e = GaussianField::new(Correlation::Exponential, -0.01, b.0, b.1, 1).unwrap_err();
    assert_eq!(
        message(e),
        "correlation_length = -0.01: must be a finite length ≥ 0 m (0 = white noise)"
    );
    let e = GaussianField::new(Correlation::Exponential, f64::NAN, b.0, b.1, 1).unwrap_err();
    assert!(message(e).starts_with("correlation_length = NaN"));
    let e = GaussianField::new(Correlation::Exponential, 1e-6, b.0, [100.0, 100.0], 1).unwrap_err();
    let m = message(e);
    assert!(
        m.contains("exceeds the limit") && m.contains("correlation length"),
        "{m}"
    );
    let e = GaussianField::new(Correlation::Exponential, L, b.0, [-1.0, 0.1], 1).unwrap_err();
    assert!(message(e).starts_with("box_max.x = -1"));
    let f = GaussianField::new(Correlation::Exponential, L, b.0, b.1, 1).unwrap();
    assert!(message(f.value_at([0.2, 0.05]).unwrap_err()).contains("outside"));

    assert_eq!(
        message(Marginal::lognormal(0.0, 0.1).unwrap_err()),
        "mean = 0: must be finite and > 0"
    );
    assert_eq!(
        message(Marginal::normal(1.0, -0.1).unwrap_err()),
        "cov = -0.1: must be finite and ≥ 0 (0 = deterministic)"
    );
    assert!(message(Marginal::weibull(f64::NAN, 0.1).unwrap_err()).starts_with("mean = NaN"));
    assert!(message(Marginal::weibull(1.0, 1e6).unwrap_err()).starts_with("cov = 1000000"));
    assert_eq!(
        message(Marginal::weibull_modulus(1.0, 0.0).unwrap_err()),
        "modulus = 0: must be finite and ≥ 0.1"
    );
    // CoV 0 is the deterministic mean for every marginal
    for m in [
        Marginal::normal(2.0, 0.0).unwrap(),
        Marginal::lognormal(2.0, 0.0).unwrap(),
        Marginal::weibull(2.0, 0.0).unwrap(),
    ] {
        assert_eq!(m.map(1.7), 2.0);
    }
}

/// Generation time and clipped spectrum for dog-bones B and F (not a test: prints figures).
/// `cargo test --release --test suite -- --ignored --nocapture random_field::measure_generation`
#[test]
#[ignore]
fn measure_generation() {
    for (name, w, h) in [("B", 0.1, 0.15), ("F", 1.6, 2.4)] {
        for kernel in [Correlation::Exponential, Correlation::SquaredExponential] {
            let t = std::time::Instant::now();
            let f = GaussianField::new(kernel, L, [0.0, 0.0], [w, h], 1).unwrap();
            let dt = t.elapsed().as_secs_f64();
            let e = f.embedding().unwrap();
            println!(
                "dog-bone {name} {kernel:?} ℓ = {L}: nodes {:?}, embedding {:?} = {} nodes, \
                 {:.3} s, negative eigenvalues {} (clipped fraction {:.2e}, min/max {:.2e})",
                f.nodes().unwrap(),
                e.m,
                e.m[0] * e.m[1],
                dt,
                e.negative_eigenvalues,
                e.clipped_fraction,
                e.min_eigenvalue_ratio
            );
        }
    }
}
