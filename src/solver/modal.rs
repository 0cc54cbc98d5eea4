//! The fundamental period T1 of the constrained specimen (docs/model.md §5), computed by the tool
//! instead of typed in: the lowest eigenvalue of K·φ = λ·M·φ of the linearised operator by
//! Lanczos ([`super::lanczos`]). (Inverse iteration with CG solves was 4–5× slower: each
//! solve needs as many iterations as the whole Lanczos run.) Rigid-body motions that the
//! supports leave free (a plate held only in y can slide in x) are zero-frequency
//! mechanisms: they are found from the constraints and deflated (M-orthogonally), so T1 is
//! the period of the lowest elastic mode. Constrained components (fixed or loaded) are held
//! at zero, as during a displacement-controlled test.

use super::lanczos::{Extreme, Lanczos};
use super::linear::LinearOperator;
use super::mechanics::Mechanics;
use nalgebra::{DMatrix, SVector};

type Field<const D: usize> = Vec<SVector<f64, D>>;

/// Relative change of the lowest Ritz value over 20 Lanczos steps at which T1 is accepted.
pub const EIGEN_TOLERANCE: f64 = 1e-8;

/// Result of the modal analysis.
#[derive(Clone, Copy, Debug)]
pub struct Fundamental {
    /// ω1² (rad²/s²).
    pub eigenvalue: f64,
    /// T1 = 2π/ω1 (s).
    pub period: f64,
    /// Lanczos steps used.
    pub iterations: usize,
    /// Number of rigid-body mechanisms deflated.
    pub mechanisms: usize,
}

fn dot<const D: usize>(a: &[SVector<f64, D>], b: &[SVector<f64, D>]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(y)).sum()
}

fn mdot<const D: usize>(m: &[f64], a: &[SVector<f64, D>], b: &[SVector<f64, D>]) -> f64 {
    a.iter()
        .zip(b)
        .zip(m)
        .map(|((x, y), mi)| mi * x.dot(y))
        .sum()
}

fn mask<const D: usize>(u: &mut [SVector<f64, D>], constrained: &[[bool; D]]) {
    for (ui, c) in u.iter_mut().zip(constrained) {
        for d in 0..D {
            if c[d] {
                ui[d] = 0.0;
            }
        }
    }
}

/// Rigid-body modes (translations, and in 2D the rotation) that leave every constrained
/// component at rest, M-orthonormalised.
pub fn mechanisms<const D: usize>(
    x0: &[SVector<f64, D>],
    mass: &[f64],
    constrained: &[[bool; D]],
) -> Vec<Field<D>> {
    let n = x0.len();
    let centre = x0.iter().fold(SVector::<f64, D>::zeros(), |a, x| a + x) / n as f64;
    let mut rigid: Vec<Field<D>> = Vec::new();
    for d in 0..D {
        let mut t = vec![SVector::<f64, D>::zeros(); n];
        for v in t.iter_mut() {
            v[d] = 1.0;
        }
        rigid.push(t);
    }
    if D == 2 {
        let r: Field<D> = x0
            .iter()
            .map(|x| {
                let q = x - centre;
                let mut v = SVector::<f64, D>::zeros();
                v[0] = -q[1];
                v[1] = q[0];
                v
            })
            .collect();
        rigid.push(r);
    } else if D == 3 {
        for (p, q) in [(1, 2), (2, 0), (0, 1)] {
            let r: Field<D> = x0
                .iter()
                .map(|x| {
                    let c = x - centre;
                    let mut v = SVector::<f64, D>::zeros();
                    v[p] = -c[q];
                    v[q] = c[p];
                    v
                })
                .collect();
            rigid.push(r);
        }
    }
    // Constraint matrix: rows = constrained components, columns = rigid modes.
    let rows: Vec<(usize, usize)> = (0..n)
        .flat_map(|i| {
            (0..D)
                .filter(move |&d| constrained[i][d])
                .map(move |d| (i, d))
        })
        .collect();
    let m = rigid.len();
    let null: Vec<nalgebra::DVector<f64>> = if rows.is_empty() {
        (0..m)
            .map(|k| nalgebra::DVector::from_fn(m, |r, _| if r == k { 1.0 } else { 0.0 }))
            .collect()
    } else {
        let scale: f64 = x0
            .iter()
            .map(|x| (x - centre).norm())
            .fold(0.0, f64::max)
            .max(1e-300);
        // At least m rows (zero rows add no constraint), so that the SVD gives all m right
        // singular vectors even when fewer components than rigid modes are held.
        let c = DMatrix::from_fn(rows.len().max(m), m, |r, k| {
            let Some(&(i, d)) = rows.get(r) else {
                return 0.0;
            };
            let w = if k >= D { 1.0 / scale } else { 1.0 };
            rigid[k][i][d] * w
        });
        let svd = c.svd(false, true);
        let vt = svd.v_t.unwrap();
        let smax = svd.singular_values.max();
        (0..m)
            .filter(|&k| k >= svd.singular_values.len() || svd.singular_values[k] <= 1e-9 * smax)
            .map(|k| {
                let mut v = vt.row(k).transpose();
                for kk in D..m {
                    v[kk] /= scale;
                }
                v
            })
            .collect()
    };
    let mut modes: Vec<Field<D>> = Vec::new();
    for coeffs in null {
        let mut f: Field<D> = (0..n)
            .map(|i| {
                (0..m).fold(SVector::<f64, D>::zeros(), |acc, k| {
                    acc + rigid[k][i] * coeffs[k]
                })
            })
            .collect();
        mask(&mut f, constrained);
        for g in &modes {
            let c = mdot(mass, &f, g);
            for (a, b) in f.iter_mut().zip(g) {
                *a -= b * c;
            }
        }
        let norm = mdot(mass, &f, &f).sqrt();
        if norm > 1e-12 {
            f.iter_mut().for_each(|v| *v /= norm);
            modes.push(f);
        }
    }
    modes
}

