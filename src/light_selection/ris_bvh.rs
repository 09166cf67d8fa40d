//! Resampled selection over the light BVH (`ris-bvh`, `ris-bvh:K`; issue 19 item 2): the RIS
//! of `ris.rs` with its K candidates drawn by walks of the light BVH (`bvh.rs`) instead of the
//! power alias table. The BVH already picks lights roughly ∝ their importance, but from the
//! conservative bounds of whole clusters at every level above the leaves; resampling its
//! candidates by the light's own importance p̂ (Φ·cos θ′/d²·cos θ′ᵢ of the light's bounds, the
//! [`importance`](super::importance) formula as the BVH's leaf lane computes it: the walk
//! returns it, so it costs no second evaluation and no access to the light's bounds) with
//! weights w = p̂/q_bvh removes the error of those cluster bounds, so as K grows the choice
//! goes from `bvh` (K = 1 has exactly `bvh`'s pmf) to `exhaustive`.
//!
//! **Stratified** ([`Ris::stratified`]): candidate i is the BVH's choice for (i + o)/K, one per
//! stratum of the BVH's sample space, and the final choice inverts the running sum of w over
//! the candidates with a second number; o and that number are the even and odd bits of the
//! sample number u, so a pixel's stratified u reaches both (hashed i.i.d. numbers, as `ris`
//! uses, lose the stratification that makes `bvh` itself 2.6× better at 8 spp). The K walks
//! go in ascending order through [`BvhSelector::sample_many`], which scores a node once while
//! consecutive walks pass through it.
//!
//! **The pmf (the same treatment as `ris`).** `sample` returns 1/W, the inverse of RIS's
//! contribution weight W = (1/p̂(y))·(1/K)·Σᵢ p̂(xᵢ)/q_bvh(xᵢ), where q_bvh is the BVH's exact
//! probability of the candidate (the product of its per-level probabilities). Dividing by it
//! gives f(y)·W, and E[f(Y)·W | candidates] = (1/K)·Σᵢ f(xᵢ)/q_bvh(xᵢ), the stratified
//! estimator of Σₗ f(l) for every f that is zero where p̂ or q_bvh is (Talbot et al. 2005; a
//! walk that ends nowhere is a candidate of weight 0): the light estimator is **exactly
//! unbiased** (`tests/ris_selection.rs` checks it against the exhaustive sum, and the choices
//! by chi² against the RIS probability integrated over the offset). `pmf(ctx, l)`, the
//! deterministic pmf both MIS weights use (`ris.rs` says why they must share one), is the
//! BVH's own q_bvh(l): it already follows the lights' importance, so weights with it left the
//! relMSE within 4 % of RIS's estimated probability on many-rooms, many-open and many-mesh,
//! which would cost K − 1 more walks per light sample. MIS with `ris-bvh` is exactly unbiased
//! (`integrator/mis_tests.rs`).
//!
//! **Support.** A light is chosen only if the BVH can draw it (q_bvh > 0) and p̂ > 0; the BVH
//! keeps every light that can reach the receiver's upper hemisphere at q_bvh > 0, p̂ is zero
//! only where the light cannot, and the hashed bits below 2^-12 of the candidates' offset
//! leave no gap in the BVH's sample space, so every light that can contribute keeps a
//! non-zero probability. **Determinism:** every number comes from u and a hash of u and the
//! shading point, never from a thread's state (same image on 1 and 2 threads: tested).

use super::bvh::BvhSelector;
use super::ris::{CandidateSource, Drawn, Ris};
use super::{FiniteSelector, ShadingPoint};
use crate::lights::LightBounds;

/// Candidates per selection unless `ris-bvh:K` says otherwise (each is a BVH walk).
pub const DEFAULT_CANDIDATES: u32 = 4;

/// RIS over BVH-sampled candidates.
pub type RisBvhSelector = Ris<BvhSelector>;

impl CandidateSource for BvhSelector {
    // The BVH's q already follows the lights' importance: MIS weights with it left relMSE
    // within 4 % of the estimate's (which costs K − 1 more walks, +60 % per selection).
    const MIS_BY_SOURCE: bool = true;
    #[inline]
    fn draw(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        FiniteSelector::sample(self, ctx, u)
    }
    #[inline]
    fn prob(&self, ctx: &ShadingPoint, l: u32) -> f32 {
        FiniteSelector::pmf(self, ctx, l)
    }
    #[inline]
    fn draw_many(&self, ctx: &ShadingPoint, us: &[f32], out: &mut [Drawn]) {
        // The walks' own score of the light at its leaf is the target: no second importance
        // and no random access to the light's bounds per candidate.
        let mut walked = [None; 16];
        for (us, out) in us.chunks(16).zip(out.chunks_mut(16)) {
            let walked = &mut walked[..us.len()];
            self.sample_many(ctx, us, walked);
            for (o, w) in out.iter_mut().zip(walked.iter()) {
                *o = w.map(|(l, q, t)| (l, q, Some(t)));
            }
        }
    }
    #[inline]
    fn prob_and_target(&self, ctx: &ShadingPoint, l: u32) -> (f32, Option<f32>) {
        let (q, t) = self.pmf_and_importance(ctx, l);
        (q, Some(t))
    }
}

impl RisBvhSelector {
    /// `k` candidates per selection from the light BVH over `bounds`.
    pub fn new(bounds: &[LightBounds], k: u32, seed: u64) -> Self {
        Ris::with_source(BvhSelector::new(bounds), bounds, k, seed).stratified(true)
    }
}
