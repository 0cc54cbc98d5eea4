//! The statistical size effect: sample statistics of the nominal strength per size, and the
//! two size-effect laws fitted to the Monte Carlo means (pure functions).
//!
//! - Bažant's type-1 size-effect law (Bažant 2004, "Scaling theory for quasibrittle structural
//!   failure", Eq. 3): σN = f_∞·(1 + r·D_b/D)^(1/r). With r = 1 (used here) it is linear in
//!   1/D, σN = f_∞ + f_∞·D_b·(1/D), and is fitted by linear least squares in 1/D.
//! - A Weibull power law: σN = σ_1·(D/1 m)^(−n_d/m), with n_d = 2 for geometrically similar 2D
//!   specimens (the stressed volume grows as D²); fitted by least squares in log–log, giving
//!   the Weibull modulus m = −n_d/slope.
//!
//! Both report the RMS of the relative residuals (σN,fit − σN)/σN over the sizes.

use serde::Serialize;

/// Mean, sample standard deviation (n − 1) and coefficient of variation of values.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Sample {
    pub n: usize,
    pub mean: f64,
    /// Sample standard deviation (divisor n − 1); NaN for n < 2.
    pub std: f64,
    /// std / mean.
    pub cov: f64,
}

/// The statistics of `values` (NaN mean for an empty sample).
pub fn sample(values: &[f64]) -> Sample {
    let n = values.len();
    let mean = values.iter().sum::<f64>() / n as f64;
    let std = if n < 2 {
        f64::NAN
    } else {
        (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
    };
    Sample {
        n,
        mean,
        std,
        cov: std / mean,
    }
}

/// Least-squares line y = a + b·x; `None` with fewer than two distinct x.
pub fn line_fit(x: &[f64], y: &[f64]) -> Option<(f64, f64)> {
    let n = x.len();
    if n < 2 || y.len() != n {
        return None;
    }
    let mx = x.iter().sum::<f64>() / n as f64;
    let my = y.iter().sum::<f64>() / n as f64;
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    if sxx <= f64::EPSILON * mx.abs().max(1.0).powi(2) * n as f64 {
        return None;
    }
    let b = sxy / sxx;
    Some((my - b * mx, b))
}

/// RMS of (fit − data)/data.
fn rms_relative(data: &[f64], fit: &[f64]) -> f64 {
    let s: f64 = data
        .iter()
        .zip(fit)
        .map(|(d, f)| ((f - d) / d).powi(2))
        .sum();
    (s / data.len() as f64).sqrt()
}

/// Bažant's type-1 size-effect law with r = 1: σN = f_∞·(1 + D_b/D).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct BazantFit {
    /// The exponent r of the law (1: linear least squares in 1/D).
    pub r: f64,
    /// Strength of an infinitely large specimen f_∞ (Pa).
    #[serde(rename = "f_inf_Pa")]
    pub f_inf_pa: f64,
    /// Boundary-layer thickness D_b (m).
    #[serde(rename = "D_b_m")]
    pub d_b_m: f64,
    pub rms_relative_residual: f64,
}

impl BazantFit {
    /// σN (Pa) at size `d` (m).
    pub fn sigma(&self, d: f64) -> f64 {
        self.f_inf_pa * (1.0 + self.r * self.d_b_m / d).powf(1.0 / self.r)
    }
}

/// Fit σN = f_∞ + f_∞·D_b·(1/D) to (D m, σN Pa) by least squares in 1/D; `None` with fewer
/// than two sizes or a non-positive intercept f_∞.
pub fn fit_bazant(d: &[f64], sigma: &[f64]) -> Option<BazantFit> {
    let x: Vec<f64> = d.iter().map(|v| 1.0 / v).collect();
    let (a, b) = line_fit(&x, sigma)?;
    if a <= 0.0 {
        return None;
    }
    let mut fit = BazantFit {
        r: 1.0,
        f_inf_pa: a,
        d_b_m: b / a,
        rms_relative_residual: 0.0,
    };
    let model: Vec<f64> = d.iter().map(|v| fit.sigma(*v)).collect();
    fit.rms_relative_residual = rms_relative(sigma, &model);
    Some(fit)
}

