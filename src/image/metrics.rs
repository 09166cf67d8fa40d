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
            Rgb::new(
                srgb_to_linear(s.x),
                srgb_to_linear(s.y),
                srgb_to_linear(s.z),
            )
        })
        .collect();
    Ok(Image {
        width: test.width,
        height: test.height,
        pixels,
    })
}

/// How an image file stores its values, as far as a comparison cares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// Linear floating point (EXR, PFM, Radiance HDR): values above 1 survive.
    LinearFloat,
    /// 8-bit sRGB display values (PNG, TGA, JPEG): clamped to [0, 1] and quantised.
    Display8,
}

impl Encoding {
    /// The encoding a file of this name has, by extension; `None` when unknown.
    pub fn of(path: &std::path::Path) -> Option<Encoding> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "exr" | "pfm" | "hdr" => Some(Encoding::LinearFloat),
            "png" | "tga" | "jpg" | "jpeg" => Some(Encoding::Display8),
            _ => None,
        }
    }
}

/// What makes a comparison's numbers meaningless (an error) or misleading (warnings): an image
/// without pixels is an error; NaN/Inf pixels and an 8-bit display image compared with a
/// linear float one are warnings, each naming the file.
pub fn comparison_warnings(
    test: (&Image, &std::path::Path),
    reference: (&Image, &std::path::Path),
) -> anyhow::Result<Vec<String>> {
    let mut warnings = Vec::new();
    for (img, path) in [test, reference] {
        if img.pixels.is_empty() {
            bail!(
                "{} is {}x{}: it has no pixels to compare",
                path.display(),
                img.width,
                img.height
            );
        }
        let bad = img.count_non_finite();
        if bad > 0 {
            // The metrics will be NaN/Inf; say why rather than leave the user guessing.
            warnings.push(format!("{}: {bad} pixel(s) with NaN/Inf", path.display()));
        }
    }
    if let (Some(a), Some(b)) = (Encoding::of(test.1), Encoding::of(reference.1))
        && a != b
    {
        let (display, linear) = if a == Encoding::Display8 {
            (test.1, reference.1)
        } else {
            (reference.1, test.1)
        };
        warnings.push(format!(
            "{} holds 8-bit sRGB display values (clamped to [0, 1], quantised) and {} linear \
             floats: the errors include that clamping and quantisation, not only the render's",
            display.display(),
            linear.display()
        ));
    }
    Ok(warnings)
}
