//! Least-squares micro-moduli (docs/model.md §3, (3.20)): each random particle's (a_i, b_i)
//! from its own bonds, and the FCC lattice's bulk and boundary constants (a, b, c).

use crate::discretise::fcc::{cell_volume, SECOND, SLOTS, STEPS};
use crate::discretise::{Particles, NONE};
use crate::model::dimension::{Dim, Dimension};
use crate::model::micro_modulus::{fit_fcc_weighted, fit_weighted_3d, FccBond, FccModuli};
use crate::run::model::ModuliFit;
use crate::scene::Plane;
use nalgebra::Vector3;

/// Each random particle's least-squares (a_i, b_i) against the elasticity matrix `d` from its
/// own bonds, with weighted dilatation ((3.20), docs/sppm.md), written into `a` and `b`;
/// particles without a fit keep their entries. Returns the residual statistics.
pub fn fit_moduli<const K: usize>(
    particles: &Particles<2, K>,
    d: &nalgebra::Matrix3<f64>,
    a: &mut [f64],
    b: &mut [f64],
) -> ModuliFit {
    fit_moduli_with(
        particles,
        |bonds, volume, ell| crate::model::dimension::fit_weighted_2d(bonds, volume, ell, d),
        a,
        b,
    )
}

/// [`fit_moduli`] in 3D (random particles in a solid): against the isotropic 6×6 `d`
/// (3.20), with the weighted dilatation.
pub fn fit_moduli_3d<const K: usize>(
    particles: &Particles<3, K>,
    d: &nalgebra::Matrix6<f64>,
    a: &mut [f64],
    b: &mut [f64],
) -> ModuliFit {
    fit_moduli_with(
        particles,
        |bonds, volume, ell| crate::model::micro_modulus::fit_weighted_3d(bonds, volume, ell, d),
        a,
        b,
    )
}

/// Each particle's (a_i, b_i) from `fit` of its reference bonds, volume and length scale, and
/// the residual statistics ([`fit_moduli`], [`fit_moduli_3d`]).
fn fit_moduli_with<const D: usize, const K: usize>(
    particles: &Particles<D, K>,
    fit: impl Fn(&[(nalgebra::SVector<f64, D>, f64)], f64, f64) -> Option<crate::model::dimension::Fit>
        + Sync,
    a: &mut [f64],
    b: &mut [f64],
) -> ModuliFit {
    use rayon::prelude::*;
    let n = particles.len();
    let fits: Vec<Option<crate::model::dimension::Fit>> = (0..n)
        .into_par_iter()
        .map(|i| {
            fit(
                &particles.reference_bonds(i),
                particles.volume[i],
                particles.length[i],
            )
        })
        .collect();
    let mut residual = vec![f64::NAN; n];
    let mut unfitted = 0;
    for (i, f) in fits.into_iter().enumerate() {
        match f {
            Some(f) => {
                a[i] = f.moduli.a;
                b[i] = f.moduli.b;
                residual[i] = f.residual;
            }
            None => unfitted += 1,
        }
    }
    let mut fitted: Vec<f64> = residual.iter().copied().filter(|r| r.is_finite()).collect();
    fitted.sort_by(f64::total_cmp);
    let pick = |q: f64| {
        if fitted.is_empty() {
            f64::NAN
        } else {
            fitted[((q * (fitted.len() - 1) as f64).round() as usize).min(fitted.len() - 1)]
        }
    };
    ModuliFit {
        residual_mean: fitted.iter().sum::<f64>() / fitted.len().max(1) as f64,
        residual_p99: pick(0.99),
        residual_max: pick(1.0),
        residual,
        unfitted,
    }
}

/// How the micro-moduli of an FCC body were set ([`assign_moduli`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ModuliReport {
    /// Particles with all 18 bonds: the bulk constants (4.8) with the erratum (× the volume
    /// fraction of a clipped cell).
    pub bulk: usize,
    /// Particles with missing bonds fitted (a, b, c) against D (3.20).
    pub fitted: usize,
    /// Particles with missing bonds whose (a, b, c) fit failed, fitted (a, b) with c = 0.
    pub fitted_without_c: usize,
    /// Particles no fit could serve (too few or coplanar bonds), given the bulk constants
    /// scaled by their volume fraction.
    pub unfitted: usize,
    /// Largest relative residual ‖D_i − D‖/‖D‖ of a fitted particle.
    pub max_residual: f64,
}

