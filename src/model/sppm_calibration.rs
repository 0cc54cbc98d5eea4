//! Elastic calibration of random particles (SPPM, docs/model.md §3 and §13).
//!
//! **Decision (measured).** Each random particle's micro-moduli are the least-squares
//! solution of D = M_i·K_i·N_i (3.20) for its own bonds. Two parameters (a_i, b_i) cannot make
//! a particle with six to ten bonds in random directions isotropic (the residual is about
//! 0.2–0.3), and the assembled body relaxes away from the affine field the fit assumes: a
//! plate fitted to (E, ν) comes out about 20% too soft with ν too high by about 0.06
//! (`min_distance` = 0.7; more at smaller minimum distances). The map from the fitted
//! in-plane pair (E*, ν*) to the body's in-plane (E, ν) is smooth and the same for every
//! particle set of one minimum distance (spread over seeds: 0.8% in E, 0.008 in ν at
//! W/L0 = 50), so the moduli are fitted to the pair (E*, ν*) that the measured map sends to
//! the scene's (E, ν).
//!
//! The table holds, per minimum distance and fitted in-plane ν*, the mean (ν*, E/E*, ν) of a
//! 100 × 200 mm plate: for the default 0.7 over 10 particle sets at L0 = 1 mm (W/L0 = 100),
//! for 0.5, 0.6 and 0.75 over 8 sets at L0 = 2 mm. Regenerate it with
//! `cargo test --release --test suite -- --ignored --nocapture sppm_elastic::calibration_table`.
//! Plane strain uses the same in-plane map (the 2D model sees only in-plane constants:
//! E' = E/(1−ν²), ν' = ν/(1−ν)).
//!
//! **In 3D** the same holds: 18-nearest particles fitted to (E, ν) with the
//! isotropic 6×6 D give a block about 15% too soft with ν about 0.02 high (`min_distance`
//! 0.7), the same for every particle set (spread over seeds 0.4% in E, 0.001 in ν at
//! W/L0 = 20; 0.851 at W/L0 = 16 against 0.854 at 24). [`fit_target_3d`] reads the 3D table:
//! per minimum distance and fitted ν*, the mean (ν*, E/E*, ν) of a W × W × 2W block
//! (W/L0 = 20) over 4 particle sets, pulled along its length with the sides free. Regenerate
//! it with `cargo test --release --test suite -- --ignored --nocapture sppm3d::calibration_table_3d`.

use crate::scene::Plane;

/// One measured point of a map: (fitted ν*, E/E*, body ν).
type Row = (f64, f64, f64);

/// (ν*, E/E*, ν) rows of one minimum distance, ν* ascending.
type Rows = [Row; 10];

/// Measured maps, by minimum distance (fraction of the spacing), ascending.
const TABLE: [(f64, Rows); 4] = [
    (0.5, ROWS_050),
    (0.6, ROWS_060),
    (0.7, ROWS_070),
    (0.75, ROWS_075),
];

include!("sppm_calibration_table.rs");

/// (ν*, E/E*, ν) rows of one minimum distance in 3D, ν* ascending.
type Rows3 = [Row; 7];

/// Measured 3D maps, by minimum distance (fraction of the spacing), ascending.
const TABLE_3D: [(f64, Rows3); 4] = [
    (0.5, ROWS3_050),
    (0.6, ROWS3_060),
    (0.7, ROWS3_070),
    (0.75, ROWS3_075),
];

include!("sppm_calibration_table_3d.rs");

/// The rows of `table` at minimum distance `md`, linear between the measured ones.
fn rows_of<const N: usize>(table: &[(f64, [Row; N])], md: f64) -> [Row; N] {
    let md = md.clamp(table[0].0, table[table.len() - 1].0);
    let k = (0..table.len() - 1)
        .find(|&k| md <= table[k + 1].0)
        .unwrap_or(table.len() - 2);
    let (m0, r0) = table[k];
    let (m1, r1) = table[k + 1];
    let t = (md - m0) / (m1 - m0);
    let mut out = r0;
    for (o, (a, b)) in out.iter_mut().zip(r0.iter().zip(r1.iter())) {
        *o = (a.0, a.1 + t * (b.1 - a.1), a.2 + t * (b.2 - a.2));
    }
    out
}

/// The 2D rows at minimum distance `md`.
fn rows_at(md: f64) -> Rows {
    rows_of(&TABLE, md)
}

/// The fitted pair (E*, ν*) the map `rows` sends to (E, ν); `None` when ν lies outside the
/// rows' range.
fn invert(rows: &[Row], e: f64, nu: f64) -> Option<(f64, f64)> {
    let k = (0..rows.len() - 1).find(|&k| nu >= rows[k].2 && nu <= rows[k + 1].2)?;
    let (a, b) = (rows[k], rows[k + 1]);
    let t = (nu - a.2) / (b.2 - a.2);
    let nu_fit = a.0 + t * (b.0 - a.0);
    let e_ratio = a.1 + t * (b.1 - a.1);
    Some((e / e_ratio, nu_fit))
}

/// The range of ν random 3D particles of minimum distance `md` represent.
pub fn nu_range_3d(md: f64) -> (f64, f64) {
    let rows = rows_of(&TABLE_3D, md);
    (rows[0].2, rows[rows.len() - 1].2)
}

