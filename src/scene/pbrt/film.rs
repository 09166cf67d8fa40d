//! `Film "rgb"`'s sensor: pbrt-v4's `PixelSensor::Create`. The imaging ratio is
//! exposure time × ISO / 100 (exposure time = the camera's `shutterclose − shutteropen`, or
//! the film's `exposuretime`), so `iso 100` with a 1 s exposure renders radiance as is. With
//! `whitebalance T` (T > 0) the image is von Kries-adapted (Bradford cone space) from the white
//! of the CIE daylight illuminant D at T (a blackbody below 4000 K, as pbrt-v4's `Spectra::D`)
//! to the sRGB white D65. pbrt-v4's camera sensors (`canon_eos_*` …) are fitted to XYZ over 24
//! colour-checker reflectances; penumbra renders RGB, so it approximates them by the CIE 1931
//! observer with the same white balance (default 6500 K for them, as pbrt-v4) and says so.

use super::named_spectra::{self, CAMERA_SENSORS};
use super::spectra::{illuminant_xyz, planck, sampled_at, srgb_to_xyz, xyz_to_srgb};
use super::textures::Warn;
use super::tokenizer::{Loc, err_at};
use crate::scene::film::SensorResponse;
use glam::{DMat3, DVec3, Mat3};

/// Chromaticity (x, y) of the sRGB white (D65).
const SRGB_WHITE: (f64, f64) = (0.3127, 0.3290);

/// Chromaticity (x, y) of pbrt-v4's `Spectra::D(temperature)`.
pub fn daylight_xy(temperature: f64) -> (f64, f64) {
    let cct = temperature * 1.4388 / 1.4380;
    let xyz = if cct < 4000.0 {
        illuminant_xyz(|l| planck(l, cct))
    } else {
        let x = if cct <= 7000.0 {
            -4.607e9 / cct.powi(3) + 2.9678e6 / (cct * cct) + 0.09911e3 / cct + 0.244063
        } else {
            -2.0064e9 / cct.powi(3) + 1.9018e6 / (cct * cct) + 0.24748e3 / cct + 0.23704
        };
        let y = -3.0 * x * x + 2.870 * x - 0.275;
        let m = 0.0241 + 0.2562 * x - 0.7341 * y;
        let m1 = (-1.3515 - 1.7703 * x + 5.9114 * y) / m;
        let m2 = (0.0300 - 31.4424 * x + 30.0717 * y) / m;
        let (s0, s1, s2) = (
            named_spectra::daylight_basis("S0"),
            named_spectra::daylight_basis("S1"),
            named_spectra::daylight_basis("S2"),
        );
        illuminant_xyz(|l| sampled_at(&s0, l) + m1 * sampled_at(&s1, l) + m2 * sampled_at(&s2, l))
    };
    let sum = xyz[0] + xyz[1] + xyz[2];
    (xyz[0] / sum, xyz[1] / sum)
}

fn xyz_of_xy((x, y): (f64, f64)) -> DVec3 {
    DVec3::new(x / y, 1.0, (1.0 - x - y) / y)
}

/// pbrt-v4's `WhiteBalance(src, dst)`: the Bradford von Kries adaptation, in XYZ.
pub fn bradford(src: (f64, f64), dst: (f64, f64)) -> DMat3 {
    // Rows of the Bradford matrix (glam stores columns, hence the transpose).
    let lms_from_xyz = DMat3::from_cols_array(&[
        0.8951, 0.2664, -0.1614, -0.7502, 1.7135, 0.0367, 0.0389, -0.0685, 1.0296,
    ])
    .transpose();
    let (s, d) = (lms_from_xyz * xyz_of_xy(src), lms_from_xyz * xyz_of_xy(dst));
    lms_from_xyz.inverse() * DMat3::from_diagonal(d / s) * lms_from_xyz
}

fn srgb_matrix(f: fn([f64; 3]) -> [f64; 3]) -> DMat3 {
    DMat3::from_cols(
        DVec3::from(f([1.0, 0.0, 0.0])),
        DVec3::from(f([0.0, 1.0, 0.0])),
        DVec3::from(f([0.0, 0.0, 1.0])),
    )
}

/// The white-balance matrix on linear sRGB adapting the white of D(`temperature`) to D65.
pub fn white_balance_srgb(temperature: f64) -> DMat3 {
    srgb_matrix(xyz_to_srgb)
        * bradford(daylight_xy(temperature), SRGB_WHITE)
        * srgb_matrix(srgb_to_xyz)
}

/// The film's parameters that decide its response.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorParams {
    /// `iso` (default 100).
    pub iso: f32,
    /// `whitebalance` in kelvin (0 = none).
    pub white_balance: f32,
    /// `sensor` (default "cie1931").
    pub sensor: String,
    /// Exposure time in seconds.
    pub exposure_time: f32,
}

impl Default for SensorParams {
    fn default() -> Self {
        Self {
            iso: 100.0,
            white_balance: 0.0,
            sensor: "cie1931".into(),
            exposure_time: 1.0,
        }
    }
}

