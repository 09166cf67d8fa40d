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
        Rgb::new(
            t * 0.37 - 2.0,
            (t * 0.11).exp() * 1e-3,
            1.0 / (t + 1.0) * 40.0,
        )
    })
}

fn no_temp_files_left(dir: &Path) {
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp-"))
        .collect();
    assert!(
        leftovers.is_empty(),
        "temp files left behind: {leftovers:?}"
    );
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
    assert_eq!(
        img.pixels,
        vec![Rgb::new(1.0, 2.0, 3.0), Rgb::new(4.0, 5.0, 6.0)]
    );

    let mut grey = b"Pf\n1 2\n-1.0\n".to_vec();
    for v in [0.25f32, 0.75] {
        grey.extend_from_slice(&v.to_le_bytes());
    }
    let img = decode_pfm(&grey).unwrap();
    assert_eq!(img.get(0, 1), Rgb::splat(0.25));
    assert_eq!(img.get(0, 0), Rgb::splat(0.75));

    assert!(
        decode_pfm(b"PF\n2 2\n-1.0\n\0\0").is_err(),
        "truncated raster accepted"
    );
    assert!(
        decode_pfm(b"P6\n2 2\n255\n").is_err(),
        "wrong magic accepted"
    );
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
    assert!(
        err.contains("bmp") && err.contains("exr") && err.contains("png"),
        "{err}"
    );
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

#[test]
fn hdr_and_tga_reads() {
    let dir = scratch("hdr");
    // Radiance HDR: linear; RGBE shares one exponent per pixel with 8-bit mantissas, so the
    // error is bounded relative to the pixel's largest channel.
    let src = image::Rgb32FImage::from_fn(5, 3, |x, y| {
        image::Rgb([
            0.5 + x as f32,
            10.0 * (y + 1) as f32,
            0.01 * (x + y + 1) as f32,
        ])
    });
    let p = dir.join("a.hdr");
    image::DynamicImage::ImageRgb32F(src.clone())
        .save(&p)
        .unwrap();
    let back = read_image(&p).unwrap();
    for (x, y, s) in src.enumerate_pixels() {
        let b = back.get(x, y);
        let max = s[0].max(s[1]).max(s[2]);
        for c in 0..3 {
            assert!((b[c] - s[c]).abs() <= max / 128.0, "({x},{y}) {b} vs {s:?}");
        }
    }
    // TGA: 8-bit sRGB code values are linearised.
    let tga = image::RgbImage::from_fn(2, 2, |x, y| {
        image::Rgb([(x * 255) as u8, (y * 128) as u8, 64])
    });
    let p = dir.join("a.tga");
    tga.save(&p).unwrap();
    let back = read_image(&p).unwrap();
    assert_eq!(back.get(1, 0).x, 1.0);
    assert!((back.get(0, 1).y - srgb_to_linear(128.0 / 255.0)).abs() < 1e-6);
    assert!((back.get(0, 0).z - srgb_to_linear(64.0 / 255.0)).abs() < 1e-6);
}

/// An EXR of `w`×`h` half-float R, G, B pixels whose chunks are missing: a header, a
/// one-entry offset table and `tail` zero bytes. `compression` is the header's code (0 none,
/// 3 ZIP, 8 DWAA, ...); `tile` makes it a one-level tiled file with that tile size.
fn exr_header_only(w: i32, h: i32, compression: u8, tile: Option<u32>, tail: usize) -> Vec<u8> {
    exr_header_only_with(&["B", "G", "R"], w, h, compression, tile, tail)
}

/// [`exr_header_only`] with the half-float channels `names` (sorted, as EXR stores them).
fn exr_header_only_with(
    names: &[&str],
    w: i32,
    h: i32,
    compression: u8,
    tile: Option<u32>,
    tail: usize,
) -> Vec<u8> {
    fn attr(out: &mut Vec<u8>, name: &str, kind: &str, value: &[u8]) {
        for s in [name, kind] {
            out.extend_from_slice(s.as_bytes());
            out.push(0);
        }
        out.extend_from_slice(&(value.len() as i32).to_le_bytes());
        out.extend_from_slice(value);
    }
    let ints = |v: &[i32]| v.iter().flat_map(|i| i.to_le_bytes()).collect::<Vec<u8>>();
    let mut out = vec![0x76, 0x2f, 0x31, 0x01];
    let flags: u32 = if tile.is_some() { 0x200 } else { 0 };
    out.extend_from_slice(&(2 | flags).to_le_bytes());
    let mut channels = Vec::new();
    for name in names {
        channels.extend_from_slice(name.as_bytes());
        channels.push(0);
        channels.extend_from_slice(&ints(&[1, 0, 1, 1])); // half, pLinear+reserved, sampling 1×1
    }
    channels.push(0);
    attr(&mut out, "channels", "chlist", &channels);
    attr(&mut out, "compression", "compression", &[compression]);
    let window = ints(&[0, 0, w - 1, h - 1]);
    attr(&mut out, "dataWindow", "box2i", &window);
    attr(&mut out, "displayWindow", "box2i", &window);
    attr(&mut out, "lineOrder", "lineOrder", &[0]);
    attr(&mut out, "pixelAspectRatio", "float", &1f32.to_le_bytes());
    attr(&mut out, "screenWindowCenter", "v2f", &[0; 8]);
    attr(&mut out, "screenWindowWidth", "float", &1f32.to_le_bytes());
    if let Some(t) = tile {
        let mut desc = ints(&[t as i32, t as i32]);
        desc.push(0);
        attr(&mut out, "tiles", "tiledesc", &desc);
    }
    out.push(0);
    let first_chunk = out.len() as u64 + 8;
    out.extend_from_slice(&first_chunk.to_le_bytes());
    out.resize(out.len() + tail, 0);
    out
}

/// Peak resident memory of this process so far (Linux), in bytes.
fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Most memory the image tests of this binary may take: the bad files below must fail before
/// the reader allocates the image their header declares (2.4 GB from 700 bytes, found by the
/// fuzz target `image`).
const PEAK_RSS_LIMIT: u64 = 512 << 20;

#[test]
fn an_exr_header_cannot_make_the_reader_allocate_what_the_file_does_not_hold() {
    let dir = scratch("exrhuge");
    // 14000² is under the pixel cap; as linear RGB it is 2.35 GB, which 700 bytes cannot hold
    // at any compression the format has.
    for (name, compression, tile) in [
        ("scan.exr", 0, None),
        ("tile.exr", 0, Some(16384)),
        ("zip.exr", 3, None),
        ("piz.exr", 4, Some(16384)),
        ("dwaa.exr", 8, None),
    ] {
        let p = dir.join(name);
        std::fs::write(&p, exr_header_only(14000, 14000, compression, tile, 400)).unwrap();
        let err = format!("{:#}", read_image(&p).unwrap_err());
        assert!(err.contains(name), "{err}");
        assert!(
            err.contains("14000x14000") && err.contains("bytes"),
            "{name}: the error should say what the header claims against the file: {err}"
        );
    }
    // DWA's worst case (run-length coding, then deflate) lets 18 kB claim 1.2 GB: such a
    // file passes the size check, and its image must still grow only as chunks decode.
    let p = dir.join("dwaa-big.exr");
    std::fs::write(&p, exr_header_only(14000, 14000, 8, None, 20_000)).unwrap();
    let err = format!("{:#}", read_image(&p).unwrap_err());
    assert!(err.contains("dwaa-big.exr"), "{err}");
    if let Some(peak) = peak_rss() {
        assert!(peak < PEAK_RSS_LIMIT, "peak memory {} MB", peak >> 20);
    }
}

#[test]
fn a_grey_dwa_exr_header_cannot_make_the_reader_allocate_what_the_file_does_not_hold() {
    // A luminance-only layer is read by a second decode when the RGB one finds no R, G, B:
    // that decode must also grow the image as chunks arrive. 10 kB of DWA claiming 16384²
    // half Y pixels (512 MB) pass the size check (DWA's worst case is 66048:1), and the
    // reader once allocated all 512 MB before finding the chunks missing.
    let dir = scratch("exrgrey");
    for (name, compression) in [("y-dwaa.exr", 8), ("y-dwab.exr", 9)] {
        let p = dir.join(name);
        let bytes = exr_header_only_with(&["Y"], 16384, 16384, compression, None, 10_000);
        std::fs::write(&p, bytes).unwrap();
        let err = format!("{:#}", read_image(&p).unwrap_err());
        assert!(err.contains(name), "{err}");
    }
    if let Some(peak) = peak_rss() {
        assert!(peak < PEAK_RSS_LIMIT, "peak memory {} MB", peak >> 20);
    }
}

#[test]
fn every_saved_image_fuzz_regression_fails_cleanly_in_bounded_memory() {
    let dir = scratch("fuzzreg");
    let saved = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/regressions/image");
    let mut n = 0;
    for entry in std::fs::read_dir(&saved).unwrap() {
        let data = std::fs::read(entry.unwrap().path()).unwrap();
        let Some((&which, bytes)) = data.split_first() else {
            continue;
        };
        // The fuzz target's first byte picks the format (fuzz/src/harness.rs).
        let ext = ["exr", "pfm", "png", "hdr"][which as usize % 4];
        let p = dir.join(format!("input{n}.{ext}"));
        std::fs::write(&p, bytes).unwrap();
        if let Err(e) = read_image(&p) {
            let err = format!("{e:#}");
            assert!(err.contains(&format!("input{n}.{ext}")), "{err}");
        }
        n += 1;
    }
    assert!(n > 0, "no regression inputs in {}", saved.display());
    if let Some(peak) = peak_rss() {
        assert!(peak < PEAK_RSS_LIMIT, "peak memory {} MB", peak >> 20);
    }
}

#[test]
fn highly_compressed_exrs_still_read() {
    // A flat 1024² image compresses by ~64:1 (RLE) to ~1000:1 (ZIP): the reader's bound on
    // what a file can hold must not refuse real files near those ratios.
    use exr::prelude::{Compression, Encoding, LineOrder, SpecificChannels, Vec2, WritableImage};
    let dir = scratch("exrflat");
    let n = 1024;
    for (name, compression) in [
        ("rle.exr", Compression::RLE),
        ("zip.exr", Compression::ZIP16),
        ("zips.exr", Compression::ZIP1),
        ("piz.exr", Compression::PIZ),
        ("pxr24.exr", Compression::PXR24),
        ("b44a.exr", Compression::B44A),
    ] {
        let channels = SpecificChannels::rgb(|_: Vec2<usize>| (half_one(), half_one(), half_one()));
        let encoding = Encoding {
            compression,
            blocks: exr::image::Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        };
        let layer = exr::image::Layer::new(
            (n, n),
            exr::meta::header::LayerAttributes::default(),
            encoding,
            channels,
        );
        let p = dir.join(name);
        exr::image::Image::from_layer(layer)
            .write()
            .to_file(&p)
            .unwrap();
        let img = read_image(&p).unwrap_or_else(|e| panic!("{name}: {e:#}"));
        assert_eq!((img.width, img.height), (n as u32, n as u32));
        assert_eq!(img.get(17, 900), Rgb::ONE, "{name}");
    }
}

fn half_one() -> exr::prelude::f16 {
    exr::prelude::f16::from_f32(1.0)
}

#[test]
fn bottom_up_and_grey_exrs_read() {
    // Rows stored bottom to top arrive last row first: the image must still be whole.
    use exr::prelude::{
        AnyChannel, AnyChannels, Encoding, FlatSamples, LineOrder, SpecificChannels, Text, Vec2,
        WritableImage,
    };
    let dir = scratch("exrorder");
    let (w, h) = (5usize, 40usize);
    let value = |x: usize, y: usize| (y * w + x) as f32;
    let channels =
        SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| (value(x, y), 2.0 * value(x, y), 0.5));
    let encoding = Encoding {
        line_order: LineOrder::Decreasing,
        ..Encoding::FAST_LOSSLESS
    };
    let layer = exr::image::Layer::new(
        (w, h),
        exr::meta::header::LayerAttributes::default(),
        encoding,
        channels,
    );
    let p = dir.join("decreasing.exr");
    exr::image::Image::from_layer(layer)
        .write()
        .to_file(&p)
        .unwrap();
    let img = read_image(&p).unwrap();
    for (x, y) in [(0, 0), (4, 0), (2, 17), (4, 39)] {
        let v = value(x, y);
        assert_eq!(img.get(x as u32, y as u32), Rgb::new(v, 2.0 * v, 0.5));
    }
    // A luminance-only file reads as grey.
    let y_channel = AnyChannel::new(
        Text::from("Y"),
        FlatSamples::F32((0..w * h).map(|i| i as f32).collect()),
    );
    let grey = exr::image::Image::from_channels((w, h), AnyChannels::sort(vec![y_channel].into()));
    let p = dir.join("grey.exr");
    grey.write().to_file(&p).unwrap();
    let img = read_image(&p).unwrap();
    assert_eq!(img.get(3, 2), Rgb::splat(value(3, 2)));
}

