//! Per-particle static data of the step kernel, in structure-of-arrays form, allocated once:
//! neighbour slots, 1/L0 per slot, micro-moduli, masses and damper coefficients.
//!
//! FCC second neighbours (docs/model.md §3 with its erratum): the force state of particle i in
//! the direction of j is F_s,ij = (a_i + c_i·[j ∈ N_II])·S_ij + b_i·θ_i, so a bond in a
//! second-neighbour slot has the bond modulus a + c at each end and the bond force
//! ½((a_i + c_i) + (a_j + c_j))·S_ij + ½(bθ_i + bθ_j). [`Mechanics::second`] holds c and
//! the first second-neighbour slot; without it (2D, random particles, any body whose c is
//! all zero) every code path is the one without c, bit for bit.

use crate::aligned::{copied, filled, Aligned, CollectAligned};
use crate::discretise::{Particles, NONE};
use crate::model::force_state::axial_stiffness;
use nalgebra::SVector;

/// The assembled SPLM model of one run.
#[derive(Clone, Debug)]
pub struct Mechanics<const D: usize, const K: usize> {
    pub neighbours: Aligned<[u32; K]>,
    pub inv_l0: Aligned<[f64; K]>,
    /// 1/L0 of slot k where every particle with that slot occupied has the same bits there
    /// (the lattices: one spacing, or FCC's two); `None` otherwise (random particles). The
    /// AVX blocks broadcast it instead of loading slot k from four rows of `inv_l0`, which
    /// saves 8·K bytes a particle-step (benchmarks/RESULTS.md, "Aligned arrays and uniform
    /// reference lengths"). Derived from `inv_l0` by [`uniform_inv_l0`]: recompute it after
    /// changing `inv_l0` or `neighbours`.
    pub slot_inv_l0: Option<[f64; K]>,
    /// Micro-modulus a_i (N).
    pub a: Aligned<f64>,
    /// Micro-modulus b_i (N).
    pub b: Aligned<f64>,
    /// The second-neighbour modulus c_i and the slots it acts in (FCC, docs/model.md §3 erratum);
    /// `None` where no particle has a c (2D, random particles).
    pub second: Option<SecondNeighbours>,
    pub mass: Aligned<f64>,
    pub inv_mass: Aligned<f64>,
    /// Bond damper coefficient C_in,i = 2·m_i·ξ_in·ω_i (3.55); a bond uses ½(C_in,i + C_in,j)
    /// so that Newton's third law holds for unequal particles.
    pub c_in: Aligned<f64>,
    /// Particle damper coefficient C_ex,i = 2·m_i·ξ_ex·ω_struct (3.56).
    pub c_ex: Aligned<f64>,
    /// The share d_i of the bond dampers taken implicitly (N·s/m; docs/model.md §5, (S.17)):
    /// all zero for bond dampers taken wholly at v^{n−½}.
    pub c_implicit: Aligned<f64>,
    /// Per-slot weight L0,ik/ℓ_i of the dilatation θ_i = Σ_k w_ik·S_ik where the body asks
    /// for it (random particles, [`Particles::weighted_dilatation`]); `None`: θ_i = Σ_k S_ik.
    pub dilatation_weight: Option<Aligned<[f64; K]>>,
    /// The weights of [`Self::dilatation_weight`] per slot where every particle with that
    /// slot occupied has the same bits there (the FCC lattice: 1 for nearest, √2 for second
    /// neighbours); `None` otherwise (random particles) or without weights. The AVX blocks
    /// broadcast it instead of gathering slot k's weight from four rows: 8·K bytes less a
    /// particle-step (benchmarks/RESULTS.md, "FCC"). Derived by [`uniform_inv_l0`]'s rule.
    pub slot_weight: Option<[f64; K]>,
    /// One past each particle's last occupied slot: the AVX blocks stop at the largest of
    /// their four (random particles fill 6–11 of 12 slots).
    pub slot_end: Aligned<u8>,
}

