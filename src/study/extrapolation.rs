//! Richardson extrapolation of a quantity computed at three lattice spacings, with a
//! general refinement ratio: f(h) = f0 + C·h^p. The observed order p solves
//! (h1^p − h2^p)/(h2^p − h3^p) = (f1 − f2)/(f2 − f3) for h1 > h2 > h3; then
//! C = (f2 − f3)/(h2^p − h3^p) and f0 = f3 − C·h3^p. When the differences change sign
//! (oscillatory convergence) or no positive p fits, the order is undefined and the
//! reference is the finest value.

use serde::Serialize;

/// The extrapolated reference of one quantity.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Richardson {
    /// Extrapolated value f0 (the finest value when the order is undefined).
    pub reference: f64,
    /// Observed order p, if defined.
    pub order: Option<f64>,
    /// How the reference was obtained ("richardson", or why the order is undefined).
    pub note: String,
}

fn undefined(reference: f64, note: &str) -> Richardson {
    Richardson {
        reference,
        order: None,
        note: note.into(),
    }
}

/// Extrapolate from spacings `h` (strictly decreasing, positive: coarse to fine) and values `f`.
pub fn richardson(h: [f64; 3], f: [f64; 3]) -> Richardson {
    let finest = f[2];
    if !(h[0] > h[1] && h[1] > h[2] && h[2] > 0.0) || f.iter().any(|v| !v.is_finite()) {
        return undefined(
            finest,
            "order undefined: needs three finite values at strictly decreasing spacings",
        );
    }
    let d1 = f[0] - f[1];
    let d2 = f[1] - f[2];
    if d1 == 0.0 && d2 == 0.0 {
        return undefined(finest, "order undefined: the three values are equal");
    }
    if d2 == 0.0 || d1 * d2 < 0.0 || d1 == 0.0 {
        return undefined(
            finest,
            "order undefined: the differences change sign (oscillatory); reference = finest value",
        );
    }
    let target = d1 / d2;
    // work with spacings relative to the finest, so that h^p stays well scaled
    let (r1, r2) = (h[0] / h[2], h[1] / h[2]);
    let ratio = |p: f64| (r1.powf(p) - r2.powf(p)) / (r2.powf(p) - 1.0);
    // ratio(p) rises from ln(r1/r2)/ln(r2) at p → 0 without bound
    let (mut lo, mut hi) = (1e-9, 64.0);
    if !(ratio(lo) < target && target < ratio(hi)) {
        return undefined(
            finest,
            "order undefined: no positive order fits the differences; reference = finest value",
        );
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if ratio(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let p = 0.5 * (lo + hi);
    let c = d2 / (h[1].powf(p) - h[2].powf(p));
    Richardson {
        reference: f[2] - c * h[2].powf(p),
        order: Some(p),
        note: "richardson".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(f0: f64, c: f64, p: f64, h: [f64; 3]) -> [f64; 3] {
        h.map(|h| f0 + c * h.powf(p))
    }

    #[test]
    fn recovers_first_order_at_ratio_two() {
        let h = [0.01, 0.005, 0.0025];
        let r = richardson(h, model(2.0e5, 3.0e6, 1.0, h));
        assert!((r.order.unwrap() - 1.0).abs() < 1e-9, "{r:?}");
        assert!((r.reference / 2.0e5 - 1.0).abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn recovers_second_order_at_a_non_uniform_ratio() {
        let h = [0.016, 0.01, 0.004];
        let r = richardson(h, model(14.5e3, -2.0e7, 2.0, h));
        assert!((r.order.unwrap() - 2.0).abs() < 1e-9, "{r:?}");
        assert!((r.reference / 14.5e3 - 1.0).abs() < 1e-12, "{r:?}");
        // a fractional order, decreasing towards the limit
        let r = richardson(h, model(80.0, 5.0e2, 1.4, h));
        assert!((r.order.unwrap() - 1.4).abs() < 1e-9, "{r:?}");
        assert!((r.reference / 80.0 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn oscillatory_differences_leave_the_order_undefined() {
        let r = richardson([0.01, 0.005, 0.0025], [100.0, 104.0, 102.0]);
        assert_eq!(r.order, None);
        assert_eq!(r.reference, 102.0);
        assert!(r.note.contains("oscillatory"), "{}", r.note);
    }

    #[test]
    fn differences_too_slow_for_a_positive_order_are_refused() {
        // uniform ratio 2: d1/d2 = 2^p; d1/d2 = 0.5 would need p = −1
        let r = richardson([0.01, 0.005, 0.0025], [100.0, 101.0, 103.0]);
        assert_eq!(r.order, None);
        assert_eq!(r.reference, 103.0);
        assert!(r.note.contains("no positive order"), "{}", r.note);
    }
}
