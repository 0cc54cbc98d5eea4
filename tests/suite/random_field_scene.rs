//! Random-field material properties in scenes (`[[random_field]]`, docs/model.md §12,
//! src/material/properties.rs): the values reach the damage kernel and the micro-moduli, the
//! field at a point does not depend on the lattice spacing, a seed reproduces the field, the
//! particles' values have the target statistics, and bad tables are refused with the key.
//! (The field generator's own statistics, correlation and seed tests are in
//! tests/suite/random_field.rs.)

use crate::common;
use common::tension_block;
use sppm::run::{prepare_model, RunOptions};
use sppm::scene::{CorrelationKind, FieldProperty, MarginalKind, RandomFieldSpec};
use sppm::Scene;

fn run(s: &Scene) -> sppm::Outcome {
    sppm::run(
        s,
        &RunOptions {
            progress: false,
            threads: Some(2),
        },
    )
    .unwrap()
}

fn field(
    property: FieldProperty,
    length: f64,
    marginal: MarginalKind,
    cov: f64,
) -> RandomFieldSpec {
    RandomFieldSpec {
        property,
        correlation: CorrelationKind::Exponential,
        length,
        marginal,
        mean: None,
        cov: Some(cov),
        modulus: None,
        seed: None,
        tie_gf: false,
    }
}

/// The Table 1 block (150 mm high, L0 = 10 mm) under relaxation, stopped after the peak.
fn block(extra: &[&str]) -> Scene {
    let mut o = vec![
        "solver.method=\"relaxation\"",
        "solver.increments=100",
        "loading.stop_after_peak=0.7",
        "output.vtk=false",
        "output.map=false",
    ];
    o.extend(extra);
    tension_block(0.15, 0.01, &o)
}

fn with_fields(mut s: Scene, fields: Vec<RandomFieldSpec>) -> Scene {
    s.random_field = fields;
    s.validate().unwrap();
    s
}

/// Scaling E and f't together by λ, with G_f tied to f't, scales every stress by λ at the same
/// strains: COD_c = 2G_f/(f't(α+γ)) is unchanged, and w(ε) = 1 − σ(COD)/(E·ε) is unchanged
/// because σ and E both scale by λ. So the quasi-static force scales by exactly λ at every
/// displacement. Fields with mean λ·(deterministic value) and a negligible CoV (1e-6) must
/// therefore give λ times the deterministic peak; the only difference is the relaxation's
/// convergence tolerance (1e-4 of the reaction), so 1e-3 is allowed. This passes only if E
/// reaches the micro-moduli and the criteria stress, and f't and the tied G_f reach the
/// damage law, at every particle.
#[test]
fn scaled_mean_fields_scale_the_whole_response() {
    let det = run(&block(&[]));
    let lambda = 1.2;
    let base = block(&[]);
    let e = base.material.youngs_modulus();
    let ft = base.derived_value("ft").unwrap();
    let mut fe = field(FieldProperty::E, 0.05, MarginalKind::Lognormal, 1e-6);
    fe.mean = Some(lambda * e);
    let mut ff = field(FieldProperty::Ft, 0.05, MarginalKind::Lognormal, 1e-6);
    ff.mean = Some(lambda * ft);
    ff.tie_gf = true;
    let scaled = run(&with_fields(block(&[]), vec![fe, ff]));
    let ratio = scaled.summary.peak_force_n / det.summary.peak_force_n;
    println!(
        "peak {:.1} N deterministic, {:.1} N scaled fields: ratio {ratio:.5}",
        det.summary.peak_force_n, scaled.summary.peak_force_n
    );
    assert!((ratio / lambda - 1.0).abs() < 1e-3, "ratio {ratio}");
    // displacement at the peak is unchanged (same strains)
    let du = scaled.summary.displacement_at_peak_m / det.summary.displacement_at_peak_m;
    assert!((du - 1.0).abs() < 1e-9, "{du}");
    // f't alone, without the tie, does not scale the response by λ: the test can fail
    let mut ft_only = field(FieldProperty::Ft, 0.05, MarginalKind::Lognormal, 1e-6);
    ft_only.mean = Some(lambda * ft);
    let one = run(&with_fields(block(&[]), vec![ft_only]));
    let r1 = one.summary.peak_force_n / det.summary.peak_force_n;
    println!("f't only: ratio {r1:.5}");
    assert!(r1 > 1.05, "a stronger f't must raise the peak: {r1}");
}

