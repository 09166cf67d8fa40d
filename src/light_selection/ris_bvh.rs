//! Resampled selection over the light BVH (`ris-bvh`, `ris-bvh:K`; issue 19 item 2): the RIS
//! of `ris.rs` with its K candidates drawn by K walks of the light BVH (`bvh.rs`) instead of
//! the power alias table. The BVH already picks lights roughly ∝ their importance, but from
//! the conservative bounds of whole clusters at every level above the leaves; resampling its
//! candidates by the light's own importance p̂ (Φ·cos θ′/d²·cos θ′ᵢ of the light's bounds,
//! [`importance`](super::importance)) with weights w = p̂/q_bvh removes the error of those
//! cluster bounds, so as K grows the choice goes from `bvh` (K = 1 is exactly `bvh`'s
//! distribution) to `exhaustive`, at K BVH walks per selection.
//!
//! **The pmf (the same treatment as `ris`).** `sample` returns 1/W, the inverse of RIS's
//! contribution weight W = (1/p̂(y))·(1/K)·Σᵢ p̂(xᵢ)/q_bvh(xᵢ), where q_bvh is the BVH's exact
//! probability of the candidate (the product of its per-level probabilities, returned by the
//! walk itself). Dividing by it gives f(y)·W, and E[f(Y)·W] = Σₗ f(l) for every f that is zero
//! where p̂ or q_bvh is (Talbot et al. 2005; the candidates are i.i.d. from q_bvh, and a walk
//! that ends nowhere is a candidate of weight 0): the light estimator is **exactly unbiased**
//! (`tests/ris_selection.rs` checks it against the exhaustive sum). `pmf(ctx, l)`, which MIS
//! asks for when a BSDF ray hits light l, returns K·p̂(l) / (p̂(l)/q_bvh(l) + Σ of K − 1 fresh
//! candidates' w), the candidates hashed from the shading point: a deterministic function of
//! (point, light), so each BSDF-sampled path gets one fixed weight, but an *estimate* of the
//! light sample's 1/W, so the two MIS weights of a path sum to 1 only on average. Under MIS
//! `ris-bvh`, like `ris`, is therefore consistent, not exactly unbiased (the render test
//! measures it); with `--strategy light` it is unbiased. Exactly unbiased MIS would need the
//! integrator to MIS-weight the light sample with this deterministic `pmf` while dividing by
//! 1/W (a second number in `SelectedLight`).
//!
//! **Support.** A light is chosen only if the BVH can draw it (q_bvh > 0) and p̂ > 0; the BVH
//! keeps every light that can reach the receiver's upper hemisphere at q_bvh > 0 and p̂ is zero
//! only where the light cannot (`tests/many_selection.rs`), so every light that can contribute
//! keeps a non-zero probability. **Determinism:** the candidates' numbers come from a hash of
//! the sample number and the shading point (as in `ris`), never from a thread's state.

use super::bvh::BvhSelector;
use super::ris::{CandidateSource, Ris};
use super::{FiniteSelector, ShadingPoint};
use crate::lights::LightBounds;

/// Candidates per selection unless `ris-bvh:K` says otherwise (each is a BVH walk).
pub const DEFAULT_CANDIDATES: u32 = 4;

/// RIS over BVH-sampled candidates.
pub type RisBvhSelector = Ris<BvhSelector>;

impl CandidateSource for BvhSelector {
    #[inline]
    fn draw(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        FiniteSelector::sample(self, ctx, u)
    }
    #[inline]
    fn prob(&self, ctx: &ShadingPoint, l: u32) -> f32 {
        FiniteSelector::pmf(self, ctx, l)
    }
    #[inline]
    fn draw_many(&self, ctx: &ShadingPoint, us: &[f32], out: &mut [Option<(u32, f32)>]) {
        self.sample_many(ctx, us, out);
    }
}

impl RisBvhSelector {
    /// `k` candidates per selection from the light BVH over `bounds`.
    pub fn new(bounds: &[LightBounds], k: u32, seed: u64) -> Self {
        Ris::with_source(BvhSelector::new(bounds), bounds, k, seed).stratified(true)
    }
}
