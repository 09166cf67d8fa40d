//! Small pbrt-v4 scenes rendered and measured (`mod render_support;`): the scene of a file's
//! text, the strategy/heuristic pairs an unbiased answer must not depend on, the pixel mean
//! with its standard error, the check of a transmitted fraction (a ratio of two means), and
//! the relative MSE against a reference image.
#![allow(dead_code)] // Each test file uses part of this module.

use penumbra::image::Image;
use penumbra::integrator::{MisHeuristic, Strategy};
use penumbra::scene::Scene;
use std::path::Path;

/// Every light-sampling strategy, MIS under both heuristics: an unbiased estimate of the same
/// radiance under each.
pub const STRATEGIES: [(Strategy, MisHeuristic); 5] = [
    (Strategy::Bsdf, MisHeuristic::Power),
    (Strategy::LightArea, MisHeuristic::Power),
    (Strategy::LightSolidAngle, MisHeuristic::Power),
    (Strategy::Mis, MisHeuristic::Power),
    (Strategy::Mis, MisHeuristic::Balance),
];

/// The scene of a pbrt-v4 file's text, its relative paths resolved in `dir`, and the loader's
/// warnings.
pub fn pbrt_scene_in(src: &str, dir: &Path) -> (Scene, Vec<String>) {
    let parsed = penumbra::scene::pbrt::parse_pbrt_str("test.pbrt", src, dir)
        .unwrap_or_else(|e| panic!("scene parses: {e:#}"));
    let (b, cam, film, warnings) = parsed.into_builder().expect("scene converts");
    (b.build(cam, film).expect("scene builds"), warnings)
}

/// The scene of a pbrt-v4 file's text that reads no other file.
pub fn pbrt_scene(src: &str) -> Scene {
    pbrt_scene_in(src, Path::new(".")).0
}

/// Mean and standard error over the pixels (independent estimates) of the red channel.
pub fn mean_se(img: &Image) -> (f64, f64) {
    let px: Vec<f64> = img.pixels.iter().map(|p| p.x as f64).collect();
    let n = px.len() as f64;
    let mean = px.iter().sum::<f64>() / n;
    let var = px.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Assert that the fraction `under / open` of two (mean, standard error) measurements is `want`
/// within 5σ, with σ small enough (< 0.02) for the test to mean something and `open` not black.
pub fn assert_fraction(what: &str, under: (f64, f64), open: (f64, f64), want: f64) {
    let ((under, err), (open, open_err)) = (under, open);
    assert!(open > 0.01, "{what}: unshadowed ground is black: {open}");
    let ratio = under / open;
    let sigma = (err * err + (ratio * open_err).powi(2)).sqrt() / open;
    eprintln!(
        "{what}: {under:.5} ± {err:.5} vs open {open:.5}: ratio {ratio:.4} ± {sigma:.4}, expected {want:.4}"
    );
    assert!(sigma > 0.0 && sigma < 0.02, "{what}: σ {sigma}");
    assert!(
        (ratio - want).abs() <= 5.0 * sigma,
        "{what}: ratio {ratio} is not {want} within 5σ = {}",
        5.0 * sigma
    );
}

/// Relative MSE of `a` against the reference `b`: the mean over pixels and channels of
/// (a − b)² / (b² + 0.01), written out here independently of `penumbra::image::metrics`.
pub fn rel_mse(a: &Image, b: &Image) -> f64 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let mut s = 0.0f64;
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        for c in 0..3 {
            let (x, y) = (p[c] as f64, q[c] as f64);
            s += (x - y) * (x - y) / (y * y + 0.01);
        }
    }
    s / (3.0 * a.pixels.len() as f64)
}
