//! Piecewise-constant 2D distribution on [0,1)², sampled by marginal + conditional inversion
//! (the lecture's multidimensional inversion). Used by environment maps: the caller supplies the
//! sin θ weighting. TODO(issue 2): implement.

use glam::Vec2;

/// 2D piecewise-constant distribution over an nu × nv grid (row-major: v rows of u columns).
#[derive(Clone, Debug)]
pub struct Distribution2D {
    /// One conditional distribution over u per row v.
    pub conditional: Vec<super::Distribution1D>,
    /// Marginal distribution over rows v.
    pub marginal: super::Distribution1D,
}

impl Distribution2D {
    /// Build from `f[v * nu + u]` (non-negative).
    pub fn new(f: &[f32], nu: usize, nv: usize) -> Self {
        let _ = (f, nu, nv);
        todo!("issue 2")
    }
    /// Sample (u, v) ∈ [0,1)² and its pdf with respect to area in [0,1)².
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let _ = u;
        todo!("issue 2")
    }
    /// Pdf at a point of [0,1)².
    pub fn pdf(&self, p: Vec2) -> f32 {
        let _ = p;
        todo!("issue 2")
    }
}
