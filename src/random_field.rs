//! Random-field material properties (docs/model.md §12).
//!
//! A property such as f't, E or G_f is drawn per particle as `marginal.map(g(x))`, where g is a
//! standard Gaussian random field (mean 0, variance 1) with correlation ρ(r) and correlation
//! length ℓ, and the [`Marginal`] maps a standard normal value to a normal (truncated at zero),
//! lognormal or Weibull property with a given mean and coefficient of variation.
//!
//! # Discretisation independence
//! The field is generated on a regular grid of spacing h = ℓ/[`NODES_PER_LENGTH`] whose nodes
//! sit at integer multiples of h from the world origin; the node range is the box to cover,
//! snapped outwards to multiples of [`SNAP_NODES`] nodes. The grid, and so the value at a point,
//! therefore depends only on (correlation, ℓ, box, seed): a coarse, fine, rotated or offset
//! lattice filling the same body (same box) samples the same field. Values between nodes come
//! from bilinear interpolation plus a small point-hashed "sub-grid" term that restores the exact
//! unit variance (see [`GaussianField::value_at`]).
//!
//! # Generation: circulant embedding
//! The grid covariance (block Toeplitz) is embedded in a periodic (block circulant) one on an
//! m1 × m2 torus with m ≥ 2(n − 1) + 2·[`PAD_LENGTHS`]·ℓ/h per axis, rounded up to a 2·3·5-smooth
//! size for the FFT (rustfft). The eigenvalues λ are the 2D FFT of the first row; negative
//! eigenvalues are clipped to zero and their share of Σ|λ| is reported in [`EmbeddingInfo`].
//! With ξ = ξ1 + iξ2 (independent standard normals), Z = FFT(√(λ/M)·ξ) has Re Z with exactly the
//! target covariance on the torus (Dietrich & Newsam 1997; Wood & Chan 1994); the n1 × n2 corner
//! is the field.
//!
//! # Random numbers
//! ξ comes from `rand::rngs::ChaCha20Rng::seed_from_u64(seed)` (the ChaCha20 stream is fixed by
//! its specification, unlike `StdRng`, whose algorithm rand may change between versions), one
//! u64 per uniform (53 high bits), normals by the Box–Muller transform, drawn in row-major order
//! of the embedding grid. Per-point values (white noise for ℓ = 0 and the sub-grid term) come from
//! a SplitMix64 hash of (seed, tag, x, y) with x and y quantised to [`QUANTUM`] = 1e−9 m, so the
//! same point gives the same value whatever else is sampled.

use rand::rngs::ChaCha20Rng;
use rand::{Rng, SeedableRng};
use rustfft::num_complex::Complex;
use rustfft::FftPlanner;
use statrs::function::erf::{erfc, erfc_inv};
use statrs::function::gamma::gamma;
use std::f64::consts::{PI, SQRT_2};

/// Grid nodes per correlation length: h = ℓ/8. Bilinear interpolation of the exponential kernel
/// at h = ℓ/8 keeps ≥ 90% of the variance at a cell centre (≥ 98.5% for the squared
/// exponential); the rest is restored exactly by the sub-grid term. The covariance of the
/// interpolant between two points (evaluated exactly over random positions and directions) is
/// within 0.005 (exponential) and 0.009 (squared exponential) of ρ at lag ℓ/2, within 0.003 at
/// lag ℓ and 0.001 at 2ℓ; at lag h it is on average 0.016 (0.010) below ρ. Finer grids
/// cost h⁻² in memory for dog-bone F (1.6 m × 2.4 m at ℓ = 16 mm is 4.3·10⁶ embedding nodes at
/// h = ℓ/8, 17·10⁶ at ℓ/16).
pub const NODES_PER_LENGTH: usize = 8;
/// The box's node range is snapped outwards to multiples of this many nodes (2ℓ), so that boxes
/// that differ slightly (the body's outline or the particles of a coarse or fine lattice inside
/// it) usually give the same grid.
pub const SNAP_NODES: i64 = 16;
/// Extra embedding length per side, in correlation lengths, beyond the minimal 2(n − 1):
/// the correlation has decayed to e^−6 (exponential) at the wrap-around, which keeps the clipped
/// negative eigenvalues negligible (measured in the tests and in the report).
pub const PAD_LENGTHS: usize = 6;
/// Largest embedding grid (m1·m2 nodes): 2^25 complex f64 is 512 MiB plus the eigenvalues.
pub const MAX_EMBEDDING_NODES: usize = 1 << 25;
/// Coordinates are quantised to this step (m) before hashing a point.
pub const QUANTUM: f64 = 1e-9;

