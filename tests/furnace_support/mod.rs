//! What the furnace tests share (`mod furnace_support;`): their scenes from pbrt-v4 text, the
//! strategy/heuristic pairs every furnace must agree under, the pixel mean with its standard
//! error, and ([`slab`]) the expected answer of a slab furnace.
#![allow(dead_code)] // Each test file uses part of this module.

pub mod slab;

use penumbra::image::Image;
use penumbra::integrator::{MisHeuristic, Strategy};
use penumbra::scene::Scene;
use std::path::Path;

/// Every light-sampling strategy, MIS under both heuristics: a furnace's answer is the same
/// under each.
pub const STRATEGIES: [(Strategy, MisHeuristic); 5] = [
    (Strategy::Bsdf, MisHeuristic::Power),
    (Strategy::LightArea, MisHeuristic::Power),
    (Strategy::LightSolidAngle, MisHeuristic::Power),
    (Strategy::Mis, MisHeuristic::Power),
    (Strategy::Mis, MisHeuristic::Balance),
];

/// The scene of a pbrt-v4 file's text (no includes, nothing loaded from disk).
pub fn furnace_scene(src: &str) -> Scene {
    let parsed = penumbra::scene::pbrt::parse_pbrt_str("furnace.pbrt", src, Path::new("."))
        .expect("furnace scene parses");
    let (b, cam, film, _) = parsed.into_builder().expect("furnace scene converts");
    b.build(cam, film).expect("furnace scene builds")
}

/// Mean and standard error over the pixels (independent estimates) of the red channel.
pub fn mean_se(img: &Image) -> (f64, f64) {
    let px: Vec<f64> = img.pixels.iter().map(|p| p.x as f64).collect();
    let n = px.len() as f64;
    let mean = px.iter().sum::<f64>() / n;
    let var = px.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}
