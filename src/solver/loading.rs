//! Displacement loading (docs/model.md §10): the 1−cos ramp (5.5) and the 5th-order smooth step
//! (Hobbs (2021), Eq. 4.9), held at Δmax after t_ramp.

use crate::scene::Ramp;

/// Fraction of Δmax applied at time t for a ramp ending at t_ramp.
#[inline]
pub fn ramp_fraction(kind: Ramp, t: f64, t_ramp: f64) -> f64 {
    if t >= t_ramp {
        return 1.0;
    }
    if t <= 0.0 {
        return 0.0;
    }
    let g = t / t_ramp;
    match kind {
        // (5.5): Δ(t) = (Δmax/2)(1 − cos(π t / t_ramp))
        Ramp::Cosine => 0.5 * (1.0 - (std::f64::consts::PI * g).cos()),
        // A = γ³(10 − 15γ + 6γ²)
        Ramp::Smoothstep => g * g * g * (10.0 - 15.0 * g + 6.0 * g * g),
    }
}

/// One prescribed displacement component of one particle.
#[derive(Clone, Copy, Debug)]
pub struct Prescribed {
    pub particle: u32,
    pub component: u8,
    /// Δmax of this component (0 for a fixed support).
    pub amplitude: f64,
}

/// One component of a force-controlled load on one particle (docs/failure.md).
#[derive(Clone, Copy, Debug)]
pub struct AppliedForce {
    pub particle: u32,
    pub component: u8,
    /// The force at the end of the ramp (N).
    pub amplitude: f64,
}

/// A group's total force P along `component` shared among its `members` by volume,
/// b_i = P·V_i/ΣV (docs/failure.md).
pub fn shared_by_volume(
    members: &[u32],
    volume: &[f64],
    component: usize,
    total: f64,
) -> Vec<AppliedForce> {
    let sum: f64 = members.iter().map(|&i| volume[i as usize]).sum();
    members
        .iter()
        .map(|&i| AppliedForce {
            particle: i,
            component: component as u8,
            amplitude: total * volume[i as usize] / sum,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shared_force_sums_to_the_groups_force_in_proportion_to_volume() {
        let b = shared_by_volume(&[0, 2], &[1.0, 5.0, 3.0], 1, -8.0);
        assert_eq!(b.len(), 2);
        assert_eq!((b[0].particle, b[0].component), (0, 1));
        assert!((b[0].amplitude + 2.0).abs() < 1e-15);
        assert!((b[1].amplitude + 6.0).abs() < 1e-15);
    }

    #[test]
    fn ramps_start_at_rest_and_end_at_full_load() {
        for k in [Ramp::Cosine, Ramp::Smoothstep] {
            assert_eq!(ramp_fraction(k, 0.0, 1.0), 0.0);
            assert!((ramp_fraction(k, 1.0, 1.0) - 1.0).abs() < 1e-15);
            assert!((ramp_fraction(k, 0.5, 1.0) - 0.5).abs() < 1e-15);
            assert_eq!(ramp_fraction(k, 2.0, 1.0), 1.0);
            // zero slope at both ends: the loading starts and stops without a jolt
            let h = 1e-6;
            assert!(ramp_fraction(k, h, 1.0) < 1e-10);
            assert!(1.0 - ramp_fraction(k, 1.0 - h, 1.0) < 1e-10);
        }
    }
}
