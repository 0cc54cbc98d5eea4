//! Concrete parameters and the correlations of docs/model.md §11 (the source's chapter 5), with
//! exact unit conversions, and the softening constants derived from them (§8, (5.4)).
//!
//! A value given in the scene always wins over a correlation; [`resolve`] returns the values
//! used and, for each, where it came from, so that the run summary can list them.

use serde::Serialize;

/// 1 psi in Pa (exact to the digits of docs/model.md §11).
pub const PSI: f64 = 6894.757;
/// 1 lb/ft³ in kg/m³.
pub const LB_PER_FT3: f64 = 16.01846;

/// f't = 6·√f'c with f'c and f't in psi (ACI 318-92; (5.1)). Argument and result in Pa.
pub fn aci_tensile_strength(fc: f64) -> f64 {
    6.0 * (fc / PSI).sqrt() * PSI
}

/// E = 33·ρ^1.5·√f'c with ρ in lb/ft³ and f'c, E in psi (ACI 318-14; (5.2)). SI in and out.
pub fn aci_youngs_modulus(fc: f64, rho: f64) -> f64 {
    33.0 * (rho / LB_PER_FT3).powf(1.5) * (fc / PSI).sqrt() * PSI
}

/// G_f = G_f0·(f_cm/10 MPa)^0.7 with f_cm = f'c + 8 MPa (CEB-FIP 1990; (5.3)). SI in and out.
pub fn ceb_fip_fracture_energy(gf0: f64, fc: f64) -> f64 {
    let fcm = fc + 8.0e6;
    gf0 * (fcm / 10.0e6).powf(0.7)
}

/// Base fracture energy G_f0 (N/m) for a maximum aggregate size (m): CEB-FIP 1990 gives
/// 25, 30 and 58 N/m for 8, 16 and 32 mm; the source uses 33.49 N/m for 19 mm (docs/validation.md
/// §B, §C; linear interpolation of the CEB-FIP table would give 35.25 N/m). Other sizes are
/// refused: give `concrete.Gf0` instead.
pub fn base_fracture_energy(max_aggregate: f64) -> Option<f64> {
    const TABLE: [(f64, f64); 4] = [(0.008, 25.0), (0.016, 30.0), (0.019, 33.49), (0.032, 58.0)];
    TABLE
        .iter()
        .find(|(d, _)| (max_aggregate - d).abs() < 1e-6)
        .map(|&(_, g)| g)
}

/// Critical crack opening of the bilinear softening law, COD_c = 2·G_f/(f't·(α+γ)) (5.4):
/// the area under the curve (0, f't) – (α·COD_c, γ·f't) – (COD_c, 0) equals G_f.
pub fn critical_crack_opening(gf: f64, ft: f64, alpha: f64, gamma: f64) -> f64 {
    2.0 * gf / (ft * (alpha + gamma))
}

/// A named concrete from the source, filling f'c, the aggregate size and (where the source
/// departs from ACI) f't. Scene values override every one of them.
#[derive(Clone, Copy, Debug, serde::Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Preset {
    /// Table 1 of Nikravesh Kazeroni (2017) (section 5.2, block in tension and compression): f'c = 27.58 MPa
    /// (4000 psi), d_max = 19 mm.
    SplmBlock,
    /// Table 5 of Nikravesh Kazeroni (2017), split cylinder (section 5.3.3): f'c = 41.23 MPa, d_max = 19 mm.
    SplmCylinder,
    /// Table 5 of Nikravesh Kazeroni (2017), dog-bones (section 5.3.2): f'c = 50 MPa, d_max = 8 mm, and the
    /// table's f't = 2.415 MPa (not the ACI value 3.52 MPa; docs/validation.md §D).
    SplmDogbone,
}

impl Preset {
    /// The name as a scene writes it.
    pub fn name(self) -> &'static str {
        match self {
            Preset::SplmBlock => "splm_block",
            Preset::SplmCylinder => "splm_cylinder",
            Preset::SplmDogbone => "splm_dogbone",
        }
    }

    /// (f'c, d_max, f't if the source fixes it), SI.
    pub fn values(self) -> (f64, f64, Option<f64>) {
        match self {
            Preset::SplmBlock => (27.58e6, 0.019, None),
            Preset::SplmCylinder => (41.23e6, 0.019, None),
            Preset::SplmDogbone => (50.0e6, 0.008, Some(2.415e6)),
        }
    }
}

/// One material value of a run and where it came from.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Derived {
    pub key: String,
    pub value: f64,
    /// "scene", "preset <name>", or the correlation used.
    pub source: String,
}
