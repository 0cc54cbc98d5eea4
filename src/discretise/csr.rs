//! Bonds in compressed sparse rows (CSR): a varying number of neighbours per particle
//! (docs/model.md §1).
//!
//! The lattices give every particle K fixed slots ([`Particles`]); SPPM's random particles
//! have as many bonds as the "either end lists the other" rule of the k nearest gives them
//! (docs/model.md §1, (3.50)), so a fixed K either wastes slots or cannot hold them. Here the
//! bonds of particle i are the flat entries `offsets[i]..offsets[i + 1]`, each directed bond
//! "ij" seen by i holding j, the position of its reverse "ji" (seen by j) and 1/L0. The
//! neighbour list is built once in the reference configuration and never changes
//! (docs/model.md §1).
//!
//! Invariants, established by the constructors and relied on by the CSR step kernel
//! (`solver::csr_kernel`): offsets start at 0 and never decrease, the last is the number of
//! directed bonds, every neighbour indexes a particle and is not the particle itself, and
//! `reverse` is an involution pairing bond ij with bond ji. The fields are private so that
//! nothing can break them after construction.

use super::{Particles, NONE};
use crate::aligned::{copied, Aligned};
use nalgebra::SVector;

/// The bonds of a body, two directed entries per undirected bond (docs/model.md §1: particle i
/// sees bond "ij", particle j sees "ji"), in arrays that start on cache lines and ask for
/// huge pages ([`crate::aligned`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Csr {
    /// Bonds of particle i: flat entries `offsets[i]..offsets[i + 1]` (n + 1 entries).
    offsets: Aligned<u32>,
    /// Per directed bond ij: the neighbour j.
    neighbours: Aligned<u32>,
    /// Per directed bond ij: the flat position of bond ji.
    reverse: Aligned<u32>,
    /// Per directed bond: 1/L0, with L0 the reference length (docs/model.md §2, (3.10)).
    inv_l0: Aligned<f64>,
}

impl Csr {
    /// The bonds of a slot layout, keeping each particle's slot order and skipping empty
    /// slots, so that a kernel summing over a particle's bonds in flat order performs the
    /// same additions as one summing over its slots. 1/L0 is computed as
    /// `solver::mechanics::Mechanics::new` does (`1.0 / l0`), so it carries the same bits.
    ///
    /// Fails where the slots are inconsistent (a neighbour that is no particle, a self bond,
    /// a reverse slot that does not point back, two reference lengths for one bond: see
    /// [`Particles::check_topology`]) or where the bonds do not fit 32-bit positions.
    pub fn from_slots<const D: usize, const K: usize>(p: &Particles<D, K>) -> Result<Self, String> {
        let n = p.len();
        if p.weighted_dilatation {
            return Err(
                "the body weighs its dilatations by bond length (random particles); the CSR kernel sums them unweighted, so run it on slots".into(),
            );
        }
        if p.neighbours.len() != n || p.reverse.len() != n || p.l0.len() != n {
            return Err(format!(
                "slot arrays of {} particles hold {} neighbour, {} reverse and {} length rows",
                n,
                p.neighbours.len(),
                p.reverse.len(),
                p.l0.len()
            ));
        }
        // Flat position of each particle's first bond and, per slot, of its bond.
        let mut offsets = Vec::with_capacity(n + 1);
        let mut total = 0usize;
        offsets.push(0);
        for (i, slots) in p.neighbours.iter().enumerate() {
            for &j in slots {
                if j != NONE && j as usize >= n {
                    return Err(format!("particle {i} has neighbour {j}: no such particle"));
                }
            }
            total += slots.iter().filter(|&&j| j != NONE).count();
            offsets.push(fit_u32(total)?);
        }
        // Flat position of the bond in slot k of particle i (occupied slots only).
        let position = |i: usize, k: usize| -> usize {
            offsets[i] as usize + p.neighbours[i][..k].iter().filter(|&&j| j != NONE).count()
        };
        let mut neighbours = Vec::with_capacity(total);
        let mut reverse = Vec::with_capacity(total);
        let mut inv_l0 = Vec::with_capacity(total);
        for i in 0..n {
            for k in 0..K {
                let j = p.neighbours[i][k];
                if j == NONE {
                    continue;
                }
                let r = p.reverse[i][k] as usize;
                if r >= K || p.neighbours[j as usize][r] as usize != i {
                    return Err(format!(
                        "bond {i}->{j} (slot {k}) has no reverse in slot {r}"
                    ));
                }
                let l0 = p.l0[i][k];
                if !(l0 > 0.0 && l0.is_finite()) {
                    return Err(format!("bond {i}-{j} has reference length {l0}"));
                }
                neighbours.push(j);
                reverse.push(position(j as usize, r) as u32);
                inv_l0.push(1.0 / l0);
            }
        }
        let csr = Csr {
            offsets: copied(&offsets),
            neighbours: copied(&neighbours),
            reverse: copied(&reverse),
            inv_l0: copied(&inv_l0),
        };
        csr.check_topology()?;
        Ok(csr)
    }

