//! Extreme eigenvalues of M^{-1/2}·A·M^{-1/2} (A = K or C of the linearised model) by the
//! Lanczos recurrence without reorthogonalisation: three vectors of memory, one operator
//! application per step. Loss of orthogonality only duplicates converged Ritz values
//! ("ghosts"), so the extreme eigenvalue stays correct. The extreme eigenvalue of the
//! tridiagonal matrix is found by Sturm-sequence bisection (O(k) per probe).

use nalgebra::SVector;

type Field<const D: usize> = Vec<SVector<f64, D>>;

/// Which end of the spectrum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Extreme {
    Smallest,
    Largest,
}

/// Number of eigenvalues of the symmetric tridiagonal (alpha, beta) below x.
fn count_below(alpha: &[f64], beta: &[f64], x: f64) -> usize {
    let mut count = 0;
    let mut d = 1.0;
    for i in 0..alpha.len() {
        let off = if i > 0 {
            beta[i - 1] * beta[i - 1] / d
        } else {
            0.0
        };
        d = alpha[i] - x - off;
        if d == 0.0 {
            d = -1e-300;
        }
        if d < 0.0 {
            count += 1;
        }
    }
    count
}

/// Extreme eigenvalue of a symmetric tridiagonal matrix.
pub fn tridiagonal_extreme(alpha: &[f64], beta: &[f64], which: Extreme) -> f64 {
    let k = alpha.len();
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for i in 0..k {
        let r = if i > 0 { beta[i - 1].abs() } else { 0.0 }
            + if i + 1 < k { beta[i].abs() } else { 0.0 };
        lo = lo.min(alpha[i] - r);
        hi = hi.max(alpha[i] + r);
    }
    let target = match which {
        Extreme::Smallest => 1,
        Extreme::Largest => k,
    };
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        // the target-th eigenvalue lies below mid iff at least `target` eigenvalues do
        if count_below(alpha, beta, mid) >= target {
            hi = mid
        } else {
            lo = mid
        }
    }
    0.5 * (lo + hi)
}

/// Settings of a Lanczos run.
pub struct Lanczos<'a, const D: usize> {
    pub mass: &'a [f64],
    /// Components held at zero (the operator is restricted to the free ones).
    pub constrained: Option<&'a [[bool; D]]>,
    /// M-orthonormal fields projected out of every Lanczos vector (rigid-body mechanisms).
    pub deflate: &'a [Field<D>],
    pub which: Extreme,
    /// Stop when the extreme Ritz value changes by less than this (relative) over 20 steps;
    /// 0 runs all `max_steps`.
    pub tolerance: f64,
    pub max_steps: usize,
}

/// Result: the eigenvalue estimate and the steps taken.
#[derive(Clone, Copy, Debug)]
pub struct Estimate {
    pub eigenvalue: f64,
    pub steps: usize,
    pub converged: bool,
}

