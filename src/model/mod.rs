//! The SPLM/SPPM constitutive model: micro-moduli, stretch, force state, stress.
pub mod micro_modulus;
pub mod stress;
pub mod stretch;