impl<const D: usize, const K: usize> Default for Mechanics<D, K> {
    /// No particles.
    fn default() -> Self {
        Mechanics {
            neighbours: Aligned::new(0),
            inv_l0: Aligned::new(0),
            slot_inv_l0: None,
            a: Aligned::new(0),
            b: Aligned::new(0),
            second: None,
            mass: Aligned::new(0),
            inv_mass: Aligned::new(0),
            c_in: Aligned::new(0),
            c_ex: Aligned::new(0),
            c_implicit: Aligned::new(0),
            dilatation_weight: None,
            slot_weight: None,
            slot_end: Aligned::new(0),
        }
    }
}

/// The FCC second-neighbour micro-modulus (docs/model.md §3 with its erratum): slots
/// `first_slot..K` hold second neighbours (N_II), whose bonds have modulus a_i + c_i at
/// particle i's end.
#[derive(Clone, Debug)]
pub struct SecondNeighbours {
    /// c_i per particle (N; negative for FCC: c = (1/(2√2) − 1)·a).
    pub c: Aligned<f64>,
    /// The first second-neighbour slot (12 for FCC: slots 0..12 are the nearest neighbours).
    pub first_slot: usize,
}

/// The first second-neighbour slot of a body with K slots whose particles carry a c:
/// 12 for the FCC lattice (K = 18: 12 nearest neighbours, then 6 second neighbours).
pub const fn first_second_slot(k: usize) -> Option<usize> {
    if k == 18 {
        Some(12)
    } else {
        None
    }
}

/// w_k·s for a row of [`Mechanics::weights`]; s itself without weights, so that the lattices
/// keep their bits. Every sum θ_i = Σ_k w_ik·S_ik goes through it.
#[inline(always)]
pub fn weighted<const K: usize>(w: Option<&[f64; K]>, k: usize, s: f64) -> f64 {
    match w {
        Some(w) => w[k] * s,
        None => s,
    }
}

/// 1/L0 per slot where it is the same, bit for bit, for every particle with that slot
/// occupied (0 for a slot that no particle occupies); `None` where any slot differs between
/// two particles. See [`Mechanics::slot_inv_l0`].
pub fn uniform_inv_l0<const K: usize>(
    neighbours: &[[u32; K]],
    inv_l0: &[[f64; K]],
) -> Option<[f64; K]> {
    let mut u: [Option<f64>; K] = [None; K];
    for (s, l) in neighbours.iter().zip(inv_l0) {
        for k in 0..K {
            if s[k] == NONE {
                continue;
            }
            match u[k] {
                None => u[k] = Some(l[k]),
                Some(v) if v.to_bits() == l[k].to_bits() => {}
                Some(_) => return None,
            }
        }
    }
    Some(u.map(|v| v.unwrap_or(0.0)))
}

/// One past the last occupied slot of each particle.
pub fn slot_end<const K: usize>(neighbours: &[[u32; K]]) -> Aligned<u8> {
    neighbours
        .iter()
        .map(|s| s.iter().rposition(|&j| j != NONE).map_or(0, |k| k + 1) as u8)
        .collect_aligned()
}

