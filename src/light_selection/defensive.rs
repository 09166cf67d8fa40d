//! Defensive mixing of a learned selector with power selection, the mixture chosen by
//! held-out measurements: what makes [`super::wald`], [`super::spatial`] and
//! [`super::adaptive`] safe on scenes where their learning or their bounds do not help.
//!
//! p(l) = δ·p_Φ(l) + (1 − δ)·p_S(l) for the strategy S. Every δ tried is at least
//! [`DEFENSIVE_FLOOR`], so every light with power keeps p ≥ δ·p_Φ: its weight in the light
//! estimator is at most 1/δ of power selection's, which bounds the tails (a light the
//! learning never saw lit is not left at a near-zero probability).
//!
//! δ is picked from [`SHARES`] to minimise the second moment of the direct-light estimator
//! over the image. Under MIS with the power heuristic (the renderer's default), one light
//! sample and one BSDF sample at a vertex have second moment ∫ f²·(p₁³ + p₂³)/(p₁² + p₂²)²,
//! with p₁ = p(l)·pdf_ω the light sample's density and p₂ = pdf_BSDF; per light sample of
//! measured contribution c = f·Li·cos/pdf_ω (shadow ray included, so occlusion counts) that is
//! c²·(p³ + r³)/(p² + r²)² with r = pdf_BSDF/pdf_ω: where BSDF sampling already finds a light
//! (large r, e.g. big emitters), its selection probability matters little, and the probes
//! see that. (Without MIS the term is c²/p, which the same choice also bounds through the
//! floor.) The sum is estimated from *probes*: light
//! samples at the hits of low-resolution eye rays and at one BSDF bounce after them (the
//! secondary vertices a path tracer also selects lights at), drawn from the defensive
//! proposal q = ½·p_Φ + ½·p_S with seeds no learning pass used, so S is not judged on the
//! samples it was fitted to, and lights S neglects are still probed as often as power would.
//! Unless some δ < 1 lowers the estimate by [`ProbeConfig::margin`] (what S's extra cost per
//! sample must buy), δ = 1 and the selector *is* power selection: S is never consulted.
//!
//! Every probe is a pure function of (seed, pixel, draw) and the sums run in pixel order, so
//! δ — and the image — is the same whatever the thread count.

use super::estimate::{
    EyeHit, bounce_hit, contribution_mis, estimate_resolution, eye_hit, pixel_rng,
};
use super::power::PowerSelector;
use super::{FiniteSelector, LightSet, ONE_MINUS_EPS, ShadingPoint};
use crate::sampling::hash::next_f32;
use crate::scene::Scene;
use glam::Vec2;
use rayon::prelude::*;

/// Smallest share of power selection in any learned selector's mixture.
pub const DEFENSIVE_FLOOR: f32 = 0.1;

/// The power shares δ the probes choose from (1 = power selection alone).
pub const SHARES: [f32; 7] = [DEFENSIVE_FLOOR, 0.2, 0.3, 0.5, 0.7, 0.85, 1.0];

/// Parameters of the probe pass.
#[derive(Clone, Debug)]
pub struct ProbeConfig {
    /// Longer side of the probe image in pixels.
    pub resolution: u32,
    /// Light samples per probed vertex.
    pub lights_per_vertex: u32,
    /// Probe the eye hits (primary vertices).
    pub primary: bool,
    /// Also probe one BSDF bounce after each eye hit.
    pub bounce: bool,
    /// Relative reduction of the second moment a δ < 1 must achieve over power alone.
    pub margin: f64,
    /// Fewer non-zero probes than this (a dark view) keep power selection.
    pub min_hits: usize,
    /// Seed (the render's seed).
    pub seed: u64,
}

impl ProbeConfig {
    /// Defaults: 64-pixel probe image, 4 light samples at the eye hit and 4 after one bounce,
    /// margin `margin`.
    pub fn new(seed: u64, margin: f64) -> Self {
        Self {
            resolution: 64,
            lights_per_vertex: 4,
            primary: true,
            bounce: true,
            margin,
            min_hits: 64,
            seed,
        }
    }
}

