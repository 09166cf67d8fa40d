//! Spectra → linear sRGB, the way pbrt-v4's spectral result comes out on its RGB film.
//!
//! Method (stated, as the issue asks). A spectrum S(λ) is projected onto the tabulated CIE 1931
//! colour matching functions (1 nm, 360–830 nm, `cie_data`) and the XYZ converted to linear
//! sRGB (D65 white):
//! - **reflectances** are seen under the sRGB white D65, which is what pbrt-v4 renders when
//!   the lights are RGB (its RGB illuminant spectra are the colour space's D65 times the RGB):
//!   rgb = M·∫S·D65·x̄ / ∫D65·ȳ, then divided per channel by the result for S ≡ 1 (which M
//!   already maps to white within 1e-3), so a flat spectrum is exactly grey;
//! - **illuminants** (blackbody, `stdillum-*`, sampled/`.spd` emission) are normalised to
//!   luminance 1, as pbrt-v4 divides light spectra by their photometric integral
//!   (`SpectrumToPhotometric`): rgb = M·∫S·x̄ / ∫S·ȳ — the light's `scale`/`power` then sets the
//!   brightness;
//! - **conductors** (η, k spectra) are reduced by [`conductor_rgb`] so that the RGB Fresnel
//!   reflectance at normal incidence equals the reflectance spectrum of the metal converted as
//!   above (what a spectral renderer shows head-on) and stays within 0.03 of it up to 80°;
//! - sampled spectra are piecewise linear and zero outside their wavelengths
//!   (pbrt-v4's `PiecewiseLinearSpectrum`).

use super::cie_data::{CIE_LAMBDA_MIN, CIE_XYZ};
use super::named_spectra::{self, NamedKind};
use super::params::SpecVal;
use crate::Rgb;
use crate::bsdf::fresnel::fr_complex;

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

/// CIE 1931 2° colour matching functions at `lambda_nm` (linear between 1 nm samples, 0
/// outside 360–830 nm).
pub fn cie_xyz(lambda_nm: f64) -> [f64; 3] {
    let x = lambda_nm - CIE_LAMBDA_MIN;
    if !(0.0..=(CIE_XYZ.len() - 1) as f64).contains(&x) {
        return [0.0; 3];
    }
    let i = (x.floor() as usize).min(CIE_XYZ.len() - 2);
    let t = x - i as f64;
    let (a, b) = (CIE_XYZ[i], CIE_XYZ[i + 1]);
    [0, 1, 2].map(|c| a[c] + t * (b[c] - a[c]))
}

/// XYZ → linear sRGB (IEC 61966-2-1, D65).
pub fn xyz_to_srgb(c: [f64; 3]) -> [f64; 3] {
    let [x, y, z] = c;
    [
        3.2404542 * x - 1.5371385 * y - 0.4985314 * z,
        -0.9692660 * x + 1.8760108 * y + 0.0415560 * z,
        0.0556434 * x - 0.2040259 * y + 1.0572252 * z,
    ]
}

/// Linear sRGB → XYZ (inverse of [`xyz_to_srgb`]).
pub fn srgb_to_xyz(c: [f64; 3]) -> [f64; 3] {
    let [r, g, b] = c;
    [
        0.4124564 * r + 0.3575761 * g + 0.1804375 * b,
        0.2126729 * r + 0.7151522 * g + 0.0721750 * b,
        0.0193339 * r + 0.1191920 * g + 0.9503041 * b,
    ]
}

/// ∫ s(λ)·w(λ)·(x̄, ȳ, z̄) dλ by the 1 nm rule over the CIE table (as pbrt-v4 integrates).
fn project(s: impl Fn(f64) -> f64, w: impl Fn(f64) -> f64) -> [f64; 3] {
    let mut acc = [0.0; 3];
    for (i, c) in CIE_XYZ.iter().enumerate() {
        let l = CIE_LAMBDA_MIN + i as f64;
        let v = s(l) * w(l);
        for k in 0..3 {
            acc[k] += v * c[k];
        }
    }
    acc
}

fn d65_table() -> Vec<(f32, f32)> {
    named_spectra::spectrum("stdillum-D65").unwrap_or_default()
}

fn reflectance_rgb_unbalanced(s: impl Fn(f64) -> f64, d65: &[(f32, f32)]) -> [f64; 3] {
    let d = |l: f64| sampled_at(d65, l);
    let y_white = project(|_| 1.0, d)[1];
    xyz_to_srgb(project(s, d).map(|v| v / y_white))
}

