//! Spectra → linear sRGB.
//!
//! Method (stated, as the issue asks): a spectrum S(λ) is projected onto the CIE 1931 colour
//! matching functions — the analytic multi-lobe Gaussian fit of Wyman, Sloan & Shirley (JCGT
//! 2013) — by a Riemann sum over 360–830 nm in 1 nm steps, the XYZ is converted to linear
//! sRGB (D65 matrix). Reflectances are white-balanced: every channel is divided by the RGB of
//! the constant spectrum 1, so a flat spectrum maps to exactly (1, 1, 1). Illuminants
//! (blackbody, sampled emission spectra) are not white-balanced (as in pbrt-v4, a 6500 K
//! blackbody comes out nearly white in sRGB) but normalised to luminance 1, as pbrt-v4 divides
//! light spectra by their photometric integral; a blackbody thus gives the *colour* of
//! temperature T and the light's `scale`/`power` its brightness.
//! Named spectra: `stdillum-*` → white (1,1,1); `metal-*-eta`/`-k` are resolved by the
//! material conversion (`bsdf::named_metal`); `glass-*` give a scalar IOR at ≈ 550 nm.

use super::params::SpecVal;
use crate::Rgb;

/// How a spectrum is used (decides normalisation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectrumUse {
    /// Reflectance in [0, 1] (clamped).
    Albedo,
    /// Unbounded material data (IOR, absorption).
    Unbounded,
    /// Emission: normalised to luminance 1 (except RGB, kept as given).
    Illuminant,
}

fn lobe(l: f64, mu: f64, s1: f64, s2: f64) -> f64 {
    let t = (l - mu) / if l < mu { s1 } else { s2 };
    (-0.5 * t * t).exp()
}

/// CIE 1931 2° colour matching functions (Wyman et al. 2013 multi-lobe fit).
pub fn cie_xyz(lambda_nm: f64) -> [f64; 3] {
    let l = lambda_nm;
    let x = 1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7)
        - 0.065 * lobe(l, 501.1, 20.4, 26.2);
    let y = 0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1);
    let z = 1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8);
    [x, y, z]
}

fn xyz_to_srgb(c: [f64; 3]) -> [f64; 3] {
    let [x, y, z] = c;
    [
        3.2406 * x - 1.5372 * y - 0.4986 * z,
        -0.9689 * x + 1.8758 * y + 0.0415 * z,
        0.0557 * x - 0.2040 * y + 1.0570 * z,
    ]
}

fn project(s: impl Fn(f64) -> f64) -> [f64; 3] {
    let mut acc = [0.0; 3];
    for i in 360..=830 {
        let l = i as f64;
        let v = s(l);
        let c = cie_xyz(l);
        for k in 0..3 {
            acc[k] += v * c[k];
        }
    }
    xyz_to_srgb(acc)
}

/// Linear sRGB of spectrum `s(λ)`, white-balanced so that s ≡ 1 gives (1, 1, 1).
pub fn spectrum_to_rgb(s: impl Fn(f64) -> f64) -> Rgb {
    let white = project(|_| 1.0);
    let c = project(s);
    Rgb::new(
        (c[0] / white[0]) as f32,
        (c[1] / white[1]) as f32,
        (c[2] / white[2]) as f32,
    )
}

/// Planck's law: spectral radiance of a blackbody at `t_kelvin` (arbitrary units).
pub fn planck(lambda_nm: f64, t_kelvin: f64) -> f64 {
    const C: f64 = 299_792_458.0;
    const H: f64 = 6.626_070_15e-34;
    const KB: f64 = 1.380_649e-23;
    let l = lambda_nm * 1e-9;
    2.0 * H * C * C / (l.powi(5) * ((H * C / (l * KB * t_kelvin)).exp() - 1.0))
}

/// Linear sRGB of an emission spectrum, normalised to luminance 1 (no white balance).
pub fn illuminant_to_rgb(s: impl Fn(f64) -> f64) -> Rgb {
    let c = project(s);
    normalise_luminance(Rgb::new(c[0] as f32, c[1] as f32, c[2] as f32))
}

/// Normalised RGB colour of a blackbody at `t_kelvin` (luminance 1).
pub fn blackbody_rgb(t_kelvin: f32) -> Rgb {
    let t = t_kelvin as f64;
    illuminant_to_rgb(|l| planck(l, t))
}

fn normalise_luminance(c: Rgb) -> Rgb {
    let y = crate::luminance(c);
    if y > 0.0 && y.is_finite() {
        c / y
    } else {
        Rgb::ZERO
    }
}

