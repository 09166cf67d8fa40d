//! What the light-selection tests share (`mod selection_support;`): random numbers and
//! directions for random light sets and shading points, and the comparison of two selectors'
//! renders within their noise.
#![allow(dead_code)] // Each test file uses part of this module.

use glam::Vec3;
use penumbra::image::Image;
use penumbra::light_selection::ShadingPoint;
use penumbra::sampling::hash::next_f32;
use rand_pcg::Pcg32;

/// A uniform random number in [a, b).
pub fn u(rng: &mut Pcg32, a: f32, b: f32) -> f32 {
    a + (b - a) * next_f32(rng)
}

/// A uniform random unit vector (by rejection from the unit ball, away from its centre).
pub fn unit(rng: &mut Pcg32) -> Vec3 {
    loop {
        let v = Vec3::new(u(rng, -1.0, 1.0), u(rng, -1.0, 1.0), u(rng, -1.0, 1.0));
        if v.length_squared() > 0.01 && v.length_squared() <= 1.0 {
            return v.normalize();
        }
    }
}

/// A shading point uniformly inside the cube [−h, h]³, with a random normal and wo = +z.
pub fn random_point(rng: &mut Pcg32, h: f32) -> ShadingPoint {
    ShadingPoint {
        p: Vec3::new(u(rng, -h, h), u(rng, -h, h), u(rng, -h, h)),
        n: unit(rng),
        wo: Vec3::Z,
    }
}

/// `f` run on a pool of `threads` threads.
pub fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool")
        .install(f)
}

/// Mean of all channels of all pixels, and the variance of that mean from the per-pixel
/// difference of two independent renders (noise only, not the image's own variation).
pub fn mean_and_variance(a: &Image, b: &Image) -> (f64, f64) {
    let n = (a.pixels.len() * 3) as f64;
    let (mut sum, mut d2) = (0.0f64, 0.0f64);
    for (x, y) in a.pixels.iter().zip(&b.pixels) {
        for c in 0..3 {
            sum += (x[c] + y[c]) as f64 * 0.5;
            let d = (x[c] - y[c]) as f64;
            d2 += d * d;
        }
    }
    // Var(pixel) ≈ E[(a − b)²] / 2; the mean of the two renders halves it again.
    let var_pixel = d2 / n / 2.0;
    (sum / n, var_pixel / n / 2.0)
}
