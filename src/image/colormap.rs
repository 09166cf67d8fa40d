//! Perceptual colormaps for false-colour images.

use crate::Rgb;

/// Viridis (matplotlib's perceptually uniform map, dark blue → yellow) at `t ∈ [0, 1]`,
/// returned as **sRGB-encoded** values in [0, 1]. `t` is clamped; NaN maps to 0.
///
/// A degree-6 polynomial fit (Matt Zucker's public-domain "colormap fits") instead of a
/// 256-entry table: it stays within 4 8-bit code values of the table (checked at eight entries in
/// tests) and keeps the source short.
pub fn viridis(t: f32) -> Rgb {
    const C: [[f32; 3]; 7] = [
        [0.277_727_33, 0.005_407_344_5, 0.334_099_8],
        [0.105_093_04, 1.404_613_5, 1.384_590_2],
        [-0.330_861_83, 0.214_847_56, 0.095_095_16],
        [-4.634_230_5, -5.799_101, -19.332_441],
        [6.228_27, 14.179_933, 56.690_55],
        [4.776_385, -13.745_146, -65.353_03],
        [-5.435_456, 4.645_852_6, 26.312_435],
    ];
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    // Horner evaluation, highest coefficient first.
    let mut c = Rgb::from(C[6]);
    for k in (0..6).rev() {
        c = c * t + Rgb::from(C[k]);
    }
    c.clamp(Rgb::ZERO, Rgb::ONE)
}
