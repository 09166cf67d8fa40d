//! Small pbrt-v4 scenes rendered and measured (`mod render_support;`): the scene of a file's
//! text (or of its world block under a small default camera), the strategy/heuristic pairs an
//! unbiased answer must not depend on, the pixel mean with its standard error, the check of a
//! transmitted fraction (a ratio of two means, or a count of rays against a binomial), the
//! ground-under-a-roof scene those fractions are measured in, and the relative MSE against a
//! reference image.
#![allow(dead_code)] // Each test file uses part of this module.

use glam::UVec2;
use penumbra::image::Image;
use penumbra::integrator::{MisHeuristic, RenderOptions, Strategy, render};
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

/// The scene of a pbrt-v4 world block (`world`: what follows `WorldBegin`) seen by an 8×8
/// perspective camera at (0, 0, 10) looking at the origin, and the loader's warnings.
pub fn pbrt_world(world: &str) -> (Scene, Vec<String>) {
    let src = format!(
        "LookAt 0 0 10  0 0 0  0 1 0\nCamera \"perspective\"\n\
         Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\nWorldBegin\n{world}\n"
    );
    pbrt_scene_in(&src, Path::new("."))
}

/// Mean and standard error over the pixels (independent estimates) of the red channel.
pub fn mean_se(img: &Image) -> (f64, f64) {
    mean_se_channel(img, 0)
}

/// Mean and standard error over the pixels of channel `c` (0 red, 1 green, 2 blue).
pub fn mean_se_channel(img: &Image, c: usize) -> (f64, f64) {
    let px: Vec<f64> = img.pixels.iter().map(|p| p[c] as f64).collect();
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

/// Assert that `passed` of `n` rays is the fraction `want` within 5σ of a binomial of `n`
/// trials.
pub fn check_fraction(what: &str, passed: usize, n: usize, want: f64) {
    let f = passed as f64 / n as f64;
    let sigma = (want * (1.0 - want) / n as f64).sqrt();
    eprintln!("{what}: passed {f:.5}, expected {want:.5} ± {sigma:.5}");
    assert!(
        (f - want).abs() <= 5.0 * sigma,
        "{what}: passed fraction {f} is not {want} within 5σ = {}",
        5.0 * sigma
    );
}

/// A diffuse ground at z = 0 seen from above by a 24×24 camera under `roof` (pbrt-v4 shape
/// lines, or none), lit by a distant light from straight above: the fraction of the sun a
/// roof passes is the ratio of the ground's brightness under it and without it.
pub fn roof_scene(roof: &str) -> String {
    format!(
        "LookAt 0 0 0.5  0 0 0  0 1 0\n\
         Camera \"perspective\" \"float fov\" 40\n\
         Film \"rgb\" \"integer xresolution\" 24 \"integer yresolution\" 24 \"string filename\" \"x.exr\"\n\
         WorldBegin\n\
         LightSource \"distant\" \"point3 from\" [0 0 10] \"point3 to\" [0 0 0] \"rgb L\" [1 1 1]\n\
         Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \
         \"point3 P\" [-20 -20 0  20 -20 0  20 20 0  -20 20 0]\n\
         {roof}\n"
    )
}

/// [`mean_se`] of [`roof_scene`]`(roof)` rendered at 16 spp (seed 5), which must load without
/// a warning about alpha.
pub fn roof_mean(roof: &str) -> (f64, f64) {
    let (scene, warnings) = pbrt_scene_in(&roof_scene(roof), Path::new("."));
    assert!(
        !warnings.iter().any(|w| w.contains("alpha")),
        "alpha warned about: {warnings:?}"
    );
    let opts = RenderOptions {
        spp: 16,
        seed: 5,
        progress: false,
        ..RenderOptions::default()
    };
    let (img, _) = render(&scene, UVec2::new(24, 24), &opts).unwrap();
    mean_se(&img)
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
