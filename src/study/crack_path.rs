//! The crack path of a damaged specimen, as numbers: the particles whose tensile damage w_t
//! is at least a threshold, their centroid, the principal axis of their reference positions
//! and their RMS distance from that axis. The threshold is [`CRACK_PATH_DAMAGE`] = 0.9 by
//! default, not the 0.99 of summary.json's `cracked_particles` ([`CRACKED`]): a crack two
//! particle rows wide shares its opening between them, and on the split cylinder at 0° the
//! particles along the whole diameter end at w_t = 0.98–0.989, so at 0.99 only the damage
//! under the strips counts; at 0.7 the diffuse damage at a free edge (30°, offset 1) pulls
//! the axis. A straight crack has a
//! well-defined axis and a width of about one crack band; a crack along the loaded diameter of
//! a split cylinder has axis ≈ 90° and centroid x ≈ 0; the crack of a block in tension runs
//! across the load, axis ≈ 0° (or just under 180°: the axis is a direction, not a vector).

use nalgebra::Vector2;
use serde::Serialize;

/// Tensile damage at and above which a particle counts as cracked (as in summary.json).
pub const CRACKED: f64 = 0.99;

/// Default tensile damage at and above which a particle belongs to the crack path.
pub const CRACK_PATH_DAMAGE: f64 = 0.9;

/// Distance from a support or a loaded group, in particle spacings, within which damage is
/// not part of the crack path: the crushing and splitting under a support or a loading point
/// spread over the group's own rows and a bond length beyond them, and on a beam those blobs,
/// far apart along the span, would turn the axis of a vertical crack towards the horizontal.
/// Two spacings clear a bond and a half beyond the group; more would hide the cracks that
/// form near a grip (the tension block turned by 30° cracks 2.8 spacings from its pulled
/// rows).
pub const CLEARANCE_SPACINGS: f64 = 2.0;

/// The particles to keep the crack path away from: those of the groups with prescribed
/// displacements (supports, loading points), and the distance (m) to keep.
#[derive(Clone, Copy, Debug)]
pub struct Clearance<'a> {
    pub held: &'a [Vector2<f64>],
    pub distance: f64,
}

impl Clearance<'_> {
    /// No clearance: every damaged particle counts.
    pub const NONE: Clearance<'static> = Clearance {
        held: &[],
        distance: 0.0,
    };

    fn keeps(&self, x: &Vector2<f64>) -> bool {
        let d2 = self.distance * self.distance;
        !self.held.iter().any(|h| (h - x).norm_squared() <= d2)
    }
}

/// Why a damage field gives no crack direction.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NoCrack {
    /// Particles with w_t at or above the threshold.
    pub damaged: usize,
    /// How many of them lie within the clearance of a support or a loaded group.
    pub near_groups: usize,
    /// Those left for the fit (all of them, or the middle half for the core).
    pub fitted: usize,
}

impl std::fmt::Display for NoCrack {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "no crack: {} damaged particles, {} of them next to a support or a loading point, \
             {} left to fit; a direction needs 2",
            self.damaged, self.near_groups, self.fitted
        )
    }
}

/// The damaged particles (w_t ≥ `threshold`) away from the held groups, and how many were
/// damaged in all.
fn on_path(
    x0: &[Vector2<f64>],
    wt: &[f64],
    threshold: f64,
    clear: &Clearance,
) -> (Vec<Vector2<f64>>, usize) {
    let damaged: Vec<Vector2<f64>> = x0
        .iter()
        .zip(wt)
        .filter(|(_, &w)| w >= threshold)
        .map(|(x, _)| *x)
        .collect();
    let n = damaged.len();
    (damaged.into_iter().filter(|x| clear.keeps(x)).collect(), n)
}

/// The principal line through a set of cracked particles.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CrackPath {
    /// Number of cracked particles.
    pub particles: usize,
    /// Direction of the principal axis (largest variance), degrees in [0, 180).
    pub axis_deg: f64,
    /// RMS distance of the cracked particles from the axis line through their centroid (m).
    pub rms_width_m: f64,
    /// Centroid of the cracked particles (m).
    pub centroid_m: [f64; 2],
}

/// The crack path of the particles at reference positions `x0` whose tensile damage `wt`
/// is at least `threshold`, those within the clearance of a support or a loaded group left
/// out; [`NoCrack`] when fewer than two remain (no axis).
/// Principal component analysis of the 2×2 covariance C: the axis angle is
/// ½·atan2(2·C_xy, C_xx − C_yy) and the RMS distance from it is √λ_min.
pub fn crack_path(
    x0: &[Vector2<f64>],
    wt: &[f64],
    threshold: f64,
    clear: &Clearance,
) -> Result<CrackPath, NoCrack> {
    fit(x0, wt, threshold, clear, |pts| pts)
}

