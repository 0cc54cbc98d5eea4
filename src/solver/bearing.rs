//! Bearing strips under a loading platen (docs/model.md §10, "Bearing strips"): a group's
//! `bearing = { E, thickness }` puts a strip of stiffness k'' = E/thickness per unit area
//! between the platen and the members. The platen follows the group's displacement
//! Δ(t); member i, of contact area A_i (the strip's area shared by volume), is pressed by
//!
//! ```text
//! f_i = s·k''·A_i·max(0, s·(Δ(t) − u_i))     (s = ±1: the direction into the body)
//! ```
//!
//! along the platen's component: the strip pushes and never pulls. The force enters the
//! step as a force-controlled load does (`loading::add_force`), and its work is the
//! work done on the specimen.

use super::kernel::State;
use super::loading::add_force;
use super::mechanics::Mechanics;
use nalgebra::SVector;

/// One member of a group pressed through a bearing strip.
#[derive(Clone, Copy, Debug)]
pub struct Bearing {
    pub particle: u32,
    pub component: u8,
    /// Δmax of the platen (m, signed).
    pub amplitude: f64,
    /// k''·A_i (N/m): the strip's stiffness over the member's share of its area.
    pub stiffness: f64,
    /// +1 or −1: the direction along `component` that points into the body.
    pub inward: f64,
}

/// Adds the strips' forces at the platen's position `ramp`·Δmax to the step the kernel took,
/// as [`super::Simulation`] adds force-controlled loads; returns their work over the step and
/// up to step n (central rule).
pub fn apply<const D: usize, const K: usize>(
    bearings: &[Bearing],
    mech: &Mechanics<D, K>,
    x0: &[SVector<f64, D>],
    state: &mut State<D>,
    ramp: f64,
    dt: f64,
) -> (f64, f64) {
    let (mut work, mut work_half) = (0.0, 0.0);
    for b in bearings {
        let (i, c) = (b.particle as usize, b.component as usize);
        let u = state.x[i][c] - x0[i][c];
        let squeeze = (b.inward * (b.amplitude * ramp - u)).max(0.0);
        if squeeze == 0.0 {
            continue;
        }
        let (w, w_half) = add_force(mech, state, (i, c), b.inward * b.stiffness * squeeze, dt);
        work += w;
        work_half += w_half;
    }
    (work, work_half)
}

/// The largest k_i/m_i of the strips' members (rad²/s²): the strips raise the squared
/// highest frequency of the specimen by at most this much (Weyl's inequality: the strips add
/// a diagonal stiffness).
pub fn largest_rate(bearings: &[Bearing], mass: &[f64]) -> f64 {
    bearings
        .iter()
        .map(|b| b.stiffness / mass[b.particle as usize])
        .fold(0.0, f64::max)
}
