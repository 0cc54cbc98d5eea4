//! Platens with Coulomb friction (docs/model.md §10, (S.19)): a group's
//! `friction = μ` lets its members slide along the platen's face only where the tangential
//! force exceeds μ times the pressure the platen exerts on them.
//!
//! The platen is the group's normal component, held or displaced like any prescribed
//! component. Each member's tangential components are free in the kernel; after the kernel's
//! step the platen adds the friction force f that brings the member's tangential velocity to
//! rest, capped at μ·N (N the member's contact pressure force, the normal reaction that pushes
//! into the body, zero where the body pulls away):
//!
//! ```text
//! f_stop = −m·(g + h)·v_t^{n+½} / Δt             (the force that stops the member, (S.5))
//! f      = f_stop                  if |f_stop| ≤ μ·N        (stick)
//!        = μ·N · f_stop / |f_stop|  otherwise               (slip, against the motion)
//! ```
//!
//! so a member at rest under a tangential force below μ·N stays at rest, and one that slides
//! is resisted by μ·N against its sliding direction. The work of f is dissipated and booked
//! with the dampers' (`damping_energy_J`), so the energy balance of the run closes.

use super::kernel::State;
use super::loading::{add_force, damper_factor};
use super::mechanics::Mechanics;
use nalgebra::SVector;

/// One member of a platen with friction.
#[derive(Clone, Copy, Debug)]
pub struct Contact {
    pub particle: u32,
    /// The platen's normal component (held or displaced by a group).
    pub normal: u8,
    /// +1 or −1: the direction along `normal` that points into the body.
    pub inward: f64,
    /// Bit c set for each tangential component c the friction acts on (free components).
    pub tangential: u8,
    /// μ, the Coulomb coefficient.
    pub mu: f64,
}

impl Contact {
    /// The tangential components (bits of `tangential`).
    fn components<const D: usize>(&self) -> impl Iterator<Item = usize> {
        let bits = self.tangential;
        (0..D).filter(move |&k| bits & (1 << k) != 0)
    }
}

/// Adds the platens' friction forces to the step the kernel took (`state.v_next`,
/// `state.x_next`, with the internal forces at x^n in `state.force`) and books their work,
/// and the particle dampers' work at the new velocities, in `state.damping_work`.
pub fn apply<const D: usize, const K: usize>(
    contacts: &[Contact],
    mech: &Mechanics<D, K>,
    state: &mut State<D>,
    dt: f64,
) {
    for c in contacts {
        let i = c.particle as usize;
        // the platen's push on the member: the reaction to the internal force, into the body
        let pressure = (-state.force[i][c.normal as usize] * c.inward).max(0.0);
        // the force that stops the member's tangential motion over this step
        let scale = damper_factor(mech, i, dt) / (dt * mech.inv_mass[i]);
        let mut stop = SVector::<f64, D>::zeros();
        for k in c.components::<D>() {
            stop[k] = -scale * state.v_next[i][k];
        }
        let (norm, cap) = (stop.norm(), c.mu * pressure);
        let f = if norm <= cap {
            stop
        } else {
            stop * (cap / norm)
        };
        for k in c.components::<D>() {
            // the friction's work is dissipated: booked with the dampers'
            let (work, _) = add_force(mech, state, (i, k), f[k], dt);
            state.damping_work[i] -= work;
        }
    }
}

/// The contacts of a platen group: its `members`, the normal component, the direction into
/// the body and μ; `constrained` marks the components some group holds or moves (those take
/// no friction).
pub fn contacts_of<const D: usize>(
    members: &[u32],
    normal: usize,
    inward: f64,
    mu: f64,
    constrained: &[[bool; D]],
) -> Vec<Contact> {
    members
        .iter()
        .filter_map(|&i| {
            let tangential = (0..D)
                .filter(|&k| k != normal && !constrained[i as usize][k])
                .fold(0u8, |bits, k| bits | (1 << k));
            (tangential != 0).then_some(Contact {
                particle: i,
                normal: normal as u8,
                inward,
                tangential,
                mu,
            })
        })
        .collect()
}
