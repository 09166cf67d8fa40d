//! pbrt-v4's named spectra: every name pbrt-v4 defines is recognised; the tables the renderer
//! needs (metals, standard illuminants, daylight basis) are in `data/named_spectra.txt` (see
//! `data/NOTICE` for sources and licenses). The glasses are dispersive indices of refraction,
//! given by their Sellmeier formulas (pbrt-v4 tabulates the same formulas); a `dielectric`
//! reduces them to one index per RGB channel (`spectra::dielectric_rgb`). Camera
//! //! sensor curves (`canon_eos_*` …) are recognised for `Film "sensor"`, which approximates them
//! by the CIE 1931 observer (see `film`).

const DATA: &str = include_str!("data/named_spectra.txt");

/// What a named spectrum is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NamedKind {
    /// A conductor's eta or k table (`metal-*-eta`, `metal-*-k`).
    Metal,
    /// A glass index of refraction (`glass-*`).
    Glass,
    /// A light emission spectrum (`stdillum-*`, `illum-acesD60`).
    Illuminant,
}

/// Sellmeier coefficients (B₁, B₂, B₃; C₁, C₂, C₃ in µm²) of pbrt-v4's glasses: Schott's
/// catalogue as refractiveindex.info gives it (CC0), the source of pbrt-v4's `Glass*_eta`
/// tables (which sample these formulas; e.g. BK7 at 300 nm: 1.552770 both). pbrt-v4's
/// `glass-F5`, `glass-F10`, `glass-F11` are Schott's dense flints SF5, SF10, SF11.
const GLASSES: [(&str, [f64; 3], [f64; 3]); 7] = [
    (
        "glass-BK7",
        [1.03961212, 0.231792344, 1.01046945],
        [0.00600069867, 0.0200179144, 103.560653],
    ),
    (
        "glass-BAF10",
        [1.5851495, 0.143559385, 1.08521269],
        [0.00926681282, 0.0424489805, 105.613573],
    ),
    (
        "glass-FK51A",
        [0.971247817, 0.216901417, 0.904651666],
        [0.00472301995, 0.0153575612, 168.68133],
    ),
    (
        "glass-LASF9",
        [2.00029547, 0.298926886, 1.80691843],
        [0.0121426017, 0.0538736236, 156.530829],
    ),
    (
        "glass-F5",
        [1.52481889, 0.187085527, 1.42729015],
        [0.011254756, 0.0588995392, 129.141675],
    ),
    (
        "glass-F10",
        [1.61625977, 0.259229334, 1.07762317],
        [0.0127534559, 0.0581983954, 116.60768],
    ),
    (
        "glass-F11",
        [1.73759695, 0.313747346, 1.89878101],
        [0.013188707, 0.0623068142, 155.23629],
    ),
];

/// Camera models whose `_r`, `_g`, `_b` sensor curves pbrt-v4 ships (`Film "sensor"`).
pub const CAMERA_SENSORS: [&str; 17] = [
    "canon_eos_100d",
    "canon_eos_1dx_mkii",
    "canon_eos_200d",
    "canon_eos_200d_mkii",
    "canon_eos_5d",
    "canon_eos_5d_mkii",
    "canon_eos_5d_mkiii",
    "canon_eos_5d_mkiv",
    "canon_eos_5ds",
    "canon_eos_m",
    "hasselblad_l1d_20c",
    "nikon_d810",
    "nikon_d850",
    "sony_ilce_6400",
    "sony_ilce_7m3",
    "sony_ilce_7rm3",
    "sony_ilce_9",
];

/// The (λ nm, value) table stored under `name` in the data file.
fn table(name: &str) -> Option<Vec<(f32, f32)>> {
    let header = format!("name {name}\n");
    let start = DATA.find(&header)? + header.len();
    let body = &DATA[start..];
    let end = body.find("name ").unwrap_or(body.len());
    let pairs = body[..end]
        .lines()
        .filter_map(|l| {
            let mut it = l.split_whitespace();
            Some((it.next()?.parse().ok()?, it.next()?.parse().ok()?))
        })
        .collect();
    Some(pairs)
}

/// Kind of a pbrt-v4 named spectrum, `None` if pbrt-v4 does not define the name.
pub fn kind(name: &str) -> Option<NamedKind> {
    if GLASSES.iter().any(|(g, ..)| *g == name) {
        return Some(NamedKind::Glass);
    }
    if name.starts_with("metal-") && table(name).is_some() {
        return Some(NamedKind::Metal);
    }
    if (name.starts_with("stdillum-") || name == "illum-acesD60") && table(name).is_some() {
        return Some(NamedKind::Illuminant);
    }
    None
}