/// Linear sRGB of a reflectance spectrum seen under D65, so that s ≡ 1 gives (1, 1, 1).
pub fn spectrum_to_rgb(s: impl Fn(f64) -> f64) -> Rgb {
    let d65 = d65_table();
    let white = reflectance_rgb_unbalanced(|_| 1.0, &d65);
    let c = reflectance_rgb_unbalanced(s, &d65);
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

/// XYZ of an emission spectrum normalised to Y = 1 (zero if it has no luminance).
pub fn illuminant_xyz(s: impl Fn(f64) -> f64) -> [f64; 3] {
    let c = project(s, |_| 1.0);
    if c[1] > 0.0 && c[1].is_finite() {
        c.map(|v| v / c[1])
    } else {
        [0.0; 3]
    }
}

/// Linear sRGB of an emission spectrum, normalised to luminance 1 (no white balance).
pub fn illuminant_to_rgb(s: impl Fn(f64) -> f64) -> Rgb {
    let c = xyz_to_srgb(illuminant_xyz(s));
    Rgb::new(c[0] as f32, c[1] as f32, c[2] as f32)
}

/// Normalised RGB colour of a blackbody at `t_kelvin` (luminance 1).
pub fn blackbody_rgb(t_kelvin: f32) -> Rgb {
    let t = t_kelvin as f64;
    illuminant_to_rgb(|l| planck(l, t))
}

/// Piecewise-linear interpolation of (λ, value) pairs, zero outside their range (pbrt-v4's
/// `PiecewiseLinearSpectrum`; a single pair is a constant).
pub fn sampled_at(pairs: &[(f32, f32)], l: f64) -> f64 {
    match pairs {
        [] => 0.0,
        [(_, v)] => *v as f64,
        _ => {
            let (first, last) = (pairs[0].0 as f64, pairs[pairs.len() - 1].0 as f64);
            if l < first || l > last {
                return 0.0;
            }
            let i = pairs
                .partition_point(|p| (p.0 as f64) <= l)
                .clamp(1, pairs.len() - 1);
            let ((l0, v0), (l1, v1)) = (pairs[i - 1], pairs[i]);
            let t = (l - l0 as f64) / (l1 - l0) as f64;
            v0 as f64 + t * (v1 - v0) as f64
        }
    }
}

/// Index of refraction at 550 nm of pbrt's named glasses.
pub fn named_glass_ior(name: &str) -> Option<f32> {
    named_spectra::glass_ior(name)
}

/// Per-channel indices of refraction of pbrt's named glasses ([`dielectric_rgb`]).
pub fn named_glass_rgb(name: &str) -> Option<Rgb> {
    named_spectra::glass_index(name, 550.0)?;
    Some(dielectric_rgb(|l| {
        named_spectra::glass_index(name, l).unwrap_or(0.0)
    }))
}

/// The weight of wavelength `l` in RGB channel `c`: the positive part of the channel's sRGB
/// colour matching function under D65 (`d65`), the weight [`conductor_rgb`] averages η with.
fn channel_weight(c: usize, l: f64, d65: &[(f32, f32)]) -> f64 {
    xyz_to_srgb(cie_xyz(l))[c].max(0.0) * sampled_at(d65, l)
}

/// One index of refraction per RGB channel for a dispersive dielectric whose index is `eta(λ)`:
/// the mean of η(λ) over the channel's weight ([`channel_weight`]), over the wavelengths where
/// η is defined (> 0; a sampled spectrum is 0 outside its range); 1 where it is nowhere.
///
/// Why this mean: a spectral renderer's channel c is ∫ L_λ w_c(λ) dλ, and each wavelength leaves
/// a refraction at its own angle; one direction per channel can only stand for the centroid of
/// those, and the deviation is close to linear in η over a channel, so the centroid is the
/// direction of the channel's mean η. The same weighting reduces conductors' η
/// ([`conductor_rgb`]), so a glass and a metal given by spectra are reduced alike. It amounts
/// to the index at the centroids of the channels' weights, ≈ 600 nm (R), 539 nm (G), 453 nm (B),
/// within 3e-4 for BK7 and 1.2e-3 for the dense flint F11 (`tests::dielectric_channels`); the
/// red channel's small second lobe in the violet pulls its centroid below the sRGB red
/// primary's dominant 611 nm.
pub fn dielectric_rgb(eta: impl Fn(f64) -> f64) -> Rgb {
    let d65 = d65_table();
    let mut out = [1.0f32; 3];
    for (c, o) in out.iter_mut().enumerate() {
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..CIE_XYZ.len() {
            let l = CIE_LAMBDA_MIN + i as f64;
            let n = eta(l);
            if n > 0.0 && n.is_finite() {
                let w = channel_weight(c, l, &d65);
                num += w * n;
                den += w;
            }
        }
        if den > 0.0 {
            *o = (num / den) as f32;
        }
    }
    Rgb::from_array(out)
}

/// RGB (η, k) of a conductor given as spectra: the RGB Fresnel reflectance at normal incidence
/// equals the metal's spectral normal-incidence reflectance converted like a reflectance
/// ([`spectrum_to_rgb`]), with η per channel the average of η(λ) over the channel's (positive)
/// response under D65, and k solved to hit that reflectance. Rationale: a spectral renderer
/// (pbrt-v4) evaluates the Fresnel equations per wavelength, so the colour users see is the
/// converted reflectance spectrum; converting η and k spectra separately (Mitsuba 3's RGB mode)
/// gets the head-on colour of gold wrong by several percent (measured in the tests).
pub fn conductor_rgb(eta: &[(f32, f32)], k: &[(f32, f32)]) -> (Rgb, Rgb) {
    let r0 = |l: f64| {
        let (n, kk) = (sampled_at(eta, l), sampled_at(k, l));
        ((n - 1.0).powi(2) + kk * kk) / ((n + 1.0).powi(2) + kk * kk)
    };
    let target = spectrum_to_rgb(r0);
    let d65 = d65_table();
    let mut eta_c = [0.0f32; 3];
    let mut k_c = [0.0f32; 3];
    for c in 0..3 {
        let resp = |l: f64| {
            let m = xyz_to_srgb(cie_xyz(l));
            m[c].max(0.0) * sampled_at(&d65, l)
        };
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..CIE_XYZ.len() {
            let l = CIE_LAMBDA_MIN + i as f64;
            num += resp(l) * sampled_at(eta, l);
            den += resp(l);
        }
        let n = if den > 0.0 {
            (num / den).max(1e-3)
        } else {
            1.0
        };
        let r = (target[c] as f64).clamp(0.0, 0.9999);
        let k2 = (r * (n + 1.0).powi(2) - (n - 1.0).powi(2)) / (1.0 - r);
        if k2 >= 0.0 {
            eta_c[c] = n as f32;
            k_c[c] = k2.sqrt() as f32;
        } else {
            // Less reflective than a dielectric of that index: a dielectric-like channel.
            let s = r.sqrt();
            eta_c[c] = ((1.0 + s) / (1.0 - s)) as f32;
            k_c[c] = 0.0;
        }
    }
    (Rgb::from_array(eta_c), Rgb::from_array(k_c))
}

/// Spectral Fresnel reflectance of a conductor at incidence cosine `cos`, converted to RGB like
/// a reflectance (the reference [`conductor_rgb`] is checked against).
pub fn conductor_reflectance_rgb(eta: &[(f32, f32)], k: &[(f32, f32)], cos: f32) -> Rgb {
    spectrum_to_rgb(|l| fr_complex(cos, sampled_at(eta, l) as f32, sampled_at(k, l) as f32) as f64)
}

/// Convert a spectrum parameter to RGB for `usage`. Metal names return `None` (the conductor
/// resolves its η/k pair with [`conductor_rgb`]); so do names pbrt-v4 does not define.
pub fn to_rgb(v: &SpecVal, usage: SpectrumUse) -> Option<Rgb> {
    let c = match v {
        SpecVal::Rgb(c) => return Some(clamp_for(*c, usage)),
        SpecVal::Blackbody(t) => blackbody_rgb(*t),
        SpecVal::Sampled(p) if usage == SpectrumUse::Illuminant => {
            illuminant_to_rgb(|l| sampled_at(p, l))
        }
        SpecVal::Sampled(p) => spectrum_to_rgb(|l| sampled_at(p, l)),
        SpecVal::Named(n) => match named_spectra::kind(n)? {
            NamedKind::Glass => Rgb::splat(named_glass_ior(n)?),
            NamedKind::Illuminant => {
                let t = named_spectra::spectrum(n)?;
                if usage == SpectrumUse::Illuminant {
                    illuminant_to_rgb(|l| sampled_at(&t, l))
                } else {
                    spectrum_to_rgb(|l| sampled_at(&t, l))
                }
            }
            NamedKind::Metal => return None,
        },
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
        assert!((crate::luminance(c) - 1.0).abs() < 2e-3, "{c}");
        assert!(c.max_element() / c.min_element() < 1.15, "{c}");
        let warm = blackbody_rgb(2700.0);
        assert!(warm.x > warm.y && warm.y > warm.z, "{warm}");
        let cold = blackbody_rgb(12000.0);
        assert!(cold.z > cold.x, "{cold}");
    }

    #[test]
    fn srgb_matrices_are_inverse_and_d65_is_white() {
        let x = srgb_to_xyz(xyz_to_srgb([0.3, 0.5, 0.7]));
        assert!((x[0] - 0.3).abs() + (x[1] - 0.5).abs() + (x[2] - 0.7).abs() < 1e-6);
        // The CIE D65 table through the CIE table and the sRGB matrix lands on white.
        let d = to_rgb(
            &SpecVal::Named("stdillum-D65".into()),
            SpectrumUse::Illuminant,
        )
        .unwrap();
        assert!((d - Rgb::ONE).abs().max_element() < 3e-3, "{d}");
        // Illuminant A (2856 K) is orange and the same colour as a 2856 K blackbody.
        let a = to_rgb(
            &SpecVal::Named("stdillum-A".into()),
            SpectrumUse::Illuminant,
        )
        .unwrap();
        let bb = blackbody_rgb(2856.0);
        assert!((a - bb).abs().max_element() < 0.01, "{a} vs {bb}");
        assert!(a.x > 1.2 && a.z < 0.5, "{a}");
    }

    #[test]
    fn sampled_spectra_interpolate_and_illuminants_normalise() {
        let p = vec![(400.0, 0.0), (700.0, 3.0)];
        assert_eq!(sampled_at(&p, 550.0), 1.5);
        assert_eq!(sampled_at(&p, 300.0), 0.0);
        assert_eq!(sampled_at(&p, 800.0), 0.0, "zero outside, as pbrt-v4");
        let l = to_rgb(&SpecVal::Sampled(p), SpectrumUse::Illuminant).unwrap();
        assert!((crate::luminance(l) - 1.0).abs() < 2e-3, "{l}");
        assert!(l.x > l.z, "increasing spectrum is reddish: {l}");
        let flat = to_rgb(
            &SpecVal::Sampled(vec![(300.0, 0.25), (900.0, 0.25)]),
            SpectrumUse::Albedo,
        );
        assert!((flat.unwrap() - Rgb::splat(0.25)).abs().max_element() < 1e-5);
    }

    /// The per-channel indices of the glasses: blue > green > red (normal dispersion), green
    /// within 3e-3 of 550 nm, each the index at the centroid wavelength of its channel's weight
    /// to 1.5e-3 (measured: 2.5e-4 for BK7, 1.2e-3 for F11's red, whose weight's violet lobe
    /// meets the steep part of η(λ)).
    #[test]
    fn dielectric_channels() {
        let d65 = d65_table();
        let centroid = |c: usize| {
            let (mut num, mut den) = (0.0, 0.0);
            for i in 0..CIE_XYZ.len() {
                let l = CIE_LAMBDA_MIN + i as f64;
                num += channel_weight(c, l, &d65) * l;
                den += channel_weight(c, l, &d65);
            }
            num / den
        };
        let lc = [centroid(0), centroid(1), centroid(2)];
        eprintln!("channel centroids: {lc:?} nm");
        // Measured: 600.2, 539.1, 453.4 nm.
        assert!((595.0..605.0).contains(&lc[0]), "{lc:?}");
        assert!((535.0..545.0).contains(&lc[1]), "{lc:?}");
        assert!((448.0..458.0).contains(&lc[2]), "{lc:?}");
        for g in ["glass-BK7", "glass-F11", "glass-FK51A", "glass-LASF9"] {
            let n = named_glass_rgb(g).unwrap();
            let at = |l: f64| named_spectra::glass_index(g, l).unwrap() as f32;
            eprintln!(
                "{g}: {n} (at the centroids {} {} {})",
                at(lc[0]),
                at(lc[1]),
                at(lc[2])
            );
            assert!(n.z > n.y && n.y > n.x, "{g}: {n}");
            assert!((n.y - at(550.0)).abs() < 3e-3, "{g}: {n}");
            for c in 0..3 {
                assert!((n[c] - at(lc[c])).abs() < 1.5e-3, "{g} channel {c}: {n}");
            }
        }
        assert_eq!(named_glass_rgb("glass-nonsense"), None);
        // A constant index stays exactly constant (no dispersion where there is none).
        assert_eq!(dielectric_rgb(|_| 1.5), Rgb::splat(1.5));
        // A sampled index counts only where it is defined.
        let p = vec![(500.0, 1.6), (600.0, 1.6)];
        assert_eq!(dielectric_rgb(|l| sampled_at(&p, l)), Rgb::splat(1.6));
        assert_eq!(dielectric_rgb(|_| 0.0), Rgb::ONE);
    }

    #[test]
    fn named_spectra() {
        assert_eq!(
            to_rgb(&SpecVal::Named("glass-BK7".into()), SpectrumUse::Unbounded),
            named_glass_ior("glass-BK7").map(Rgb::splat)
        );
        assert_eq!(
            to_rgb(
                &SpecVal::Named("metal-Cu-eta".into()),
                SpectrumUse::Unbounded
            ),
            None
        );
        assert_eq!(
            to_rgb(&SpecVal::Named("nonsense".into()), SpectrumUse::Unbounded),
            None
        );
        assert_eq!(
            to_rgb(&SpecVal::Rgb(Rgb::new(2.0, 0.5, -1.0)), SpectrumUse::Albedo),
            Some(Rgb::new(1.0, 0.5, 0.0))
        );
    }

    /// The RGB (η, k) of pbrt's metals against the spectrally integrated Fresnel reflectance:
    /// exact head-on (up to the sRGB gamut), within 0.03 up to 80°; the per-channel η/k averaging of an RGB renderer
    /// (Mitsuba 3's RGB mode converts η and k spectra separately) is measurably further off.
    #[test]
    fn conductor_rgb_matches_the_spectral_fresnel() {
        for m in ["Au", "Cu", "Ag", "Al"] {
            let eta = named_spectra::spectrum(&format!("metal-{m}-eta")).unwrap();
            let k = named_spectra::spectrum(&format!("metal-{m}-k")).unwrap();
            let (e, kk) = conductor_rgb(&eta, &k);
            let naive_e = spectrum_to_rgb(|l| sampled_at(&eta, l));
            let naive_k = spectrum_to_rgb(|l| sampled_at(&k, l));
            let mut worst = 0.0f32;
            let mut naive_head_on = 0.0f32;
            for deg in [0.0f32, 20.0, 40.0, 60.0, 70.0, 80.0] {
                let cos = deg.to_radians().cos();
                // Gold's red is outside the sRGB gamut (1.02 head-on): an RGB reflectance
                // cannot exceed 1, so the reference is clamped there.
                let reference = conductor_reflectance_rgb(&eta, &k, cos).min(Rgb::ONE);
                let ours = crate::bsdf::fresnel::fr_complex_rgb(cos, e, kk);
                let err = (ours - reference).abs().max_element();
                if deg == 0.0 {
                    assert!(err < 2e-4, "{m} head-on: {ours} vs {reference}");
                    let naive = crate::bsdf::fresnel::fr_complex_rgb(cos, naive_e, naive_k);
                    naive_head_on = (naive - reference).abs().max_element();
                }
                worst = worst.max(err);
            }
            // Measured: Au 0.015, Cu 0.029 (at 80°), Ag/Al smaller.
            assert!(worst < 0.03, "{m}: worst {worst}");
            if m == "Au" || m == "Cu" {
                // Measured: Au 0.025, Cu 0.0097 head-on for the separate η/k conversion.
                assert!(
                    naive_head_on > 0.009,
                    "{m}: naive head-on error {naive_head_on}"
                );
            }
        }
        // Gold is gold: red > green > blue at normal incidence.
        let eta = named_spectra::spectrum("metal-Au-eta").unwrap();
        let k = named_spectra::spectrum("metal-Au-k").unwrap();
        let r = conductor_reflectance_rgb(&eta, &k, 1.0);
        assert!(r.x > r.y && r.y > r.z && r.x > 0.9, "{r}");
    }
}