    /// The bonds of `x0.len()` particles at reference positions `x0` given as undirected
    /// pairs (i, j), as SPPM's neighbour search produces them (a bond wherever either end
    /// lists the other among its k nearest, docs/model.md §1). A pair may appear in either order
    /// and more than once; it makes one bond. Each particle's bonds are ordered by
    /// neighbour index; L0 = |x0_j − x0_i| is computed once per bond, so both directions
    /// carry the same 1/L0 bit for bit.
    ///
    /// Fails on a pair naming no particle, a self pair, coincident particles (L0 = 0) or
    /// more bonds than 32-bit positions hold.
    pub fn from_pairs<const D: usize>(
        x0: &[SVector<f64, D>],
        pairs: &[(u32, u32)],
    ) -> Result<Self, String> {
        let n = x0.len();
        let mut sorted = Vec::with_capacity(pairs.len());
        for &(i, j) in pairs {
            if i as usize >= n || j as usize >= n {
                return Err(format!("pair ({i}, {j}) names no particle: there are {n}"));
            }
            if i == j {
                return Err(format!("pair ({i}, {j}) bonds a particle to itself"));
            }
            sorted.push((i.min(j), i.max(j)));
        }
        sorted.sort_unstable();
        sorted.dedup();
        fit_u32(2 * sorted.len())?;
        let mut count = vec![0u32; n];
        for &(i, j) in &sorted {
            count[i as usize] += 1;
            count[j as usize] += 1;
        }
        let mut offsets = Vec::with_capacity(n + 1);
        offsets.push(0u32);
        for c in &count {
            offsets.push(offsets[offsets.len() - 1] + c);
        }
        // Pairs sorted by (low, high) fill each particle's bonds in increasing neighbour
        // order: first those with lower neighbours (in the order of the low end), then its
        // own pairs (in the order of the high end).
        let total = 2 * sorted.len();
        let mut next: Vec<u32> = offsets[..n].to_vec();
        let mut neighbours = vec![0u32; total];
        let mut reverse = vec![0u32; total];
        let mut inv_l0 = vec![0.0; total];
        for &(i, j) in &sorted {
            let l0 = (x0[j as usize] - x0[i as usize]).norm();
            if !(l0 > 0.0 && l0.is_finite()) {
                return Err(format!(
                    "particles {i} and {j} are bonded at reference distance {l0}"
                ));
            }
            let (u, w) = (next[i as usize], next[j as usize]);
            next[i as usize] += 1;
            next[j as usize] += 1;
            neighbours[u as usize] = j;
            neighbours[w as usize] = i;
            reverse[u as usize] = w;
            reverse[w as usize] = u;
            inv_l0[u as usize] = 1.0 / l0;
            inv_l0[w as usize] = 1.0 / l0;
        }
        let csr = Csr {
            offsets: copied(&offsets),
            neighbours: copied(&neighbours),
            reverse: copied(&reverse),
            inv_l0: copied(&inv_l0),
        };
        debug_assert!(csr.check_topology().is_ok());
        Ok(csr)
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.offsets.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of undirected bonds.
    pub fn bonds(&self) -> usize {
        self.neighbours.len() / 2
    }

    /// Number of bonds of particle i.
    pub fn bond_count(&self, i: usize) -> usize {
        (self.offsets[i + 1] - self.offsets[i]) as usize
    }

    /// Flat positions of the bonds of particle i.
    #[inline(always)]
    pub fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }

