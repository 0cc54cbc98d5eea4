//! Is a spread of per-angle means real, or what the number of realisations alone produces?
//!
//! The objectivity study on random particles compares the means of the peak force and the
//! energy at each rotation. Each mean carries the scatter of its realisations: with a CoV
//! of c over n realisations per angle, the means of four angles spread by about
//! 2.06·c/√n (the expected range of four normal samples) even when the model does not
//! depend on the angle at all. So a spread of means says nothing unless it is set against
//! that noise.
//!
//! The test is a permutation test of the angle labels: under "the result does not depend on
//! the angle", every assignment of the observed values to the angles (keeping each angle's
//! number of runs) is equally likely. The p-value is the share of random assignments whose
//! spread of means, (max − min)/mean, is at least the observed one; the expected spread is
//! their mean. A small p (say below 0.05) says the angles differ; a large p says the spread
//! is within what this many realisations produce. No distribution is assumed. The shuffles
//! come from the study's seed, so the report is reproducible.

use rand::rngs::ChaCha20Rng;
use rand::{RngExt, SeedableRng};
use serde::Serialize;

/// Random assignments drawn for the p-value.
pub const PERMUTATIONS: usize = 10_000;

/// The angle effect of one quantity.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AngleEffect {
    /// (max − min)/mean of the per-angle means.
    pub spread_of_means: f64,
    /// The mean of that spread over random assignments of the values to the angles: what the
    /// realisations' scatter alone gives.
    pub expected_spread_without_angle_effect: f64,
    /// Share of random assignments with a spread of means at least the observed one,
    /// (count + 1)/(permutations + 1).
    pub p_value: f64,
    pub permutations: usize,
}

/// (max − min)/`mean` of the means of the consecutive groups of `sizes` in `values` (`mean`:
/// the mean of all values, which no assignment changes).
fn spread_of_means(values: &[f64], sizes: &[usize], mean: f64) -> f64 {
    let (mut hi, mut lo, mut start) = (f64::MIN, f64::MAX, 0);
    for &n in sizes {
        let m = values[start..start + n].iter().sum::<f64>() / n as f64;
        (hi, lo) = (hi.max(m), lo.min(m));
        start += n;
    }
    (hi - lo) / mean
}

/// The angle effect of `groups` (one group of finite values per angle), from `seed`;
/// `None` with fewer than two groups, a group with fewer than two values, or a mean of 0.
pub fn angle_effect(groups: &[Vec<f64>], seed: u64) -> Option<AngleEffect> {
    if groups.len() < 2 || groups.iter().any(|g| g.len() < 2) {
        return None;
    }
    let sizes: Vec<usize> = groups.iter().map(Vec::len).collect();
    let mut values: Vec<f64> = groups.iter().flatten().cloned().collect();
    if values.iter().any(|v| !v.is_finite()) || values.iter().sum::<f64>() == 0.0 {
        return None;
    }
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    let observed = spread_of_means(&values, &sizes, mean);
    let mut rng = ChaCha20Rng::seed_from_u64(seed);
    let (mut at_least, mut sum) = (0usize, 0.0);
    for _ in 0..PERMUTATIONS {
        // Fisher–Yates
        for i in (1..values.len()).rev() {
            let j = rng.random_range(0..=i);
            values.swap(i, j);
        }
        let s = spread_of_means(&values, &sizes, mean);
        sum += s;
        // a relative tolerance, so that an assignment equal to the observed one counts
        if s >= observed * (1.0 - 1e-12) {
            at_least += 1;
        }
    }
    Some(AngleEffect {
        spread_of_means: observed,
        expected_spread_without_angle_effect: sum / PERMUTATIONS as f64,
        p_value: (at_least + 1) as f64 / (PERMUTATIONS + 1) as f64,
        permutations: PERMUTATIONS,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Standard normal draws (Box–Muller) from a seeded stream.
    fn normals(rng: &mut ChaCha20Rng, n: usize, mean: f64, sd: f64) -> Vec<f64> {
        (0..n)
            .map(|_| {
                let u1: f64 = 1.0 - rng.random::<f64>();
                let u2: f64 = rng.random::<f64>();
                mean + sd * (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
            })
            .collect()
    }

    #[test]
    fn separated_groups_are_an_angle_effect() {
        // two angles of five runs each, 1.0 ± 0.01 and 2.0 ± 0.01: of the C(10, 5) = 252
        // assignments only the observed one and its mirror reach the observed spread, so
        // p ≈ 2/252 = 0.008
        let a = vec![0.99, 1.0, 1.01, 1.005, 0.995];
        let b: Vec<f64> = a.iter().map(|v| v + 1.0).collect();
        let e = angle_effect(&[a, b], 7).unwrap();
        assert!((e.spread_of_means - 1.0 / 1.5).abs() < 1e-12, "{e:?}");
        assert!(e.p_value < 0.02, "{e:?}");
        assert!(e.p_value > 0.002, "{e:?}");
    }

    #[test]
    fn the_test_has_its_nominal_size_without_an_angle_effect() {
        // four angles of 20 runs from one distribution (CoV 19%, as the tension block's
        // energy): p < 0.05 in about 5% of the studies (binomial: 200 studies, 10 ± 3.1),
        // and the expected spread near 2.06·0.19/√20 = 8.8% (the mean range of four normal
        // samples, in units of their standard deviation, is 2.059)
        let mut rng = ChaCha20Rng::seed_from_u64(1);
        let mut rejected = 0;
        let mut expected = 0.0;
        for s in 0..200 {
            let groups: Vec<Vec<f64>> = (0..4).map(|_| normals(&mut rng, 20, 1.0, 0.19)).collect();
            let e = angle_effect(&groups, s).unwrap();
            rejected += (e.p_value < 0.05) as usize;
            expected += e.expected_spread_without_angle_effect / 200.0;
        }
        assert!((2..=20).contains(&rejected), "{rejected} of 200 below 0.05");
        let theory = 2.059 * 0.19 / 20f64.sqrt();
        assert!(
            (expected / theory - 1.0).abs() < 0.1,
            "{expected} vs {theory}"
        );
    }

    #[test]
    fn too_few_runs_have_no_test() {
        assert_eq!(angle_effect(&[vec![1.0, 2.0]], 1), None);
        assert_eq!(angle_effect(&[vec![1.0, 2.0], vec![3.0]], 1), None);
        assert_eq!(
            angle_effect(&[vec![1.0, f64::NAN], vec![3.0, 4.0]], 1),
            None
        );
    }

    #[test]
    fn the_same_seed_gives_the_same_report() {
        let g = vec![
            vec![1.0, 1.2, 0.9],
            vec![1.1, 0.8, 1.3],
            vec![1.0, 1.05, 0.95],
        ];
        assert_eq!(angle_effect(&g, 3), angle_effect(&g, 3));
    }
}