impl<const D: usize, const K: usize> Mechanics<D, K> {
    /// Model of a body with its micro-moduli (`p.a`, `p.b`, `p.c`) and density; dampers off.
    ///
    /// [`Self::second`] is set when any c_i is non-zero (not merely because K = 18: a body
    /// with 18 slots and no c, such as the simple-cubic block of `tests/suite/concrete_3d.rs`, keeps
    /// the kernels without c); the second-neighbour slots are then those of
    /// [`first_second_slot`], which must know K.
    pub fn new(p: &Particles<D, K>, rho: &[f64]) -> Self {
        let n = p.len();
        let second = p.c.iter().any(|&c| c != 0.0).then(|| {
            let first_slot = first_second_slot(K).unwrap_or_else(|| {
                panic!("micro-modulus c is set but {K} slots have no second-neighbour slots")
            });
            SecondNeighbours {
                c: copied(&p.c),
                first_slot,
            }
        });
        // The kernel's unchecked gathers rely on this.
        assert!(
            p.neighbours
                .iter()
                .flatten()
                .all(|&j| j == crate::discretise::NONE || (j as usize) < n),
            "a neighbour slot indexes no particle"
        );
        let inv_l0 =
            p.l0.iter()
                .map(|s| {
                    let mut r = [0.0; K];
                    for k in 0..K {
                        if s[k] > 0.0 {
                            r[k] = 1.0 / s[k];
                        }
                    }
                    r
                })
                .collect_aligned();
        let mass: Aligned<f64> = (0..n).map(|i| rho[i] * p.volume[i]).collect_aligned();
        let dilatation_weight = p.weighted_dilatation.then(|| {
            (0..n)
                .map(|i| {
                    std::array::from_fn(|k| {
                        if p.neighbours[i][k] != NONE {
                            p.l0[i][k] / p.length[i]
                        } else {
                            0.0
                        }
                    })
                })
                .collect_aligned()
        });
        let slot_weight = dilatation_weight
            .as_ref()
            .and_then(|w| uniform_inv_l0(&p.neighbours, w));
        Mechanics {
            neighbours: copied(&p.neighbours),
            slot_inv_l0: uniform_inv_l0(&p.neighbours, &inv_l0),
            slot_weight,
            inv_l0,
            a: copied(&p.a),
            b: copied(&p.b),
            second,
            inv_mass: mass.iter().map(|m| 1.0 / m).collect_aligned(),
            mass,
            c_in: filled(0.0, n),
            c_ex: filled(0.0, n),
            c_implicit: filled(0.0, n),
            dilatation_weight,
            slot_end: slot_end(&p.neighbours),
        }
    }

    /// Particle i's row of dilatation weights; `None` without weights (see [`weighted`]).
    #[inline(always)]
    pub fn weights(&self, i: usize) -> Option<&[f64; K]> {
        self.dilatation_weight.as_ref().map(|w| &w[i])
    }

    pub fn len(&self) -> usize {
        self.mass.len()
    }

    pub fn is_empty(&self) -> bool {
        self.mass.is_empty()
    }

    /// Whether any bond damper is on.
    pub fn has_bond_dampers(&self) -> bool {
        self.c_in.iter().any(|&c| c != 0.0)
    }

    /// The bond moduli (at i's end, at j's end) of the bond in slot k of particle i to j:
    /// (a_i, a_j), or (a_i + c_i, a_j + c_j) in a second-neighbour slot (docs/model.md §3
    /// erratum). The bond force is `bond_force(mi, mj, S, bθ_i, bθ_j)` and particle i's force
    /// state `force_state(mi, S, bθ_i)` with (mi, mj) from here.
    #[inline(always)]
    pub fn bond_moduli(&self, i: usize, j: usize, k: usize) -> (f64, f64) {
        (self.slot_modulus(i, k), self.slot_modulus(j, k))
    }

    /// Particle i's own bond modulus in slot k: a_i, or a_i + c_i in a second-neighbour slot
    /// (`force_state::slot_modulus`).
    #[inline(always)]
    pub fn slot_modulus(&self, i: usize, k: usize) -> f64 {
        crate::model::force_state::slot_modulus(self.a[i], self.second_of(i), k)
    }

    /// (c_i, the first second-neighbour slot), `None` without second neighbours: what
    /// `force_state::slot_modulus` and the damage laws (`ParticleBonds::second`) take.
    #[inline(always)]
    pub fn second_of(&self, i: usize) -> Option<(f64, usize)> {
        self.second.as_ref().map(|s| (s.c[i], s.first_slot))
    }