/// Errors from bad field or marginal parameters, each naming the parameter, its value and what
/// is allowed (the scene keys will be `random_field.<name>`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FieldError {
    #[error("{name} = {value}: {allowed}")]
    Parameter {
        name: &'static str,
        value: f64,
        allowed: &'static str,
    },
    #[error(
        "random field grid of {m1} × {m2} = {nodes} embedding nodes (h = {h} m for correlation \
         length {length} m over a box of {width} m × {height} m) exceeds the limit of {max} \
         nodes: use a larger correlation_length or a smaller body"
    )]
    TooLarge {
        m1: usize,
        m2: usize,
        nodes: usize,
        h: f64,
        length: f64,
        width: f64,
        height: f64,
        max: usize,
    },
    #[error("point ({x}, {y}) lies outside the random field's box [{x0}, {x1}] × [{y0}, {y1}] m")]
    Outside {
        x: f64,
        y: f64,
        x0: f64,
        x1: f64,
        y0: f64,
        y1: f64,
    },
}

fn bad(name: &'static str, value: f64, allowed: &'static str) -> FieldError {
    FieldError::Parameter {
        name,
        value,
        allowed,
    }
}

/// Correlation function ρ(r) of the Gaussian field (docs/model.md §12).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Correlation {
    /// ρ(r) = exp(−r/ℓ).
    Exponential,
    /// ρ(r) = exp(−(r/ℓ)²).
    SquaredExponential,
}

impl Correlation {
    /// ρ(r) for correlation length ℓ > 0.
    pub fn rho(self, r: f64, length: f64) -> f64 {
        match self {
            Correlation::Exponential => (-r / length).exp(),
            Correlation::SquaredExponential => (-(r / length).powi(2)).exp(),
        }
    }
}

/// How the periodic embedding came out: sizes and the clipped negative eigenvalues.
#[derive(Debug, Clone, PartialEq)]
pub struct EmbeddingInfo {
    /// Embedding (torus) size in nodes per axis.
    pub m: [usize; 2],
    /// Number of negative eigenvalues clipped to zero.
    pub negative_eigenvalues: usize,
    /// Σ|λ_negative| / Σ|λ|: the share of the spectrum that was clipped.
    pub clipped_fraction: f64,
    /// Most negative eigenvalue relative to the largest one (0 if none).
    pub min_eigenvalue_ratio: f64,
}

/// The grid of a correlated field: nodes at (i·h, j·h) for i in i0..i0+n1, j in j0..j0+n2.
#[derive(Debug, Clone)]
struct Grid {
    h: f64,
    i0: i64,
    j0: i64,
    n1: usize,
    n2: usize,
    values: Vec<f64>,
    /// ρ(h) and ρ(√2·h) for the variance of the bilinear interpolant.
    rho_h: f64,
    rho_diag: f64,
    info: EmbeddingInfo,
}

/// A standard Gaussian random field (mean 0, variance 1) over an axis-aligned box (docs/model.md §12).
#[derive(Debug, Clone)]
pub struct GaussianField {
    correlation: Correlation,
    length: f64,
    seed: u64,
    box_min: [f64; 2],
    box_max: [f64; 2],
    /// None for white noise (ℓ = 0).
    grid: Option<Grid>,
}

const TAG_WHITE: u64 = 0x5748_4954_455f_4e4f; // "WHITE_NO"
const TAG_SUBGRID: u64 = 0x5355_4247_5249_445f; // "SUBGRID_"

