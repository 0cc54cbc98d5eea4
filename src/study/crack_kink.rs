//! The direction in which a preset straight crack grows from its tips: the kink angle that
//! the maximum tangential stress theory predicts (Erdogan & Sih 1963: 0° in pure mode I,
//! 53.1° when K_II = K_I, a crack at 45° to a uniaxial pull), measured on a run's damage.

use crate::run::Outcome;
use crate::scene::CutoutSpec;
use nalgebra::Vector2;

/// The growth from one tip of the preset crack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kink {
    /// The tip (m).
    pub tip: [f64; 2],
    /// The angle between the grown crack and the preset crack's line ahead of the tip (°,
    /// 0 to 90).
    pub angle_deg: f64,
    /// The damaged points the direction was fitted to.
    pub points: usize,
}

/// The kink at each tip of a bond-based run's preset crack, the scene's first slit, measured
/// on the points with φ ≥ [`BOND_CRACK_DAMAGE`](super::families::BOND_CRACK_DAMAGE) within
/// 2δ of the tip; `None` without a slit, without damage or at a tip without a crack.
pub fn bond_based_kinks(o: &Outcome) -> [Option<Kink>; 2] {
    let crack = o.scene.cutouts.iter().find_map(|c| match c {
        CutoutSpec::Slit { start, end, .. } => Some((
            Vector2::new(start[0], start[1]),
            Vector2::new(end[0], end[1]),
        )),
        _ => None,
    });
    let (Some(d), Some(b), Some(crack)) = (&o.damage, &o.summary.bond_based, crack) else {
        return [None, None];
    };
    let x0: Vec<_> = (0..o.x0.len()).map(|i| o.point2(i)).collect();
    let phi: Vec<f64> = d.iter().map(|p| p.wt).collect();
    kinks(
        &x0,
        &phi,
        crack,
        super::families::BOND_CRACK_DAMAGE,
        (0.0, 2.0 * b.horizon_m),
    )
}

/// The kink at each tip of the preset crack from `start` to `end`: the line through the
/// tip that best fits the points with damage at least `threshold` at distances from `r_min`
/// to `r_max` ahead of the tip (on the far side of the line through the tip normal to the
/// crack), in least squares of their distances from it. `None` at a tip with fewer than
/// three such points.
pub fn kinks(
    x0: &[Vector2<f64>],
    damage: &[f64],
    (start, end): (Vector2<f64>, Vector2<f64>),
    threshold: f64,
    (r_min, r_max): (f64, f64),
) -> [Option<Kink>; 2] {
    let along = (end - start).normalize();
    [(end, along), (start, -along)].map(|(tip, ahead)| {
        let pts: Vec<Vector2<f64>> = x0
            .iter()
            .zip(damage)
            .filter(|(_, &d)| d >= threshold)
            .map(|(p, _)| p - tip)
            .filter(|d| (r_min..=r_max).contains(&d.norm()) && d.dot(&ahead) >= 0.0)
            .collect();
        if pts.len() < 3 {
            return None;
        }
        // the line through the tip: the principal axis of the second moments about the tip
        let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
        for d in &pts {
            sxx += d.x * d.x;
            syy += d.y * d.y;
            sxy += d.x * d.y;
        }
        let theta = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        let dir = Vector2::new(theta.cos(), theta.sin());
        let cos = dir.dot(&ahead).abs().min(1.0);
        Some(Kink {
            tip: [tip.x, tip.y],
            angle_deg: cos.acos().to_degrees(),
            points: pts.len(),
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points along a line kinked by 53.1° at each end of a crack at 45° give 53.1° at both
    /// tips; points behind a tip or undamaged are not counted.
    #[test]
    fn a_kinked_line_of_damage_gives_its_angle() {
        let (start, end) = (Vector2::new(-1.0, -1.0), Vector2::new(1.0, 1.0));
        let t = (end - start).normalize();
        let kink = 53.13f64.to_radians();
        let turn = |v: Vector2<f64>, a: f64| {
            Vector2::new(v.x * a.cos() - v.y * a.sin(), v.x * a.sin() + v.y * a.cos())
        };
        let mut x0 = Vec::new();
        let mut damage = Vec::new();
        for k in 1..40 {
            let r = 0.1 * k as f64;
            x0.push(end + turn(t, kink) * r);
            x0.push(start + turn(-t, kink) * r);
            damage.extend([0.5, 0.5]);
            // undamaged points straight ahead, damaged ones behind the tip (on the crack)
            x0.push(end + t * r);
            damage.push(0.1);
            if r < 2.0 {
                x0.push(end - t * r + Vector2::new(0.01, 0.0));
                damage.push(0.9);
            }
        }
        let got = kinks(&x0, &damage, (start, end), 0.35, (0.2, 2.0));
        for k in got {
            let k = k.expect("a kink");
            assert!((k.angle_deg - 53.13).abs() < 1e-9, "{k:?}");
        }
    }
}