/// The Weibull power law σN = σ_1·(D/1 m)^(−n_d/m).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct WeibullFit {
    /// Dimension of geometric similarity n_d (2 for 2D specimens).
    pub n_d: f64,
    /// σN at D = 1 m (Pa).
    #[serde(rename = "sigma_1_Pa")]
    pub sigma_1_pa: f64,
    /// Slope of log σN against log D (= −n_d/m).
    pub slope: f64,
    /// Weibull modulus m = −n_d/slope (infinite or negative when σN does not fall with D).
    pub modulus: f64,
    pub rms_relative_residual: f64,
}

impl WeibullFit {
    /// σN (Pa) at size `d` (m).
    pub fn sigma(&self, d: f64) -> f64 {
        self.sigma_1_pa * d.powf(self.slope)
    }
}

/// Fit log σN = log σ_1 + slope·log D by least squares; m = −n_d/slope. `None` with fewer
/// than two sizes or a non-positive value.
pub fn fit_weibull(d: &[f64], sigma: &[f64], n_d: f64) -> Option<WeibullFit> {
    if d.iter().chain(sigma).any(|v| *v <= 0.0) {
        return None;
    }
    let x: Vec<f64> = d.iter().map(|v| v.ln()).collect();
    let y: Vec<f64> = sigma.iter().map(|v| v.ln()).collect();
    let (a, slope) = line_fit(&x, &y)?;
    let mut fit = WeibullFit {
        n_d,
        sigma_1_pa: a.exp(),
        slope,
        modulus: -n_d / slope,
        rms_relative_residual: 0.0,
    };
    let model: Vec<f64> = d.iter().map(|v| fit.sigma(*v)).collect();
    fit.rms_relative_residual = rms_relative(sigma, &model);
    Some(fit)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SIZES: [f64; 6] = [0.05, 0.1, 0.2, 0.4, 0.8, 1.6];

    #[test]
    fn sample_statistics_use_the_n_minus_1_divisor() {
        let s = sample(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(s.n, 4);
        assert!((s.mean - 2.5).abs() < 1e-15);
        // Σ(x − 2.5)² = 5, / 3
        assert!((s.std - (5.0f64 / 3.0).sqrt()).abs() < 1e-15);
        assert!((s.cov - s.std / 2.5).abs() < 1e-15);
        assert!(sample(&[3.0]).std.is_nan());
    }

    #[test]
    fn bazant_fit_recovers_the_law_it_was_sampled_from() {
        let (f_inf, d_b) = (2.1e6, 0.035);
        let sigma: Vec<f64> = SIZES.iter().map(|d| f_inf * (1.0 + d_b / d)).collect();
        let fit = fit_bazant(&SIZES, &sigma).unwrap();
        assert_eq!(fit.r, 1.0);
        assert!((fit.f_inf_pa / f_inf - 1.0).abs() < 1e-12, "{fit:?}");
        assert!((fit.d_b_m / d_b - 1.0).abs() < 1e-10, "{fit:?}");
        assert!(fit.rms_relative_residual < 1e-12);
        // with ±1% alternating noise the parameters move by about that much and the
        // residual reports it
        let noisy: Vec<f64> = sigma
            .iter()
            .enumerate()
            .map(|(k, s)| s * if k % 2 == 0 { 1.01 } else { 0.99 })
            .collect();
        let fit = fit_bazant(&SIZES, &noisy).unwrap();
        assert!((fit.f_inf_pa / f_inf - 1.0).abs() < 0.03, "{fit:?}");
        assert!(
            fit.rms_relative_residual > 0.005 && fit.rms_relative_residual < 0.012,
            "{fit:?}"
        );
    }

    #[test]
    fn weibull_fit_recovers_the_modulus() {
        let (s1, m) = (1.8e6, 12.0);
        let sigma: Vec<f64> = SIZES.iter().map(|d| s1 * d.powf(-2.0 / m)).collect();
        let fit = fit_weibull(&SIZES, &sigma, 2.0).unwrap();
        assert!((fit.modulus / m - 1.0).abs() < 1e-10, "{fit:?}");
        assert!((fit.sigma_1_pa / s1 - 1.0).abs() < 1e-12, "{fit:?}");
        assert!(fit.rms_relative_residual < 1e-12);
        assert!((fit.sigma(0.4) - s1 * 0.4f64.powf(-2.0 / m)).abs() < 1e-6);
    }

    #[test]
    fn fits_need_two_sizes() {
        assert!(fit_bazant(&[0.1], &[2e6]).is_none());
        assert!(fit_weibull(&[0.1, 0.1], &[2e6, 2.1e6], 2.0).is_none());
        assert!(fit_weibull(&[0.1, 0.2], &[2e6, -1.0], 2.0).is_none());
    }
}