impl GaussianField {
    /// Generate the field covering `[box_min, box_max]` from `seed`. `length` = ℓ ≥ 0 (m);
    /// ℓ = 0 gives white noise (independent values at distinct points, no grid).
    pub fn new(
        correlation: Correlation,
        length: f64,
        box_min: [f64; 2],
        box_max: [f64; 2],
        seed: u64,
    ) -> Result<Self, FieldError> {
        if !length.is_finite() || length < 0.0 {
            return Err(bad(
                "correlation_length",
                length,
                "must be a finite length ≥ 0 m (0 = white noise)",
            ));
        }
        for (name, v) in [
            ("box_min.x", box_min[0]),
            ("box_min.y", box_min[1]),
            ("box_max.x", box_max[0]),
            ("box_max.y", box_max[1]),
        ] {
            if !v.is_finite() {
                return Err(bad(name, v, "must be a finite coordinate (m)"));
            }
        }
        if box_max[0] < box_min[0] {
            return Err(bad("box_max.x", box_max[0], "must be ≥ box_min.x"));
        }
        if box_max[1] < box_min[1] {
            return Err(bad("box_max.y", box_max[1], "must be ≥ box_min.y"));
        }
        let grid = if length == 0.0 {
            None
        } else {
            Some(Grid::generate(correlation, length, box_min, box_max, seed)?)
        };
        Ok(GaussianField {
            correlation,
            length,
            seed,
            box_min,
            box_max,
            grid,
        })
    }

    pub fn correlation(&self) -> Correlation {
        self.correlation
    }
    pub fn length(&self) -> f64 {
        self.length
    }
    pub fn seed(&self) -> u64 {
        self.seed
    }
    /// Grid spacing h (m); None for white noise.
    pub fn spacing(&self) -> Option<f64> {
        self.grid.as_ref().map(|g| g.h)
    }
    /// Grid nodes per axis covering the (snapped) box; None for white noise.
    pub fn nodes(&self) -> Option<[usize; 2]> {
        self.grid.as_ref().map(|g| [g.n1, g.n2])
    }
    /// Embedding sizes and clipped eigenvalues; None for white noise.
    pub fn embedding(&self) -> Option<&EmbeddingInfo> {
        self.grid.as_ref().map(|g| &g.info)
    }

    /// Value g(x) at a point inside the box. For ℓ > 0: the bilinear interpolant of the four
    /// surrounding nodes, Σ wₖ gₖ, whose variance v(x) = Σₖₗ wₖ wₗ ρ(|xₖ − xₗ|) is < 1 between
    /// nodes, plus √(1 − v(x))·ε(x) with ε a standard normal hashed from (seed, x) (a sub-grid
    /// "nugget"), so that the variance is exactly 1 everywhere and the covariance at lags beyond
    /// h is that of the interpolant. For ℓ = 0: ε(x) alone (white noise).
    pub fn value_at(&self, p: [f64; 2]) -> Result<f64, FieldError> {
        if !(p[0] >= self.box_min[0]
            && p[0] <= self.box_max[0]
            && p[1] >= self.box_min[1]
            && p[1] <= self.box_max[1])
        {
            return Err(FieldError::Outside {
                x: p[0],
                y: p[1],
                x0: self.box_min[0],
                x1: self.box_max[0],
                y0: self.box_min[1],
                y1: self.box_max[1],
            });
        }
        Ok(match &self.grid {
            None => hashed_normal(self.seed, TAG_WHITE, p),
            Some(g) => {
                let (value, var) = g.interpolate(p);
                let nugget = (1.0 - var).max(0.0);
                if nugget > 0.0 {
                    value + nugget.sqrt() * hashed_normal(self.seed, TAG_SUBGRID, p)
                } else {
                    value
                }
            }
        })
    }

    /// g at each point (see [`GaussianField::value_at`]); each value depends only on its point.
    pub fn sample(&self, points: &[[f64; 2]]) -> Result<Vec<f64>, FieldError> {
        points.iter().map(|&p| self.value_at(p)).collect()
    }
}