/// The bulk constants (a, b, c) of an FCC particle with nearest spacing `l0` under the
/// weighted dilatation the lattice runs with (docs/model.md §3 with its erratum; the closed forms
/// (4.8) hold for the source's unweighted θ, see [`fit_fcc_weighted`]): the exact fit of the
/// 18 bonds and the full cell to the isotropic D.
pub fn bulk_moduli(e: f64, nu: f64, l0: f64) -> FccModuli {
    let d = <Dim<3> as Dimension<3>>::elasticity(e, nu, Plane::Stress);
    let bonds: Vec<FccBond> = STEPS
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let v = Vector3::new(s[0] as f64, s[1] as f64, s[2] as f64);
            (v.normalize(), v.norm() * l0 / 2f64.sqrt(), k >= SECOND)
        })
        .collect();
    fit_fcc_weighted(&bonds, cell_volume(l0), l0, &d)
        .expect("the bulk FCC particle spans D")
        .moduli
}

/// Set a, b, c of every particle of an FCC body for the isotropic (E, ν) (docs/model.md §3 with
/// its erratum) and its volume `p.volume` (the full cell, or the cell clipped to the body,
/// `voronoi3::fcc_clipped_volumes`), for the weighted dilatation θ_i = Σ_m (L0,im/ℓ_i)·S_im
/// the lattice runs with ([`FccLattice::fill`](crate::discretise::fcc::FccLattice::fill) sets it): [`bulk_moduli`] scaled by the
/// particle's volume fraction for a particle with all 18 bonds; for one with missing bonds
/// the least-squares (a, b, c) of its own bonds and volume against D (3.20,
/// [`fit_fcc_weighted`]), or (a, b) with c = 0 where that fit fails, or the bulk constants
/// scaled by the volume fraction where no fit exists.
pub fn assign_moduli(p: &mut Particles<3, SLOTS>, e: f64, nu: f64) -> ModuliReport {
    let d = <Dim<3> as Dimension<3>>::elasticity(e, nu, Plane::Stress);
    let mut report = ModuliReport::default();
    let bulk = bulk_moduli(e, nu, p.spacing);
    for i in 0..p.len() {
        let ell = p.length[i];
        let fraction = p.volume[i] / cell_volume(p.spacing);
        let (mut a, mut b, mut c) = (bulk.a * fraction, bulk.b * fraction, bulk.c * fraction);
        if p.bond_count(i) == SLOTS {
            report.bulk += 1;
        } else {
            let bonds: Vec<FccBond> = (0..SLOTS)
                .filter(|&k| p.neighbours[i][k] != NONE)
                .map(|k| {
                    let j = p.neighbours[i][k] as usize;
                    ((p.x0[j] - p.x0[i]).normalize(), p.l0[i][k], k >= SECOND)
                })
                .collect();
            if let Some(f) = fit_fcc_weighted(&bonds, p.volume[i], ell, &d) {
                (a, b, c) = (f.moduli.a, f.moduli.b, f.moduli.c);
                report.fitted += 1;
                report.max_residual = report.max_residual.max(f.residual);
            } else {
                let plain: Vec<_> = bonds.iter().map(|&(n, l, _)| (n, l)).collect();
                if let Some(f) = fit_weighted_3d(&plain, p.volume[i], ell, &d) {
                    (a, b, c) = (f.moduli.a, f.moduli.b, 0.0);
                    report.fitted_without_c += 1;
                    report.max_residual = report.max_residual.max(f.residual);
                } else {
                    report.unfitted += 1;
                }
            }
        }
        p.a[i] = a;
        p.b[i] = b;
        p.c[i] = c;
    }
    report
}
