//! Two-spring damage (docs/model.md §6, (3.36), (3.37)) and the concrete laws that drive it:
//! tensile initiation and bilinear softening (§8, (4.12)–(4.14)), compressive damage
//! (§9, (4.16), (4.17)).

use crate::scene::{CrackOpening, Initiation, Plane, Scene, SofteningStress};

/// The resolved concrete law of a run (every value in SI; see `Scene::concrete_law`).
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct ConcreteLaw {
    pub e: f64,
    pub nu: f64,
    pub plane: Plane,
    pub fc: f64,
    pub ft: f64,
    pub fy: f64,
    pub fult: f64,
    pub gf: f64,
    /// COD_c (5.4).
    pub cod_c: f64,
    /// COD_1 = α·COD_c, the knee.
    pub cod_1: f64,
    pub gamma: f64,
    pub eps_ult: f64,
    pub wt_cr: f64,
    pub wc_max: f64,
    pub initiation: Initiation,
    pub crack_opening: CrackOpening,
    pub softening_stress: SofteningStress,
    pub tensile_damage: bool,
    pub compressive_damage: bool,
    pub plasticity: bool,
    /// The crack band in units of a particle's own length scale L0,i (the body's
    /// `length`): COD_eq = crack_band·L0,i·ε_I ((4.13) writes 2; see `concrete.crack_band`).
    pub crack_band: f64,
}

/// The values of the law that a random field varies per particle (docs/model.md §12; see
/// `material::properties`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalProperties {
    pub e: f64,
    pub ft: f64,
    pub fc: f64,
    pub fy: f64,
    pub fult: f64,
    pub gf: f64,
    pub cod_c: f64,
    pub cod_1: f64,
}

impl ConcreteLaw {
    /// The Table 1 concrete of Nikravesh Kazeroni (2017) in plane stress (E = 30 GPa, ν = 0.2, f'c = 27.58 MPa,
    /// f't = 2.6168 MPa, G_f = 81.4 N/m, α = 0.1, γ = 0.25, Rankine initiation, crack band
    /// 2.8·L0) with tensile damage, and with compressive damage and plasticity where `full`:
    /// the law `sppm bench` times.
    pub fn table1(full: bool) -> ConcreteLaw {
        let (ft, gf, alpha, gamma) = (2.6168e6, 81.4, 0.1, 0.25);
        let cod_c = crate::scene::concrete::critical_crack_opening(gf, ft, alpha, gamma);
        ConcreteLaw {
            e: 30e9,
            nu: 0.2,
            plane: Plane::Stress,
            fc: 27.58e6,
            ft,
            fy: 22.983e6,
            fult: 27.58e6,
            gf,
            cod_c,
            cod_1: alpha * cod_c,
            gamma,
            eps_ult: 0.0035,
            wt_cr: 1.0 / 3.0,
            wc_max: 1.0,
            initiation: Initiation::Rankine,
            crack_opening: CrackOpening::Total,
            softening_stress: SofteningStress::Strain,
            tensile_damage: true,
            compressive_damage: full,
            plasticity: full,
            crack_band: 2.8,
        }
    }

    /// The concrete law of a resolved scene (`Scene::resolve`), if it has `[concrete]`.
    pub fn from_scene(scene: &Scene) -> Option<ConcreteLaw> {
        let c = scene.concrete.as_ref()?;
        let get = |k: &str| scene.derived_value(k).unwrap_or(f64::NAN);
        let cod_c = get("COD_c");
        let (softening_stress, crack_opening) = scene.law_reading()?;
        Some(ConcreteLaw {
            e: scene.material.youngs_modulus(),
            nu: scene.material.nu,
            plane: scene.material.plane(),
            fc: get("fc"),
            ft: get("ft"),
            fy: get("fy"),
            fult: get("fult"),
            gf: get("Gf"),
            cod_c,
            cod_1: c.alpha * cod_c,
            gamma: c.gamma,
            eps_ult: c.eps_ult,
            wt_cr: c.wt_cr,
            wc_max: c.wc_max,
            initiation: c.initiation,
            crack_opening,
            softening_stress,
            tensile_damage: c.tensile_damage,
            compressive_damage: c.compressive_damage,
            plasticity: c.plasticity,
            crack_band: c.crack_band.unwrap_or(f64::NAN),
        })
    }

