//! Metrics on hand-computed tiny images, error-map colours, and the `compare` CLI.

use std::path::PathBuf;
use std::process::Command;

use penumbra::Rgb;
use penumbra::image::colormap::viridis;
use penumbra::image::metrics::ERROR_IMAGE_LOG10_RANGE;
use penumbra::image::{Image, compare, error_image, write_image};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-image-met-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// 2x1 images: test = [(1,2,3), (0,0,0)], ref = [(1,1,1), (0.1,0,0)].
fn pair() -> (Image, Image) {
    let t = Image {
        width: 2,
        height: 1,
        pixels: vec![Rgb::new(1.0, 2.0, 3.0), Rgb::ZERO],
    };
    let r = Image {
        width: 2,
        height: 1,
        pixels: vec![Rgb::ONE, Rgb::new(0.1, 0.0, 0.0)],
    };
    (t, r)
}

#[test]
fn metrics_match_hand_computation() {
    let (t, r) = pair();
    let s = compare(&t, &r).unwrap();
    // Differences: 0, 1, 2, -0.1, 0, 0 (six channel values).
    let f = |x: f32| x as f64; // the images hold f32; 0.1f32 is not 0.1
    let d = [0.0, 1.0, 2.0, -f(0.1), 0.0, 0.0];
    let b = [1.0, 1.0, 1.0, f(0.1), 0.0, 0.0];
    let mse = d.iter().map(|x| x * x).sum::<f64>() / 6.0;
    let mae = d.iter().map(|x: &f64| x.abs()).sum::<f64>() / 6.0;
    let rel = d.iter().zip(&b).map(|(d, b)| d * d / (b * b + 0.01)).sum::<f64>() / 6.0;
    assert!((s.mse - mse).abs() < 1e-12, "{s:?}");
    assert!((s.mae - mae).abs() < 1e-12, "{s:?}");
    assert!((s.rel_mse - rel).abs() < 1e-12, "{s:?}");
    // Spot-check against decimal arithmetic: mse = 5.01/6, rel = (1+4)/1.01/6 + 0.01/0.02/6.
    assert!((s.mse - 5.01 / 6.0).abs() < 1e-8);
    assert!((s.rel_mse - (5.0 / 1.01 + 0.5) / 6.0).abs() < 1e-6);
    // Identical images: all zero.
    let z = compare(&r, &r).unwrap();
    assert_eq!((z.mse, z.rel_mse, z.mae), (0.0, 0.0, 0.0));
}

#[test]
fn size_mismatch_is_a_clear_error() {
    let a = Image::new(4, 3);
    let b = Image::new(3, 4);
    let e = compare(&a, &b).unwrap_err().to_string();
    assert!(e.contains("4x3") && e.contains("3x4"), "{e}");
    assert!(error_image(&a, &b).is_err());
}

#[test]
fn viridis_matches_known_entries_and_brightens() {
    // Eight evenly spaced viridis samples (8-bit sRGB) as listed by plotters' `ViridisRGB`.
    let known: [[u8; 3]; 8] = [
        [68, 1, 84],
        [70, 50, 127],
        [54, 92, 141],
        [39, 127, 143],
        [31, 162, 136],
        [74, 194, 110],
        [160, 219, 57],
        [254, 232, 37],
    ];
    for (i, c) in known.iter().enumerate() {
        let t = i as f32 / 7.0;
        let v = viridis(t);
        for k in 0..3 {
            let err = (v[k] * 255.0 - c[k] as f32).abs();
            assert!(err < 4.0, "t={t}: {} vs {c:?}", v * 255.0);
        }
    }
    // Perceptual ordering: luminance strictly increases along the map.
    let mut last = -1.0;
    for i in 0..=100 {
        let l = penumbra::luminance(viridis(i as f32 / 100.0));
        assert!(l > last, "luminance not increasing at {i}");
        last = l;
    }
}

#[test]
fn error_image_is_log_scaled_viridis() {
    let (lo, hi) = ERROR_IMAGE_LOG10_RANGE;
    let r = Image::from_fn(3, 1, |_, _| Rgb::ONE);
    // Per-pixel relMSE = d²/1.01: 0 (below range), mid-range, far above range.
    let mid = 10f64.powf((lo + hi) / 2.0) * 1.01;
    let t = Image {
        width: 3,
        height: 1,
        pixels: vec![Rgb::ONE, Rgb::splat(1.0 + mid.sqrt() as f32), Rgb::splat(100.0)],
    };
    let e = error_image(&t, &r).unwrap();
    let enc = |p: Rgb| penumbra::image::io::linear_to_srgb(p.x);
    assert!((enc(e.get(0, 0)) - viridis(0.0).x).abs() < 1e-4);
    assert!((enc(e.get(1, 0)) - viridis(0.5).x).abs() < 1e-3);
    assert!((enc(e.get(2, 0)) - viridis(1.0).x).abs() < 1e-4);
}

#[test]
fn compare_cli_prints_metrics_and_fails_on_mismatch() {
    let dir = scratch("cli");
    let (t, r) = pair();
    let (tp, rp) = (dir.join("t.pfm"), dir.join("r.exr"));
    write_image(&t, &tp, 0.0).unwrap();
    write_image(&r, &rp, 0.0).unwrap();
    let err_png = dir.join("err.png");
    let out = Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(["compare"])
        .arg(&tp)
        .arg(&rp)
        .arg("--error-image")
        .arg(&err_png)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout} {}", String::from_utf8_lossy(&out.stderr));
    let value = |name: &str| -> f64 {
        let line = stdout
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("no {name} line in {stdout}"));
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    let s = compare(&t, &r).unwrap();
    assert!((value("MSE") / s.mse - 1.0).abs() < 1e-3);
    assert!((value("relMSE") / s.rel_mse - 1.0).abs() < 1e-3);
    assert!((value("MAE") / s.mae - 1.0).abs() < 1e-3);
    assert!(std::fs::metadata(&err_png).unwrap().len() > 0);

    // Size mismatch and missing file: non-zero exit, message on stderr.
    let big = dir.join("big.pfm");
    write_image(&Image::new(3, 3), &big, 0.0).unwrap();
    for (a, b) in [(&tp, &big), (&tp, &dir.join("missing.exr"))] {
        let out = Command::new(env!("CARGO_BIN_EXE_penumbra"))
            .arg("compare")
            .arg(a)
            .arg(b)
            .output()
            .unwrap();
        assert!(!out.status.success());
        assert!(!String::from_utf8_lossy(&out.stderr).is_empty());
    }
}
