//! Probability ∝ emitted power Φ, from an alias table (O(1) sampling and pmf).

use super::{FiniteSelector, ShadingPoint};
use crate::lights::LightBounds;
use crate::sampling::AliasTable;

/// Power-proportional selection; falls back to uniform when no light has positive power.
#[derive(Clone, Debug)]
pub struct PowerSelector {
    table: Option<AliasTable>,
}

impl PowerSelector {
    /// A table over the powers of `bounds`.
    pub fn new(bounds: &[LightBounds]) -> Self {
        let phi: Vec<f32> = bounds.iter().map(|b| b.phi).collect();
        Self::from_weights(&phi)
    }

    /// A table ∝ `weights` (uniform if they are all zero); also used as the defensive
    /// component of the other strategies.
    pub fn from_weights(weights: &[f32]) -> Self {
        if weights.is_empty() {
            return Self { table: None };
        }
        let table = AliasTable::new(weights).or_else(|| AliasTable::new(&vec![1.0; weights.len()]));
        Self { table }
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.table.as_ref().map_or(0, |t| t.pmf.len())
    }

    /// True when there are no lights.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Pick a light (context-free).
    #[inline]
    pub fn pick(&self, u: f32) -> Option<(u32, f32)> {
        let (i, p) = self.table.as_ref()?.sample(u);
        Some((i as u32, p))
    }

    /// Probability of light `i` (context-free).
    #[inline]
    pub fn prob(&self, i: u32) -> f32 {
        self.table.as_ref().map_or(0.0, |t| t.pmf(i as usize))
    }
}

impl FiniteSelector for PowerSelector {
    fn sample(&self, _ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        self.pick(u)
    }

    fn pmf(&self, _ctx: &ShadingPoint, i: u32) -> f32 {
        self.prob(i)
    }
}