impl Grid {
    fn generate(
        correlation: Correlation,
        length: f64,
        box_min: [f64; 2],
        box_max: [f64; 2],
        seed: u64,
    ) -> Result<Grid, FieldError> {
        let h = length / NODES_PER_LENGTH as f64;
        let too_large = |m1: usize, m2: usize| FieldError::TooLarge {
            m1,
            m2,
            nodes: m1.saturating_mul(m2),
            h,
            length,
            width: box_max[0] - box_min[0],
            height: box_max[1] - box_min[1],
            max: MAX_EMBEDDING_NODES,
        };
        // node ranges snapped outwards; computed in f64 first so absurd ratios fail cleanly
        let range = |lo: f64, hi: f64| -> Option<(i64, usize)> {
            let a = (lo / h).floor();
            let b = (hi / h).ceil();
            let limit = 1e12;
            if a.abs() > limit || b.abs() > limit {
                return None;
            }
            let a = (a as i64).div_euclid(SNAP_NODES) * SNAP_NODES;
            let mut b = -((-(b as i64)).div_euclid(SNAP_NODES) * SNAP_NODES);
            if b <= a {
                b = a + SNAP_NODES;
            }
            Some((a, (b - a + 1) as usize))
        };
        let (Some((i0, n1)), Some((j0, n2))) =
            (range(box_min[0], box_max[0]), range(box_min[1], box_max[1]))
        else {
            return Err(too_large(usize::MAX, usize::MAX));
        };
        let pad = 2 * PAD_LENGTHS * NODES_PER_LENGTH;
        let m1 = smooth_size(2 * (n1 - 1) + pad);
        let m2 = smooth_size(2 * (n2 - 1) + pad);
        if m1.saturating_mul(m2) > MAX_EMBEDDING_NODES {
            return Err(too_large(m1, m2));
        }
        let m = m1 * m2;

        // first row of the block-circulant covariance on the torus
        let mut buf: Vec<Complex<f64>> = Vec::with_capacity(m);
        for k1 in 0..m1 {
            let d1 = k1.min(m1 - k1) as f64 * h;
            for k2 in 0..m2 {
                let d2 = k2.min(m2 - k2) as f64 * h;
                buf.push(Complex::new(
                    correlation.rho((d1 * d1 + d2 * d2).sqrt(), length),
                    0.0,
                ));
            }
        }
        let mut planner = FftPlanner::<f64>::new();
        fft2(&mut planner, &mut buf, m1, m2);

        let max_lambda = buf.iter().map(|c| c.re).fold(0.0, f64::max);
        let mut negative = 0usize;
        let mut neg_sum = 0.0;
        let mut abs_sum = 0.0;
        let mut min_lambda = 0.0f64;
        let mut rng = ChaCha20Rng::seed_from_u64(seed);
        for c in buf.iter_mut() {
            let lambda = c.re;
            abs_sum += lambda.abs();
            if lambda < 0.0 {
                negative += 1;
                neg_sum -= lambda;
                min_lambda = min_lambda.min(lambda);
            }
            let scale = (lambda.max(0.0) / m as f64).sqrt();
            let (x1, x2) = box_muller(uniform(&mut rng), uniform(&mut rng));
            *c = Complex::new(scale * x1, scale * x2);
        }
        fft2(&mut planner, &mut buf, m1, m2);

        let mut values = Vec::with_capacity(n1 * n2);
        for k1 in 0..n1 {
            for k2 in 0..n2 {
                values.push(buf[k1 * m2 + k2].re);
            }
        }
        Ok(Grid {
            h,
            i0,
            j0,
            n1,
            n2,
            values,
            rho_h: correlation.rho(h, length),
            rho_diag: correlation.rho(SQRT_2 * h, length),
            info: EmbeddingInfo {
                m: [m1, m2],
                negative_eigenvalues: negative,
                clipped_fraction: if abs_sum > 0.0 {
                    neg_sum / abs_sum
                } else {
                    0.0
                },
                min_eigenvalue_ratio: if max_lambda > 0.0 {
                    min_lambda / max_lambda
                } else {
                    0.0
                },
            },
        })
    }

