//! The lecture's claims as measurements on the Cornell box: each configuration is rendered with
//! several seeds, and a claim "A beats B" must hold by a margin of many standard errors of the
//! difference of the mean relMSEs (σ measured from the seeds), so the tests can fail.

use glam::UVec2;
use penumbra::image::{Image, compare};
use penumbra::integrator::{RenderOptions, Strategy, render};
use penumbra::lab::mask::{edge_mask, smooth_rel_mse};
use penumbra::sampling::PatternKind;
use penumbra::scene::Scene;
use penumbra::scene::load::{LoadOptions, load};
use std::sync::OnceLock;

const RES: UVec2 = UVec2::new(64, 64);
/// Independent renders per configuration.
const SEEDS: u64 = 6;
/// Required separation in standard errors of the difference of the means.
const SIGMAS: f64 = 5.0;

struct Fixture {
    scene: Scene,
    reference: Image,
    mask: Vec<bool>,
}

/// The Cornell box and a MIS reference at 512 spp, built once for every test.
fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let scene = load("cornell", &LoadOptions::default()).unwrap().scene;
        let opts = RenderOptions {
            spp: 512,
            seed: 0xfeed,
            strategy: Strategy::Mis,
            ..RenderOptions::default()
        };
        let reference = render(&scene, RES, &opts).unwrap().0;
        let mask = edge_mask(&reference);
        Fixture {
            scene,
            reference,
            mask,
        }
    })
}

/// Which error to compare.
#[derive(Clone, Copy, Debug)]
enum Metric {
    /// relMSE over all pixels.
    Full,
    /// relMSE away from edges (light-sampling noise only).
    Smooth,
}

/// (mean, standard error of the mean) of the metric over [`SEEDS`] renders.
fn measure(strategy: Strategy, pattern: PatternKind, spp: u32, m: u32, metric: Metric) -> (f64, f64) {
    let f = fixture();
    let v: Vec<f64> = (0..SEEDS)
        .map(|seed| {
            let opts = RenderOptions {
                spp,
                shadow_rays: m,
                seed: seed + 1,
                strategy,
                pattern,
                ..RenderOptions::default()
            };
            let img = render(&f.scene, RES, &opts).unwrap().0;
            match metric {
                Metric::Full => compare(&img, &f.reference).unwrap().rel_mse,
                Metric::Smooth => smooth_rel_mse(&img, &f.reference, &f.mask).0,
            }
        })
        .collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Assert `better` has a lower mean error than `worse` by [`SIGMAS`] standard errors.
fn assert_beats(what: &str, better: (f64, f64), worse: (f64, f64)) {
    let se = (better.1 * better.1 + worse.1 * worse.1).sqrt();
    eprintln!(
        "{what}: {:.4e} ± {:.1e} vs {:.4e} ± {:.1e} (ratio {:.2})",
        better.0,
        better.1,
        worse.0,
        worse.1,
        worse.0 / better.0
    );
    assert!(
        worse.0 - better.0 > SIGMAS * se,
        "{what}: {:.4e} ± {:.1e} does not beat {:.4e} ± {:.1e}",
        better.0,
        better.1,
        worse.0,
        worse.1
    );
}

#[test]
fn lab_claim_light_area_beats_bsdf_sampling_for_small_light() {
    use Metric::Full;
    let light = measure(Strategy::LightArea, PatternKind::Stratified, 4, 16, Full);
    let bsdf = measure(Strategy::Bsdf, PatternKind::Stratified, 4, 16, Full);
    assert_beats("light-area vs bsdf, 4 × 16", light, bsdf);
}

#[test]
fn lab_claim_stratified_beats_random_at_equal_samples() {
    // Smooth pixels: the full relMSE at 4 eye rays is dominated by (heavy-tailed) emitter-edge
    // aliasing, which would need many more seeds to resolve the same difference.
    let strat = measure(Strategy::LightArea, PatternKind::Stratified, 4, 16, Metric::Smooth);
    let random = measure(Strategy::LightArea, PatternKind::Random, 4, 16, Metric::Smooth);
    assert_beats("stratified vs random, 4 × 16, smooth", strat, random);
}

#[test]
fn lab_claim_random_beats_fixed_light_sample_in_penumbrae() {
    // A fixed point on the light renders hard shadows: a bias no sample count removes.
    let random = measure(Strategy::LightArea, PatternKind::Random, 4, 4, Metric::Smooth);
    let fixed = measure(Strategy::LightArea, PatternKind::Fixed, 4, 4, Metric::Smooth);
    assert_beats("random vs fixed, 4 × 4, smooth", random, fixed);
}

#[test]
fn lab_claim_more_eye_rays_beat_more_shadow_rays_at_equal_cost() {
    let eye = measure(Strategy::LightArea, PatternKind::Stratified, 64, 1, Metric::Full);
    let shadow = measure(Strategy::LightArea, PatternKind::Stratified, 4, 16, Metric::Full);
    assert_beats("64 × 1 vs 4 × 16", eye, shadow);
}
