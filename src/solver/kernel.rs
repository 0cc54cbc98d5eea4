//! The explicit step kernel (ARCHITECTURE.md, "The step kernel"; MODEL.md §2–5).
//!
//! Two gather passes per step, parallel over chunks of particles, with no scatter, atomics or
//! allocation, so results do not depend on the thread count:
//!
//! 1. `bθ_i = b_i·Σ_m S_im` from the current positions (one number per particle);
//! 2. for each particle, over its own slots: the bond force
//!    F_b,ij = ½(F_s,ij + F_s,ji) = ½((a_i + a_j)·S_ij + bθ_i + bθ_j) (3.7, 3.8) along the
//!    current unit vector e_ij, plus the bond damper (3.55), then central differences
//!    (3.58) with the particle damper (3.56) taken semi-implicitly.
//!
//! Writing F_b through bθ uses that S_ji = S_ij, so F_s,ji never needs the neighbour's other
//! bonds. `LAG = true` is the literal reading (A) of MODEL.md §4: the force from the previous
//! step's positions drives this step.

use super::mechanics::Mechanics;
use crate::model::stretch::total_stretch;
use nalgebra::SVector;
use rayon::prelude::*;

/// Particles per parallel work item.
pub const CHUNK: usize = 2048;

/// Dynamic state, allocated once.
#[derive(Clone, Debug)]
pub struct State<const D: usize> {
    /// Positions x^n.
    pub x: Vec<SVector<f64, D>>,
    /// Velocities v^{n−½}.
    pub v: Vec<SVector<f64, D>>,
    pub x_next: Vec<SVector<f64, D>>,
    pub v_next: Vec<SVector<f64, D>>,
    /// Internal force (bonds and bond dampers) at x^n.
    pub force: Vec<SVector<f64, D>>,
    /// Internal force at x^{n−1} (reading A only).
    pub force_prev: Vec<SVector<f64, D>>,
    /// b_i·θ_i of the current step.
    pub b_theta: Vec<f64>,
    /// Work done on each particle's dampers so far (J).
    pub damping_work: Vec<f64>,
}

impl<const D: usize> State<D> {
    /// At rest in the reference configuration.
    pub fn at_rest(x0: &[SVector<f64, D>]) -> Self {
        let n = x0.len();
        let z = vec![SVector::zeros(); n];
        State {
            x: x0.to_vec(),
            v: z.clone(),
            x_next: x0.to_vec(),
            v_next: z.clone(),
            force: z.clone(),
            force_prev: z,
            b_theta: vec![0.0; n],
            damping_work: vec![0.0; n],
        }
    }
}

/// Pass 1: b_i·Σ_m S_im for every particle.
pub fn pass_dilatation<const D: usize, const K: usize>(
    m: &Mechanics<D, K>,
    x: &[SVector<f64, D>],
    out: &mut [f64],
) {
    assert!(x.len() == m.len() && out.len() == m.len());
    out.par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(c, chunk)| {
            let base = c * CHUNK;
            for (o, bt) in chunk.iter_mut().enumerate() {
                let i = base + o;
                let xi = x[i];
                let nb = &m.neighbours[i];
                let il = &m.inv_l0[i];
                let mut s = 0.0;
                for k in 0..K {
                    let j = nb[k];
                    if j == crate::discretise::NONE {
                        continue;
                    }
                    // SAFETY: Mechanics::new checks every occupied slot indexes a particle.
                    let xj = unsafe { *x.get_unchecked(j as usize) };
                    s += total_stretch((xj - xi).norm(), il[k]);
                }
                *bt = m.b[i] * s;
            }
        });
}

/// Internal force on particle i at positions x with velocities v (bond dampers if `DAMP`);
/// returns the force and the power dissipated in its bond dampers (half of each bond's).
#[inline(always)]
pub fn particle_force<const D: usize, const K: usize, const DAMP: bool>(
    m: &Mechanics<D, K>,
    x: &[SVector<f64, D>],
    v: &[SVector<f64, D>],
    b_theta: &[f64],
    i: usize,
) -> (SVector<f64, D>, f64) {
    debug_assert!(x.len() == m.len() && v.len() == m.len() && b_theta.len() == m.len());
    let xi = x[i];
    let ai = m.a[i];
    let bti = b_theta[i];
    let nb = &m.neighbours[i];
    let il = &m.inv_l0[i];
    let mut f = SVector::<f64, D>::zeros();
    let mut power = 0.0;
    for k in 0..K {
        let j = nb[k];
        if j == crate::discretise::NONE {
            continue;
        }
        let j = j as usize;
        // SAFETY: Mechanics::new checks every occupied slot indexes a particle, and the
        // state arrays have one entry per particle.
        let (xj, aj, btj) = unsafe {
            (
                *x.get_unchecked(j),
                *m.a.get_unchecked(j),
                *b_theta.get_unchecked(j),
            )
        };
        let d = xj - xi;
        let len = d.norm();
        let e = d * (1.0 / len);
        let s = total_stretch(len, il[k]);
        let mut fb = 0.5 * ((ai + aj) * s + bti + btj);
        if DAMP {
            let (vj, cj) = unsafe { (*v.get_unchecked(j), *m.c_in.get_unchecked(j)) };
            let c = 0.5 * (m.c_in[i] + cj);
            let rate = (vj - v[i]).dot(&e);
            fb += c * rate;
            power += 0.5 * c * rate * rate;
        }
        f += e * fb;
    }
    (f, power)
}

/// Pass 2: forces and the central-difference update of every particle into x_next, v_next.
pub fn pass_update<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>(
    m: &Mechanics<D, K>,
    st: &mut State<D>,
    dt: f64,
) {
    let State {
        x,
        v,
        x_next,
        v_next,
        force,
        force_prev,
        b_theta,
        damping_work,
    } = st;
    let n = m.len();
    assert!([
        x.len(),
        v.len(),
        x_next.len(),
        v_next.len(),
        force.len(),
        force_prev.len(),
        b_theta.len()
    ]
    .iter()
    .all(|&l| l == n));
    let (x, v, b_theta, force_prev) = (&x[..], &v[..], &b_theta[..], &force_prev[..]);
    x_next
        .par_chunks_mut(CHUNK)
        .zip(v_next.par_chunks_mut(CHUNK))
        .zip(force.par_chunks_mut(CHUNK))
        .zip(damping_work.par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(c, (((xn, vn), fo), dw))| {
            let base = c * CHUNK;
            for o in 0..xn.len() {
                let i = base + o;
                let (f, bond_power) = particle_force::<D, K, DAMP>(m, x, v, b_theta, i);
                fo[o] = f;
                let drive = if LAG { force_prev[i] } else { f };
                let h = 0.5 * dt * m.c_ex[i] * m.inv_mass[i];
                let vi = v[i];
                let vnew = (vi * (1.0 - h) + drive * (dt * m.inv_mass[i])) / (1.0 + h);
                vn[o] = vnew;
                xn[o] = x[i] + vnew * dt;
                if DAMP || h != 0.0 {
                    let vm = (vi + vnew) * 0.5;
                    dw[o] += dt * (bond_power + m.c_ex[i] * vm.norm_squared());
                }
            }
        });
}

/// One explicit step from x^n, v^{n−½} to x^{n+1}, v^{n+½} (not yet swapped in).
pub fn step<const D: usize, const K: usize, const LAG: bool, const DAMP: bool>(
    m: &Mechanics<D, K>,
    st: &mut State<D>,
    dt: f64,
) {
    pass_dilatation(m, &st.x, &mut st.b_theta);
    pass_update::<D, K, LAG, DAMP>(m, st, dt);
}
