//! Floating-point error bounds (Higham's γ) used to offset spawned rays conservatively.

/// Machine epsilon of f32 rounding (half an ulp of 1).
pub const MACHINE_EPSILON: f32 = f32::EPSILON * 0.5;

/// γ(n) = n·ε / (1 − n·ε): bound on the relative error of n chained f32 operations.
#[inline]
pub const fn gamma(n: i32) -> f32 {
    let ne = n as f32 * MACHINE_EPSILON;
    ne / (1.0 - ne)
}
