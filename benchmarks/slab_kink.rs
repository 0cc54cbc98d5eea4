//! The kinks at the two tips of the bond-based centre-cracked slab's preset crack
//! (benchmarks/RESULTS.md, "Bond-based centre-cracked slab"), measured as
//! `tests/suite/bond_based.rs` measures them: the points with φ ≥ 0.35 within 2δ of each tip.
//!
//! `cargo run --release --example slab_kink -- 45 [KEY=VALUE ...]` runs
//! `lattices/slab_centre_crack_45_bond_based.toml` with the overrides and prints the angle of
//! each tip's crack from the preset crack's line, and the wall time.

use sppm::study::crack_kink::bond_based_kinks;

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
    let got = bond_based_kinks(&o);
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
