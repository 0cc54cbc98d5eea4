//! SPPM (random particles, issue 13): the Table 1 tension block
//! (`lattices/uniaxial_tension_random.toml`, L0 = 10 mm) over five particle sets. Its peak
//! must lie within ±5% of f't·A in the mean (the acceptance; measured 0.981 over seeds
//! 1–5, 0.977 over 1–10), and every crack must run across the block perpendicular to the load:
//! the cracked particles (w_t ≥ 0.99) span the block's width, and each crack (cracked
//! particles grouped where their heights leave a gap of more than 30 mm) stays within a band
//! of half the width in height. With each particle's own strain in the criteria, the peak was
//! 0.854 × f't·A and the cracks ran inclined over up to 100 mm. The energy is not asserted:
//! its mean over 40 runs is 1.25 × G_f·A, outside the issue's ±10% (some sets crack twice;
//! docs/sppm.md).

use sppm::run::{run, Outcome, RunOptions};
use sppm::Scene;

const FT_A: f64 = 2.6168e6 * 0.15 * 0.15;

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
fn random_tension_block_peak_and_crack() {
    let mut peaks = vec![];
    for seed in 1..=5u64 {
        let (_, o) = run_set("uniaxial_tension_random", seed);
        peaks.push(o.summary.peak_force_n / FT_A);
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
        for w in cracked.windows(2) {
            if w[1].0 - w[0].0 > 0.03 {
                start = w[1].0;
            }
            assert!(
                w[1].0 - start <= 0.075,
                "seed {seed}: a crack spreads over {} m of height",
                w[1].0 - start
            );
        }
    }
    let mean = peaks.iter().sum::<f64>() / peaks.len() as f64;
    println!("peaks / f't·A: {peaks:?}, mean {mean:.4}");
    assert!((mean - 1.0).abs() <= 0.05, "mean peak {mean} × f't·A");
}

/// The split cylinder on random particles (`lattices/split_cylinder_random.toml`, L0 = 3.5 mm)
/// over three particle sets: the mean peak within ±10% of (5.6) (the acceptance;
/// measured +5.2% over 10 sets, CoV 5.4%), and in every set the crack runs along the loaded
/// diameter: the principal axis of the particles with w_t ≥ 0.9 within 20° of vertical and
/// their centroid within 20 mm of the axis (measured: the 10 sets of the study 82–107° and
/// within 17 mm; seeds 1–3 here 100°, 79°, 72° and within 14 mm, peaks +6.2%, +14.1%, +4.2%,
/// mean +8.2%).
#[test]
fn random_split_cylinder_peak_and_crack() {
    let (d, h, b) = (0.15, 0.30, 0.025);
    let beta: f64 = b / d;
    let mut ratios = vec![];
    for seed in 1..=3u64 {
        let (scene, o) = run_set("split_cylinder_random", seed);
        let ft = scene.derived_value("ft").unwrap();
        let p56 = std::f64::consts::FRAC_PI_2 * ft * d * h / (1.0 - beta * beta).powf(1.5);
        ratios.push(o.summary.peak_force_n / p56);
        let x0: Vec<nalgebra::Vector2<f64>> =
            o.x0.iter()
                .map(|x| nalgebra::Vector2::new(x[0], x[1]))
                .collect();
        let wt: Vec<f64> = o.damage.as_ref().unwrap().iter().map(|w| w.wt).collect();
        let path = sppm::study::crack_path::crack_path(&x0, &wt, 0.9).expect("a crack");
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
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    println!("peaks / (5.6): {ratios:?}, mean {mean:.4}");
    assert!((mean - 1.0).abs() <= 0.10, "mean peak {mean} × (5.6)");
}