/// Weakest link: uncorrelated f't (CoV 0.2, normal) in a bar of 15 particles per row and
/// ~17 rows. Each row's mean strength scatters by 0.2/√15 ≈ 5%, and the weakest of 17 rows
/// lies about 1.8 standard deviations low, ~9% below the mean; single weak particles start
/// the crack earlier still. The mean strength equals the deterministic f't, so the peak must
/// drop clearly below the deterministic one (asserted: by more than 3%).
#[test]
fn uncorrelated_strength_lowers_the_peak() {
    let det = run(&block(&[]));
    for seed in [1u64, 2] {
        let s = with_fields(
            block(&[&format!("seed={seed}")]),
            vec![field(FieldProperty::Ft, 0.0, MarginalKind::Normal, 0.2)],
        );
        let out = run(&s);
        let r = out.summary.peak_force_n / det.summary.peak_force_n;
        println!("seed {seed}: peak ratio {r:.4}");
        assert!(r < 0.97, "seed {seed}: ratio {r}");
        assert!(r > 0.5, "seed {seed}: ratio {r}");
        assert_eq!(out.summary.seed, Some(seed));
        assert_eq!(out.summary.random_fields.len(), 1);
    }
}

/// The same point of the body gets the same value whatever the lattice spacing: the lattice
/// at L0/2 contains every particle of the lattice at L0 (same rotation and offset), and those
/// particles' values must agree bit for bit. The same seed gives the same field; another seed
/// another one.
#[test]
fn field_is_independent_of_the_spacing_and_reproducible() {
    let spec = field(FieldProperty::Ft, 0.03, MarginalKind::Weibull, 0.15);
    let coarse = prepare_model(
        &with_fields(tension_block(0.15, 0.01, &["seed=7"]), vec![spec.clone()]),
        sppm::run::Hexagonal,
    )
    .unwrap();
    let fine = prepare_model(
        &with_fields(tension_block(0.15, 0.005, &["seed=7"]), vec![spec.clone()]),
        sppm::run::Hexagonal,
    )
    .unwrap();
    let (pc, pf) = (&coarse.particles, &fine.particles);
    let mut matched = 0;
    for (i, x) in pc.x0.iter().enumerate() {
        if let Some(j) = pf.x0.iter().position(|y| (x - y).norm() < 1e-12) {
            assert_eq!(
                coarse.fields[0].values[i].to_bits(),
                fine.fields[0].values[j].to_bits(),
                "particle at {x:?}"
            );
            matched += 1;
        }
    }
    println!("{matched} of {} coarse particles matched", pc.len());
    assert!(matched * 10 >= pc.len() * 9, "{matched} of {}", pc.len());

    let again = prepare_model(
        &with_fields(tension_block(0.15, 0.01, &["seed=7"]), vec![spec.clone()]),
        sppm::run::Hexagonal,
    )
    .unwrap();
    assert_eq!(coarse.fields[0].values, again.fields[0].values);
    let other = prepare_model(
        &with_fields(tension_block(0.15, 0.01, &["seed=8"]), vec![spec]),
        sppm::run::Hexagonal,
    )
    .unwrap();
    let differ = coarse.fields[0]
        .values
        .iter()
        .zip(&other.fields[0].values)
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(differ, pc.len());
}