/// One probe: c²/q for the light drawn, its BSDF-to-light density ratio and its power and
/// strategy probabilities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Probe {
    /// Squared measured contribution over the proposal's probability.
    pub c2_over_q: f64,
    /// pdf_BSDF / pdf_ω at the sampled direction (0 for delta lights and without MIS).
    pub r: f32,
    /// p_Φ of the light.
    pub p_power: f32,
    /// p_S of the light at the probed point.
    pub p_learned: f32,
}

/// Estimated second moment of the one-light estimator with power share `delta`, up to a
/// constant factor common to every δ.
pub fn second_moment(probes: &[Probe], delta: f32) -> f64 {
    probes
        .iter()
        .map(|p| {
            let m = delta as f64 * p.p_power as f64 + (1.0 - delta as f64) * p.p_learned as f64;
            let r = p.r as f64;
            let d = m * m + r * r;
            if d > 0.0 {
                p.c2_over_q * (m * m * m + r * r * r) / (d * d)
            } else {
                0.0
            }
        })
        .sum()
}

/// The share δ of [`SHARES`] with the smallest estimated second moment, unless it is not
/// `margin` below power selection's (δ = 1); δ = 1 too with fewer than `min_hits` probes.
pub fn choose_share(probes: &[Probe], margin: f64, min_hits: usize) -> f32 {
    if probes.len() < min_hits {
        return 1.0;
    }
    let power = second_moment(probes, 1.0);
    let (best, m) = SHARES
        .iter()
        .map(|&d| (d, second_moment(probes, d)))
        .fold((1.0, power), |a, b| if b.1 < a.1 { b } else { a });
    if m < (1.0 - margin) * power {
        best
    } else {
        1.0
    }
}

/// Probes of `learned` against `power` on `scene`'s finite lights `set`, in pixel order.
pub fn probe(
    scene: &Scene,
    set: &LightSet,
    power: &PowerSelector,
    learned: &dyn FiniteSelector,
    cfg: &ProbeConfig,
) -> Vec<Probe> {
    if set.finite.is_empty() {
        return Vec::new();
    }
    let res = estimate_resolution(scene, cfg.resolution);
    let at = |eh: &EyeHit, rng: &mut rand_pcg::Pcg32, out: &mut Vec<Probe>| {
        for _ in 0..cfg.lights_per_vertex {
            let u = next_f32(rng);
            let picked = if u < 0.5 {
                power.pick((2.0 * u).min(ONE_MINUS_EPS)).map(|(i, _)| i)
            } else {
                learned
                    .sample_at(&eh.sp, (2.0 * u - 1.0).min(ONE_MINUS_EPS), eh.secondary)
                    .map(|(i, _)| i)
            };
            let lu = Vec2::new(next_f32(rng), next_f32(rng));
            let Some(i) = picked else { continue };
            let (pp, pl) = (power.prob(i), learned.pmf_at(&eh.sp, i, eh.secondary));
            let q = 0.5 * pp as f64 + 0.5 * pl as f64;
            let (c, r) = contribution_mis(scene, eh, set.finite[i as usize], lu);
            let c = c as f64;
            if c > 0.0 && q > 0.0 {
                out.push(Probe {
                    c2_over_q: c * c / q,
                    r,
                    p_power: pp,
                    p_learned: pl,
                });
            }
        }
    };
    let per_pixel: Vec<Vec<Probe>> = (0..res.x * res.y)
        .into_par_iter()
        .map(|px| {
            let mut rng = pixel_rng(cfg.seed, 0xdefe, 0, px);
            let mut out = Vec::new();
            if let Some(eh) = eye_hit(scene, res, px, &mut rng) {
                if cfg.primary {
                    at(&eh, &mut rng, &mut out);
                }
                if cfg.bounce
                    && let Some(bh) = bounce_hit(scene, &eh, &mut rng)
                {
                    at(&bh, &mut rng, &mut out);
                }
            }
            out
        })
        .collect();
    per_pixel.into_iter().flatten().collect()
}

