//! Resampled importance sampling of lights (Talbot et al. 2005; the light-selection half of
//! ReSTIR, Bitterli et al. 2020): draw K candidate lights from a cheap source (the power alias
//! table), weight each by its target p̂ over its source probability, w = p̂/q, and keep one
//! ∝ w. The target is the light's unshadowed contribution as its bounds predict it — the
//! [`importance`] Φ·cos θ′/d²·cos θ′ᵢ, i.e. Le·G with a Lambertian f (the selector does not see
//! the BSDF) — so as K grows the choice approaches `exhaustive` at O(K) per sample.
//!
//! **The pmf.** The probability that RIS returns a light is an expectation over the other
//! candidates and has no closed form. `sample` therefore returns, as its `pmf`, the inverse of
//! RIS's *contribution weight* W = (1/p̂(y))·(1/K)·Σᵢ wᵢ: with it the light estimator
//! f(y)·W is exactly unbiased (E[g(Y)·W] = Σₗ g(l) for every g that is zero where p̂ is;
//! `tests/ris_selection.rs` checks this against the exhaustive sum). MIS needs more: the weight
//! of a light sample and the weight a BSDF ray reaching the same light gets must sum to 1 for
//! every direction, so both must use one *deterministic* pmf of (point, light) — 1/W is random,
//! and weighting with it made the sum off by up to 0.63 (a bias, `integrator/mis_tests.rs`).
//! That pmf is [`FiniteSelector::pmf`], and `sample_mis_at` returns it beside 1/W
//! ([`crate::light_selection::SelectedLight::mis_pmf`]); since the light estimate g·W is
//! unbiased for *any* g, including g = f·w_MIS, the MIS combination is exactly unbiased. Over
//! power's candidates the pmf is RIS's form for a fresh candidate set (hashed from the shading
//! point) conditioned to hold l, K·p̂(l) / (w(l) + Σ of K − 1 other candidates' w), an estimate
//! of the choice's probability (power's own q, ignoring where the receiver is, made 1.78× the
//! error); over the BVH it is the BVH's q ([`CandidateSource::MIS_BY_SOURCE`]).
//!
//! Lights whose importance is zero (cannot reach the receiver's upper hemisphere) are never
//! chosen; every other light keeps a positive probability (its source probability is > 0).
//! K is part of the name: `ris` (K = [`DEFAULT_CANDIDATES`]) or `ris:K`.

use super::power::PowerSelector;
use super::{FiniteSelector, ShadingPoint, importance};
use crate::lights::LightBounds;
use crate::sampling::hash::{hash_keys, hash_step, u32_to_unit};

/// Where RIS draws its candidates from: a cheap selector whose probability of every light is
/// known exactly (`power` here, the light BVH in `ris_bvh.rs`).
pub trait CandidateSource: Send + Sync {
    /// Whether RIS's deterministic pmf ([`FiniteSelector::pmf`], the one inside the MIS
    /// weights) is the source's own probability q of the light (cheap, and as good as the
    /// estimate of RIS's probability when the source already follows the light's importance,
    /// as the BVH does) rather than that estimate (K − 1 more candidates per call).
    const MIS_BY_SOURCE: bool;
    /// Draw one candidate with the uniform number `u`: (local light, its exact probability q).
    /// `None` counts as a candidate of weight zero (the source's "nowhere" mass).
    fn draw(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)>;
    /// q of light `l` at `ctx`: the probability that `draw` returns it.
    fn prob(&self, ctx: &ShadingPoint, l: u32) -> f32;
    /// `out[i] = draw(ctx, us[i])` for every i, with the light's target p̂ when the source
    /// computed it on the way (else RIS computes it; a source that gives it must give the same
    /// in [`Self::prob_and_target`]). A source may share work between the draws: `us` is
    /// ascending when RIS asks.
    fn draw_many(&self, ctx: &ShadingPoint, us: &[f32], out: &mut [Drawn]) {
        for (o, &u) in out.iter_mut().zip(us) {
            *o = self.draw(ctx, u).map(|(l, q)| (l, q, None));
        }
    }
    /// [`Self::prob`] of `l`, with its target p̂ if the source gives it in `draw_many`.
    fn prob_and_target(&self, ctx: &ShadingPoint, l: u32) -> (f32, Option<f32>) {
        (self.prob(ctx, l), None)
    }
}

