//! The yardstick: at every shading point, the [`importance`] of every light, sampled by a linear
//! scan. O(N) per sample and per pmf query — only for measuring how close the fast strategies
//! come to "the best a bound-based selector can do".

use super::{FiniteSelector, ShadingPoint, importance};
use crate::lights::LightBounds;

/// Per-shading-point selection ∝ the conservative importance of each light.
#[derive(Clone, Debug)]
pub struct ExhaustiveSelector {
    bounds: Vec<LightBounds>,
}

impl ExhaustiveSelector {
    /// Selector over `bounds`.
    pub fn new(bounds: &[LightBounds]) -> Self {
        Self {
            bounds: bounds.to_vec(),
        }
    }

    /// Sum of the importances at `ctx` (f64: a million terms of very different size).
    fn total(&self, ctx: &ShadingPoint) -> f64 {
        self.bounds
            .iter()
            .map(|b| importance(ctx.p, ctx.n, b) as f64)
            .sum()
    }
}

impl FiniteSelector for ExhaustiveSelector {
    fn sample(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        let total = self.total(ctx);
        if (total.is_nan() || total <= 0.0) || !total.is_finite() {
            return None;
        }
        let target = u as f64 * total;
        let mut acc = 0.0f64;
        let mut last = None;
        for (i, b) in self.bounds.iter().enumerate() {
            let w = importance(ctx.p, ctx.n, b) as f64;
            if w <= 0.0 {
                continue;
            }
            acc += w;
            last = Some((i as u32, w));
            if target < acc {
                break;
            }
        }
        // Rounding may leave `target` beyond the last sum: take the last positive light.
        last.map(|(i, w)| (i, (w / total) as f32))
    }

    fn pmf(&self, ctx: &ShadingPoint, i: u32) -> f32 {
        let Some(b) = self.bounds.get(i as usize) else {
            return 0.0;
        };
        let w = importance(ctx.p, ctx.n, b) as f64;
        if w <= 0.0 {
            return 0.0;
        }
        (w / self.total(ctx)) as f32
    }
}