/// The principal line of the points `kept` keeps of the damaged particles on the path, or
/// the counts of why there is none.
fn fit(
    x0: &[Vector2<f64>],
    wt: &[f64],
    threshold: f64,
    clear: &Clearance,
    kept: fn(Vec<Vector2<f64>>) -> Vec<Vector2<f64>>,
) -> Result<CrackPath, NoCrack> {
    let (pts, damaged) = on_path(x0, wt, threshold, clear);
    let near_groups = damaged - pts.len();
    let pts = kept(pts);
    principal_line(&pts).ok_or(NoCrack {
        damaged,
        near_groups,
        fitted: pts.len(),
    })
}

/// The principal line of a point set (at least two points).
pub fn principal_line(pts: &[Vector2<f64>]) -> Option<CrackPath> {
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let c = pts.iter().sum::<Vector2<f64>>() / n;
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for p in pts {
        let d = p - c;
        sxx += d.x * d.x;
        syy += d.y * d.y;
        sxy += d.x * d.y;
    }
    let (sxx, syy, sxy) = (sxx / n, syy / n, sxy / n);
    let mut axis = 0.5 * (2.0 * sxy).atan2(sxx - syy).to_degrees();
    if axis < 0.0 {
        axis += 180.0;
    }
    if axis >= 180.0 {
        axis -= 180.0;
    }
    // smaller eigenvalue of [[sxx, sxy], [sxy, syy]]
    let mean = 0.5 * (sxx + syy);
    let half = (0.25 * (sxx - syy).powi(2) + sxy * sxy).sqrt();
    let lambda_min = (mean - half).max(0.0);
    Some(CrackPath {
        particles: pts.len(),
        axis_deg: axis,
        rms_width_m: lambda_min.sqrt(),
        centroid_m: [c.x, c.y],
    })
}

/// The core of the crack: the principal line of the cracked particles in the middle half of
/// the crack's length, those whose position along the principal axis of all of them lies
/// within a quarter of the extent from its midpoint. Damage at the ends of a crack (under the
/// loading strips of a split cylinder, at the grips) weighs on the axis of the whole set; the
/// core is the crack itself.
pub fn crack_core(
    x0: &[Vector2<f64>],
    wt: &[f64],
    threshold: f64,
    clear: &Clearance,
) -> Result<CrackPath, NoCrack> {
    fit(x0, wt, threshold, clear, |pts| core_points(&pts))
}

/// The principal line of the points in the middle half of a point set's extent along its
/// principal axis.
pub fn core_line(pts: &[Vector2<f64>]) -> Option<CrackPath> {
    principal_line(&core_points(pts))
}

/// The points of a set in the middle half of its extent along its principal axis (none for
/// fewer than two points).
fn core_points(pts: &[Vector2<f64>]) -> Vec<Vector2<f64>> {
    let Some(all) = principal_line(pts) else {
        return vec![];
    };
    let (s, c) = all.axis_deg.to_radians().sin_cos();
    let centre = Vector2::new(all.centroid_m[0], all.centroid_m[1]);
    let along = |p: &Vector2<f64>| (p - centre).dot(&Vector2::new(c, s));
    let (lo, hi) = pts
        .iter()
        .map(along)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), t| {
            (l.min(t), h.max(t))
        });
    let (mid, quarter) = (0.5 * (lo + hi), 0.25 * (hi - lo));
    pts.iter()
        .filter(|p| (along(p) - mid).abs() <= quarter)
        .copied()
        .collect()
}

/// Mean of axes (degrees in [0, 180)): the doubled-angle circular mean, so that the mean of
/// 179° and 1° is 0°, not 90°. `None` for no axes or axes that cancel.
pub fn mean_axis_deg(axes: &[f64]) -> Option<f64> {
    let (s, c) = axes.iter().fold((0.0, 0.0), |(s, c), a| {
        let (sa, ca) = (2.0 * a.to_radians()).sin_cos();
        (s + sa, c + ca)
    });
    if axes.is_empty() || s.hypot(c) < 1e-9 * axes.len() as f64 {
        return None;
    }
    Some((0.5 * s.atan2(c).to_degrees()).rem_euclid(180.0))
}