/// A drawn candidate: (local light, its probability q, its target p̂ if the source gives it).
pub type Drawn = Option<(u32, f32, Option<f32>)>;

impl CandidateSource for PowerSelector {
    // Power ignores where the receiver is, so its q makes poor MIS weights: with it `ris`'s
    // relMSE was 1.78× the estimate's on many-rooms and many-open (docs/many-lights.md).
    const MIS_BY_SOURCE: bool = false;
    #[inline]
    fn draw(&self, _ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        self.pick(u)
    }
    #[inline]
    fn prob(&self, _ctx: &ShadingPoint, l: u32) -> f32 {
        PowerSelector::prob(self, l)
    }
}

/// Candidates per selection unless `ris:K` says otherwise.
pub const DEFAULT_CANDIDATES: u32 = 8;
/// Most candidates accepted (a stack array holds them).
pub const MAX_CANDIDATES: u32 = 256;
/// Levels of each of the two numbers [`Ris::stratified`] splits u's top 24 bits into.
const SPLIT: u32 = 1 << 12;
/// Candidates the stratified choice keeps on the stack (more go to the heap).
const INLINE_CANDIDATES: usize = 16;

/// RIS over candidates from a [`CandidateSource`] `S`.
#[derive(Clone, Debug)]
pub struct Ris<S> {
    source: S,
    bounds: Vec<LightBounds>,
    k: u32,
    seed: u64,
    /// Candidate i from the stratum [i/K, (i+1)/K) of the source's sample space, candidates and
    /// final choice from u's bits (instead of i.i.d. hashed numbers): see [`Ris::stratified`].
    stratified: bool,
}

/// RIS over power-sampled candidates (`ris`, `ris:K`).
pub type RisSelector = Ris<PowerSelector>;

/// The even and odd bits of a 24-bit number, each compacted to 12 bits (the odd ones hold the
/// top bit).
fn deinterleave(b: u32) -> (u32, u32) {
    let mut x = 0;
    let mut y = 0;
    for i in 0..12 {
        x |= ((b >> (2 * i)) & 1) << i;
        y |= ((b >> (2 * i + 1)) & 1) << i;
    }
    (x, y)
}

#[inline]
fn unit(h: u64) -> f32 {
    u32_to_unit((h >> 32) as u32)
}

impl RisSelector {
    /// `k` candidates per selection from power sampling over `bounds`.
    pub fn new(bounds: &[LightBounds], k: u32, seed: u64) -> Self {
        // I.i.d. candidates (and the images `ris` always made): over power's candidates the
        // stratified choice measured about even on `many-rooms` (relMSE 0.99 vs 0.94 at K = 8,
        // 0.21 vs 0.31 at K = 32; light sampling only, 8 spp).
        Ris::with_source(PowerSelector::new(bounds), bounds, k, seed)
    }
}

impl<S: CandidateSource> Ris<S> {
    /// `k` candidates per selection from `source` (built over the same `bounds`).
    pub fn with_source(source: S, bounds: &[LightBounds], k: u32, seed: u64) -> Self {
        Self {
            source,
            bounds: bounds.to_vec(),
            k: k.clamp(1, MAX_CANDIDATES),
            seed,
            stratified: false,
        }
    }

