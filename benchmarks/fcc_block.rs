//! An elastic FCC block W × W × 2W in uniaxial tension (side faces free) against the input
//! (E, ν) for the three boundary treatments of the FCC lattice, at three orientations and
//! two offsets. Prints one table row per case (`study::elastic_checks::fcc_block_modulus`).
//!
//! `cargo run --release --example fcc_block` (about two minutes on 2 cores).

use nalgebra::Vector3;
use sppm::discretise::fcc::FccLattice;
use sppm::scene::Surface;
use sppm::study::elastic_checks::fcc_block_modulus;

const METHODS: [Surface; 3] = [Surface::VoronoiFit, Surface::LatticeFit, Surface::Lattice];

fn main() {
    let l0 = 0.001;
    println!("# FCC block W × W × 2W, uniaxial tension: E/E0 − 1, ν/ν0 − 1 (%)");
    println!(
        "| W/L0 | rotation [α, β, γ] | offset/L0 | {} |",
        METHODS.map(Surface::name).join(" | ")
    );
    println!("|---|---|---|{}", "---|".repeat(METHODS.len()));
    for w in [10.0, 20.0] {
        for rot in [[0.0, 0.0, 0.0], [30.0, 20.0, 10.0], [45.0, 35.26, 0.0]] {
            for off in [[0.0, 0.0, 0.0], [0.37, 0.61, 0.13]] {
                let lattice = FccLattice {
                    spacing: l0,
                    rotation_deg: rot,
                    offset: Vector3::from(off) * l0,
                };
                let cells: Vec<String> = METHODS
                    .iter()
                    .map(|&s| {
                        let (e, nu) =
                            fcc_block_modulus(w * l0, 2.0 * w * l0, &lattice, s).expect("block");
                        format!("{:+.2} / {:+.2}", (e - 1.0) * 100.0, (nu - 1.0) * 100.0)
                    })
                    .collect();
                println!("| {w} | {rot:?} | {off:?} | {} |", cells.join(" | "));
            }
        }
    }
}
