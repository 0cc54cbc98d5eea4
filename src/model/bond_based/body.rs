//! A bond-based body built on any set of points with volumes (the cubic grid, or the
//! particles of another discretisation): each point's family within the horizon δ in
//! compressed rows, with the partial-volume weight (B.4), the influence function, the
//! volume method's surface factor λ (docs/bond_based.md, "Families") and the law of each
//! bond. The arrays the kernel (`kernel.rs`) streams every step are 24 bytes a bond.

use super::family::partial_volume;
use super::micromodulus::Influence;
use super::softening::Softening;
use nalgebra::SVector;
use rayon::prelude::*;

/// The short-range repulsion of LAMMPS's peri styles and of the extended model of concrete: points
/// pressed closer than d_ij = min(0.9·ξ, 1.35·(r_i + r_j)) push apart with a stiffness 15·c
/// (docs/bond_based.md, "Contact").
#[derive(Clone, Copy, Debug)]
pub struct Contact {
    /// 1.35·(r_i + r_j) with r the half cell size: the reach of the repulsion (m).
    pub reach: f64,
    /// 15·c·ΔV²/δ (N/m): the repulsion's force per metre of overlap on a point.
    pub stiffness: f64,
}

/// What a body is built from, besides its points.
#[derive(Clone, Copy, Debug)]
pub struct BodySettings {
    /// Horizon δ (m).
    pub delta: f64,
    /// Cell size Δx of the partial-volume weight (m): the grid spacing, or the mean cell's
    /// edge of other points.
    pub dx: f64,
    /// Micromodulus c, or c0 of the conical influence (N/m⁶ in 3D).
    pub c: f64,
    pub influence: Influence,
    pub surface_correction: bool,
    /// Fit each bond's law to its corrected micromodulus λ·c.
    pub critical_stretch_correction: bool,
    /// The law of a bulk bond (λ = 1); `None`: elastic bonds.
    pub law: Option<Softening>,
    /// Compressive critical stretch s_cc (positive).
    pub compressive: Option<f64>,
    pub contact: bool,
}

/// A bond-based body: points, families and the bonds' history.
#[derive(Clone, Debug)]
pub struct BondBody<const D: usize> {
    pub x0: Vec<SVector<f64, D>>,
    /// ΔV of each point (m³).
    pub volume: Vec<f64>,
    /// Point i's bonds are `start[i]..start[i + 1]`.
    pub start: Vec<u32>,
    pub neighbour: Vec<u32>,
    /// 1/ξ of each bond, ξ its reference length (1/m).
    pub inv_xi: Vec<f64>,
    /// c·ω(ξ)·λ·v_c·ΔV_i·ΔV_j: the force on the bond's point per unit stretch (N).
    pub stiffness: Vec<f32>,
    /// The surface factor λ of each bond (1 without the correction).
    pub lambda: Vec<f32>,
    /// The largest stretch each bond has seen; +∞ once broken.
    pub s_max: Vec<f32>,
    pub settings: BodySettings,
    /// The repulsion of points pressed together (`model.contact`).
    pub contact: Option<Contact>,
    /// The bulk family's volume Σ v_c·ΔV (m³), the reference of λ.
    pub bulk_family_volume: f64,
    /// The smallest stretch at which any bond's law starts to soften (+∞ for elastic
    /// bonds): below it the kernel skips the law.
    pub elastic_limit: f64,
}

/// The bond of one point to a neighbour, found by the search.
struct Found {
    j: u32,
    xi: f64,
    weight: f64,
}

impl<const D: usize> BondBody<D> {
    /// The body of the points `x0` with volumes, every pair within δ that `admits` (the bond
    /// stays in the body: no bond across a notch or a hole) bonded; `bulk_volume` is the family
    /// volume of a point far from every surface (m³; its bonds get λ = 1), or `None` for the
    /// median of the family volumes within 10% of the largest (the points whose family is
    /// whole, on a lattice all equal).
    pub fn new(
        x0: Vec<SVector<f64, D>>,
        volume: Vec<f64>,
        settings: BodySettings,
        bulk_volume: Option<f64>,
        admits: &(dyn Fn(usize, usize) -> bool + Sync),
    ) -> Self {
        let s = settings;
        let families: Vec<Vec<Found>> = search(&x0, s.delta, &|i, j, xi| {
            if !admits(i, j) {
                return None;
            }
            let w = partial_volume(xi, s.delta, s.dx);
            (w > 0.0).then_some(w)
        });
        let n = x0.len();
        let mut start = Vec::with_capacity(n + 1);
        start.push(0u32);
        let total: usize = families.iter().map(Vec::len).sum();
        let (mut neighbour, mut xi, mut weight) = (
            Vec::with_capacity(total),
            Vec::with_capacity(total),
            Vec::with_capacity(total),
        );
        for f in &families {
            for b in f {
                neighbour.push(b.j);
                xi.push(b.xi);
                weight.push(b.weight);
            }
            start.push(neighbour.len() as u32);
        }
        // family volumes Σ v_c·ΔV_j and the surface factors λ_ij = 2·V0/(V_i + V_j)
        let family_volume: Vec<f64> = (0..n)
            .map(|i| {
                (start[i] as usize..start[i + 1] as usize)
                    .map(|b| weight[b] * volume[neighbour[b] as usize])
                    .sum()
            })
            .collect();
        let bulk_volume = bulk_volume.unwrap_or_else(|| whole_family_volume(&family_volume));
        let mut stiffness = Vec::with_capacity(total);
        let mut lambda = Vec::with_capacity(total);
        for i in 0..n {
            for b in start[i] as usize..start[i + 1] as usize {
                let j = neighbour[b] as usize;
                let l = if s.surface_correction {
                    2.0 * bulk_volume / (family_volume[i] + family_volume[j])
                } else {
                    1.0
                };
                let omega = match s.influence {
                    Influence::Constant => 1.0,
                    Influence::Conical => 1.0 - xi[b] / s.delta,
                };
                stiffness.push((s.c * omega * l * weight[b] * volume[i] * volume[j]) as f32);
                lambda.push(l as f32);
            }
        }
        let mean_volume = volume.iter().sum::<f64>() / n.max(1) as f64;
        let contact = s.contact.then(|| Contact {
            reach: 1.35 * s.dx,
            stiffness: 15.0 * s.c * mean_volume * mean_volume / s.delta,
        });
        let elastic_limit = match s.law {
            None => f64::INFINITY,
            Some(law) if s.critical_stretch_correction => {
                lambda.iter().fold(f64::INFINITY, |m: f64, &l| {
                    m.min(law.for_stiffness(l as f64).elastic_limit())
                })
            }
            Some(law) => law.elastic_limit(),
        };
        let inv_xi = xi.iter().map(|l| 1.0 / l).collect();
        drop(xi);
        BondBody {
            elastic_limit,
            inv_xi,
            x0,
            volume,
            start,
            neighbour,
            stiffness,
            lambda,
            s_max: vec![0.0; total],
            settings,
            contact,
            bulk_family_volume: bulk_volume,
        }
    }