    /// Keep the stratification of `sample`'s number u instead of throwing it away. u's top 24
    /// bits are split into their even and odd bits, two 12-bit numbers x and y (independent
    /// for a uniform u; a pixel's 2^m strata of u make a 2^⌊m/2⌋ × 2^⌈m/2⌉ grid of (x, y)),
    /// each filled in below 2^-12 by a hash of u and the shading point. The K candidates share
    /// the offset o = x: candidate i is the source's choice for (i + o)/K, one per stratum of
    /// the source's sample space. The final choice inverts the candidates' running sum of w
    /// (in candidate order) with r = y. Given the candidates, r is uniform (y is independent of
    /// x, and the hash below it is uniform: the independence of hashed numbers `ris`'s
    /// reservoir relies on), so candidate j is kept with probability wⱼ/Σw exactly as in the
    /// reservoir, and E[f(Y)·W | candidates] = (1/K)·Σᵢ f(xᵢ)/q(xᵢ) — the stratified estimator
    /// of Σₗ f(l), since candidate i covers stratum i of q — so the light estimator stays
    /// exactly unbiased. What it gains: the pixel's stratification reaches both the candidates
    /// and the choice (made in the source's sample-space order, so u → light stays roughly
    /// monotone as in `bvh`'s own inversion), where hashed candidates and a hashed reservoir
    /// number make every choice i.i.d. — and 1D-stratified selection is what makes `bvh` and
    /// `exhaustive` 2.6–2.8× better at 8 spp on `many-rooms` than with i.i.d. numbers
    /// (docs/many-lights.md).
    pub fn stratified(mut self, on: bool) -> Self {
        self.stratified = on;
        self
    }

    /// Candidates per selection.
    pub fn candidates(&self) -> u32 {
        self.k
    }

    /// Target p̂ of local light `l` at `ctx`.
    #[inline]
    fn target(&self, ctx: &ShadingPoint, l: u32) -> f32 {
        importance(ctx.p, ctx.n, &self.bounds[l as usize])
    }

    /// Key of a shading point's candidate stream.
    fn point_key(&self, ctx: &ShadingPoint, salt: u64) -> u64 {
        hash_keys(&[
            self.seed,
            salt,
            ctx.p.x.to_bits() as u64 | (ctx.p.y.to_bits() as u64) << 32,
            ctx.p.z.to_bits() as u64 | (ctx.n.x.to_bits() as u64) << 32,
            ctx.n.y.to_bits() as u64 | (ctx.n.z.to_bits() as u64) << 32,
        ])
    }

    /// Draw candidate `i` of stream `key`: (light, p̂, w = p̂/q).
    #[inline]
    fn candidate(&self, ctx: &ShadingPoint, key: u64, i: u32) -> Option<(u32, f32, f64)> {
        self.candidate_at(ctx, unit(hash_step(key, i as u64)))
    }

    /// The candidate the source draws with number `v`: (light, p̂, w = p̂/q).
    #[inline]
    fn candidate_at(&self, ctx: &ShadingPoint, v: f32) -> Option<(u32, f32, f64)> {
        let (l, q) = self.source.draw(ctx, v)?;
        let t = self.target(ctx, l);
        let w = if q > 0.0 { t as f64 / q as f64 } else { 0.0 };
        Some((l, t, w))
    }

