//! Discretisations: particles with reference positions, volumes, fixed neighbour slots
//! (with the reverse-slot index) and named groups (MODEL.md §1).
//!
//! One container serves every dimension `D` and slot count `K` (6 for the 2D hexagonal
//! lattice, 18 for 3D FCC and SPPM): an empty slot holds [`NONE`].

pub mod csr;
pub mod groups;
pub mod hex;

use nalgebra::SVector;

/// Sentinel of an empty neighbour slot.
pub const NONE: u32 = u32::MAX;

/// Particles of a discretised body.
#[derive(Clone, Debug)]
pub struct Particles<const D: usize, const K: usize> {
    /// Reference positions (m).
    pub x0: Vec<SVector<f64, D>>,
    /// Volume ΔV of each particle (m³; in 2D thickness × area).
    pub volume: Vec<f64>,
    /// Neighbour index per slot, [`NONE`] where empty.
    pub neighbours: Vec<[u32; K]>,
    /// For slot k of particle i holding j: the slot of j that holds i.
    pub reverse: Vec<[u8; K]>,
    /// Reference bond length per slot (m); 0 where empty.
    pub l0: Vec<[f64; K]>,
    /// Nearest-neighbour spacing L0 of the lattice (m).
    pub spacing: f64,
}

impl<const D: usize, const K: usize> Particles<D, K> {
    pub fn len(&self) -> usize {
        self.x0.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x0.is_empty()
    }

    /// Number of undirected bonds.
    pub fn bonds(&self) -> usize {
        self.neighbours
            .iter()
            .map(|s| s.iter().filter(|&&j| j != NONE).count())
            .sum::<usize>()
            / 2
    }

    /// Number of bonds of particle i.
    pub fn bond_count(&self, i: usize) -> usize {
        self.neighbours[i].iter().filter(|&&j| j != NONE).count()
    }

    /// Check the slot structure: every bond seen from both ends through `reverse`, same
    /// reference length, no self bonds. Used by tests and debug builds.
    pub fn check_topology(&self) -> Result<(), String> {
        for i in 0..self.len() {
            for k in 0..K {
                let j = self.neighbours[i][k];
                if j == NONE {
                    continue;
                }
                let j = j as usize;
                if j == i {
                    return Err(format!("particle {i} is bonded to itself"));
                }
                let r = self.reverse[i][k] as usize;
                if self.neighbours[j][r] as usize != i {
                    return Err(format!(
                        "bond {i}->{j} (slot {k}) has no reverse in slot {r}"
                    ));
                }
                if (self.l0[i][k] - self.l0[j][r]).abs() > 1e-12 * self.l0[i][k] {
                    return Err(format!("bond {i}-{j} has two reference lengths"));
                }
            }
        }
        Ok(())
    }
}

/// Bytes of memory per particle that a run of dimension D with K slots allocates
/// (discretisation, model and solver state), used to refuse scenes too large for the machine
/// before anything is allocated.
pub const fn bytes_per_particle(d: usize, k: usize) -> usize {
    // x0, x, x_next, v, v_next, force, force_prev: 7·D f64; volume, mass, inv_mass, a, b,
    // c_in, c_ex, b·theta, damping energy: 9 f64; neighbours (u32), reverse (u8),
    // l0 and 1/l0 (f64) and the kernel's cached stretch and 1/length (f64) per slot; group
    // bookkeeping and outputs: ~64 bytes.
    7 * d * 8 + 9 * 8 + k * (4 + 1 + 32) + 64
}

/// Slots per particle of the standard lattices: 6 for the 2D hexagonal lattice, 18 for 3D.
pub const fn slots(d: usize) -> usize {
    if d == 2 {
        6
    } else {
        18
    }
}