/// A strategy mixed with power selection at the share δ its probes chose.
pub struct Defensive<S> {
    inner: S,
    power: PowerSelector,
    delta: f32,
}

impl<S: FiniteSelector> Defensive<S> {
    /// Probe `inner` on `scene` and mix it with power selection at the chosen δ.
    pub fn new(scene: &Scene, set: &LightSet, inner: S, cfg: &ProbeConfig) -> Self {
        let power = PowerSelector::new(&set.bounds);
        let probes = probe(scene, set, &power, &inner, cfg);
        let delta = choose_share(&probes, cfg.margin, cfg.min_hits);
        Self::with_share(inner, power, delta)
    }

    /// `inner` mixed with `power` at share `delta` (clamped to [`DEFENSIVE_FLOOR`], 1).
    pub fn with_share(inner: S, power: PowerSelector, delta: f32) -> Self {
        Self {
            inner,
            power,
            delta: delta.clamp(DEFENSIVE_FLOOR, 1.0),
        }
    }

    /// The share δ of power selection.
    pub fn share(&self) -> f32 {
        self.delta
    }

    /// The mixed strategy.
    pub fn inner(&self) -> &S {
        &self.inner
    }
}

impl<S: FiniteSelector> FiniteSelector for Defensive<S> {
    fn sample(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        if self.delta >= 1.0 {
            return self.power.pick(u);
        }
        let d = self.delta;
        if u < d {
            let i = self.power.pick((u / d).min(ONE_MINUS_EPS))?.0;
            Some((i, self.pmf(ctx, i)))
        } else {
            // Every strategy's `sample` returns its own `pmf` of the pick: reuse it (the
            // same bits as `pmf`, without the strategy's second lookup).
            let (i, q) = self
                .inner
                .sample(ctx, ((u - d) / (1.0 - d)).min(ONE_MINUS_EPS))?;
            Some((i, d * self.power.prob(i) + (1.0 - d) * q))
        }
    }

    fn pmf(&self, ctx: &ShadingPoint, i: u32) -> f32 {
        if self.delta >= 1.0 {
            return self.power.prob(i);
        }
        self.delta * self.power.prob(i) + (1.0 - self.delta) * self.inner.pmf(ctx, i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn probes(c: &[(f64, f32, f32)]) -> Vec<Probe> {
        c.iter()
            .map(|&(c2_over_q, p_power, p_learned)| Probe {
                c2_over_q,
                r: 0.0,
                p_power,
                p_learned,
            })
            .collect()
    }

    #[test]
    fn a_useless_table_keeps_power() {
        // The table is power selection itself: no δ < 1 helps.
        let p = probes(&[(1.0, 0.5, 0.5), (1.0, 0.5, 0.5)].repeat(50));
        assert_eq!(choose_share(&p, 0.05, 10), 1.0);
    }

    #[test]
    fn a_good_table_takes_over_but_keeps_the_floor() {
        // Light 0 carries all the contribution; power gives it 1%, the table 99%.
        let p = probes(&[(1.0, 0.01, 0.99)].repeat(100));
        assert_eq!(choose_share(&p, 0.05, 10), DEFENSIVE_FLOOR);
    }

    #[test]
    fn a_table_that_misses_a_light_is_rejected() {
        // The table neglects a light that contributes half the time.
        let p = probes(&[(1.0, 0.5, 0.999), (1.0, 0.5, 0.001)].repeat(50));
        assert_eq!(choose_share(&p, 0.05, 10), 1.0);
    }

    #[test]
    fn too_few_probes_keep_power() {
        let p = probes(&[(1.0, 0.01, 0.99)].repeat(5));
        assert_eq!(choose_share(&p, 0.05, 10), 1.0);
    }
}