    /// A particle's values for E, f't, f'c and G_f: COD_c from (5.4) with the law's α and γ,
    /// f_y and f_ult in proportion to f'c.
    pub fn local(&self, e: f64, ft: f64, fc: f64, gf: f64) -> LocalProperties {
        let alpha = self.cod_1 / self.cod_c;
        let cod_c = crate::scene::concrete::critical_crack_opening(gf, ft, alpha, self.gamma);
        LocalProperties {
            e,
            ft,
            fc,
            fy: self.fy * fc / self.fc,
            fult: self.fult * fc / self.fc,
            gf,
            cod_c,
            cod_1: alpha * cod_c,
        }
    }

    /// This law with a particle's own values.
    #[inline]
    pub fn with(&self, l: &LocalProperties) -> ConcreteLaw {
        ConcreteLaw {
            e: l.e,
            ft: l.ft,
            fc: l.fc,
            fy: l.fy,
            fult: l.fult,
            gf: l.gf,
            cod_c: l.cod_c,
            cod_1: l.cod_1,
            ..*self
        }
    }
}

/// Damage factor of a bond whose two particles have damage w_i and w_j (3.37): the two
/// springs in series, d = 2(1−w_i)(1−w_j)/(2−w_i−w_j); 0 when either is fully damaged
/// (including the 0/0 case w_i = w_j = 1). Symmetric bit for bit in (w_i, w_j), so that
/// F_b,ij and F_b,ji cancel exactly.
#[inline(always)]
pub fn damage_factor(wi: f64, wj: f64) -> f64 {
    if wi >= 1.0 || wj >= 1.0 {
        return 0.0;
    }
    2.0 * ((1.0 - wi) * (1.0 - wj)) / (2.0 - (wi + wj))
}

/// Bilinear stress–crack-opening law (Hillerborg; Fig. 4.4): f't at COD = 0, γ·f't at
/// COD_1, zero at COD_c and beyond.
#[inline]
pub fn softening_stress(law: &ConcreteLaw, cod: f64) -> f64 {
    if cod <= 0.0 {
        law.ft
    } else if cod < law.cod_1 {
        law.ft * (law.cod_1 + (law.gamma - 1.0) * cod) / law.cod_1
    } else if cod < law.cod_c {
        law.gamma * law.ft * (law.cod_c - cod) / (law.cod_c - law.cod_1)
    } else {
        0.0
    }
}

/// Whether tensile damage starts (docs/model.md §8) for principal stresses p1 ≥ p2 ≥ p3
/// (σ_PI = max(p1, 0) (4.12), σ_PIII = p3).
#[inline]
pub fn initiates(law: &ConcreteLaw, p1: f64, p3: f64) -> bool {
    let s1 = p1.max(0.0);
    match law.initiation {
        Initiation::Rankine => s1 >= law.ft,
        Initiation::Interaction => s1 / law.ft - p3.min(0.0) / law.fc >= 1.0,
    }
}

/// Tensile damage (4.14) of an initiated particle with largest principal strain ε_I, so that
/// (1−w_t)·σ_ref follows the softening law at COD_eq = band·ε_I (4.13), or, with
/// [`CrackOpening::Inelastic`], at band·(ε_I − ε_I,0) with ε_I,0 the strain at initiation
/// (S.14), or, with [`CrackOpening::Stress`], at band·σ_ref/E (S.23);
/// `band` is the particle's crack band in m (`crack_band`·L0,i). σ_ref = `stress` is what
/// [`SofteningStress`] chooses ([`softened_stress`]): E·ε_I as (4.14) writes, or the effective
/// principal stress σ̃_I (S.22). Returns 0 where ε_I ≤ 0 or σ_ref ≤ 0 short of COD_c (the
/// caller keeps the larger of old and new).
#[inline]
pub fn tensile_damage(
    law: &ConcreteLaw,
    band: f64,
    eps_i: f64,
    eps_at_initiation: f64,
    stress: f64,
) -> f64 {
    if eps_i <= 0.0 {
        return 0.0;
    }
    let cod = match law.crack_opening {
        CrackOpening::Total => band * eps_i,
        CrackOpening::Inelastic => band * (eps_i - eps_at_initiation),
        CrackOpening::Stress => band * stress.max(0.0) / law.e,
    };
    if cod >= law.cod_c {
        return 1.0;
    }
    if stress <= 0.0 {
        return 0.0;
    }
    let w = 1.0 - softening_stress(law, cod) / stress;
    w.clamp(0.0, 1.0)
}

