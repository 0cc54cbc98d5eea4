//! The two-spring concrete law (docs/model.md §6–9) as a [`DamageLaw`]: tensile damage by
//! Rankine or interaction initiation and bilinear softening over a crack band, compressive
//! damage, and plasticity with linear hardening.
//!
//! **Decision (criteria stress).** Initiation (§8) and yield (§9) use σ_c = D·ε_d of the
//! particle, ε_d the least-squares strain (see `model::strain`) of its damaged elastic
//! stretches d_ij·S_e,ij (or its neighbourhood's mean (S.16), `concrete.criteria_strain`),
//! rather than (3.18). For an undamaged bulk particle the two are
//! identical, and with damage they differ only by the d_ij on the b-term; but (3.18)
//! under-reads at free surfaces (full ΔV, half the bonds) by up to ~60%, so cracks could
//! neither start nor run through surface particles. The stress maps show the same D·ε of the
//! particle's own strain (`run::stress_recovery`).

use super::damage::{self, ConcreteLaw, LocalProperties};
use super::damage_law::{DamageLaw, Kernel, ParticleBonds, ParticleDamage};
use super::dimension::{Dim, Dimension, Tensor};
use super::force_state::force_state;
use super::plasticity;

/// The two-spring law of a run in D dimensions (2D plane stress or strain by the law's
/// `plane`, or 3D): the concrete law, its elasticity matrix and, with random fields, each
/// particle's own E, f't, f'c and G_f.
#[derive(Clone, Debug)]
pub struct TwoSpring<const D: usize>
where
    Dim<D>: Dimension<D>,
{
    pub law: ConcreteLaw,
    /// Elasticity matrix D of the law (Voigt, engineering shear).
    pub d: <Dim<D> as Dimension<D>>::Stiffness,
    /// Each particle's own values (random fields, docs/model.md §12); `None`: the law's values
    /// everywhere.
    pub local: Option<Vec<LocalProperties>>,
}

impl<const D: usize> TwoSpring<D>
where
    Dim<D>: Dimension<D>,
{
    pub fn new(law: ConcreteLaw, local: Option<Vec<LocalProperties>>) -> Self {
        TwoSpring {
            law,
            d: Dim::<D>::elasticity(law.e, law.nu, law.plane),
            local,
        }
    }
}

