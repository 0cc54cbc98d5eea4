//! SPPM (random particles): the Table 1 tension block
//! (`lattices/uniaxial_tension_random.toml`, L0 = 7 mm, crack band 3.2) over ten particle
//! sets, and the split cylinder.
//!
//! Tension block, the acceptance on the means of seeds 1–10: the peak within ±5% of
//! f't·A and the dissipated energy within ±10% of G_f·A (measured over the 200 runs of the
//! rotation study: 0.994 and 1.017; seeds 1–10: 0.992 and 0.960). Every set's crack runs
//! across the block: the cracked particles (w_t ≥ 0.99) span its width. Perpendicular to the
//! load: each crack (cracked particles grouped where their heights leave a gap of more than
//! 30 mm) stays within a band of half the width in height — in at least 8 of the 10 sets.
//! Not in all: a random body sometimes cracks inclined (by up to about 30°) or in two offset
//! pieces; over the 200 runs of the rotation study 181 pass this check (so 8 of 10 or more
//! with probability 0.94), and seeds 2 and 10 here do not (87 and 84 mm).

use crate::common;

use sppm::run::{run, Outcome, RunOptions};
use sppm::Scene;

const FT_A: f64 = 2.6168e6 * 0.15 * 0.15;

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// The shipped scene `lattices/<name>.toml` with particle set `seed`, run on 2 threads to the
/// end (it must not fail).
fn run_set(name: &str, seed: u64) -> (Scene, Outcome) {
    let path = format!("{}/lattices/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    let scene = Scene::from_file(std::path::Path::new(&path), &[format!("seed={seed}")]).unwrap();
    let o = run(
        &scene,
        &RunOptions {
            progress: false,
            threads: Some(2),
        },
    )
    .unwrap();
    assert!(!o.failed(), "{name}, seed {seed}: {:?}", o.summary.message);
    (scene, o)
}

#[test]
#[cfg_attr(
    not(feature = "validation"),
    ignore = "validation: cargo test --release --features validation"
)]
fn random_tension_block_peak_energy_and_crack() {
    let (mut peaks, mut energies, mut straight) = (vec![], vec![], 0);
    for seed in 1..=10u64 {
        let (scene, o) = run_set("uniaxial_tension_random", seed);
        let gf = scene.derived_value("Gf").unwrap();
        peaks.push(o.summary.peak_force_n / FT_A);
        energies.push(o.summary.dissipated_energy_j / (gf * 0.15 * 0.15));
        let damage = o.damage.as_ref().unwrap();
        let mut cracked: Vec<(f64, f64)> =
            o.x0.iter()
                .zip(damage)
                .filter(|(_, d)| d.wt >= 0.99)
                .map(|(x, _)| (x[1], x[0]))
                .collect();
        assert!(!cracked.is_empty(), "seed {seed}: no crack");
        cracked.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (xmin, xmax) = cracked
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p.1), b.max(p.1))
            });
        assert!(
            xmin <= 0.01 && xmax >= 0.14,
            "seed {seed}: the crack spans x = {xmin}..{xmax} m of 0..0.15"
        );
        let mut start = cracked[0].0;
        let mut spread: f64 = 0.0;
        for w in cracked.windows(2) {
            if w[1].0 - w[0].0 > 0.03 {
                start = w[1].0;
            }
            spread = spread.max(w[1].0 - start);
        }
        println!("seed {seed}: a crack spreads over {spread:.4} m of height");
        if spread <= 0.075 {
            straight += 1;
        }
    }
    let (peak, energy) = (mean(&peaks), mean(&energies));
    println!("peaks / f't·A: {peaks:?}, mean {peak:.4}");
    println!("energies / G_f·A: {energies:?}, mean {energy:.4}");
    assert!((peak - 1.0).abs() <= 0.05, "mean peak {peak} × f't·A");
    assert!((energy - 1.0).abs() <= 0.10, "mean energy {energy} × G_f·A");
    assert!(
        straight >= 8,
        "{straight} of 10 sets crack within a 75 mm band"
    );
}

/// The split cylinder on random particles (`lattices/split_cylinder_random.toml`, L0 = 3.5 mm)
/// over three particle sets: the mean peak within ±10% of (5.6) (the acceptance of the random 2D concrete;
/// measured +4.0% over 10 sets, CoV 6.5%), and in every set the crack runs along the loaded
/// diameter: the principal axis of the particles with w_t ≥ 0.9 within 20° of vertical and
/// their centroid within 20 mm of the axis (measured: the 10 sets of the study 62–110°, one
/// of them outside, and within 14 mm; seeds 1–3 here 109.7°, 92.1°, 73.2° and within 13 mm,
/// peaks +5.6%, +13.9%, −0.2%, mean +6.4%).
#[test]
#[cfg_attr(
    not(feature = "validation"),
    ignore = "validation: cargo test --release --features validation"
)]
fn random_split_cylinder_peak_and_crack() {
    let mut ratios = vec![];
    for seed in 1..=3u64 {
        let (scene, o) = run_set("split_cylinder_random", seed);
        let ft = scene.derived_value("ft").unwrap();
        let p56 = common::split_cylinder_peak(ft, 0.15, 0.30, 0.025);
        ratios.push(o.summary.peak_force_n / p56);
        let x0: Vec<nalgebra::Vector2<f64>> =
            o.x0.iter()
                .map(|x| nalgebra::Vector2::new(x[0], x[1]))
                .collect();
        let wt: Vec<f64> = o.damage.as_ref().unwrap().iter().map(|w| w.wt).collect();
        // every damaged particle, as the numbers above were measured
        let none = &sppm::study::crack_path::Clearance::NONE;
        let path = sppm::study::crack_path::crack_path(&x0, &wt, 0.9, none).expect("a crack");
        println!(
            "seed {seed}: peak / (5.6) = {:.4}, crack {path:?}",
            ratios[ratios.len() - 1]
        );
        assert!(
            (path.axis_deg - 90.0).abs() <= 20.0,
            "seed {seed}: crack axis {}°",
            path.axis_deg
        );
        assert!(
            path.centroid_m[0].abs() <= 0.02,
            "seed {seed}: crack centroid at x = {} m",
            path.centroid_m[0]
        );
    }
    let peak = mean(&ratios);
    println!("peaks / (5.6): {ratios:?}, mean {peak:.4}");
    assert!((peak - 1.0).abs() <= 0.10, "mean peak {peak} × (5.6)");
}