/// The (E*, ν*) to fit random 3D particles' moduli to (with the isotropic D (3.20)), so that a
/// body of minimum distance `md` shows (E, ν). `Err` names the ν range the calibration covers
/// when ν lies outside it.
pub fn fit_target_3d(e: f64, nu: f64, md: f64) -> Result<(f64, f64), String> {
    invert(&rows_of(&TABLE_3D, md), e, nu).ok_or_else(|| {
        let (lo, hi) = nu_range_3d(md);
        format!(
            "random 3D particles of min_distance {md} represent ν in [{lo:.3}, {hi:.3}] (the range of the measured elastic calibration, model::sppm_calibration)"
        )
    })
}

/// In-plane (E', ν') of a material in the scene's plane.
fn in_plane(e: f64, nu: f64, plane: Plane) -> (f64, f64) {
    match plane {
        Plane::Stress => (e, nu),
        Plane::Strain => (e / (1.0 - nu * nu), nu / (1.0 - nu)),
    }
}

/// The material (E, ν) in the scene's plane of an in-plane pair.
fn from_in_plane(e: f64, nu: f64, plane: Plane) -> (f64, f64) {
    match plane {
        Plane::Stress => (e, nu),
        Plane::Strain => {
            let nu3 = nu / (1.0 + nu);
            (e * (1.0 - nu3 * nu3), nu3)
        }
    }
}

/// The range of the scene's ν random particles of minimum distance `md` represent.
pub fn nu_range(md: f64, plane: Plane) -> (f64, f64) {
    let rows = rows_at(md);
    let lo = from_in_plane(1.0, rows[0].2, plane).1;
    let hi = from_in_plane(1.0, rows[rows.len() - 1].2, plane).1;
    (lo, hi)
}

/// The (E*, ν*) in the scene's plane to fit the particles' moduli to, so that a body of random
/// particles of minimum distance `md` shows the scene's (E, ν). `Err` names the ν range the
/// calibration covers when ν lies outside it.
pub fn fit_target(e: f64, nu: f64, plane: Plane, md: f64) -> Result<(f64, f64), String> {
    let (e_ip, nu_ip) = in_plane(e, nu, plane);
    let Some((e_fit, nu_fit)) = invert(&rows_at(md), e_ip, nu_ip) else {
        let (lo, hi) = nu_range(md, plane);
        return Err(format!(
            "random particles of min_distance {md} represent ν in [{lo:.3}, {hi:.3}] ({plane:?} plane; the range of the measured elastic calibration, model::sppm_calibration)"
        ));
    };
    Ok(from_in_plane(e_fit, nu_fit, plane))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_monotone_in_nu() {
        let rows = TABLE.iter().flat_map(|(_, r)| r.windows(2));
        let rows3 = TABLE_3D.iter().flat_map(|(_, r)| r.windows(2));
        for w in rows.chain(rows3) {
            assert!(w[1].0 > w[0].0 && w[1].2 > w[0].2, "{w:?}");
        }
    }

    /// In 3D: reading the table forward from the fitted pair gives (E, ν) back, and ν = 0.2
    /// lies inside every minimum distance's range.
    #[test]
    fn target_3d_inverts_the_map() {
        for md in [0.5, 0.65, 0.7, 0.75] {
            let (e_fit, nu_fit) = fit_target_3d(30e9, 0.2, md).unwrap();
            let rows = rows_of(&TABLE_3D, md);
            let k = (0..rows.len() - 1)
                .find(|&k| nu_fit >= rows[k].0 && nu_fit <= rows[k + 1].0)
                .unwrap();
            let t = (nu_fit - rows[k].0) / (rows[k + 1].0 - rows[k].0);
            let nu_eff = rows[k].2 + t * (rows[k + 1].2 - rows[k].2);
            let e_eff = e_fit * (rows[k].1 + t * (rows[k + 1].1 - rows[k].1));
            assert!((e_eff / 30e9 - 1.0).abs() < 1e-12, "{md}");
            assert!((nu_eff - 0.2).abs() < 1e-12, "{md}");
        }
        assert!(fit_target_3d(30e9, 0.499, 0.7).is_err());
    }

    /// Fitting to the target and reading the table forward gives the scene's pair back.
    #[test]
    fn target_inverts_the_map() {
        for plane in [Plane::Stress, Plane::Strain] {
            for nu in [0.1, 0.2, 0.3] {
                let (e_fit, nu_fit) = fit_target(30e9, nu, plane, 0.7).unwrap();
                let (e_ip, nu_ip) = in_plane(e_fit, nu_fit, plane);
                let rows = rows_at(0.7);
                let k = (0..rows.len() - 1)
                    .find(|&k| nu_ip >= rows[k].0 && nu_ip <= rows[k + 1].0)
                    .unwrap();
                let t = (nu_ip - rows[k].0) / (rows[k + 1].0 - rows[k].0);
                let nu_eff = rows[k].2 + t * (rows[k + 1].2 - rows[k].2);
                let e_eff = e_ip * (rows[k].1 + t * (rows[k + 1].1 - rows[k].1));
                let (e_back, nu_back) = from_in_plane(e_eff, nu_eff, plane);
                assert!((e_back / 30e9 - 1.0).abs() < 1e-12, "{plane:?} {nu}");
                assert!((nu_back - nu).abs() < 1e-12, "{plane:?} {nu}");
            }
        }
        assert!(fit_target(30e9, 0.499, Plane::Strain, 0.7).is_err());
    }
}