    /// Bilinear interpolant at p and its variance under the target covariance.
    fn interpolate(&self, p: [f64; 2]) -> (f64, f64) {
        let s = p[0] / self.h - self.i0 as f64;
        let t = p[1] / self.h - self.j0 as f64;
        // the snapped box covers the field's box, so 0 ≤ s ≤ n1 − 1 up to rounding
        let a = (s.floor().max(0.0) as usize).min(self.n1 - 2);
        let b = (t.floor().max(0.0) as usize).min(self.n2 - 2);
        let fx = (s - a as f64).clamp(0.0, 1.0);
        let fy = (t - b as f64).clamp(0.0, 1.0);
        let w00 = (1.0 - fx) * (1.0 - fy);
        let w10 = fx * (1.0 - fy);
        let w01 = (1.0 - fx) * fy;
        let w11 = fx * fy;
        let at = |i: usize, j: usize| self.values[i * self.n2 + j];
        let value =
            w00 * at(a, b) + w10 * at(a + 1, b) + w01 * at(a, b + 1) + w11 * at(a + 1, b + 1);
        let var = w00 * w00
            + w10 * w10
            + w01 * w01
            + w11 * w11
            + 2.0 * self.rho_h * (w00 * w10 + w01 * w11 + w00 * w01 + w10 * w11)
            + 2.0 * self.rho_diag * (w00 * w11 + w10 * w01);
        (value, var)
    }
}

/// In-place unnormalised 2D DFT of a row-major m1 × m2 array.
fn fft2(planner: &mut FftPlanner<f64>, data: &mut [Complex<f64>], m1: usize, m2: usize) {
    planner.plan_fft_forward(m2).process(data);
    let mut t = vec![Complex::new(0.0, 0.0); data.len()];
    for i in 0..m1 {
        for j in 0..m2 {
            t[j * m1 + i] = data[i * m2 + j];
        }
    }
    planner.plan_fft_forward(m1).process(&mut t);
    for i in 0..m1 {
        for j in 0..m2 {
            data[i * m2 + j] = t[j * m1 + i];
        }
    }
}

/// Smallest 2·3·5-smooth even number ≥ n.
fn smooth_size(n: usize) -> usize {
    let mut m = n.max(2);
    loop {
        if m.is_multiple_of(2) {
            let mut r = m;
            for p in [2, 3, 5] {
                while r.is_multiple_of(p) {
                    r /= p;
                }
            }
            if r == 1 {
                return m;
            }
        }
        m += 1;
    }
}

/// Uniform in (0, 1] from the 53 high bits of one u64.
fn uniform(rng: &mut ChaCha20Rng) -> f64 {
    ((rng.next_u64() >> 11) + 1) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Two independent standard normals from two uniforms in (0, 1].
fn box_muller(u1: f64, u2: f64) -> (f64, f64) {
    let r = (-2.0 * u1.ln()).sqrt();
    let (s, c) = (2.0 * PI * u2).sin_cos();
    (r * c, r * s)
}

/// SplitMix64 finaliser (Steele, Lea & Flood 2014): a bijective 64-bit mix, the hash of every
/// seed derivation in sppm.
pub fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Standard normal hashed from (seed, tag, point quantised to [`QUANTUM`]).
fn hashed_normal(seed: u64, tag: u64, p: [f64; 2]) -> f64 {
    let qx = (p[0] / QUANTUM).round() as i64 as u64;
    let qy = (p[1] / QUANTUM).round() as i64 as u64;
    let h = splitmix64(splitmix64(splitmix64(seed ^ tag) ^ qx) ^ qy);
    let u = |k: u64| ((splitmix64(h ^ k) >> 11) + 1) as f64 * (1.0 / (1u64 << 53) as f64);
    box_muller(u(1), u(2)).0
}

/// Standard normal CDF Φ(x).
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * erfc(-x / SQRT_2)
}