    /// [`FiniteSelector::sample`] with stratified candidates and a stratified final choice
    /// ([`Ris::stratified`]).
    fn sample_stratified(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        let key = hash_step(self.point_key(ctx, 3), u.to_bits() as u64);
        // u's top 24 bits split into two 12-bit numbers (even and odd bits): independent for a
        // uniform u, and a pixel's 2^m strata of u become a 2^⌊m/2⌋ × 2^⌈m/2⌉ grid of them.
        let bits = (u.clamp(0.0, 1.0) as f64 * (1u64 << 24) as f64) as u32 & 0xff_ffff;
        let (bx, by) = deinterleave(bits);
        // The hashes fill in below 2^-12, so every light keeps its probability.
        let offset = ((bx as f64 + unit(hash_step(key, 0)) as f64) / SPLIT as f64) as f32;
        let k = self.k as usize;
        let mut inline_u = [0.0f32; INLINE_CANDIDATES];
        let mut inline_d: [Drawn; INLINE_CANDIDATES] = [None; INLINE_CANDIDATES];
        let mut inline_w = [0.0f64; INLINE_CANDIDATES];
        let (mut heap_u, mut heap_d, mut heap_w) = (Vec::new(), Vec::new(), Vec::new());
        let (us, drawn, ws): (&mut [f32], &mut [Drawn], &mut [f64]) = if k <= INLINE_CANDIDATES {
            (&mut inline_u[..k], &mut inline_d[..k], &mut inline_w[..k])
        } else {
            heap_u.resize(k, 0.0);
            heap_d.resize(k, None);
            heap_w.resize(k, 0.0);
            (&mut heap_u, &mut heap_d, &mut heap_w)
        };
        for (i, v) in us.iter_mut().enumerate() {
            *v = ((i as f32 + offset) / self.k as f32).min(super::ONE_MINUS_EPS);
        }
        self.source.draw_many(ctx, us, drawn);
        let mut sum = 0.0f64;
        for (d, w) in drawn.iter_mut().zip(ws.iter_mut()) {
            // Not drawn (a BVH walk that ended nowhere) or zero target: weight 0.
            if let Some((l, q, given)) = *d {
                let t = given.unwrap_or_else(|| self.target(ctx, l));
                *w = if q > 0.0 && t > 0.0 {
                    t as f64 / q as f64
                } else {
                    0.0
                };
                // Keep the target where the choice needs it.
                *d = Some((l, q, Some(t)));
                sum += *w;
            }
        }
        if !(sum > 0.0 && sum.is_finite()) {
            return None;
        }
        let r = (by as f64 + unit(hash_step(key, 1)) as f64) / SPLIT as f64;
        let target = r * sum;
        let mut acc = 0.0f64;
        let mut chosen = None;
        for (&d, &w) in drawn.iter().zip(ws.iter()) {
            if w <= 0.0 {
                continue;
            }
            acc += w;
            chosen = d.map(|(l, _, t)| (l, t.unwrap_or(0.0)));
            if target < acc {
                break;
            }
        }
        // Rounding may leave `target` at or past the last sum: the last positive candidate.
        let (l, t) = chosen?;
        let pmf = (self.k as f64 * t as f64 / sum) as f32;
        (pmf > 0.0 && pmf.is_finite()).then_some((l, pmf))
    }
}

impl<S: CandidateSource> FiniteSelector for Ris<S> {
    fn sample(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        if self.stratified {
            return self.sample_stratified(ctx, u);
        }
        // The candidates come from u (and the point); the final choice from a further number
        // of the same stream.
        let key = hash_step(self.point_key(ctx, 1), u.to_bits() as u64);
        let mut chosen: Option<(u32, f32)> = None;
        let mut sum = 0.0f64;
        for i in 0..self.k {
            // A candidate the source could not draw weighs nothing (power never fails while it
            // has lights; a BVH walk can end at a node whose children all score zero).
            let Some((l, t, w)) = self.candidate(ctx, key, i) else {
                continue;
            };
            if w <= 0.0 {
                continue;
            }
            sum += w;
            // Weighted reservoir: replace with probability w / sum.
            let v = unit(hash_step(key, (MAX_CANDIDATES + i) as u64)) as f64;
            if v * sum < w {
                chosen = Some((l, t));
            }
        }
        let (l, t) = chosen?;
        let pmf = (self.k as f64 * t as f64 / sum) as f32;
        (pmf > 0.0 && pmf.is_finite()).then_some((l, pmf))
    }

    fn sample_mis_at(
        &self,
        ctx: &ShadingPoint,
        u: f32,
        _secondary: bool,
    ) -> Option<(u32, f32, f32)> {
        let (l, inv_w) = self.sample(ctx, u)?;
        Some((l, inv_w, self.pmf(ctx, l)))
    }

    fn pmf(&self, ctx: &ShadingPoint, light: u32) -> f32 {
        if light as usize >= self.bounds.len() {
            return 0.0;
        }
        let (q, given) = self.source.prob_and_target(ctx, light);
        if S::MIS_BY_SOURCE {
            return q;
        }
        let t = given.unwrap_or_else(|| self.target(ctx, light));
        if t <= 0.0 || q <= 0.0 {
            return 0.0;
        }
        let w = t as f64 / q as f64;
        // The hashed estimate's K − 1 other candidates are i.i.d. draws of the source even
        // for a stratified `sample`: any deterministic function of (point, light) keeps the
        // MIS weights summing to 1, and only power's RIS (never stratified) asks for it.
        let key = self.point_key(ctx, 2);
        let mut sum = w;
        for i in 1..self.k {
            if let Some((_, _, wi)) = self.candidate(ctx, key, i) {
                sum += wi;
            }
        }
        (self.k as f64 * t as f64 / sum) as f32
    }
}