impl<const D: usize, const K: usize> DamageLaw<D, K> for TwoSpring<D>
where
    Dim<D>: Dimension<D>,
{
    type State = ParticleDamage;

    /// The tension kernel unless the law has compressive damage or plasticity
    /// (docs/architecture.md, "skip what the scene does not need").
    fn kernel(&self) -> Kernel {
        if self.law.compressive_damage || self.law.plasticity {
            Kernel::Full
        } else {
            Kernel::Tension
        }
    }

    /// The two springs in series (3.37) with the tensile damage of both particles where the
    /// bond is stretched, the compressive damage where it is shortened (the tension kernel
    /// has none). Computed identically from either end of the bond.
    #[inline(always)]
    fn bond_factor<const FULL: bool>(
        &self,
        pi: &ParticleDamage,
        pj: &ParticleDamage,
        se: f64,
    ) -> (f64, f64) {
        let (wi, wj) = if se >= 0.0 {
            (pi.wt, pj.wt)
        } else if FULL {
            (pi.wc, pj.wc)
        } else {
            (0.0, 0.0)
        };
        // The undamaged bond (most of them) skips the division and the square root.
        if wi == 0.0 && wj == 0.0 {
            (1.0, 1.0)
        } else {
            let d = damage::damage_factor(wi, wj);
            (d, d.sqrt())
        }
    }

    const SERIES_DAMAGE: bool = true;

    #[inline(always)]
    fn series_damage(&self, p: &ParticleDamage) -> (f64, f64) {
        (p.wt, p.wc)
    }

    /// Tensile initiation and damage (§8), compressive damage and plastic flow (§9).
    /// `FULL = false` (the tension kernel) evaluates neither ε_eff, compressive damage nor the
    /// yield criterion; on a law without them it gives the same numbers as `FULL = true`.
    #[inline(always)]
    fn update<const FULL: bool>(
        &self,
        b: &ParticleBonds<'_, D, K>,
        p: &mut ParticleDamage,
        sps: &mut [f64; K],
    ) {
        if p.wt >= 1.0 && (p.wc >= 1.0 || !FULL) {
            return;
        }
        let local_law;
        let law = match &self.local {
            Some(l) => {
                local_law = self.law.with(&l[b.i]);
                &local_law
            }
            None => &self.law,
        };
        // Strains (§7): total for the damage law and ε_eff; the criteria stress from the
        // damaged elastic stretches.
        let eps = Dim::<D>::strain_tensor(b.fit, b.total);
        // D·ε with the particle's own E (D is linear in E: it scales the law's D).
        let stress_of =
            |e: &Tensor<D>| Dim::<D>::stress_of_strain(&(self.d * (law.e / self.law.e)), e);
        // The criteria stress D·ε_d, needed only to test initiation and yield.
        let criteria_stress = || {
            let eps_d = match b.criteria_strain {
                Some(e) => *e,
                None if b.undamaged => eps,
                None => Dim::<D>::strain_tensor(b.fit, b.damaged),
            };
            stress_of(&eps_d)
        };

        // Tensile damage (§8). The initiation test is monotone in (σ_max, −σ_min), so bounds
        // that fail it settle it without the principal stresses (in 3D an eigenvalue solve).
        let mut sigma = None;
        let mut initiates_now = false;
        if law.tensile_damage && !p.initiated {
            let sigma = *sigma.insert(criteria_stress());
            let (hi, lo) = Dim::<D>::principal_stress_bounds(&sigma, law.nu, law.plane);
            if damage::initiates(law, hi, lo) {
                // σ_max, σ_min, with the out-of-plane σ_zz in 2D
                let (hi, lo) = Dim::<D>::principal_stress_extremes(&sigma, law.nu, law.plane);
                initiates_now = damage::initiates(law, hi, lo);
            }
        }
        if !(FULL || p.initiated || initiates_now) {
            return;
        }
        // The principal strains where tensile damage needs ε_I; elsewhere ε_eff comes from
        // the invariants (no eigenvalue solve in 3D). The tension kernel needs ε_I alone
        // (in 3D a third of the eigenvalue solve's cosines).
        let principal = (p.initiated || initiates_now).then(|| {
            if FULL {
                Dim::<D>::principal_strains(&eps, law.nu, law.plane)
            } else {
                let e1 = Dim::<D>::principal_strain_max(&eps, law.nu, law.plane);
                (e1, f64::NAN, f64::NAN)
            }
        });
        if let Some((e1, _, _)) = principal {
            if initiates_now {
                p.initiated = true;
                p.eps_init = e1;
            }
            let band = law.crack_band * b.length();
            // (S.22): σ̃_I of the undamaged elastic strain, D·ε_e (ε itself where nothing
            // has yielded or been damaged).
            let sigma_i = || {
                let eps_e = if b.undamaged {
                    eps
                } else {
                    Dim::<D>::strain_tensor(b.fit, b.elastic)
                };
                Dim::<D>::principal_stress_extremes(&stress_of(&eps_e), law.nu, law.plane).0
            };
            let stress = damage::softened_stress(law, e1, sigma_i);
            p.wt =
                p.wt.max(damage::tensile_damage(law, band, e1, p.eps_init, stress));
        }
        if FULL {
            let eps_eff = match principal {
                Some((e1, e2, e3)) => damage::effective_strain(e1, e2, e3),
                None => Dim::<D>::effective_strain(&eps, law.nu, law.plane),
            };
            // Compressive damage (§9).
            if law.compressive_damage {
                p.wc = p.wc.max(damage::compressive_damage(law, p.wt, eps_eff));
            }
            // Plasticity (§9): yield on the criteria stress, flow along the deviatoric part of
            // the undamaged force states (3.44).
            if law.plasticity && p.wc < 1.0 {
                let f_eff = plasticity::effective_yield(law.fy, law.fult, law.eps_ult, eps_eff);
                let sigma = sigma.unwrap_or_else(criteria_stress);
                let ratio = Dim::<D>::equivalent_stress(&sigma, law.nu, law.plane) / f_eff;
                if ratio >= 1.0 {
                    // The flow's direction (3.44): the deviator of the undamaged force
                    // states, a·(S_e − mean S_e) where every bond has the modulus a. On the
                    // FCC lattice, whose second neighbours have a + c (0.354·a at ν = 0.2),
                    // the elastic stretches, so that the plastic stretches are a plastic
                    // strain's (S.21). Where the moduli are equal both give one direction; the
                    // force states stay there so that those results keep their golden records
                    // bit for bit (the rounding differs).
                    let mut fs = [0.0; K];
                    for (k, f) in fs.iter_mut().enumerate() {
                        if b.used[k] {
                            *f = match b.second {
                                Some(_) => b.elastic[k],
                                None => force_state(b.modulus(k), b.elastic[k], b.b_theta_elastic),
                            };
                        }
                    }
                    plasticity::flow(&fs, b.used, ratio, law.fy / law.e, sps);
                    p.yielded = true;
                }
            }
        }
    }

    fn view(&self, state: &ParticleDamage) -> ParticleDamage {
        *state
    }
}