#[test]
fn exr_files_are_byte_identical_for_the_same_image() {
    // Same seed and scene must give the same file, not only the same pixels: the chunks of a
    // parallel-compressed EXR must not appear in the order the threads finished them.
    let (w, h) = (192u32, 160u32);
    let mut img = Image::new(w, h);
    let mut s = 0x9e37_79b9u32;
    for p in &mut img.pixels {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        let v = (s >> 8) as f32 / (1 << 24) as f32;
        *p = Rgb::new(v, v * 0.5, 1.0 - v);
    }
    let dir = scratch("bytes");
    let first = dir.join("0.exr");
    write_image(&img, &first, 0.0).unwrap();
    let want = std::fs::read(&first).unwrap();
    for i in 1..8 {
        let p = dir.join(format!("{i}.exr"));
        write_image(&img, &p, 0.0).unwrap();
        assert!(
            std::fs::read(&p).unwrap() == want,
            "write {i} differs from the first"
        );
    }
}

#[test]
fn an_image_too_large_to_read_names_its_size() {
    // A Radiance header declaring 60000×50000 pixels (36 GB as linear RGB) over a few bytes of
    // data: the error must say how large the file claims to be, not only that a limit was hit.
    let dir = scratch("huge-hdr");
    let p = dir.join("huge.hdr");
    let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 50000 +X 60000\n".to_vec();
    bytes.extend_from_slice(&[0x80; 64]);
    std::fs::write(&p, bytes).unwrap();
    let err = format!("{:#}", read_image(&p).unwrap_err());
    assert!(err.contains("60000x50000"), "{err}");
    assert!(err.contains("huge.hdr"), "{err}");
}