/// Inverse standard normal CDF Φ⁻¹(p), p in (0, 1).
pub fn normal_quantile(p: f64) -> f64 {
    -SQRT_2 * erfc_inv(2.0 * p)
}

/// Marginal distribution of a property, mapping a standard normal g to the property value by
/// matching probabilities, value = F⁻¹(Φ(g)) (docs/model.md §12). Build with the checked
/// constructors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Marginal {
    /// Normal with parent mean μ and CoV (σ = CoV·μ), truncated to [0, ∞): value =
    /// μ + σ·Φ⁻¹(Φ(a) + Φ(g)(1 − Φ(a))) with a = −1/CoV. `mean` and `cov` are those of the
    /// untruncated parent; the truncated mean is μ + σφ(a)/(1 − Φ(a)), relatively larger by
    /// 4.6·10⁻⁴ at CoV 0.3 and 3.0·10⁻⁷ at CoV 0.2 ([`Marginal::truncated_normal_mean`]).
    Normal { mean: f64, cov: f64 },
    /// Lognormal with exact mean and CoV: value = exp(μ_ln + σ_ln·g), σ_ln² = ln(1 + CoV²),
    /// μ_ln = ln(mean) − σ_ln²/2.
    LogNormal { mean: f64, cov: f64 },
    /// Weibull with modulus (shape) m and scale λ = mean/Γ(1 + 1/m): value =
    /// λ(−ln(1 − Φ(g)))^{1/m}, computed with 1 − Φ(g) = Φ(−g).
    Weibull { modulus: f64, scale: f64 },
}

fn check_mean(mean: f64) -> Result<(), FieldError> {
    if mean.is_finite() && mean > 0.0 {
        Ok(())
    } else {
        Err(bad("mean", mean, "must be finite and > 0"))
    }
}

fn check_cov(cov: f64) -> Result<(), FieldError> {
    if cov.is_finite() && cov >= 0.0 {
        Ok(())
    } else {
        Err(bad(
            "cov",
            cov,
            "must be finite and ≥ 0 (0 = deterministic)",
        ))
    }
}

/// Smallest Weibull modulus accepted (CoV ≈ 4.5·10⁴ there); below it Γ(1 + 2/m) overflows.
pub const WEIBULL_MIN_MODULUS: f64 = 0.1;
/// Largest Weibull modulus used (CoV ≈ 1.3·10⁻⁴); CoV = 0 gives the deterministic mean.
pub const WEIBULL_MAX_MODULUS: f64 = 1e4;

/// CoV of a Weibull distribution of modulus m: √(Γ(1+2/m)/Γ(1+1/m)² − 1).
pub fn weibull_cov(modulus: f64) -> f64 {
    let g1 = gamma(1.0 + 1.0 / modulus);
    let g2 = gamma(1.0 + 2.0 / modulus);
    (g2 / (g1 * g1) - 1.0).max(0.0).sqrt()
}

impl Marginal {
    /// Normal truncated at zero; `mean` and `cov` of the untruncated parent.
    pub fn normal(mean: f64, cov: f64) -> Result<Self, FieldError> {
        check_mean(mean)?;
        check_cov(cov)?;
        Ok(Marginal::Normal { mean, cov })
    }

    /// Lognormal with exact mean and CoV.
    pub fn lognormal(mean: f64, cov: f64) -> Result<Self, FieldError> {
        check_mean(mean)?;
        check_cov(cov)?;
        Ok(Marginal::LogNormal { mean, cov })
    }

