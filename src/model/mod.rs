//! The SPLM/SPPM constitutive model: micro-moduli, stretch, force state, stress, strain,
//! damage and plasticity, in 2D and 3D (`dimension`: dimension as a type).
pub mod bond_based;
pub mod damage;
pub mod damage_law;
pub mod dimension;
pub mod force_state;
pub mod micro_modulus;
pub mod plasticity;
pub mod sppm_calibration;
pub mod strain;
pub mod stress;
pub mod stretch;
pub mod two_spring;