pub fn deflate<const D: usize>(u: &mut [SVector<f64, D>], modes: &[Field<D>], mass: &[f64]) {
    for g in modes {
        let c = mdot(mass, u, g);
        for (a, b) in u.iter_mut().zip(g) {
            *a -= b * c;
        }
    }
}

/// Error of the modal analysis.
#[derive(Debug, thiserror::Error)]
pub enum ModalError {
    #[error("the fundamental period could not be computed: {0}")]
    Failed(String),
}

/// Lowest elastic eigenpair of the constrained linearised model.
pub fn fundamental<const D: usize, const K: usize>(
    mech: &Mechanics<D, K>,
    x0: &[SVector<f64, D>],
    constrained: &[[bool; D]],
) -> Result<Fundamental, ModalError> {
    let mut op = LinearOperator::new(mech, x0);
    // Lanczos needs about as many steps as one CG solve (√ of the condition number, which
    // grows with (extent/L0)²): allow 100 per lattice spacing across the body.
    let max_steps = (100.0 * extent_in_spacings(mech, x0)) as usize + 2000;
    lowest_mode(x0, &mech.mass, constrained, max_steps, |u, out| {
        op.internal_forces(u, out)
    })
}

/// The lowest mode of a body of points `x0` with masses, held in its `constrained`
/// components, whose linearised internal forces at displacements u are `forces(u, out)`
/// (−K·u): Lanczos on K with the rigid-body mechanisms the supports leave deflated.
pub fn lowest_mode<const D: usize>(
    x0: &[SVector<f64, D>],
    mass: &[f64],
    constrained: &[[bool; D]],
    max_steps: usize,
    mut forces: impl FnMut(&[SVector<f64, D>], &mut [SVector<f64, D>]),
) -> Result<Fundamental, ModalError> {
    let modes = mechanisms(x0, mass, constrained);
    if constrained.iter().all(|c| c.iter().all(|&b| b)) {
        return Err(ModalError::Failed("every particle is constrained".into()));
    }
    let est = Lanczos {
        mass,
        constrained: Some(constrained),
        deflate: &modes,
        which: Extreme::Smallest,
        tolerance: EIGEN_TOLERANCE,
        max_steps,
    }
    .run(|u, out| {
        forces(u, out);
        out.iter_mut().for_each(|v| *v = -*v);
    });
    if !est.converged || est.eigenvalue.is_nan() || est.eigenvalue <= 0.0 {
        return Err(ModalError::Failed(format!(
            "Lanczos did not converge in {} steps (estimate ω1² = {:e})",
            est.steps, est.eigenvalue
        )));
    }
    Ok(Fundamental {
        eigenvalue: est.eigenvalue,
        period: 2.0 * std::f64::consts::PI / est.eigenvalue.sqrt(),
        iterations: est.steps,
        mechanisms: modes.len(),
    })
}