    /// Panics when the model has second-neighbour moduli: for the kernels that do not
    /// implement them yet (`what` names the kernel), so that none ignores a c silently.
    pub fn assert_no_second(&self, what: &str) {
        assert!(
            self.second.is_none(),
            "{what} does not implement the second-neighbour modulus c (docs/model.md §3, FCC)"
        );
    }

    /// Iterate over the occupied slots of particle i: (slot, neighbour, 1/L0).
    #[inline(always)]
    pub fn bonds(&self, i: usize) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
        let s = &self.neighbours[i];
        let l = &self.inv_l0[i];
        (0..K)
            .filter(move |&k| s[k] != NONE)
            .map(move |k| (k, s[k] as usize, l[k]))
    }

    /// Upper bound of the spectral radius of M⁻¹K of the linearised model (the induced
    /// block-row-sum norm, a Gershgorin bound), with each block bounded by its 2-norm.
    /// Derivation: f_i = Σ_j ½((a_i+a_j)S_ij + b_i θ_i + b_j θ_j)·n_ij with
    /// S_ij = n_ij·(u_j − u_i)/L_ij and θ_i = Σ_m w_im·S_im (a + c in place of a in a
    /// second-neighbour slot, [`Self::bond_moduli`]).
    pub fn max_eigenvalue_bound(&self, x0: &[SVector<f64, D>]) -> f64 {
        self.row_bounds(x0)
            .iter()
            .zip(self.inv_mass.iter())
            .map(|(r, im)| r * im)
            .fold(0.0, f64::max)
    }

    /// Each particle's block-row sum r_i of the linearised stiffness (N/m), blocks bounded by
    /// their 2-norms: r_i/m_i bounds the squared frequency of the particle moving alone, and
    /// the largest of them bounds ω_max² ([`Self::max_eigenvalue_bound`], which derives it).
    pub fn row_bounds(&self, x0: &[SVector<f64, D>]) -> Vec<f64> {
        let n = self.len();
        // |Σ_m n_im / L_im| and Σ_m 1/L_im per particle
        let mut sum_n_over_l = vec![0.0; n];
        let mut sum_inv_l = vec![0.0; n];
        let mut sum_n = vec![0.0; n];
        for i in 0..n {
            let mut s = SVector::<f64, D>::zeros();
            let mut sn = SVector::<f64, D>::zeros();
            let w = self.weights(i);
            for (k, j, il) in self.bonds(i) {
                let e = (x0[j] - x0[i]) * il;
                let wil = weighted(w, k, il);
                s += e * wil;
                sn += e;
                sum_inv_l[i] += wil;
            }
            sum_n_over_l[i] = s.norm();
            sum_n[i] = sn.norm();
        }
        let mut rows = vec![0.0; n];
        for (i, row) in rows.iter_mut().enumerate() {
            let mut r = 0.0;
            let bi = self.b[i].abs();
            for (k, j, il) in self.bonds(i) {
                // a-term: block to u_j and its share of the diagonal block
                let (mi, mj) = self.bond_moduli(i, j, k);
                r += 2.0 * axial_stiffness(mi, mj).abs() * il;
                // b_j θ_j term: blocks to the neighbours m of j and to u_j
                let bj = self.b[j].abs();
                r += 0.5 * bj * (sum_inv_l[j] + sum_n_over_l[j]);
            }
            // b_i θ_i term: ½ b_i θ_i Σ_j n_ij, blocks to every neighbour m and to u_i
            r += 0.5 * bi * sum_n[i] * (sum_inv_l[i] + sum_n_over_l[i]);
            *row = r;
        }
        rows
    }

    /// Upper bound of the spectral radius of M⁻¹C_in (bond dampers, treated explicitly).
    pub fn max_bond_damping_rate(&self) -> f64 {
        (0..self.len())
            .map(|i| {
                let s: f64 = self
                    .bonds(i)
                    .map(|(_, j, _)| self.c_in[i] + self.c_in[j])
                    .sum();
                s * self.inv_mass[i]
            })
            .fold(0.0, f64::max)
    }
}