impl<const D: usize> Lanczos<'_, D> {
    /// Run with `apply(u, out)` computing out = A·u.
    pub fn run(
        &self,
        mut apply: impl FnMut(&[SVector<f64, D>], &mut [SVector<f64, D>]),
    ) -> Estimate {
        let n = self.mass.len();
        let sqrt_m: Vec<f64> = self.mass.iter().map(|m| m.sqrt()).collect();
        let free = |u: &mut [SVector<f64, D>]| {
            if let Some(c) = self.constrained {
                for (ui, ci) in u.iter_mut().zip(c) {
                    for d in 0..D {
                        if ci[d] {
                            ui[d] = 0.0;
                        }
                    }
                }
            }
        };
        // In the scaled space q = M^{1/2}·u, a mechanism g becomes M^{1/2}·g (unit norm).
        let scaled_modes: Vec<Field<D>> = self
            .deflate
            .iter()
            .map(|g| g.iter().zip(&sqrt_m).map(|(v, s)| v * *s).collect())
            .collect();
        let project = |q: &mut [SVector<f64, D>]| {
            for g in &scaled_modes {
                let c: f64 = q.iter().zip(g).map(|(a, b)| a.dot(b)).sum();
                for (a, b) in q.iter_mut().zip(g) {
                    *a -= b * c;
                }
            }
        };
        // deterministic pseudo-random start (xorshift), so results are reproducible
        let mut seed: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut q: Field<D> = (0..n).map(|_| SVector::from_fn(|_, _| rnd())).collect();
        free(&mut q);
        project(&mut q);
        let norm = q.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
        if norm == 0.0 || !norm.is_finite() {
            return Estimate {
                eigenvalue: f64::NAN,
                steps: 0,
                converged: false,
            };
        }
        q.iter_mut().for_each(|v| *v /= norm);
        let mut q_prev: Field<D> = vec![SVector::zeros(); n];
        let mut u: Field<D> = vec![SVector::zeros(); n];
        let mut w: Field<D> = vec![SVector::zeros(); n];
        let (mut alpha, mut beta) = (Vec::new(), Vec::new());
        let mut beta_prev = 0.0;
        let mut last = f64::NAN;
        // Not capped at the dimension D·n: without reorthogonalisation the recurrence goes on
        // past it (ghost copies of converged values appear, the extreme one stays right), and
        // a small, ill-conditioned model (a few dozen particles) needs more than D·n steps to
        // meet the tolerance.
        for step in 1..=self.max_steps {
            for i in 0..n {
                u[i] = q[i] / sqrt_m[i];
            }
            apply(&u, &mut w);
            for i in 0..n {
                w[i] = w[i] / sqrt_m[i] - q_prev[i] * beta_prev;
            }
            let a: f64 = w.iter().zip(&q).map(|(x, y)| x.dot(y)).sum();
            for i in 0..n {
                w[i] -= q[i] * a;
            }
            // Mask and deflate last: any step after this one (the −α·q above) would bring
            // back q's round-off component along a mechanism, amplified by α/β every step.
            free(&mut w);
            project(&mut w);
            let b = w.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt();
            alpha.push(a);
            if step % 20 == 0 && self.tolerance > 0.0 {
                let now = tridiagonal_extreme(&alpha, &beta, self.which);
                if (now - last).abs() <= self.tolerance * now.abs() {
                    return Estimate {
                        eigenvalue: now,
                        steps: step,
                        converged: true,
                    };
                }
                last = now;
            }
            if b <= 1e-14 * a.abs().max(1e-300) {
                return Estimate {
                    eigenvalue: tridiagonal_extreme(&alpha, &beta, self.which),
                    steps: step,
                    converged: true,
                };
            }
            beta.push(b);
            for i in 0..n {
                q_prev[i] = q[i];
                q[i] = w[i] / b;
            }
            beta_prev = b;
        }
        beta.truncate(alpha.len().saturating_sub(1));
        Estimate {
            eigenvalue: tridiagonal_extreme(&alpha, &beta, self.which),
            steps: alpha.len(),
            converged: self.tolerance == 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bisection_finds_the_extremes_of_a_tridiagonal() {
        // the 1D Laplacian tridiag(-1, 2, -1) of size k: λ_j = 2 − 2cos(jπ/(k+1))
        let k = 50;
        let alpha = vec![2.0; k];
        let beta = vec![-1.0; k - 1];
        let pi = std::f64::consts::PI;
        let smallest = 2.0 - 2.0 * (pi / (k as f64 + 1.0)).cos();
        let largest = 2.0 - 2.0 * (k as f64 * pi / (k as f64 + 1.0)).cos();
        assert!((tridiagonal_extreme(&alpha, &beta, Extreme::Smallest) - smallest).abs() < 1e-12);
        assert!((tridiagonal_extreme(&alpha, &beta, Extreme::Largest) - largest).abs() < 1e-12);
    }

    #[test]
    fn lanczos_finds_both_ends_of_a_chain() {
        // a fixed–fixed chain of unit masses and springs: K = tridiag(-1, 2, -1) on 1D
        // "particles" embedded in 2D (y components held)
        let n = 200;
        let mass = vec![1.0; n];
        let constrained: Vec<[bool; 2]> = vec![[false, true]; n];
        let apply = |u: &[SVector<f64, 2>], out: &mut [SVector<f64, 2>]| {
            for i in 0..n {
                let l = if i > 0 { u[i - 1].x } else { 0.0 };
                let r = if i + 1 < n { u[i + 1].x } else { 0.0 };
                out[i] = SVector::<f64, 2>::new(2.0 * u[i].x - l - r, 0.0);
            }
        };
        let pi = std::f64::consts::PI;
        let exact_min = 2.0 - 2.0 * (pi / (n as f64 + 1.0)).cos();
        let exact_max = 2.0 - 2.0 * (n as f64 * pi / (n as f64 + 1.0)).cos();
        let run = |which, steps, tol| {
            Lanczos {
                mass: &mass,
                constrained: Some(&constrained),
                deflate: &[],
                which,
                tolerance: tol,
                max_steps: steps,
            }
            .run(apply)
        };
        let lo = run(Extreme::Smallest, 400, 1e-10);
        assert!(
            lo.converged && (lo.eigenvalue / exact_min - 1.0).abs() < 1e-6,
            "{lo:?} vs {exact_min}"
        );
        let hi = run(Extreme::Largest, 60, 0.0);
        assert!(
            hi.eigenvalue <= exact_max * (1.0 + 1e-12) && hi.eigenvalue > 0.99 * exact_max,
            "{hi:?}"
        );
    }
}
#[cfg(test)]
mod deflation_tests {
    use super::*;
    #[test]
    fn free_chain_with_translation_deflated() {
        let n = 100;
        let mass = vec![2.0; n];
        let apply = |u: &[SVector<f64, 1>], out: &mut [SVector<f64, 1>]| {
            for i in 0..n {
                let mut f = 0.0;
                if i > 0 {
                    f += u[i].x - u[i - 1].x;
                }
                if i + 1 < n {
                    f += u[i].x - u[i + 1].x;
                }
                out[i] = SVector::<f64, 1>::new(f);
            }
        };
        let g: Vec<SVector<f64, 1>> =
            vec![SVector::<f64, 1>::new(1.0 / (2.0 * n as f64).sqrt()); n];
        let modes = vec![g];
        let est = Lanczos {
            mass: &mass,
            constrained: None,
            deflate: &modes,
            which: Extreme::Smallest,
            tolerance: 0.0,
            max_steps: 150,
        }
        .run(apply);
        let exact = (2.0 - 2.0 * (std::f64::consts::PI / n as f64).cos()) / 2.0;
        println!("{est:?} exact {exact}");
        assert!((est.eigenvalue / exact - 1.0).abs() < 1e-6);
    }
}