/// Remove from a residual its components along M·g for each mechanism g (so the singular
/// system stays consistent).
fn deflate_euclid<const D: usize>(r: &mut [SVector<f64, D>], modes: &[Field<D>], mass: &[f64]) {
    for g in modes {
        let mg: Field<D> = g.iter().zip(mass).map(|(v, m)| v * *m).collect();
        let c = dot(r, g) / dot(&mg, g);
        for (a, b) in r.iter_mut().zip(&mg) {
            *a -= b * c;
        }
    }
}

/// Scratch vectors of [`conjugate_gradient`].
pub struct CgWork<const D: usize> {
    r: Field<D>,
    p: Field<D>,
    ap: Field<D>,
    zr: Field<D>,
    diag: Option<Field<D>>,
}

impl<const D: usize> CgWork<D> {
    pub fn new(n: usize) -> Self {
        let z = vec![SVector::zeros(); n];
        CgWork {
            r: z.clone(),
            p: z.clone(),
            ap: z.clone(),
            zr: z,
            diag: None,
        }
    }
}

/// Solve K·z = rhs on the free components (constrained ones held at zero) by conjugate
/// gradients with a Jacobi preconditioner, from the initial guess in `z`. Mechanisms
/// (rigid motions the constraints leave free) are projected out of the residual.
/// Returns the number of iterations.
#[allow(clippy::too_many_arguments)]
pub fn conjugate_gradient<const D: usize, const K: usize>(
    op: &mut LinearOperator<D, K>,
    constrained: &[[bool; D]],
    modes: &[Field<D>],
    mass: &[f64],
    rhs: &[SVector<f64, D>],
    z: &mut Field<D>,
    tol: f64,
    w: &mut CgWork<D>,
) -> Result<usize, ModalError> {
    let n = rhs.len();
    let mech = op.mech;
    let x0 = op.x0;
    let diag = w.diag.get_or_insert_with(|| {
        // diagonal blocks of the a-part, Σ_j ½(a_i + a_j)/L · n n
        (0..n)
            .map(|i| {
                let mut dg = SVector::<f64, D>::zeros();
                for (_, j, il) in mech.bonds(i) {
                    let e = (x0[j] - x0[i]) * il;
                    dg += e.component_mul(&e) * (0.5 * (mech.a[i] + mech.a[j]) * il);
                }
                dg.map(|v| if v > 0.0 { 1.0 / v } else { 0.0 })
            })
            .collect()
    });
    // Each mechanism g (M-normalised) gets a penalty σ_g·(Mg)(Mg)ᵀ so that the operator is
    // positive definite: since Kg = 0 and the right-hand side is orthogonal to g, the
    // solution of the penalised system is the M-orthogonal solution of K·z = rhs, and CG no
    // longer lets round-off grow along g. σ_g puts g's eigenvalue at a typical K/M ratio.
    let typical = (0..n)
        .map(|i| {
            diag[i]
                .iter()
                .filter(|v| **v > 0.0)
                .map(|v| 1.0 / v)
                .sum::<f64>()
                / mass[i]
        })
        .sum::<f64>()
        / n as f64;
    let penalties: Vec<(Field<D>, f64)> = modes
        .iter()
        .map(|g| {
            let mg: Field<D> = g.iter().zip(mass).map(|(v, m)| v * *m).collect();
            let sigma = typical / dot(&mg, &mg);
            (mg, sigma)
        })
        .collect();
    let apply = |op: &mut LinearOperator<D, K>, u: &[SVector<f64, D>], out: &mut Field<D>| {
        op.internal_forces(u, out);
        for o in out.iter_mut() {
            *o = -*o;
        }
        for (mg, sigma) in &penalties {
            let c = sigma * dot(mg, u);
            for (o, v) in out.iter_mut().zip(mg) {
                *o += v * c;
            }
        }
        mask(out, constrained);
    };
    mask(z, constrained);
    apply(op, z, &mut w.ap);
    for ((r, b), ap) in w.r.iter_mut().zip(rhs).zip(&w.ap) {
        *r = b - ap;
    }
    mask(&mut w.r, constrained);
    deflate_euclid(&mut w.r, modes, mass);
    let bnorm = dot(rhs, rhs).sqrt().max(1e-300);
    precondition(&w.r, diag, &mut w.zr);
    w.p.clone_from(&w.zr);
    let mut rz = dot(&w.r, &w.zr);
    // CG needs O(√cond) iterations and cond grows with (extent/L0)²: allow 200 per spacing
    let max_cg = (200.0 * extent_in_spacings(mech, x0)) as usize + 500;
    for it in 0..max_cg {
        if dot(&w.r, &w.r).sqrt() <= tol * bnorm {
            return Ok(it);
        }
        apply(op, &w.p, &mut w.ap);
        let pap = dot(&w.p, &w.ap);
        if pap.is_nan() || pap <= 0.0 {
            return Err(ModalError::Failed(
                "the stiffness is not positive definite on the free components: the supports leave a mechanism that is not a rigid motion".into(),
            ));
        }
        let alpha = rz / pap;
        for (zi, p) in z.iter_mut().zip(&w.p) {
            *zi += p * alpha;
        }
        for (r, ap) in w.r.iter_mut().zip(&w.ap) {
            *r -= ap * alpha;
        }
        precondition(&w.r, diag, &mut w.zr);
        let rz_new = dot(&w.r, &w.zr);
        let beta = rz_new / rz;
        rz = rz_new;
        for (p, zr) in w.p.iter_mut().zip(&w.zr) {
            *p = zr + *p * beta;
        }
    }
    Err(ModalError::Failed(format!(
        "conjugate gradients did not converge in {max_cg} iterations"
    )))
}