/// pbrt-v4's `PixelSensor::Create` as a linear-RGB response.
pub fn sensor_response(
    p: &SensorParams,
    loc: &Loc,
    warn: &mut Warn,
) -> anyhow::Result<SensorResponse> {
    if !(p.iso.is_finite() && p.iso > 0.0) {
        return Err(err_at(
            loc,
            format!("Film: 'iso' must be positive, found {}", p.iso),
        ));
    }
    if !(p.exposure_time.is_finite() && p.exposure_time > 0.0) {
        return Err(err_at(
            loc,
            format!("exposure time must be positive, found {}", p.exposure_time),
        ));
    }
    if !(p.white_balance.is_finite() && p.white_balance >= 0.0) {
        return Err(err_at(
            loc,
            format!(
                "Film: 'whitebalance' must be ≥ 0 K, found {}",
                p.white_balance
            ),
        ));
    }
    let mut wb = p.white_balance;
    if p.sensor != "cie1931" {
        if !CAMERA_SENSORS.contains(&p.sensor.as_str()) {
            return Err(err_at(
                loc,
                format!(
                    "Film: unknown sensor \"{}\" (expected cie1931 or one of {})",
                    p.sensor,
                    CAMERA_SENSORS.join(", ")
                ),
            ));
        }
        if wb == 0.0 {
            wb = 6500.0;
        }
        warn(
            "film-sensor",
            loc,
            format!(
                "Film sensor \"{}\" approximated by the CIE 1931 observer white-balanced at {wb} K (penumbra renders RGB, not the camera's spectral curves)",
                p.sensor
            ),
        );
    }
    let ratio = (p.exposure_time as f64) * (p.iso as f64) / 100.0;
    let m = if wb > 0.0 {
        white_balance_srgb(wb as f64) * ratio
    } else {
        DMat3::from_diagonal(DVec3::splat(ratio))
    };
    let matrix = if m == DMat3::IDENTITY {
        Mat3::IDENTITY
    } else {
        m.as_mat3()
    };
    Ok(SensorResponse { matrix })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Rgb;

    fn resp(p: SensorParams) -> Mat3 {
        let loc = Loc {
            file: "f.pbrt".into(),
            line: 1,
            col: 1,
        };
        sensor_response(&p, &loc, &mut |_: &str, _: &Loc, _: String| {})
            .unwrap()
            .matrix
    }

    #[test]
    fn imaging_ratio_is_exposure_times_iso_over_100() {
        assert_eq!(resp(SensorParams::default()), Mat3::IDENTITY);
        let iso200 = resp(SensorParams {
            iso: 200.0,
            ..Default::default()
        });
        assert_eq!(iso200, Mat3::from_diagonal(glam::Vec3::splat(2.0)));
        let short = resp(SensorParams {
            iso: 400.0,
            exposure_time: 0.125,
            ..Default::default()
        });
        assert_eq!(short, Mat3::from_diagonal(glam::Vec3::splat(0.5)));
    }

    #[test]
    fn white_balance_maps_the_illuminant_white_to_white() {
        // D(6500) is within a hair of D65: almost the identity.
        let m = white_balance_srgb(6500.0);
        assert!(
            (m - DMat3::IDENTITY)
                .to_cols_array()
                .iter()
                .all(|x| x.abs() < 0.01),
            "{m}"
        );
        // A surface lit by a 3000 K light (white balanced at 3000 K) comes out neutral.
        let warm = illuminant_xyz(|l| planck(l, 3000.0 * 1.4388 / 1.4380));
        let rgb = DVec3::from(xyz_to_srgb(warm));
        let out = white_balance_srgb(3000.0) * rgb;
        assert!(
            (out.x / out.y - 1.0).abs() < 1e-3 && (out.z / out.y - 1.0).abs() < 1e-3,
            "{out}"
        );
        // The CIE formula for D65's chromaticity (0.3127, 0.3290) at 6504 K.
        let (x, y) = daylight_xy(6504.0 * 1.4380 / 1.4388);
        assert!(
            (x - 0.3127).abs() < 1e-3 && (y - 0.3290).abs() < 1e-3,
            "{x} {y}"
        );
        let _ = Rgb::ONE;
    }

    #[test]
    fn camera_sensors_are_recognised_and_others_refused() {
        let loc = Loc {
            file: "f.pbrt".into(),
            line: 3,
            col: 1,
        };
        let mut warned = Vec::new();
        let p = SensorParams {
            sensor: "canon_eos_5d_mkiv".into(),
            ..Default::default()
        };
        let r =
            sensor_response(&p, &loc, &mut |_: &str, _: &Loc, m: String| warned.push(m)).unwrap();
        assert!(!r.is_identity(), "white balanced at 6500 K");
        assert_eq!(warned.len(), 1);
        let bad = SensorParams {
            sensor: "kodak_brownie".into(),
            ..Default::default()
        };
        let e = sensor_response(&bad, &loc, &mut |_: &str, _: &Loc, _: String| {})
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("f.pbrt:3:1:") && e.contains("canon_eos_100d"),
            "{e}"
        );
    }
}