/// The stress (4.14) softens (docs/model.md §8): E·ε_I ([`SofteningStress::Strain`]) or σ̃_I,
/// the largest principal stress of the undamaged elastic strain, given as `sigma_i`, which
/// is only called for where it is needed ([`SofteningStress::Stress`], (S.22)).
#[inline]
pub fn softened_stress(law: &ConcreteLaw, eps_i: f64, sigma_i: impl FnOnce() -> f64) -> f64 {
    match law.softening_stress {
        SofteningStress::Strain => law.e * eps_i,
        SofteningStress::Stress => sigma_i(),
    }
}

/// Compressive damage (4.16) from the tensile damage, and 1 once ε_eff > ε_ult (4.17).
#[inline]
pub fn compressive_damage(law: &ConcreteLaw, wt: f64, eps_eff: f64) -> f64 {
    if eps_eff > law.eps_ult {
        return 1.0;
    }
    if wt > law.wt_cr {
        let r = law.wt_cr.sqrt();
        (law.wc_max * (wt.sqrt() - r) / (1.0 - r)).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Effective strain (4.17) from the principal strains.
#[inline]
pub fn effective_strain(e1: f64, e2: f64, e3: f64) -> f64 {
    (0.5 * ((e1 - e2).powi(2) + (e2 - e3).powi(2) + (e3 - e1).powi(2))).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn law(opening: CrackOpening) -> ConcreteLaw {
        let (ft, gf, alpha, gamma) = (3.0e6, 100.0, 0.1, 0.25);
        let cod_c = 2.0 * gf / (ft * (alpha + gamma));
        ConcreteLaw {
            e: 30e9,
            nu: 0.2,
            plane: Plane::Stress,
            fc: 40e6,
            ft,
            fy: 40e6 * 5.0 / 6.0,
            fult: 40e6,
            gf,
            cod_c,
            cod_1: alpha * cod_c,
            gamma,
            eps_ult: 0.0035,
            wt_cr: 1.0 / 3.0,
            wc_max: 1.0,
            initiation: Initiation::Rankine,
            crack_opening: opening,
            softening_stress: SofteningStress::Strain,
            tensile_damage: true,
            compressive_damage: true,
            plasticity: true,
            crack_band: 0.01,
        }
    }

    #[test]
    fn damage_factor_is_two_springs_in_series() {
        assert_eq!(damage_factor(0.0, 0.0), 1.0);
        // one spring at half stiffness, the other intact: series stiffness 2·(½·1)/(½+1) = 2/3
        assert!((damage_factor(0.5, 0.0) - 2.0 / 3.0).abs() < 1e-15);
        assert_eq!(damage_factor(1.0, 0.3), 0.0);
        assert_eq!(damage_factor(1.0, 1.0), 0.0);
        for (a, b) in [(0.1, 0.7), (0.33, 0.999), (0.25, 0.5)] {
            assert_eq!(damage_factor(a, b).to_bits(), damage_factor(b, a).to_bits());
        }
    }

    #[test]
    fn bilinear_law_has_area_gf() {
        let l = law(CrackOpening::Inelastic);
        let n = 200_000;
        let h = l.cod_c / n as f64;
        let area: f64 = (0..n)
            .map(|k| softening_stress(&l, (k as f64 + 0.5) * h) * h)
            .sum();
        assert!((area / l.gf - 1.0).abs() < 1e-6, "{}", area / l.gf);
        assert!((softening_stress(&l, l.cod_1) - l.gamma * l.ft).abs() < 1e-6);
    }

    #[test]
    fn tensile_damage_follows_the_softening_curve() {
        for opening in [
            CrackOpening::Total,
            CrackOpening::Inelastic,
            CrackOpening::Stress,
        ] {
            let l = law(opening);
            let e0 = l.ft / l.e;
            for f in [1.0, 1.5, 3.0, 10.0, 30.0] {
                let eps = f * e0;
                let w = tensile_damage(&l, l.crack_band, eps, e0, l.e * eps);
                let cod = match opening {
                    // with E·ε_I softened, (S.23) reads the opening of ε_I
                    CrackOpening::Total | CrackOpening::Stress => l.crack_band * eps,
                    CrackOpening::Inelastic => l.crack_band * (eps - e0),
                };
                let sigma = (1.0 - w) * l.e * eps;
                assert!((sigma - softening_stress(&l, cod)).abs() < 1e-6 * l.ft);
            }
            // beyond COD_c the particle is fully damaged
            let eps = 2.0 * l.cod_c / l.crack_band + e0;
            assert_eq!(tensile_damage(&l, l.crack_band, eps, e0, l.e * eps), 1.0);
        }
        // As written, w_t jumps at initiation by (1−γ)·COD_el/COD_1 (the source says so).
        let l = law(CrackOpening::Total);
        let e0 = l.ft / l.e;
        let jump = (1.0 - l.gamma) * l.crack_band * e0 / l.cod_1;
        assert!((tensile_damage(&l, l.crack_band, e0, e0, l.ft) - jump).abs() < 1e-12);
        assert_eq!(
            tensile_damage(&law(CrackOpening::Inelastic), 0.01, e0, e0, l.ft),
            0.0
        );
    }

    /// (S.22) at the split cylinder's initiation, σ_x = f't across the crack and σ_y = −3·f't
    /// along it (plane stress): E·ε_I = 1.6·f't, so (4.14) as written puts the particle past
    /// w_t,cr at once, with compressive damage to follow, at a tension test's opening; softening
    /// σ̃_I = f't leaves (1 − w_t)·σ̃_I on the law, w_t near the uniaxial jump.
    #[test]
    fn the_effective_stress_softens_on_the_law_under_lateral_compression() {
        let mut l = law(CrackOpening::Total);
        let (sx, sy) = (l.ft, -3.0 * l.ft);
        let eps = (sx - l.nu * sy) / l.e;
        let on_law = softening_stress(&l, l.crack_band * eps);
        let w = |l: &ConcreteLaw| {
            tensile_damage(l, l.crack_band, eps, eps, softened_stress(l, eps, || sx))
        };
        let as_written = w(&l);
        assert!(((1.0 - as_written) * l.e * eps - on_law).abs() < 1e-6 * l.ft);
        assert!(as_written > l.wt_cr, "{as_written}");
        l.softening_stress = SofteningStress::Stress;
        let effective = w(&l);
        assert!(((1.0 - effective) * sx - on_law).abs() < 1e-6 * l.ft);
        assert!(effective < 0.1, "{effective}");
        // where compression leaves no tension to soften, only COD_c damages
        assert_eq!(tensile_damage(&l, l.crack_band, eps, eps, -1.0), 0.0);
        assert_eq!(
            tensile_damage(&l, l.crack_band, l.cod_c / l.crack_band, 0.0, -1.0),
            1.0
        );
    }

    /// (S.23) at the same initiation: the opening read from σ̃_I/E is the uniaxial one, so w_t
    /// is the uniaxial jump (1 − γ)·COD_el/COD_1 exactly, where ε_I's opening is 1.6 × it;
    /// with E·ε_I softened, as written, (S.23) is the opening as written.
    #[test]
    fn the_opening_of_the_effective_stress_is_the_uniaxial_one() {
        let mut l = law(CrackOpening::Stress);
        let (sx, sy) = (l.ft, -3.0 * l.ft);
        let eps = (sx - l.nu * sy) / l.e;
        let w = |l: &ConcreteLaw| {
            tensile_damage(l, l.crack_band, eps, eps, softened_stress(l, eps, || sx))
        };
        let total = law(CrackOpening::Total);
        assert!((w(&l) - w(&total)).abs() < 1e-15);
        l.softening_stress = SofteningStress::Stress;
        let jump = (1.0 - l.gamma) * l.crack_band * (l.ft / l.e) / l.cod_1;
        assert!((w(&l) - jump).abs() < 1e-12, "{} against {jump}", w(&l));
        // (S.22) alone reads the opening of ε_I = 1.6·f't/E: a larger jump
        l.crack_opening = CrackOpening::Total;
        assert!(w(&l) > 1.5 * jump, "{} against {jump}", w(&l));
    }

    #[test]
    fn compressive_damage_law() {
        let l = law(CrackOpening::Inelastic);
        assert_eq!(compressive_damage(&l, 1.0 / 3.0, 0.0), 0.0);
        assert!((compressive_damage(&l, 1.0, 0.0) - 1.0).abs() < 1e-15);
        let w = 0.6f64;
        let r = (1.0f64 / 3.0).sqrt();
        assert!((compressive_damage(&l, w, 0.0) - (w.sqrt() - r) / (1.0 - r)).abs() < 1e-15);
        assert_eq!(compressive_damage(&l, 0.0, 0.0036), 1.0);
        assert!((effective_strain(1.0, 0.0, 0.0) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn initiation_criteria() {
        let mut l = law(CrackOpening::Inelastic);
        assert!(initiates(&l, l.ft, 0.0));
        assert!(!initiates(&l, 0.99 * l.ft, -0.5 * l.fc));
        l.initiation = Initiation::Interaction;
        assert!(initiates(&l, 0.5 * l.ft, -0.5 * l.fc));
        assert!(!initiates(&l, 0.0, -0.99 * l.fc));
        assert!(initiates(&l, 0.0, -l.fc));
    }
}