/// Static linear-elastic response to prescribed displacements (small strain): the
/// displacement field u with u = ū on the constrained components and K·u = 0 on the free
/// ones. Used by the verification tests (stiffness, E and ν, rotation objectivity).
pub fn static_response<const D: usize, const K: usize>(
    mech: &Mechanics<D, K>,
    x0: &[SVector<f64, D>],
    constrained: &[[bool; D]],
    prescribed: &[SVector<f64, D>],
) -> Result<Field<D>, ModalError> {
    // rhs = f(ū) = −K ū on the free components
    let mut rhs: Field<D> = vec![SVector::zeros(); x0.len()];
    LinearOperator::new(mech, x0).internal_forces(prescribed, &mut rhs);
    let z = static_force_response(mech, x0, constrained, &rhs)?;
    Ok(z.iter()
        .zip(prescribed)
        .zip(constrained)
        .map(|((z, p), c)| SVector::from_fn(|d, _| if c[d] { p[d] } else { z[d] }))
        .collect())
}

/// Static linear-elastic response to applied forces (small strain): K·u = f on the free
/// components, u = 0 on the constrained ones (rigid motions the constraints leave free are
/// removed; the forces must not load them). Used to measure stiffnesses (the cantilever of
/// `tests/suite/surfaces.rs` and `benchmarks/surfaces.rs`).
pub fn static_force_response<const D: usize, const K: usize>(
    mech: &Mechanics<D, K>,
    x0: &[SVector<f64, D>],
    constrained: &[[bool; D]],
    forces: &[SVector<f64, D>],
) -> Result<Field<D>, ModalError> {
    let n = x0.len();
    let modes = mechanisms(x0, &mech.mass, constrained);
    let mut op = LinearOperator::new(mech, x0);
    let mut rhs = forces.to_vec();
    mask(&mut rhs, constrained);
    let mut z: Field<D> = vec![SVector::zeros(); n];
    let mut w = CgWork::new(n);
    conjugate_gradient(
        &mut op,
        constrained,
        &modes,
        &mech.mass,
        &rhs,
        &mut z,
        1e-12,
        &mut w,
    )?;
    Ok(z)
}

/// Jacobi preconditioning: zr = diag ∘ r.
fn precondition<const D: usize>(
    r: &[SVector<f64, D>],
    diag: &[SVector<f64, D>],
    zr: &mut [SVector<f64, D>],
) {
    for ((z, r), d) in zr.iter_mut().zip(r).zip(diag) {
        *z = r.component_mul(d);
    }
}

/// The body's diagonal in units of its shortest bond: iterative solvers on the lattice need
/// a number of iterations proportional to it (√ of the condition number).
fn extent_in_spacings<const D: usize, const K: usize>(
    mech: &Mechanics<D, K>,
    x0: &[SVector<f64, D>],
) -> f64 {
    let (mut lo, mut hi) = (x0[0], x0[0]);
    for x in x0 {
        lo = lo.inf(x);
        hi = hi.sup(x);
    }
    let l0_min = (0..x0.len())
        .flat_map(|i| mech.bonds(i).map(|(_, _, il)| 1.0 / il))
        .fold(f64::INFINITY, f64::min);
    (hi - lo).norm() / l0_min
}
