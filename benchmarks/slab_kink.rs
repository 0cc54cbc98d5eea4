//! The kinks at the two tips of the bond-based centre-cracked slab's preset crack
//! (benchmarks/RESULTS.md, "Bond-based centre-cracked slab"), measured as
//! `tests/suite/bond_based.rs` measures them: the points with φ ≥ 0.35 within 2δ of each tip.
//!
//! `cargo run --release --example slab_kink -- 45 [KEY=VALUE ...]` runs
//! `lattices/slab_centre_crack_45_bond_based.toml` with the overrides and prints the angle of
//! each tip's crack from the preset crack's line, and the wall time.

use nalgebra::Vector2;
use sppm::study::crack_kink::kinks;
use sppm::study::families::BOND_CRACK_DAMAGE;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let beta: f64 = args
        .first()
        .and_then(|a| a.parse().ok())
        .expect("the crack's angle to the pull: 45 or 90");
    let overrides = &args[1..];
    let path = format!("lattices/slab_centre_crack_{beta}_bond_based.toml");
    let scene = sppm::Scene::from_file(std::path::Path::new(&path), overrides).unwrap();
    let start = std::time::Instant::now();
    let o = sppm::run::run(&scene, &sppm::run::RunOptions::default()).unwrap();
    let delta = o.summary.bond_based.as_ref().unwrap().horizon_m;
    let x0: Vec<_> = (0..o.x0.len()).map(|i| o.point2(i)).collect();
    let phi: Vec<f64> = o.damage.as_ref().unwrap().iter().map(|d| d.wt).collect();
    let b = beta.to_radians();
    let half = Vector2::new(b.cos(), b.sin()) * 0.02;
    let centre = Vector2::new(0.25, 0.2);
    let got = kinks(
        &x0,
        &phi,
        (centre - half, centre + half),
        BOND_CRACK_DAMAGE,
        (0.0, 2.0 * delta),
    );
    let angles: Vec<String> = got
        .iter()
        .map(|k| {
            k.as_ref()
                .map_or("no crack".into(), |k| format!("{:.1}°", k.angle_deg))
        })
        .collect();
    println!(
        "beta {beta}° {overrides:?}: kinks {} and {}; peak {:.1} N; {:.0} s",
        angles[0],
        angles[1],
        o.summary.peak_force_n,
        start.elapsed().as_secs_f64()
    );
}
