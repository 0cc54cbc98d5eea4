//! docs/validation.md §A: E and ν of a plate in uniaxial tension, with and without the surface
//! correction, in plane stress and plane strain, and the stiffness at lattice rotations.
//!
//! The plate (100 × 200 mm, L0 = 1 mm, ν = 0.2) is solved statically (small strain) with the
//! linearised operator; E = σ/ε_yy with σ = F/(W·t) from the reaction of the pulled rows, and
//! the strains fitted over the middle half of the plate. Measured (this test prints them):
//! plane stress, correction on/off: E +0.25% / −0.20%, ν +0.07% / +0.07%; the boundary error
//! is first order in L0/W (on: +0.51%, +1.02%; off: −0.39%, −0.77% at W/L0 = 50, 25), which
//! is why `surface_correction` defaults to off.

use crate::common;
use common::*;
use sppm::run::prepare_model;

const W: f64 = 0.1;
const H: f64 = 0.2;
const T: f64 = 0.05;
const L0: f64 = 0.001;
/// docs/validation.md §A.
const TOL: f64 = 0.01;

fn measure(rotation: f64, plane: &str, correction: bool) -> (f64, f64) {
    let p = prepare_model(
        &scene(&plate_toml(W, H, L0, rotation, plane, correction, 0.2)),
        sppm::run::Hexagonal,
    )
    .unwrap();
    measure_e_nu(&p, W, H, T)
}

/// In plane strain the in-plane pair (E', ν') relates to (E, ν) by E' = E/(1−ν²), ν' = ν/(1−ν).
fn to_3d(e_plane: f64, nu_plane: f64) -> (f64, f64) {
    let nu = nu_plane / (1.0 + nu_plane);
    (e_plane * (1.0 - nu * nu), nu)
}

#[test]
fn young_modulus_and_poisson_ratio_within_one_percent() {
    for plane in ["stress", "strain"] {
        for corr in [true, false] {
            let (e, nu) = measure(0.0, plane, corr);
            let (e, nu) = if plane == "strain" {
                to_3d(e, nu)
            } else {
                (e, nu)
            };
            println!(
                "plane {plane:6} surface_correction {corr:5}: E = {:.5} GPa ({:+.3}%), nu = {:.5} ({:+.3}%)",
                e / 1e9,
                (e / 30e9 - 1.0) * 100.0,
                nu,
                (nu / 0.2 - 1.0) * 100.0
            );
            assert!(
                (e / 30e9 - 1.0).abs() < TOL,
                "plane {plane}, correction {corr}: E = {e:e}"
            );
            assert!(
                (nu / 0.2 - 1.0).abs() < TOL,
                "plane {plane}, correction {corr}: nu = {nu}"
            );
        }
    }
}

#[test]
fn stiffness_does_not_depend_on_lattice_rotation() {
    let (e0, nu0) = measure(0.0, "stress", false);
    for rot in [7.5, 15.0, 30.0] {
        let (e, nu) = measure(rot, "stress", false);
        println!(
            "rotation {rot:4}°: E/E(0°) − 1 = {:+.3}%, nu = {nu:.5}",
            (e / e0 - 1.0) * 100.0
        );
        assert!(
            (e / e0 - 1.0).abs() < TOL,
            "rotation {rot}: E = {e:e} vs {e0:e}"
        );
        assert!(
            (nu / nu0 - 1.0).abs() < TOL,
            "rotation {rot}: nu = {nu} vs {nu0}"
        );
    }
}