    pub fn len(&self) -> usize {
        self.x0.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x0.is_empty()
    }

    /// Bonds counted once (each is held by both its points).
    pub fn bonds(&self) -> usize {
        self.neighbour.len() / 2
    }

    /// The law of bond b: the bulk law, or with the critical-stretch correction the law fitted
    /// to λ_b·c.
    #[inline]
    pub fn law_of(&self, b: usize) -> Option<Softening> {
        let law = self.settings.law?;
        Some(if self.settings.critical_stretch_correction {
            law.for_stiffness(self.lambda[b] as f64)
        } else {
            law
        })
    }

    /// Each point's damage φ_i: the share of its family's bond volume that is broken, or
    /// softened (Σ w·d / Σ w, the usual peridynamic damage index).
    pub fn damage(&self) -> Vec<f64> {
        (0..self.len())
            .into_par_iter()
            .map(|i| {
                let (mut lost, mut all) = (0.0, 0.0);
                for b in self.start[i] as usize..self.start[i + 1] as usize {
                    let w = self.stiffness[b] as f64;
                    all += w;
                    lost += w * self.bond_damage(b);
                }
                if all > 0.0 {
                    lost / all
                } else {
                    0.0
                }
            })
            .collect()
    }

    /// The softening d of bond b at its largest stretch (1 once broken).
    pub fn bond_damage(&self, b: usize) -> f64 {
        let s = self.s_max[b] as f64;
        if s.is_infinite() {
            return 1.0;
        }
        self.law_of(b).map(|l| l.damage(s)).unwrap_or(0.0)
    }

    /// Bonds broken (counted once).
    pub fn broken_bonds(&self) -> usize {
        self.s_max.iter().filter(|s| s.is_infinite()).count() / 2
    }
}

/// The median of the family volumes within 10% of the largest: the volume of a whole family.
fn whole_family_volume(volumes: &[f64]) -> f64 {
    let top = volumes.iter().cloned().fold(0.0, f64::max);
    let mut whole: Vec<f64> = volumes
        .iter()
        .cloned()
        .filter(|&v| v >= 0.9 * top)
        .collect();
    whole.sort_by(f64::total_cmp);
    whole.get(whole.len() / 2).copied().unwrap_or(top)
}

/// For every point, the points within `delta` that `accept` (i, j, ξ) gives a weight, in
/// increasing index, found through a grid of cells of side δ.
fn search<const D: usize>(
    x0: &[SVector<f64, D>],
    delta: f64,
    accept: &(dyn Fn(usize, usize, f64) -> Option<f64> + Sync),
) -> Vec<Vec<Found>> {
    let n = x0.len();
    if n == 0 {
        return Vec::new();
    }
    let mut lo = x0[0];
    for p in x0 {
        lo = lo.inf(p);
    }
    let cell_of = |p: &SVector<f64, D>| -> [i64; D] {
        std::array::from_fn(|k| ((p[k] - lo[k]) / delta).floor() as i64)
    };
    let mut cells: std::collections::HashMap<[i64; D], Vec<u32>> = Default::default();
    for (i, p) in x0.iter().enumerate() {
        cells.entry(cell_of(p)).or_default().push(i as u32);
    }
    let reach = delta * (1.0 + 1e-12);
    (0..n)
        .into_par_iter()
        .map(|i| {
            let c = cell_of(&x0[i]);
            let mut out = Vec::new();
            let neighbours = 3usize.pow(D as u32);
            for k in 0..neighbours {
                let mut r = k;
                let cell: [i64; D] = std::array::from_fn(|d| {
                    let o = (r % 3) as i64 - 1;
                    r /= 3;
                    c[d] + o
                });
                let Some(members) = cells.get(&cell) else {
                    continue;
                };
                for &j in members {
                    let j = j as usize;
                    if j == i {
                        continue;
                    }
                    let xi = (x0[j] - x0[i]).norm();
                    if xi > reach {
                        continue;
                    }
                    if let Some(weight) = accept(i, j, xi) {
                        out.push(Found {
                            j: j as u32,
                            xi,
                            weight,
                        });
                    }
                }
            }
            out.sort_by_key(|f| f.j);
            out
        })
        .collect()
}
