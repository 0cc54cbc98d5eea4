//! Elastic constants and the values derived from them for the dampers (docs/model.md §5).
pub mod properties;

/// Bulk modulus κ = E/(3(1−2ν)) as the source uses it for the wave speed (3.57).
pub fn bulk_modulus(e: f64, nu: f64) -> f64 {
    e / (3.0 * (1.0 - 2.0 * nu))
}

/// Wave speed c̃ = √(κ/ρ) (3.57).
pub fn wave_speed(e: f64, nu: f64, rho: f64) -> f64 {
    (bulk_modulus(e, nu) / rho).sqrt()
}

/// Particle frequency ω_i = 2π·c̃/λ_i with λ ≈ 2·L0 for SPLM (section 4.3).
pub fn particle_frequency(e: f64, nu: f64, rho: f64, spacing: f64) -> f64 {
    2.0 * std::f64::consts::PI * wave_speed(e, nu, rho) / (2.0 * spacing)
}
