//! Bond stretch (docs/model.md §2).

/// Total stretch S_T = (L − L0)/L0 (3.10), written with 1/L0 precomputed.
#[inline(always)]
pub fn total_stretch(length: f64, inv_l0: f64) -> f64 {
    length * inv_l0 - 1.0
}