/// Uncorrelated fields over a fine block (≈ 2,500 particles) have the target mean and CoV
/// within sampling error: the standard error of the mean is CoV/√n ≈ 0.3%, that of the
/// standard deviation about (1/√(2n))·√(1 + κ/2) ≈ 1.5–3% (κ the excess kurtosis), so 5
/// standard errors are allowed. Properties drawn together are independent (different seeds).
#[test]
fn particle_values_have_the_target_statistics() {
    let s = with_fields(
        tension_block(0.15, 0.003, &["seed=11"]),
        vec![
            field(FieldProperty::Ft, 0.0, MarginalKind::Weibull, 0.18),
            field(FieldProperty::E, 0.0, MarginalKind::Lognormal, 0.1),
            field(FieldProperty::Gf, 0.0, MarginalKind::Normal, 0.2),
        ],
    );
    let m = prepare_model(&s, sppm::run::Hexagonal).unwrap();
    let n = m.particles.len() as f64;
    assert!(n > 2000.0, "{n}");
    let mut seeds = Vec::new();
    for f in &m.fields {
        let r = &f.report;
        let se_mean = r.cov / n.sqrt();
        let se_cov = r.cov * (1.0 / (2.0 * n)).sqrt() * 2.0;
        println!(
            "{:?}: mean {:.4e} (target {:.4e}), CoV {:.4} (target {:.4})",
            f.property, r.sample_mean, r.mean, r.sample_cov, r.cov
        );
        assert!((r.sample_mean / r.mean - 1.0).abs() < 5.0 * se_mean);
        assert!((r.sample_cov / r.cov - 1.0).abs() < 5.0 * se_cov / r.cov);
        seeds.push(r.seed);
    }
    seeds.sort();
    seeds.dedup();
    assert_eq!(seeds.len(), 3);
    // the sample correlation of two independent fields is within 4/√n of zero
    let (a, b) = (&m.fields[0].values, &m.fields[1].values);
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (ma, mb) = (mean(a), mean(b));
    let cov: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - ma) * (y - mb))
        .sum::<f64>();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    let corr = cov / (va * vb).sqrt();
    assert!(corr.abs() < 4.0 / n.sqrt(), "{corr}");
    // E scales the micro-moduli of bulk particles in proportion
    let e = s.material.youngs_modulus();
    for i in (0..m.particles.len()).filter(|&i| m.particles.bond_count(i) == 6) {
        let f = m.fields[1].values[i] / e;
        assert!((m.mech.a[i] / (m.bulk.a * f) - 1.0).abs() < 1e-12);
        assert!((m.mech.b[i] / (m.bulk.b * f) - 1.0).abs() < 1e-12);
    }
}

/// Bad tables: one message naming the key, the value and what is allowed.
#[test]
fn bad_random_field_tables_are_refused() {
    let ok = field(FieldProperty::Ft, 0.02, MarginalKind::Weibull, 0.15);
    let cases: Vec<(Vec<RandomFieldSpec>, &str)> = vec![
        (
            vec![RandomFieldSpec {
                length: -1.0,
                ..ok.clone()
            }],
            "random_field[0].length",
        ),
        (
            vec![RandomFieldSpec {
                cov: None,
                ..ok.clone()
            }],
            "random_field[0].cov",
        ),
        (
            vec![RandomFieldSpec {
                cov: Some(-0.1),
                ..ok.clone()
            }],
            "random_field[0].cov",
        ),
        (
            vec![RandomFieldSpec {
                marginal: MarginalKind::Lognormal,
                cov: None,
                modulus: Some(8.0),
                ..ok.clone()
            }],
            "random_field[0].modulus",
        ),
        (vec![ok.clone(), ok.clone()], "random_field[1].property"),
        (
            vec![RandomFieldSpec {
                property: FieldProperty::E,
                tie_gf: true,
                ..ok.clone()
            }],
            "random_field[0].tie_gf",
        ),
        (
            vec![
                RandomFieldSpec {
                    tie_gf: true,
                    ..ok.clone()
                },
                field(FieldProperty::Gf, 0.02, MarginalKind::Normal, 0.1),
            ],
            "random_field[0].tie_gf",
        ),
        (
            vec![RandomFieldSpec {
                mean: Some(0.0),
                ..ok.clone()
            }],
            "random_field[0].mean",
        ),
    ];
    for (fields, key) in cases {
        let mut s = tension_block(0.15, 0.01, &[]);
        s.random_field = fields;
        let e = s.validate().unwrap_err().to_string();
        assert!(e.contains(key), "expected {key}: {e}");
    }
    // f't needs [concrete]; parsed from TOML, the error names the key
    let text = format!(
        "{}\n[[random_field]]\nproperty = \"ft\"\ncorrelation = \"exponential\"\nlength = 0.01\nmarginal = \"normal\"\ncov = 0.1\n",
        common::plate_toml(0.1, 0.2, 0.01, 0.0, "stress", false, 0.2)
    );
    let e = Scene::from_toml_str(&text, &[]).unwrap_err().to_string();
    assert!(
        e.contains("random_field[0].property") && e.contains("[concrete]"),
        "{e}"
    );
    // an unknown marginal is a parse error naming the variants
    let bad = text.replace("\"normal\"", "\"gumbel\"");
    let e = Scene::from_toml_str(&bad, &[]).unwrap_err().to_string();
    assert!(e.contains("gumbel") && e.contains("weibull"), "{e}");
}