/// Piecewise-linear interpolation of (λ, value) pairs, constant beyond the ends.
pub fn sampled_at(pairs: &[(f32, f32)], l: f64) -> f64 {
    let l = l as f32;
    match pairs {
        [] => 0.0,
        [(_, v)] => *v as f64,
        _ => {
            if l <= pairs[0].0 {
                return pairs[0].1 as f64;
            }
            for w in pairs.windows(2) {
                let ((l0, v0), (l1, v1)) = (w[0], w[1]);
                if l <= l1 {
                    let t = (l - l0) / (l1 - l0);
                    return (v0 + t * (v1 - v0)) as f64;
                }
            }
            pairs[pairs.len() - 1].1 as f64
        }
    }
}

/// Index of refraction at ≈ 550 nm of pbrt's named glasses.
pub fn named_glass_ior(name: &str) -> Option<f32> {
    Some(match name {
        "glass-BK7" => 1.5185,
        "glass-BAF10" => 1.6700,
        "glass-FK51A" => 1.4866,
        "glass-LASF9" => 1.8503,
        "glass-F5" => 1.6034,
        "glass-F10" => 1.7283,
        "glass-F11" => 1.7847,
        "fused-silica" | "glass-fused-silica" => 1.4599,
        _ => return None,
    })
}

/// Convert a spectrum parameter to RGB for `usage`. `Named` metal spectra return `None`
/// (the caller resolves them); unknown names return `None` too.
pub fn to_rgb(v: &SpecVal, usage: SpectrumUse) -> Option<Rgb> {
    let c = match v {
        SpecVal::Rgb(c) => return Some(clamp_for(*c, usage)),
        SpecVal::Blackbody(t) => blackbody_rgb(*t),
        SpecVal::Sampled(p) if usage == SpectrumUse::Illuminant => {
            illuminant_to_rgb(|l| sampled_at(p, l))
        }
        SpecVal::Sampled(p) => spectrum_to_rgb(|l| sampled_at(p, l)),
        SpecVal::Named(n) if n.starts_with("stdillum-") => Rgb::ONE,
        SpecVal::Named(n) => return named_glass_ior(n).map(Rgb::splat),
    };
    Some(clamp_for(c, usage))
}

fn clamp_for(c: Rgb, usage: SpectrumUse) -> Rgb {
    match usage {
        SpectrumUse::Albedo => c.clamp(Rgb::ZERO, Rgb::ONE),
        _ => c.max(Rgb::ZERO),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_spectrum_is_white_and_blackbody_6500k_is_near_white() {
        let w = spectrum_to_rgb(|_| 0.5);
        assert!((w - Rgb::splat(0.5)).abs().max_element() < 1e-5, "{w}");
        // 6500 K is close to D65: channels within 10% of each other.
        let c = blackbody_rgb(6500.0);
        assert!((crate::luminance(c) - 1.0).abs() < 1e-4);
        assert!(c.max_element() / c.min_element() < 1.15, "{c}");
        // Low temperatures are red, high ones blue.
        let warm = blackbody_rgb(2700.0);
        assert!(warm.x > warm.y && warm.y > warm.z, "{warm}");
        let cold = blackbody_rgb(12000.0);
        assert!(cold.z > cold.x, "{cold}");
    }

    #[test]
    fn sampled_spectra_interpolate_and_illuminants_normalise() {
        let p = vec![(400.0, 0.0), (700.0, 3.0)];
        assert_eq!(sampled_at(&p, 550.0), 1.5);
        assert_eq!(sampled_at(&p, 300.0), 0.0);
        assert_eq!(sampled_at(&p, 800.0), 3.0);
        let l = to_rgb(&SpecVal::Sampled(p), SpectrumUse::Illuminant).unwrap();
        assert!((crate::luminance(l) - 1.0).abs() < 1e-4);
        assert!(l.x > l.z, "increasing spectrum is reddish: {l}");
        let flat = to_rgb(
            &SpecVal::Sampled(vec![(300.0, 0.25), (900.0, 0.25)]),
            SpectrumUse::Albedo,
        );
        assert!((flat.unwrap() - Rgb::splat(0.25)).abs().max_element() < 1e-5);
    }

    #[test]
    fn named_spectra() {
        assert_eq!(
            to_rgb(
                &SpecVal::Named("stdillum-D65".into()),
                SpectrumUse::Illuminant
            ),
            Some(Rgb::ONE)
        );
        assert_eq!(
            to_rgb(&SpecVal::Named("glass-BK7".into()), SpectrumUse::Unbounded),
            Some(Rgb::splat(1.5185))
        );
        assert_eq!(
            to_rgb(
                &SpecVal::Named("metal-Cu-eta".into()),
                SpectrumUse::Unbounded
            ),
            None
        );
        assert_eq!(
            to_rgb(&SpecVal::Rgb(Rgb::new(2.0, 0.5, -1.0)), SpectrumUse::Albedo),
            Some(Rgb::new(1.0, 0.5, 0.0))
        );
    }
}
