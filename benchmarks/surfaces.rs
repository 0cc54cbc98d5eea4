//! The elastic stiffness of plates and cantilevers against theory for every boundary
//! treatment (`discretisation.surface`), at several depths in spacings, lattice rotations
//! and offsets, and the mass of the discrete body. Prints one table row per case.
//!
//! `cargo run --release --example surfaces` (about a minute on 2 cores); with
//! `-- --3d [depths in spacings, default 10]`, the 3D prism cantilevers of FCC and random
//! particles instead (h = 10·L0: about 30 s).

use nalgebra::Vector3;
use sppm::discretise::fcc::FccLattice;
use sppm::discretise::random3::RandomSolid;
use sppm::scene::Surface;
use sppm::study::elastic_checks::{
    cantilever_stiffness, fcc_prism_cantilever, hole_stress, plate_modulus,
    random_prism_cantilever, Placement,
};

const METHODS: [&str; 4] = ["voronoi_fit", "voronoi", "lattice", "lattice_fit"];
const L0: f64 = 0.001;
/// Offsets (in spacings): the origin and two fixed "random" ones.
const OFFSETS: [[f64; 2]; 3] = [[0.0, 0.0], [0.37, 0.61], [0.83, 0.12]];

fn placement(rotation_deg: f64, offset: [f64; 2], surface: &'static str) -> Placement {
    Placement {
        spacing: L0,
        rotation_deg,
        offset: [offset[0] * L0, offset[1] * L0],
        surface,
    }
}

/// The 3D prism cantilever (h × h section, length 10·h, tip load): FCC at two rotations and
/// two offsets (`voronoi_fit`), and random particles (five sets).
fn prism_cantilevers(depths: &[f64]) {
    println!("# 3D prism cantilever, h × h, length 10·h, tip load: Timoshenko's tip deflection / measured − 1 (%)");
    println!("| h/L0 | particles | rotation [α, β, γ] | offset/L0 or seed | stiffness |");
    println!("|---|---|---|---|---|");
    for &hl in depths {
        prism_rows(hl);
    }
    println!();
}

/// The rows of [`prism_cantilevers`] at depth `hl` spacings.
fn prism_rows(hl: f64) {
    let h = hl * L0;
    for rot in [[0.0, 0.0, 0.0], [30.0, 20.0, 10.0]] {
        for off in [[0.0, 0.0, 0.0], [0.37, 0.61, 0.13]] {
            let lattice = FccLattice {
                spacing: L0,
                rotation_deg: rot,
                offset: Vector3::from(off) * L0,
            };
            let k = fcc_prism_cantilever(h, 10.0 * h, &lattice, Surface::VoronoiFit)
                .expect("FCC prism cantilever");
            println!(
                "| {hl} | FCC | {rot:?} | {off:?} | {:+.2} |",
                (k - 1.0) * 100.0
            );
        }
    }
    let mut sum = 0.0;
    for seed in 1..=5 {
        let recipe = RandomSolid {
            spacing: L0,
            min_distance: sppm::discretise::random::DEFAULT_MIN_DISTANCE,
            seed,
            rotation_deg: [0.0; 3],
        };
        let k = random_prism_cantilever(h, 10.0 * h, &recipe).expect("random prism cantilever");
        sum += k - 1.0;
        println!("| {hl} | random | – | {seed} | {:+.2} |", (k - 1.0) * 100.0);
    }
    println!(
        "| {hl} | random | – | mean of 5 | {:+.2} |",
        sum / 5.0 * 100.0
    );
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().is_some_and(|a| a == "--3d") {
        let depths: Vec<f64> = args[1..]
            .iter()
            .map(|a| {
                a.parse().unwrap_or_else(|_| {
                    panic!("--3d takes depths in spacings (numbers), not {a:?}")
                })
            })
            .collect();
        prism_cantilevers(if depths.is_empty() { &[10.0] } else { &depths });
        return;
    }
    println!("# plate with a hole, W = 20·R, uniaxial tension, recovered stress / remote: hoop stress at the hole's sides (Howland 3.03), largest |σ_rr| and |σ_rθ| on the hole's edge");
    println!("| R/L0 | rotation | hoop | max σ_rr | max σ_rθ |");
    println!("|---|---|---|---|---|");
    for r in [10.0, 20.0] {
        for rot in [0.0, 30.0] {
            let p = placement(rot, [0.0, 0.0], "voronoi_fit");
            let s = hole_stress(20.0 * r * L0, r * L0, &p).expect("plate with a hole");
            println!(
                "| {r} | {rot}° | {:.3} | {:.3} | {:.3} |",
                s.hoop, s.max_normal, s.max_shear
            );
        }
    }
    println!();
    println!("# plate in uniaxial tension (W × 2W, pulled along 2W): E/E0 − 1, ν/ν0 − 1 (%)");
    println!("| W/L0 | rotation | {} |", METHODS.join(" | "));
    println!("|---|---|{}", "---|".repeat(METHODS.len()));
    for w in [10.0, 20.0, 40.0] {
        for rot in [0.0, 15.0, 30.0] {
            let cells: Vec<String> = METHODS
                .iter()
                .map(|&surface| {
                    let p = placement(rot, [0.0, 0.0], surface);
                    let (e, nu) = plate_modulus(w * L0, 2.0 * w * L0, &p).expect("plate");
                    format!("{:+.2} / {:+.2}", (e - 1.0) * 100.0, (nu - 1.0) * 100.0)
                })
                .collect();
            println!("| {w} | {rot}° | {} |", cells.join(" | "));
        }
    }
    println!();
    println!("# cantilever, length 10·h, tip load: Timoshenko's tip deflection / measured − 1 (%), and mass/ρV − 1 (%)");
    println!("| h/L0 | rotation | offset/L0 | {} |", METHODS.join(" | "));
    println!("|---|---|---|{}", "---|".repeat(METHODS.len()));
    for h in [10.0, 20.0, 40.0] {
        for rot in [0.0, 15.0, 30.0] {
            for off in OFFSETS {
                let cells: Vec<String> = METHODS
                    .iter()
                    .map(|&surface| {
                        let p = placement(rot, off, surface);
                        let (k, model) =
                            cantilever_stiffness(h * L0, 10.0 * h * L0, &p).expect("cantilever");
                        let mass: f64 = model.mech.mass.iter().sum();
                        let want =
                            2400.0 * model.scene.shape().area() * model.scene.material.thickness();
                        format!(
                            "{:+.2} (m {:+.2})",
                            (k - 1.0) * 100.0,
                            (mass / want - 1.0) * 100.0
                        )
                    })
                    .collect();
                println!("| {h} | {rot}° | {:?} | {} |", off, cells.join(" | "));
            }
        }
    }
}
