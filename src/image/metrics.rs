//! Error metrics between a render and a reference, and a false-colour per-pixel error map.

use anyhow::bail;

use super::Image;
use super::colormap::viridis;
use super::io::srgb_to_linear;
use crate::Rgb;

/// Denominator offset of relMSE: keeps near-black reference pixels from dominating.
pub const REL_MSE_EPSILON: f64 = 0.01;

/// log10 range of per-pixel relMSE mapped onto the colormap by [`error_image`]:
/// 1e-4 (and below) is darkest, 1e1 (and above) brightest.
pub const ERROR_IMAGE_LOG10_RANGE: (f64, f64) = (-4.0, 1.0);

/// Whole-image error statistics (means over all pixels and channels).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorStats {
    /// Mean squared error, mean of (a − b)².
    pub mse: f64,
    /// Relative MSE, mean of (a − b)² / (b² + 0.01).
    pub rel_mse: f64,
    /// Mean absolute error, mean of |a − b|.
    pub mae: f64,
}

/// Fail with both sizes when `test` and `reference` differ in size.
fn check_sizes(test: &Image, reference: &Image) -> anyhow::Result<()> {
    if !test.same_size(reference) {
        bail!(
            "image sizes differ: test is {}x{}, reference is {}x{}",
            test.width,
            test.height,
            reference.width,
            reference.height
        );
    }
    Ok(())
}

/// Per-channel relMSE term; f64 so the sum of millions of terms stays accurate.
#[inline]
fn rel_sq(a: f32, b: f32) -> f64 {
    let (a, b) = (a as f64, b as f64);
    (a - b) * (a - b) / (b * b + REL_MSE_EPSILON)
}

/// MSE, relMSE and MAE of `test` against `reference` (linear values, no tonemapping).
/// Empty images give all zeros; differing sizes are an error naming both sizes.
pub fn compare(test: &Image, reference: &Image) -> anyhow::Result<ErrorStats> {
    check_sizes(test, reference)?;
    let (mut se, mut rel, mut ae) = (0.0f64, 0.0f64, 0.0f64);
    for (a, b) in test.pixels.iter().zip(&reference.pixels) {
        for c in 0..3 {
            let d = a[c] as f64 - b[c] as f64;
            se += d * d;
            ae += d.abs();
            rel += rel_sq(a[c], b[c]);
        }
    }
    let n = (3 * test.pixels.len()).max(1) as f64;
    Ok(ErrorStats {
        mse: se / n,
        rel_mse: rel / n,
        mae: ae / n,
    })
}

/// False-colour map of per-pixel relMSE (mean over the pixel's channels), log-scaled over
/// [`ERROR_IMAGE_LOG10_RANGE`] through viridis. Returned as a *linear* image so that writing
/// it as PNG with exposure 0 reproduces the colormap's sRGB colours exactly.
/// Non-finite errors (NaN/Inf in the test image) are shown in magenta.
pub fn error_image(test: &Image, reference: &Image) -> anyhow::Result<Image> {
    check_sizes(test, reference)?;
    let (lo, hi) = ERROR_IMAGE_LOG10_RANGE;
    let pixels = test
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, b)| {
            let e = (0..3).map(|c| rel_sq(a[c], b[c])).sum::<f64>() / 3.0;
            if !e.is_finite() {
                return Rgb::new(1.0, 0.0, 1.0);
            }
            let t = ((e.max(1e-30).log10() - lo) / (hi - lo)) as f32;
            let s = viridis(t);
            Rgb::new(srgb_to_linear(s.x), srgb_to_linear(s.y), srgb_to_linear(s.z))
        })
        .collect();
    Ok(Image {
        width: test.width,
        height: test.height,
        pixels,
    })
}