/// The tabulated spectrum of a metal or illuminant name.
pub fn spectrum(name: &str) -> Option<Vec<(f32, f32)>> {
    match kind(name)? {
        NamedKind::Metal | NamedKind::Illuminant => table(name),
        NamedKind::Glass => None,
    }
}

/// Index of refraction of a `glass-*` name at `lambda_nm` (Sellmeier:
/// n² = 1 + Σ Bᵢ λ² / (λ² − Cᵢ), λ in µm).
pub fn glass_index(name: &str, lambda_nm: f64) -> Option<f64> {
    let (_, b, c) = GLASSES.iter().find(|(g, ..)| *g == name)?;
    let l2 = (lambda_nm * 1e-3).powi(2);
    let s: f64 = (0..3).map(|i| b[i] * l2 / (l2 - c[i])).sum();
    Some((1.0 + s).sqrt())
}

/// Index of refraction at 550 nm of a `glass-*` name.
pub fn glass_ior(name: &str) -> Option<f32> {
    glass_index(name, 550.0).map(|n| n as f32)
}

/// The CIE daylight basis function `S0`, `S1` or `S2` (for white balance).
pub fn daylight_basis(which: &str) -> Vec<(f32, f32)> {
    table(&format!("cie-daylight-{which}")).unwrap_or_default()
}

/// Every spectrum name pbrt-v4 defines (for "unknown name" errors).
pub fn all_names() -> Vec<String> {
    let mut v: Vec<String> = GLASSES.iter().map(|(g, ..)| g.to_string()).collect();
    for l in DATA.lines() {
        if let Some(n) = l.strip_prefix("name ")
            && !n.starts_with("cie-")
        {
            v.push(n.to_string());
        }
    }
    for c in CAMERA_SENSORS {
        for ch in ["r", "g", "b"] {
            v.push(format!("{c}_{ch}"));
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_pbrt_v4_name_is_known() {
        let names = all_names();
        // pbrt-v4's list: 7 glasses, 12 metal tables, 15 standard illuminants + ACES D60,
        // 17 cameras × 3 channels.
        assert_eq!(names.len(), 7 + 12 + 16 + 17 * 3, "{names:?}");
        for n in [
            "metal-Au-eta",
            "metal-TiO2-k",
            "stdillum-F12",
            "illum-acesD60",
        ] {
            assert!(spectrum(n).is_some_and(|t| t.len() > 20), "{n}");
        }
        assert!((glass_ior("glass-BK7").unwrap() - 1.51852).abs() < 1e-5);
        assert_eq!(kind("metal-Unobtainium-eta"), None);
        // Tables increase in wavelength (pbrt's PiecewiseLinearSpectrum requires it).
        for n in names.iter().filter(|n| spectrum(n).is_some()) {
            let t = spectrum(n).unwrap();
            assert!(t.windows(2).all(|w| w[1].0 > w[0].0), "{n}");
        }
        // Gold's eta at the first luxpop sample (pbrt-v4's Au_eta starts 298.757050, 1.795).
        assert_eq!(spectrum("metal-Au-eta").unwrap()[0], (298.75705, 1.795));
    }

    /// The Sellmeier formulas against Schott's catalogue indices nd (587.56 nm), the
    /// numbers every glass is known by, and pbrt-v4's first table sample of BK7.
    #[test]
    fn glass_indices_match_the_catalogue() {
        for (name, nd) in [
            ("glass-BK7", 1.51680),
            ("glass-BAF10", 1.67003),
            ("glass-FK51A", 1.48656),
            ("glass-LASF9", 1.85025),
            ("glass-F5", 1.67271),
            ("glass-F10", 1.72825),
            ("glass-F11", 1.78472),
        ] {
            let n = glass_index(name, 587.5618).unwrap();
            assert!((n - nd).abs() < 2e-5, "{name}: {n} vs nd {nd}");
            // Normal dispersion: the index falls with wavelength.
            let (blue, red) = (glass_index(name, 450.0), glass_index(name, 650.0));
            assert!(blue.unwrap() > n && n > red.unwrap(), "{name}");
        }
        assert!((glass_index("glass-BK7", 300.0).unwrap() - 1.5527702635739).abs() < 1e-6);
        assert_eq!(glass_index("glass-XYZ", 550.0), None);
    }
}
