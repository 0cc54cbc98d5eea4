//! Bond-based peridynamics (docs/bond_based.md): the families of a cubic grid, the
//! micromoduli of a body of horizon δ and the softening laws of a bond, for running the concrete models of the literature beside
//! the state-based lattice.

pub mod body;
pub mod bonds;
pub mod family;
pub mod kernel;
pub mod micromodulus;
pub mod softening;
