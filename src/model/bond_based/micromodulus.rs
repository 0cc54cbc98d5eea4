//! Micromodulus of a bond-based peridynamic body (docs/bond_based.md, (B.2)–(B.4)): the bond
//! stiffness c that gives a body of horizon δ the elastic energy of the continuum with
//! Young's modulus E (Poisson's ratio fixed by the bond-based model: 1/4 in 3D and plane
//! strain, 1/3 in plane stress). Constant influence function, and the conical one
//! ω(ξ) = 1 − ξ/δ (Hobbs 2021, §3.4).

use std::f64::consts::PI;

/// Which body the micromodulus is for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Body {
    Solid,
    /// A plate of thickness t (m) in plane stress.
    PlaneStress {
        t: f64,
    },
    /// A plate of thickness t (m) in plane strain.
    PlaneStrain {
        t: f64,
    },
}

/// The influence function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Influence {
    Constant,
    /// ω(ξ) = 1 − ξ/δ: the micromodulus is c0·ω(ξ), c0 returned.
    Conical,
}

/// The micromodulus c (constant influence) or its value c0 at ξ = 0 (conical), N/m⁶: 3D
/// 12E/(πδ⁴), plane stress 9E/(πtδ³), plane strain 48E/(5πtδ³) (B.2); conical the
/// constant's × 5 in 3D and × 4 in 2D, so that ∫c0·ω(ξ)·ξ^D dξ equals the constant's (B.3).
pub fn micromodulus(e: f64, delta: f64, body: Body, influence: Influence) -> f64 {
    let (c, conical) = match body {
        Body::Solid => (12.0 * e / (PI * delta.powi(4)), 5.0),
        Body::PlaneStress { t } => (9.0 * e / (PI * t * delta.powi(3)), 4.0),
        Body::PlaneStrain { t } => (48.0 * e / (5.0 * PI * t * delta.powi(3)), 4.0),
    };
    match influence {
        Influence::Constant => c,
        Influence::Conical => conical * c,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The energy density of an isotropic stretch s, ¼·∫ c(ξ)·s²·ξ dV over the horizon
    /// (each bond's ½·c·s²·ξ, shared by its two ends), by the midpoint rule in ξ.
    fn energy_density(c0: f64, delta: f64, body: Body, influence: Influence, s: f64) -> f64 {
        let n = 100_000;
        let h = delta / n as f64;
        (0..n)
            .map(|k| {
                let xi = (k as f64 + 0.5) * h;
                let w = match influence {
                    Influence::Constant => 1.0,
                    Influence::Conical => 1.0 - xi / delta,
                };
                let shell = match body {
                    Body::Solid => 4.0 * PI * xi * xi,
                    Body::PlaneStress { t } | Body::PlaneStrain { t } => 2.0 * PI * xi * t,
                };
                0.25 * c0 * w * s * s * xi * shell * h
            })
            .sum()
    }

    /// Each micromodulus gives the continuum's energy of an isotropic strain ε with the
    /// bond-based Poisson's ratio: 3D (ν = 1/4) 9/2·K·ε² = 3E·ε²; plane stress (ν = 1/3)
    /// E/(1 − ν)·ε² = 1.5E·ε²; plane strain (ν = 1/4) E/((1 + ν)(1 − 2ν))·ε² = 1.6E·ε².
    /// The midpoint rule is exact to about 1e-10 here.
    #[test]
    fn micromoduli_give_the_continuum_energy_of_an_isotropic_strain() {
        let (e, delta, t, s) = (37e9, 0.0157, 0.05, 1e-4);
        for (body, w) in [
            (Body::Solid, 3.0),
            (Body::PlaneStress { t }, 1.5),
            (Body::PlaneStrain { t }, 1.6),
        ] {
            for influence in [Influence::Constant, Influence::Conical] {
                let c = micromodulus(e, delta, body, influence);
                let got = energy_density(c, delta, body, influence, s);
                let want = w * e * s * s;
                assert!(
                    (got / want - 1.0).abs() < 1e-8,
                    "{body:?} {influence:?}: {got} against {want}"
                );
            }
        }
    }
}
