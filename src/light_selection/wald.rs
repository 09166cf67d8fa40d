//! Wald et al., "Interactive Global Illumination in Complex and Highly Occluded Environments"
//! (EGSR 2003): before rendering, trace a low-resolution grid of eye rays, connect each hit to
//! a few lights chosen uniformly at random (with shadow rays) and record, per light, the
//! largest contribution it made to any estimation pixel. The maxima of several jittered passes
//! are averaged and lights are then chosen ∝ that estimate, everywhere in the image.
//!
//! Unbiasedness and tails: lights the passes never saw (or saw only occluded) would get
//! probability 0, so the estimate is mixed with power selection: p = (1 − ε)·p_est + ε·p_Φ
//! with ε = max([`WaldConfig::floor`], power mass of the lights no pass tested):
//! the estimate only takes over the probability of lights it has an opinion about. A light
//! tested only where it is dark (a spot light whose cone the random tests missed) gets no
//! share of the estimate; with the former fixed 10 % floor it was then drawn at 1/10 of
//! power's rate where it does shine, which gave `wald` its heavy tails. `make_selector`
//! mixes the estimate with power selection at a share δ ≥ 10 % chosen by held-out probes
//! ([`super::defensive`]): more power where the estimate misses light, power alone where the
//! estimate does not pay. The pmf does not
//! depend on the shading point.

use super::estimate::{contribution, estimate_resolution, eye_hit, next_2d, pixel_rng};
use super::power::PowerSelector;
use super::{FiniteSelector, LightSet, ShadingPoint};
use crate::sampling::hash::next_f32;
use crate::scene::Scene;
use rayon::prelude::*;

/// Parameters of the estimation passes.
#[derive(Clone, Debug)]
pub struct WaldConfig {
    /// Longer side of the estimation image in pixels.
    pub resolution: u32,
    /// Jittered passes whose per-light maxima are averaged.
    pub passes: u32,
    /// Lights tested (shadow rays) per estimation pixel and pass.
    pub lights_per_pixel: u32,
    /// Share ε of power-proportional selection mixed in for unseen lights (at least the power
    /// mass of the untested lights). 0 by default: `make_selector` mixes the estimate with
    /// power selection again at a probed share of at least `DEFENSIVE_FLOOR`, which is the
    /// floor every light keeps; a second 10 % here would only dilute the estimate.
    pub floor: f32,
    /// Seed (the render's seed).
    pub seed: u64,
}

impl WaldConfig {
    /// Defaults: 64-pixel estimation image, 4 passes, 16 lights per pixel, no floor of its own.
    pub fn new(seed: u64) -> Self {
        Self {
            resolution: 64,
            passes: 4,
            lights_per_pixel: 16,
            floor: 0.0,
            seed,
        }
    }
}

/// Global selection ∝ estimated maximum contribution, with a power floor.
#[derive(Clone, Debug)]
pub struct WaldSelector {
    estimate: PowerSelector,
    power: PowerSelector,
    floor: f32,
    /// Lights with a positive estimate (seen by the passes).
    pub seen: usize,
}

/// Per-light maxima of one pass (f32 values, compared as is) and how often each light was
/// tested.
fn pass_maxima(scene: &Scene, set: &LightSet, cfg: &WaldConfig, pass: u32) -> (Vec<f32>, Vec<u32>) {
    let res = estimate_resolution(scene, cfg.resolution);
    let n = set.finite.len();
    let pixels = res.x * res.y;
    // Max and integer counts are order-independent, so a parallel fold + reduce is
    // deterministic.
    (0..pixels)
        .into_par_iter()
        .fold(
            || (vec![0.0f32; n], vec![0u32; n]),
            |(mut acc, mut tested), px| {
                let mut rng = pixel_rng(cfg.seed, 0x3a1d, pass, px);
                if let Some(eh) = eye_hit(scene, res, px, &mut rng) {
                    for _ in 0..cfg.lights_per_pixel {
                        let k = ((next_f32(&mut rng) * n as f32) as usize).min(n - 1);
                        let c = contribution(scene, &eh, set.finite[k], next_2d(&mut rng));
                        tested[k] += 1;
                        if c > acc[k] {
                            acc[k] = c;
                        }
                    }
                }
                (acc, tested)
            },
        )
        .reduce(
            || (vec![0.0f32; n], vec![0u32; n]),
            |(mut a, mut ta), (b, tb)| {
                for (x, y) in a.iter_mut().zip(b) {
                    *x = x.max(y);
                }
                for (x, y) in ta.iter_mut().zip(tb) {
                    *x += y;
                }
                (a, ta)
            },
        )
}

impl WaldSelector {
    /// Run the estimation passes on `scene` for the finite lights of `set`.
    pub fn new(scene: &Scene, set: &LightSet, cfg: &WaldConfig) -> Self {
        let power = PowerSelector::new(&set.bounds);
        let n = set.finite.len();
        if n == 0 {
            return Self {
                estimate: PowerSelector::from_weights(&[]),
                power,
                floor: 1.0,
                seen: 0,
            };
        }
        let passes = cfg.passes.max(1);
        let mut avg = vec![0.0f64; n];
        let mut tested = vec![0u32; n];
        for pass in 0..passes {
            let (maxima, t) = pass_maxima(scene, set, cfg, pass);
            for (a, m) in avg.iter_mut().zip(maxima) {
                *a += m as f64 / passes as f64;
            }
            for (a, t) in tested.iter_mut().zip(t) {
                *a += t;
            }
        }
        let weights: Vec<f32> = avg.iter().map(|&a| a as f32).collect();
        let seen = weights.iter().filter(|&&w| w > 0.0).count();
        // Nothing seen at all (camera sees no lit surface): power selection alone.
        // Otherwise: power's share of the lights no pass tested stays theirs.
        let untested: f32 = (0..n as u32)
            .filter(|&i| tested[i as usize] == 0)
            .map(|i| power.prob(i))
            .sum();
        let floor = if seen == 0 {
            1.0
        } else {
            cfg.floor.max(untested).clamp(0.0, 1.0)
        };
        Self {
            estimate: PowerSelector::from_weights(&weights),
            power,
            floor,
            seen,
        }
    }
}

impl FiniteSelector for WaldSelector {
    fn sample(&self, _ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        let (i, _) = if u < self.floor {
            self.power.pick(u / self.floor)?
        } else {
            self.estimate
                .pick(((u - self.floor) / (1.0 - self.floor)).min(super::ONE_MINUS_EPS))?
        };
        Some((i, FiniteSelector::pmf(self, _ctx, i)))
    }

    fn pmf(&self, _ctx: &ShadingPoint, i: u32) -> f32 {
        let est = if self.floor < 1.0 {
            self.estimate.prob(i)
        } else {
            0.0
        };
        self.floor * self.power.prob(i) + (1.0 - self.floor) * est
    }
}
