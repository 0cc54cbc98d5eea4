//! Discretisations fill a body (docs/model.md §1): particles with reference positions, volumes,
//! a horizon and a length scale each, their micro-moduli, and bonds with their own reference
//! length; and named groups of particles.
//!
//! Bonds sit in fixed slots ([`Particles`]): 6 for the 2D hexagonal lattice, 18 for 3D FCC,
//! 12 and 36 for random particles in 2D and 3D; an empty slot holds [`NONE`]. One container
//! serves every dimension `D` and slot count `K`.
//! Everything downstream (micro-moduli, dampers, time step, crack band) reads a particle's
//! own values from the body, never the scene's nominal spacing.

pub mod fcc;
pub mod groups;
pub mod hex;
pub mod random;
pub mod random3;
pub mod voronoi;
pub mod voronoi3;

pub(crate) use hex::drop_isolated;
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
    /// Horizon r_i of each particle (m): the reach of its bonds (docs/model.md §1; L0 for the
    /// hexagonal lattice, √2·L0 for FCC, the distance to the k-th nearest particle for SPPM).
    pub horizon: Vec<f64>,
    /// Each particle's own length scale L0,i (m), its nearest-neighbour spacing: the particle
    /// frequency ω_i (section 4.3, (3.55)) and the crack band (4.13) use it.
    pub length: Vec<f64>,
    /// Micro-modulus a_i of each particle (N; docs/model.md §3), filled for the discretisation
    /// by `run::prepare` (0 until then).
    pub a: Vec<f64>,
    /// Micro-modulus b_i (N).
    pub b: Vec<f64>,
    /// Micro-modulus c_i of second-neighbour bonds (N; FCC; 0 in 2D).
    pub c: Vec<f64>,
    /// Nominal spacing of the discretisation (m): the row pitch by which groups select edge
    /// rows. Per-particle quantities use [`Self::length`].
    pub spacing: f64,
    /// Whether the dilatation of particle i weighs each bond by L0,im/ℓ_i (ℓ_i =
    /// [`Self::length`]): θ_i = Σ_m (L0,im/ℓ_i)·S_im. Random particles need it (docs/sppm.md,
    /// "dilatation of unequal bonds"); on a lattice every weight would be 1, so it is off.
    pub weighted_dilatation: bool,
}

impl<const D: usize, const K: usize> Particles<D, K> {
    /// A body of particles at `x0` with volumes, slots and per-slot reference lengths; each
    /// particle's horizon is its longest bond and its length scale its shortest, the
    /// micro-moduli are 0 until filled.
    pub fn new(
        x0: Vec<SVector<f64, D>>,
        volume: Vec<f64>,
        neighbours: Vec<[u32; K]>,
        reverse: Vec<[u8; K]>,
        l0: Vec<[f64; K]>,
        spacing: f64,
    ) -> Self {
        let n = x0.len();
        let mut p = Particles {
            x0,
            volume,
            neighbours,
            reverse,
            l0,
            horizon: vec![0.0; n],
            length: vec![0.0; n],
            a: vec![0.0; n],
            b: vec![0.0; n],
            c: vec![0.0; n],
            spacing,
            weighted_dilatation: false,
        };
        p.measure_bonds();
        p
    }

    /// Set each particle's horizon (its longest bond) and length scale (its shortest bond;
    /// the nominal spacing for a particle without bonds).
    pub fn measure_bonds(&mut self) {
        for i in 0..self.len() {
            let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
            for k in 0..K {
                if self.neighbours[i][k] != NONE {
                    lo = lo.min(self.l0[i][k]);
                    hi = hi.max(self.l0[i][k]);
                }
            }
            self.horizon[i] = if hi > 0.0 { hi } else { self.spacing };
            self.length[i] = if lo.is_finite() { lo } else { self.spacing };
        }
    }

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

    /// The bonds of particle i in the reference configuration: (unit direction, L0).
    pub fn reference_bonds(&self, i: usize) -> Vec<(SVector<f64, D>, f64)> {
        (0..K)
            .filter(|&k| self.neighbours[i][k] != NONE)
            .map(|k| {
                let j = self.neighbours[i][k] as usize;
                ((self.x0[j] - self.x0[i]).normalize(), self.l0[i][k])
            })
            .collect()
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
///
/// Counted field by field (`Particles`, `solver::mechanics::Mechanics`,
/// `solver::kernel::State`): x0, x, x_next, v, v_next, force, force_prev: 7·D f64; volume,
/// horizon, length and the body's a, b, c; the kernel's a, b, mass, inv_mass, c_in, c_ex;
/// b·θ and the damper work: 14 f64, and in 3D the kernel's second-neighbour c (docs/model.md §3):
/// 15; per slot the neighbour index twice (the body's and the kernel's, u32), reverse (u8),
/// l0 and 1/l0 (f64): 25 bytes; the kernel's slot end (u8), group bookkeeping and outputs:
/// ~64 bytes; in 3D also the dilatation weight per slot (f64; the FCC lattice runs with the
/// weighted dilatation). D = 2, K = 6: 438 B; D = 3, K = 18 (FCC): 946 B.
pub const fn bytes_per_particle(d: usize, k: usize) -> usize {
    let scalars = if d == 3 { 15 } else { 14 };
    // 3D (FCC): the dilatation weights per slot (f64)
    let weights = if d == 3 { 8 } else { 0 };
    7 * d * 8 + scalars * 8 + k * (2 * 4 + 1 + 2 * 8 + weights) + 64
}

/// Slots per particle of the standard lattices: 6 for the 2D hexagonal lattice, 18 for 3D.
pub const fn slots(d: usize) -> usize {
    if d == 2 {
        6
    } else {
        18
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn bytes_per_particle_of_the_lattices() {
        assert_eq!(super::bytes_per_particle(2, 6), 438);
        assert_eq!(super::bytes_per_particle(3, 18), 946);
    }
}
