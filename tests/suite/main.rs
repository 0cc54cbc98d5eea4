//! The fast test suite: one test crate (one link) whose modules mirror the topics of src/.
//! The long physics validations are ignored here unless the `validation` feature is on
//! (`cargo test --release --features validation`, which CI runs after the fast suite).

mod bending;
mod bond_based;
mod cli;
#[path = "../common/mod.rs"]
mod common;
mod concrete;
mod concrete_3d;
mod concrete_input;
mod cutouts;
mod damage_law;
mod dampers_and_pace;
mod docs;
mod elastic_plate;
mod fcc;
mod fcc_kernel;
mod force_law;
mod fuzz_cli;
mod golden;
mod layering;
mod load_control;
mod montecarlo;
mod outputs_agree;
mod patch_and_newton;
mod platens;
mod proptest_scenes;
mod quasi_static;
mod random_field;
mod random_field_scene;
mod readme;
mod relaxation;
mod reliability;
mod reliability_studies;
mod run_plate;
mod scene_errors;
mod snapshots;
mod specimens;
mod sppm3d;
mod sppm_concrete;
mod sppm_elastic;
mod stability;
mod studies;
mod surfaces;
mod vibration_and_stability;