/// Angle between two axes (degrees in [0, 90]): axes are directions, so 179° and 1° are 2° apart.
pub fn axis_difference_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(180.0);
    d.min(180.0 - d)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(angle_deg: f64, centre: [f64; 2], n: usize, offsets: &[f64]) -> Vec<Vector2<f64>> {
        let (s, c) = angle_deg.to_radians().sin_cos();
        let dir = Vector2::new(c, s);
        let normal = Vector2::new(-s, c);
        let mut pts = Vec::new();
        for k in 0..n {
            let t = (k as f64 - 0.5 * (n - 1) as f64) * 0.01;
            for &o in offsets {
                pts.push(Vector2::new(centre[0], centre[1]) + t * dir + o * normal);
            }
        }
        pts
    }

    #[test]
    fn a_straight_line_has_its_angle_zero_width_and_centre() {
        for angle in [0.0, 30.0, 90.0, 135.0, 179.0] {
            let p = principal_line(&line(angle, [0.02, -0.01], 21, &[0.0])).unwrap();
            assert!(
                axis_difference_deg(p.axis_deg, angle) < 1e-9,
                "{angle}: {p:?}"
            );
            assert!((0.0..180.0).contains(&p.axis_deg));
            assert!(p.rms_width_m < 1e-12, "{p:?}");
            assert!((p.centroid_m[0] - 0.02).abs() < 1e-12);
            assert!((p.centroid_m[1] + 0.01).abs() < 1e-12);
            assert_eq!(p.particles, 21);
        }
    }

    #[test]
    fn a_band_of_two_rows_has_the_half_separation_as_rms_width() {
        // two parallel rows ±w from the axis: every point is w away from it
        let p = principal_line(&line(90.0, [0.0, 0.0], 31, &[-0.003, 0.003])).unwrap();
        assert!(axis_difference_deg(p.axis_deg, 90.0) < 1e-9);
        assert!((p.rms_width_m - 0.003).abs() < 1e-12, "{p:?}");
    }

    #[test]
    fn only_cracked_particles_count() {
        let x0 = vec![
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            Vector2::new(0.5, 7.0),
        ];
        let none = &Clearance::NONE;
        let p = crack_path(&x0, &[1.0, 0.995, 0.5], CRACKED, none).unwrap();
        assert_eq!(p.particles, 2);
        assert!(p.axis_deg.abs() < 1e-12);
        assert!(crack_path(&x0, &[1.0, 0.2, 0.5], CRACKED, none).is_err());
        assert_eq!(
            crack_path(&x0, &[1.0, 0.2, 0.5], 0.5, none)
                .unwrap()
                .particles,
            2
        );
    }

    #[test]
    fn the_core_is_the_crack_without_the_damage_at_its_ends() {
        // an inclined crack through the centre (41 points over ±50 mm at 70°) with a
        // horizontal row of damage at each end (under the strips of a split cylinder)
        let mut pts = line(70.0, [0.0, 0.0], 41, &[0.0]);
        pts.iter_mut().for_each(|p| *p *= 0.25); // spacing 2.5 mm
        for y in [-0.06, 0.06] {
            pts.extend((0..5).map(|k| Vector2::new(-0.02 + 0.01 * k as f64, y)));
        }
        let all = principal_line(&pts).unwrap();
        let core = core_line(&pts).unwrap();
        assert!(axis_difference_deg(all.axis_deg, 70.0) > 5.0, "{all:?}");
        assert!(axis_difference_deg(core.axis_deg, 70.0) < 1e-9, "{core:?}");
        // √λ_min carries the round-off of λ_max (~1e-3 m²): √(1e-16·1e-3) ≈ 3e-10 m
        assert!(core.rms_width_m < 1e-8, "{core:?} {all:?}");
        // the middle half of the extent (±60 mm along the axis): the 25 points within ±30 mm
        assert_eq!(core.particles, 25, "{core:?}");
    }

    /// Reference positions, tensile damage, held particles and grid pitch h.
    type BeamDamage = (Vec<Vector2<f64>>, Vec<f64>, Vec<Vector2<f64>>, f64);

    /// A notched beam's damage field: a square grid of pitch h over 200 × 50 mm, with a blob
    /// of radius 2.5·h damaged at each support (x = 25 and 175 mm, bottom) and under the load
    /// (x = 100 mm, top), and a vertical crack two columns wide (x = 100 mm ± h/2, 13 rows from
    /// the bottom up to 30 mm). The held particles: each group's 3 × 2 grid points about its
    /// centre.
    fn beam_damage() -> BeamDamage {
        let h = 0.0025;
        let (mut x0, mut wt, mut held) = (vec![], vec![], vec![]);
        let centres = [
            Vector2::new(0.025, 0.0),
            Vector2::new(0.175, 0.0),
            Vector2::new(0.1, 0.05),
        ];
        for i in 0..=80 {
            for j in 0..=20 {
                let p = Vector2::new(i as f64 * h, j as f64 * h);
                let blob = centres.iter().any(|c| (p - c).norm() <= 2.5 * h + 1e-12);
                x0.push(p);
                wt.push(if blob { 1.0 } else { 0.1 });
                if centres
                    .iter()
                    .any(|c| (p.x - c.x).abs() <= h + 1e-12 && (p.y - c.y).abs() <= h + 1e-12)
                {
                    held.push(p);
                }
            }
        }
        for j in 0..=12 {
            for dx in [-0.5 * h, 0.5 * h] {
                x0.push(Vector2::new(0.1 + dx, j as f64 * h));
                wt.push(1.0);
            }
        }
        (x0, wt, held, h)
    }

    /// The damage at the supports turns the axis of the whole set towards the horizontal; kept
    /// 2 spacings away from the held particles, only the band is left: by symmetry about
    /// x = 100 mm its axis is 90° (to round-off) and its RMS width h/2.
    #[test]
    fn damage_at_supports_and_loading_points_leaves_the_crack_axis() {
        let (x0, wt, held, h) = beam_damage();
        let all = crack_path(&x0, &wt, CRACK_PATH_DAMAGE, &Clearance::NONE).unwrap();
        assert!(axis_difference_deg(all.axis_deg, 90.0) > 45.0, "{all:?}");
        let clear = Clearance {
            held: &held,
            distance: CLEARANCE_SPACINGS * h,
        };
        let p = crack_path(&x0, &wt, CRACK_PATH_DAMAGE, &clear).unwrap();
        assert!(axis_difference_deg(p.axis_deg, 90.0) < 1e-9, "{p:?}");
        assert_eq!(p.particles, 2 * 13, "the band's two columns of 13 rows");
        assert!((p.rms_width_m - 0.5 * h).abs() < 1e-12, "{p:?}");
        assert!((p.centroid_m[0] - 0.1).abs() < 1e-12, "{p:?}");
        let core = crack_core(&x0, &wt, CRACK_PATH_DAMAGE, &clear).unwrap();
        assert!(axis_difference_deg(core.axis_deg, 90.0) < 1e-9, "{core:?}");
    }

    /// No damaged particle, one, or only particles next to the groups: an explicit "no crack"
    /// with the counts, never an axis of NaN.
    #[test]
    fn too_few_damaged_particles_give_no_crack_not_nan() {
        let x0 = vec![Vector2::new(0.0, 0.0), Vector2::new(0.01, 0.0)];
        let none = &Clearance::NONE;
        for wt in [[0.0, 0.0], [1.0, 0.0]] {
            let e = crack_path(&x0, &wt, CRACK_PATH_DAMAGE, none).unwrap_err();
            assert_eq!(e.fitted, wt.iter().filter(|w| **w >= 0.9).count());
            let text = e.to_string();
            assert!(
                text.starts_with("no crack") && !text.contains("NaN"),
                "{text}"
            );
            assert!(crack_core(&x0, &wt, CRACK_PATH_DAMAGE, none).is_err());
        }
        // two particles: a path, but the middle half of its extent holds none
        let core = crack_core(&x0, &[1.0, 1.0], CRACK_PATH_DAMAGE, none).unwrap_err();
        assert_eq!((core.damaged, core.fitted), (2, 0));
        let held = [Vector2::new(0.0, 0.001)];
        let clear = Clearance {
            held: &held,
            distance: 0.005,
        };
        let e = crack_path(&x0, &[1.0, 1.0], CRACK_PATH_DAMAGE, &clear).unwrap_err();
        assert_eq!((e.damaged, e.near_groups, e.fitted), (2, 1, 1));
    }

    #[test]
    fn the_mean_of_axes_wraps_at_180() {
        assert!(axis_difference_deg(mean_axis_deg(&[179.0, 1.0]).unwrap(), 0.0) < 1e-9);
        assert!((mean_axis_deg(&[80.0, 100.0, 90.0]).unwrap() - 90.0).abs() < 1e-9);
        assert!((mean_axis_deg(&[30.0]).unwrap() - 30.0).abs() < 1e-9);
        assert_eq!(mean_axis_deg(&[0.0, 90.0]), None);
        assert_eq!(mean_axis_deg(&[]), None);
    }

    #[test]
    fn axis_difference_wraps_at_180() {
        assert!((axis_difference_deg(179.0, 1.0) - 2.0).abs() < 1e-12);
        assert!((axis_difference_deg(90.0, 0.0) - 90.0).abs() < 1e-12);
        assert!((axis_difference_deg(10.0, 170.0) - 20.0).abs() < 1e-12);
    }
}
