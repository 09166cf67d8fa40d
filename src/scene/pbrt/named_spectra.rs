//! pbrt-v4's named spectra: every name pbrt-v4 defines is recognised; the tables the renderer
//! needs (metals, standard illuminants, daylight basis) are in `data/named_spectra.txt` (see
//! `data/NOTICE` for sources and licenses). The glasses are dispersive index tables in pbrt-v4;
//! penumbra renders RGB with one index per material and keeps their index at 550 nm. Camera
//! sensor curves (`canon_eos_*` …) are recognised for `Film "sensor"`, which approximates them
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

/// pbrt-v4's glasses with their index of refraction at 550 nm (Schott Sellmeier fits, as in
/// pbrt-v4's tables from refractiveindex.info, CC0).
const GLASSES: [(&str, f32); 7] = [
    ("glass-BK7", 1.5185),
    ("glass-BAF10", 1.6700),
    ("glass-FK51A", 1.4866),
    ("glass-LASF9", 1.8503),
    ("glass-F5", 1.6034),
    ("glass-F10", 1.7283),
    ("glass-F11", 1.7847),
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
    if GLASSES.iter().any(|(g, _)| *g == name) {
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

/// Index of refraction at 550 nm of a `glass-*` name.
pub fn glass_ior(name: &str) -> Option<f32> {
    GLASSES.iter().find(|(g, _)| *g == name).map(|(_, n)| *n)
}

/// The CIE daylight basis function `S0`, `S1` or `S2` (for white balance).
pub fn daylight_basis(which: &str) -> Vec<(f32, f32)> {
    table(&format!("cie-daylight-{which}")).unwrap_or_default()
}

/// Every spectrum name pbrt-v4 defines (for "unknown name" errors).
pub fn all_names() -> Vec<String> {
    let mut v: Vec<String> = GLASSES.iter().map(|(g, _)| g.to_string()).collect();
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
        assert_eq!(glass_ior("glass-BK7"), Some(1.5185));
        assert_eq!(kind("metal-Unobtainium-eta"), None);
        // Tables increase in wavelength (pbrt's PiecewiseLinearSpectrum requires it).
        for n in names.iter().filter(|n| spectrum(n).is_some()) {
            let t = spectrum(n).unwrap();
            assert!(t.windows(2).all(|w| w[1].0 > w[0].0), "{n}");
        }
        // Gold's eta at the first luxpop sample (pbrt-v4's Au_eta starts 298.757050, 1.795).
        assert_eq!(spectrum("metal-Au-eta").unwrap()[0], (298.75705, 1.795));
    }
}
