//! Selective mass scaling (docs/model.md §5, (S.18)): the few particles whose own stable step
//! lies far below the median's (short bonds between random particles, corner particles) get
//! the mass that brings their step up to a fraction of the median, so that they no longer set
//! the step of the whole specimen.
//!
//! A particle's own squared frequency is bounded by r_i/m_i, r_i its block-row sum of the
//! linearised stiffness ([`Mechanics::row_bounds`]). With ω̄² the median of r_i/m_i over the
//! particles and q = `solver.mass_scaling`, every particle with r_i/m_i > ω̄²/q² gets
//! m_i = q²·r_i/ω̄²: its own step rises to q × the median particle's. The dampers keep the
//! coefficients of the true masses, and the fundamental period, and with it the loading time,
//! is that of the true masses. The added mass is inertia the specimen does not have: it acts
//! only through accelerations, so it leaves a quasi-static result unchanged while the kinetic
//! energy stays small, which the summary's kinetic-to-internal energy ratio shows.

use super::mechanics::Mechanics;
use nalgebra::SVector;

/// The largest added mass accepted, as a fraction of the specimen's mass: beyond it the
/// scaling no longer touches a few particles but the body.
pub const MAX_ADDED_MASS: f64 = 0.05;

/// What the scaling did, for summary.json and `sppm check`.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct MassScaling {
    /// q: the fraction of the median particle's step every particle's step was raised to.
    pub fraction_of_median_step: f64,
    /// Particles whose mass was raised.
    pub particles: usize,
    /// The added mass over the specimen's mass.
    pub added_mass_fraction: f64,
    /// The largest factor on one particle's mass.
    pub largest_factor: f64,
}

/// Raise the masses of the particles whose own step is below `q` × the median particle's
/// (see the module text); updates `mass` and `inv_mass` and reports what it added.
pub fn scale_masses<const D: usize, const K: usize>(
    mech: &mut Mechanics<D, K>,
    x0: &[SVector<f64, D>],
    q: f64,
) -> MassScaling {
    let rows = mech.row_bounds(x0);
    let mut omega2: Vec<f64> = rows
        .iter()
        .zip(mech.inv_mass.iter())
        .map(|(r, im)| r * im)
        .collect();
    let mid = omega2.len() / 2;
    let median = *omega2.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1;
    let limit = median / (q * q);
    let total: f64 = mech.mass.iter().sum();
    let mut report = MassScaling {
        fraction_of_median_step: q,
        largest_factor: 1.0,
        ..Default::default()
    };
    let mut added = 0.0;
    for (i, &r) in rows.iter().enumerate() {
        let m = mech.mass[i];
        if r > limit * m {
            let scaled = r / limit;
            added += scaled - m;
            report.particles += 1;
            report.largest_factor = report.largest_factor.max(scaled / m);
            mech.mass[i] = scaled;
            mech.inv_mass[i] = 1.0 / scaled;
        }
    }
    report.added_mass_fraction = added / total;
    report
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aligned::{copied, filled, CollectAligned};
    use crate::discretise::NONE;

    /// A chain along x of equal particles (slot 0 the left neighbour, slot 1 the right), one
    /// bond of it at half the spacing.
    fn chain() -> (Mechanics<2, 2>, Vec<SVector<f64, 2>>) {
        let mut x: Vec<f64> = (0..11).map(|i| i as f64).collect();
        for v in x.iter_mut().skip(6) {
            *v -= 0.5;
        }
        let n = x.len();
        let x0: Vec<SVector<f64, 2>> = x.iter().map(|&v| SVector::from([v, 0.0])).collect();
        let neighbours: Vec<[u32; 2]> = (0..n)
            .map(|i| {
                [
                    if i == 0 { NONE } else { i as u32 - 1 },
                    if i + 1 == n { NONE } else { i as u32 + 1 },
                ]
            })
            .collect();
        let inv_l0: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let l = |j: usize| 1.0 / (x[j] - x[i]).abs();
                [
                    if i == 0 { 0.0 } else { l(i - 1) },
                    if i + 1 == n { 0.0 } else { l(i + 1) },
                ]
            })
            .collect();
        let mass = filled(2.0, n);
        let mech = Mechanics {
            slot_inv_l0: None,
            slot_end: crate::solver::mechanics::slot_end(&neighbours),
            neighbours: copied(&neighbours),
            inv_l0: copied(&inv_l0),
            a: filled(1e3, n),
            b: filled(0.0, n),
            second: None,
            inv_mass: mass.iter().map(|m| 1.0 / m).collect_aligned(),
            mass,
            c_in: filled(0.0, n),
            c_ex: filled(0.0, n),
            c_implicit: filled(0.0, n),
            dilatation_weight: None,
            slot_weight: None,
        };
        (mech, x0)
    }

    /// The two particles of the short bond have the highest own frequencies; scaled to the
    /// median step (q = 1) they get exactly the mass that brings r_i/m_i down to the median's,
    /// and no other particle changes.
    #[test]
    fn only_the_stiff_particles_gain_mass_and_reach_the_median_step() {
        let (mut mech, x0) = chain();
        let before = mech.mass.clone();
        let rows = mech.row_bounds(&x0);
        let r = scale_masses(&mut mech, &x0, 1.0);
        let mut own: Vec<f64> = (0..11).map(|i| rows[i] / before[i]).collect();
        own.sort_by(f64::total_cmp);
        let median = own[5];
        for i in 0..11 {
            if rows[i] / before[i] > median {
                assert!((rows[i] / mech.mass[i] - median).abs() <= 1e-12 * median);
            } else {
                assert_eq!(mech.mass[i], before[i]);
            }
            assert_eq!(mech.inv_mass[i], 1.0 / mech.mass[i]);
        }
        assert_eq!(r.particles, 2);
        let added: f64 = (0..11).map(|i| mech.mass[i] - before[i]).sum();
        assert!((r.added_mass_fraction - added / 22.0).abs() < 1e-15);
        // the short bond's stiffness is twice a regular one's: r = 2k + k against 2k
        assert!(
            (r.largest_factor - 1.5).abs() < 1e-12,
            "{}",
            r.largest_factor
        );
    }
}
