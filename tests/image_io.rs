//! Image I/O: exact float round trips, PNG quantisation bounds, PFM variants, atomic writes.

use std::path::{Path, PathBuf};

use penumbra::Rgb;
use penumbra::image::io::{decode_pfm, linear_to_srgb, srgb_to_linear};
use penumbra::image::{Image, read_image, write_image};

/// A fresh scratch directory per test (tests run in parallel).
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-image-io-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A small non-square HDR test image with distinct values everywhere (catches row flips and
/// transposes) including values > 1, tiny values and negatives.
fn test_image() -> Image {
    Image::from_fn(7, 5, |x, y| {
        let t = (y * 7 + x) as f32;
        Rgb::new(t * 0.37 - 2.0, (t * 0.11).exp() * 1e-3, 1.0 / (t + 1.0) * 40.0)
    })
}

fn no_temp_files_left(dir: &Path) {
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp-"))
        .collect();
    assert!(leftovers.is_empty(), "temp files left behind: {leftovers:?}");
}

#[test]
fn exr_round_trip_is_exact() {
    let dir = scratch("exr");
    let img = test_image();
    let p = dir.join("a.exr");
    write_image(&img, &p, 0.0).unwrap();
    assert_eq!(read_image(&p).unwrap(), img);
    no_temp_files_left(&dir);
}

#[test]
fn pfm_round_trip_is_exact() {
    let dir = scratch("pfm");
    let img = test_image();
    let p = dir.join("a.PFM"); // extension matching is case-insensitive
    write_image(&img, &p, 3.0).unwrap();
    assert_eq!(read_image(&p).unwrap(), img);
    // Our writer is little-endian with rows bottom to top: check the first stored float is the
    // red channel of the bottom-left pixel.
    let bytes = std::fs::read(&p).unwrap();
    let header = b"PF\n7 5\n-1.0\n";
    assert_eq!(&bytes[..header.len()], header);
    let first = f32::from_le_bytes(bytes[header.len()..header.len() + 4].try_into().unwrap());
    assert_eq!(first, img.get(0, 4).x);
}

#[test]
fn pfm_big_endian_and_grey_decode() {
    // 2x1 big-endian colour, then 1x2 grey little-endian (bottom row first).
    let mut be = b"PF\n2 1\n1.0\n".to_vec();
    for v in [1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0] {
        be.extend_from_slice(&v.to_be_bytes());
    }
    let img = decode_pfm(&be).unwrap();
    assert_eq!(img.pixels, vec![Rgb::new(1.0, 2.0, 3.0), Rgb::new(4.0, 5.0, 6.0)]);

    let mut grey = b"Pf\n1 2\n-1.0\n".to_vec();
    for v in [0.25f32, 0.75] {
        grey.extend_from_slice(&v.to_le_bytes());
    }
    let img = decode_pfm(&grey).unwrap();
    assert_eq!(img.get(0, 1), Rgb::splat(0.25));
    assert_eq!(img.get(0, 0), Rgb::splat(0.75));

    assert!(decode_pfm(b"PF\n2 2\n-1.0\n\0\0").is_err(), "truncated raster accepted");
    assert!(decode_pfm(b"P6\n2 2\n255\n").is_err(), "wrong magic accepted");
}

#[test]
fn png_round_trip_within_one_code_value() {
    let dir = scratch("png");
    // Values across [0, 1] in linear space, including both ends.
    let img = Image::from_fn(16, 4, |x, y| {
        let t = (y * 16 + x) as f32 / 63.0;
        Rgb::new(t, t * t, 1.0 - t)
    });
    let p = dir.join("a.png");
    write_image(&img, &p, 0.0).unwrap();
    let back = read_image(&p).unwrap();
    assert_eq!((back.width, back.height), (16, 4));
    for (a, b) in img.pixels.iter().zip(&back.pixels) {
        for c in 0..3 {
            let (ea, eb) = (linear_to_srgb(a[c]), linear_to_srgb(b[c]));
            assert!((ea - eb).abs() <= 0.5 / 255.0 + 1e-6, "{a} vs {b}");
        }
    }
    // Exposure: +1 stop doubles the linear value before encoding.
    write_image(&img, &p, 1.0).unwrap();
    let bright = read_image(&p).unwrap();
    let (src, got) = (img.get(3, 0).x * 2.0, bright.get(3, 0).x);
    assert!((linear_to_srgb(src) - linear_to_srgb(got)).abs() <= 0.5 / 255.0 + 1e-6);
}

#[test]
fn srgb_transfer_inverts() {
    for i in 0..=1000 {
        let x = i as f32 / 1000.0;
        assert!((srgb_to_linear(linear_to_srgb(x)) - x).abs() < 1e-5);
    }
}

#[test]
fn non_finite_pixels_are_written_as_black() {
    let dir = scratch("nan");
    let mut img = test_image();
    img.set(1, 1, Rgb::new(f32::NAN, 1.0, 1.0));
    img.set(2, 3, Rgb::new(1.0, f32::INFINITY, 1.0));
    assert!(img.has_non_finite());
    assert_eq!(img.count_non_finite(), 2);
    let p = dir.join("a.exr");
    write_image(&img, &p, 0.0).unwrap();
    let back = read_image(&p).unwrap();
    assert!(!back.has_non_finite());
    assert_eq!(back.get(1, 1), Rgb::ZERO);
    assert_eq!(back.get(2, 3), Rgb::ZERO);
    assert_eq!(back.get(0, 0), img.get(0, 0));
}

#[test]
fn failed_writes_leave_existing_file_untouched() {
    let dir = scratch("atomic");
    let img = test_image();
    // Unsupported extension: clear error, nothing created.
    let bad = dir.join("a.bmp");
    std::fs::write(&bad, b"keep me").unwrap();
    let err = write_image(&img, &bad, 0.0).unwrap_err().to_string();
    assert!(err.contains("bmp") && err.contains("exr") && err.contains("png"), "{err}");
    assert_eq!(std::fs::read(&bad).unwrap(), b"keep me");

    // Rename onto a directory fails after the temp file was written: the temp must vanish and
    // the destination stay as it was.
    let target = dir.join("x.png");
    std::fs::create_dir(&target).unwrap();
    std::fs::write(target.join("inside"), b"keep").unwrap();
    assert!(write_image(&img, &target, 0.0).is_err());
    assert_eq!(std::fs::read(target.join("inside")).unwrap(), b"keep");

    // Missing directory: error names the file.
    let missing = dir.join("no/such/dir/a.exr");
    let err = format!("{:#}", write_image(&img, &missing, 0.0).unwrap_err());
    assert!(err.contains("a.exr"), "{err}");
    no_temp_files_left(&dir);
}

#[test]
fn read_errors_name_the_file() {
    let dir = scratch("readerr");
    let p = dir.join("broken.exr");
    std::fs::write(&p, b"not an exr").unwrap();
    let err = format!("{:#}", read_image(&p).unwrap_err());
    assert!(err.contains("broken.exr"), "{err}");
    let err = format!("{:#}", read_image(&dir.join("missing.pfm")).unwrap_err());
    assert!(err.contains("missing.pfm"), "{err}");
    let err = format!("{:#}", read_image(&dir.join("a.gif")).unwrap_err());
    assert!(err.contains("gif"), "{err}");
}

#[test]
fn image_arithmetic() {
    let mut a = Image::from_fn(3, 2, |x, y| Rgb::splat((x + y) as f32));
    let b = Image::from_fn(3, 2, |_, _| Rgb::ONE);
    a.add_assign(&b);
    a.scale(0.5);
    assert_eq!(a.get(2, 1), Rgb::splat(2.0));
    assert_eq!(a.get(0, 0), Rgb::splat(0.5));
    assert!(!a.has_non_finite());
}
