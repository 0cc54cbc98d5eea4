//! Displacement loading (docs/model.md §10): the 1−cos ramp (5.5) and the 5th-order smooth step
//! (Hobbs (2021), Eq. 4.9), held at Δmax after t_ramp.

use super::kernel::State;
use super::mechanics::Mechanics;
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

/// g + h of particle i: a force f added after the kernel's step changes v^{n+½} by
/// Δv = Δt·f/(m_i·(g + h)), (3.58) being linear in the drive, with the particle damper's h
/// and the implicit bond dampers' g of (S.5), (S.17).
#[inline]
pub fn damper_factor<const D: usize, const K: usize>(
    mech: &Mechanics<D, K>,
    i: usize,
    dt: f64,
) -> f64 {
    let h = 0.5 * dt * mech.c_ex[i] * mech.inv_mass[i];
    let g = 1.0 + dt * mech.c_implicit[i] * mech.inv_mass[i];
    g + h
}

/// Adds the force `f` on component `c` of particle i to the step the kernel took from the
/// internal forces alone (force-controlled loads, bearing strips, friction): Δv on
/// v^{n+½} ([`damper_factor`]) and Δt·Δv on x^{n+1}, with the dampers' work booked
/// again for the new mid-step velocity. Returns the work of f over the step and up to step
/// n (central rule, f·½(x^{n+1} − x^{n−1}) and f·½(x^n − x^{n−1})).
#[inline]
pub fn add_force<const D: usize, const K: usize>(
    mech: &Mechanics<D, K>,
    state: &mut State<D>,
    (i, c): (usize, usize),
    f: f64,
    dt: f64,
) -> (f64, f64) {
    let dv = f * dt * mech.inv_mass[i] / damper_factor(mech, i, dt);
    let (v0, v1) = (state.v[i][c], state.v_next[i][c]);
    let (vm, vm_new) = (0.5 * (v0 + v1), 0.5 * (v0 + v1 + dv));
    state.damping_work[i] += dt
        * (mech.c_ex[i] * (vm_new * vm_new - vm * vm)
            + mech.c_implicit[i] * ((v1 + dv - v0) * vm_new - (v1 - v0) * vm));
    state.v_next[i][c] = v1 + dv;
    state.x_next[i][c] += dv * dt;
    (f * dt * vm_new, f * 0.5 * dt * v0)
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
