//! The fundamental period T1 of the constrained specimen (MODEL.md §5), computed by the tool
//! instead of typed in: inverse iteration on K·φ = λ·M·φ with the linearised operator,
//! each solve by conjugate gradients (Jacobi preconditioner). Rigid-body motions that the
//! supports leave free (a plate held only in y can slide in x) are zero-frequency
//! mechanisms: they are found from the constraints and deflated (M-orthogonally), so T1 is
//! the period of the lowest elastic mode. Constrained components (fixed or loaded) are held
//! at zero, as during a displacement-controlled test.

use super::linear::LinearOperator;
use super::mechanics::Mechanics;
use nalgebra::{DMatrix, SVector};

type Field<const D: usize> = Vec<SVector<f64, D>>;

/// Result of the modal analysis.
#[derive(Clone, Copy, Debug)]
pub struct Fundamental {
    /// ω1² (rad²/s²).
    pub eigenvalue: f64,
    /// T1 = 2π/ω1 (s).
    pub period: f64,
    /// Inverse iterations used.
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
fn mechanisms<const D: usize>(
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
        let c = DMatrix::from_fn(rows.len(), m, |r, k| {
            let (i, d) = rows[r];
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

fn deflate<const D: usize>(u: &mut [SVector<f64, D>], modes: &[Field<D>], mass: &[f64]) {
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
    let n = x0.len();
    let mass = &mech.mass;
    let modes = mechanisms(x0, mass, constrained);
    let mut op = LinearOperator::new(mech, x0);
    // Jacobi preconditioner: diagonal blocks of the a-part, Σ_j ½(a_i + a_j)/L · n n.
    let diag: Field<D> = (0..n)
        .map(|i| {
            let mut dg = SVector::<f64, D>::zeros();
            for (_, j, il) in mech.bonds(i) {
                let e = (x0[j] - x0[i]) * il;
                dg += e.component_mul(&e) * (0.5 * (mech.a[i] + mech.a[j]) * il);
            }
            dg.map(|v| if v > 0.0 { 1.0 / v } else { 0.0 })
        })
        .collect();
    let apply = |op: &mut LinearOperator<D, K>, u: &[SVector<f64, D>], out: &mut Field<D>| {
        op.internal_forces(u, out);
        for o in out.iter_mut() {
            *o = -*o;
        }
        mask(out, constrained);
    };
    // Start: a smooth field (positions), masked and deflated.
    let mut x: Field<D> = x0
        .iter()
        .map(|p| p.map(|c| c + 1.0) + SVector::<f64, D>::repeat(0.1))
        .collect();
    let centre = x0.iter().fold(SVector::<f64, D>::zeros(), |a, p| a + p) / n as f64;
    for (xi, p) in x.iter_mut().zip(x0) {
        let q = p - centre;
        *xi += q.map(|c| c * c);
    }
    mask(&mut x, constrained);
    deflate(&mut x, &modes, mass);
    let norm = mdot(mass, &x, &x).sqrt();
    if !(norm > 0.0) {
        return Err(ModalError::Failed("every particle is constrained".into()));
    }
    x.iter_mut().for_each(|v| *v /= norm);

    let mut z: Field<D> = vec![SVector::zeros(); n];
    let mut kz: Field<D> = vec![SVector::zeros(); n];
    let mut lambda_prev = f64::INFINITY;
    let mut r: Field<D> = vec![SVector::zeros(); n];
    let mut p: Field<D> = vec![SVector::zeros(); n];
    let mut ap: Field<D> = vec![SVector::zeros(); n];
    for it in 1..=60 {
        // rhs = M x
        let rhs: Field<D> = x.iter().zip(mass).map(|(v, m)| v * *m).collect();
        // CG on K z = rhs, warm start from the last z scaled
        apply(&mut op, &z, &mut kz);
        for i in 0..n {
            r[i] = rhs[i] - kz[i];
        }
        deflate_euclid(&mut r, &modes, mass);
        let bnorm = dot(&rhs, &rhs).sqrt();
        let mut zr: Field<D> = r
            .iter()
            .zip(&diag)
            .map(|(a, d)| a.component_mul(d))
            .collect();
        p.clone_from(&zr);
        let mut rz = dot(&r, &zr);
        let max_cg = 20 * (n as f64).sqrt() as usize + 200;
        let mut converged = false;
        for _ in 0..max_cg {
            if dot(&r, &r).sqrt() <= 1e-10 * bnorm {
                converged = true;
                break;
            }
            apply(&mut op, &p, &mut ap);
            let pap = dot(&p, &ap);
            if !(pap > 0.0) {
                return Err(ModalError::Failed(
                    "the stiffness is not positive definite on the free components: the supports leave a mechanism that is not a rigid motion".into(),
                ));
            }
            let alpha = rz / pap;
            for i in 0..n {
                z[i] += p[i] * alpha;
                r[i] -= ap[i] * alpha;
            }
            zr = r
                .iter()
                .zip(&diag)
                .map(|(a, d)| a.component_mul(d))
                .collect();
            let rz_new = dot(&r, &zr);
            let beta = rz_new / rz;
            rz = rz_new;
            for i in 0..n {
                p[i] = zr[i] + p[i] * beta;
            }
        }
        if !converged {
            return Err(ModalError::Failed(format!(
                "conjugate gradients did not converge in {max_cg} iterations"
            )));
        }
        deflate(&mut z, &modes, mass);
        let zn = mdot(mass, &z, &z).sqrt();
        // Rayleigh quotient λ = xᵀKx / xᵀMx with x = z/|z|_M; since Kz = Mx: λ = zᵀMx/zᵀMz.
        let lambda = mdot(mass, &z, &x) / (zn * zn);
        x = z.iter().map(|v| v / zn).collect();
        z.iter_mut().for_each(|v| *v /= zn);
        if std::env::var("SPPM_DEBUG_MODAL").is_ok() {
            eprintln!(
                "it {it} lambda {lambda:.9e} T {:.6e}",
                2.0 * std::f64::consts::PI / lambda.sqrt()
            );
        }
        if (lambda - lambda_prev).abs() <= 1e-7 * lambda {
            return Ok(Fundamental {
                eigenvalue: lambda,
                period: 2.0 * std::f64::consts::PI / lambda.sqrt(),
                iterations: it,
                mechanisms: modes.len(),
            });
        }
        lambda_prev = lambda;
    }
    Err(ModalError::Failed(
        "inverse iteration did not converge in 60 iterations".into(),
    ))
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