    /// Weibull with exact mean and CoV: the modulus m solves CoV = √(Γ(1+2/m)/Γ(1+1/m)² − 1)
    /// (bisection in ln m; the CoV falls monotonically with m). CoV = 0 is the deterministic
    /// mean (modulus +∞).
    pub fn weibull(mean: f64, cov: f64) -> Result<Self, FieldError> {
        check_mean(mean)?;
        check_cov(cov)?;
        if cov == 0.0 {
            return Ok(Marginal::Weibull {
                modulus: f64::INFINITY,
                scale: mean,
            });
        }
        let (lo_cov, hi_cov) = (
            weibull_cov(WEIBULL_MAX_MODULUS),
            weibull_cov(WEIBULL_MIN_MODULUS),
        );
        if cov < lo_cov || cov > hi_cov {
            return Err(bad(
                "cov",
                cov,
                "for a Weibull marginal must be 0 or within [1.3e-4, 4.5e4] (modulus 1e4 to 0.1)",
            ));
        }
        let (mut lo, mut hi) = (WEIBULL_MIN_MODULUS.ln(), WEIBULL_MAX_MODULUS.ln());
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if weibull_cov(mid.exp()) > cov {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Self::weibull_modulus(mean, (0.5 * (lo + hi)).exp())
    }

    /// Weibull by modulus m and mean.
    pub fn weibull_modulus(mean: f64, modulus: f64) -> Result<Self, FieldError> {
        check_mean(mean)?;
        if !(modulus.is_finite() && modulus >= WEIBULL_MIN_MODULUS) {
            return Err(bad("modulus", modulus, "must be finite and ≥ 0.1"));
        }
        Ok(Marginal::Weibull {
            modulus,
            scale: mean / gamma(1.0 + 1.0 / modulus),
        })
    }

    /// Mean of the distribution the samples follow (the truncated one for `Normal`).
    pub fn mean(&self) -> f64 {
        match *self {
            Marginal::Normal { mean, cov } => Self::truncated_normal_mean(mean, cov),
            Marginal::LogNormal { mean, .. } => mean,
            Marginal::Weibull { modulus, scale } => {
                if modulus.is_infinite() {
                    scale
                } else {
                    scale * gamma(1.0 + 1.0 / modulus)
                }
            }
        }
    }

    /// Mean μ + σφ(a)/(1 − Φ(a)), a = −1/CoV, of a normal(μ, CoV·μ) truncated to [0, ∞).
    pub fn truncated_normal_mean(mean: f64, cov: f64) -> f64 {
        if cov == 0.0 {
            return mean;
        }
        let sigma = cov * mean;
        let a = -1.0 / cov;
        let phi = (-0.5 * a * a).exp() / (2.0 * PI).sqrt();
        mean + sigma * phi / normal_cdf(-a)
    }

    /// The property value for a standard normal g.
    pub fn map(&self, g: f64) -> f64 {
        match *self {
            Marginal::Normal { mean, cov } => {
                if cov == 0.0 {
                    return mean;
                }
                let sigma = cov * mean;
                let a = -1.0 / cov;
                let pa = normal_cdf(a);
                // work in the tail that keeps precision
                let z = if g <= 0.0 {
                    normal_quantile(pa + normal_cdf(g) * (1.0 - pa))
                } else {
                    -normal_quantile(normal_cdf(-g) * (1.0 - pa))
                };
                (mean + sigma * z).max(0.0)
            }
            Marginal::LogNormal { mean, cov } => {
                let s2 = (1.0 + cov * cov).ln();
                (mean.ln() - 0.5 * s2 + s2.sqrt() * g).exp()
            }
            Marginal::Weibull { modulus, scale } => {
                if modulus.is_infinite() {
                    return scale;
                }
                // −ln(1 − Φ(g)) = −ln Φ(−g)
                scale * (-normal_cdf(-g).ln()).powf(1.0 / modulus)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_sizes() {
        assert_eq!(smooth_size(7), 8);
        assert_eq!(smooth_size(31), 32);
        assert_eq!(smooth_size(33), 36);
        assert_eq!(smooth_size(121), 128);
    }

    #[test]
    fn quantile_inverts_cdf() {
        for x in [-7.0, -3.0, -0.5, 0.0, 0.7, 2.0, 5.0] {
            let p = normal_cdf(x);
            assert!(
                (normal_quantile(p) - x).abs() < 1e-9 * (1.0 + x.abs()),
                "{x}"
            );
        }
    }
}