    /// Offsets (n + 1 entries): the bonds of particle i are `offsets[i]..offsets[i + 1]`.
    pub fn offsets(&self) -> &[u32] {
        &self.offsets
    }

    /// Neighbour j of each directed bond ij.
    pub fn neighbours(&self) -> &[u32] {
        &self.neighbours
    }

    /// Flat position of bond ji for each directed bond ij.
    pub fn reverse(&self) -> &[u32] {
        &self.reverse
    }

    /// 1/L0 of each directed bond.
    pub fn inv_l0(&self) -> &[f64] {
        &self.inv_l0
    }

    /// Bytes per particle of the CSR arrays for `bonds_per_particle` directed bonds each:
    /// an offset (u32) per particle, and a neighbour (u32), a reverse position (u32) and 1/L0
    /// (f64) per bond.
    pub const fn bytes_per_particle(bonds_per_particle: usize) -> usize {
        4 + bonds_per_particle * (4 + 4 + 8)
    }

    /// Check the structure: offsets increasing up to the bond count, every neighbour a
    /// particle other than itself, every bond's reverse pointing back from the neighbour
    /// (reverse of reverse is the identity), no bond listed twice by one particle and one
    /// reference length per bond (to 1e-12 relative, as [`Particles::check_topology`]).
    pub fn check_topology(&self) -> Result<(), String> {
        let n = self.len();
        let total = self.neighbours.len();
        if self.offsets.first() != Some(&0) || self.offsets[n] as usize != total {
            return Err(format!(
                "offsets run from {:?} to {} for {total} bonds",
                self.offsets.first(),
                self.offsets[n]
            ));
        }
        if self.reverse.len() != total || self.inv_l0.len() != total {
            return Err(format!(
                "{total} bonds but {} reverse positions and {} lengths",
                self.reverse.len(),
                self.inv_l0.len()
            ));
        }
        for i in 0..n {
            if self.offsets[i + 1] < self.offsets[i] {
                return Err(format!("offsets decrease at particle {i}"));
            }
            let r = self.range(i);
            for b in r.clone() {
                let j = self.neighbours[b] as usize;
                if j >= n {
                    return Err(format!("particle {i} has neighbour {j}: no such particle"));
                }
                if j == i {
                    return Err(format!("particle {i} is bonded to itself"));
                }
                if self.neighbours[r.start..b].contains(&(j as u32)) {
                    return Err(format!("particle {i} lists neighbour {j} twice"));
                }
                let rb = self.reverse[b] as usize;
                if !self.range(j).contains(&rb) || self.neighbours[rb] as usize != i {
                    return Err(format!(
                        "bond {i}->{j} (position {b}) has no reverse at position {rb}"
                    ));
                }
                if self.reverse[rb] as usize != b {
                    return Err(format!(
                        "bond {i}->{j}: the reverse of its reverse is {}, not {b}",
                        self.reverse[rb]
                    ));
                }
                let (u, w) = (self.inv_l0[b], self.inv_l0[rb]);
                if !(u > 0.0 && u.is_finite()) || (u - w).abs() > 1e-12 * u {
                    return Err(format!("bond {i}-{j} has two reference lengths"));
                }
            }
        }
        Ok(())
    }
}

/// A flat position as u32, or why not.
fn fit_u32(total: usize) -> Result<u32, String> {
    u32::try_from(total).map_err(|_| format!("{total} directed bonds: at most {} fit", u32::MAX))
}
