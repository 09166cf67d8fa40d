//! Image files: EXR and PFM (linear float), PNG (sRGB, 8-bit) writing; EXR, PFM, PNG, TGA,
//! JPEG and Radiance HDR reading.
//!
//! Every write is atomic: the file is encoded in memory, written to a hidden temporary file in
//! the destination directory and renamed over the destination. A failed or interrupted write
//! therefore never leaves a truncated image behind, and an existing file survives any error.

use std::io::{Cursor, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};

use super::Image;
use crate::Rgb;

/// Extensions accepted by [`write_image`].
pub const WRITE_EXTENSIONS: &[&str] = &["exr", "pfm", "png"];
/// Extensions accepted by [`read_image`].
pub const READ_EXTENSIONS: &[&str] = &["exr", "pfm", "png", "tga", "jpg", "jpeg", "hdr"];

/// Lower-cased extension of `path`, or "" when it has none.
pub fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

/// sRGB opto-electronic transfer: linear [0,1] → encoded [0,1] (IEC 61966-2-1).
#[inline]
pub fn linear_to_srgb(x: f32) -> f32 {
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse sRGB transfer: encoded [0,1] → linear [0,1].
#[inline]
pub fn srgb_to_linear(s: f32) -> f32 {
    if s <= 0.040_45 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    }
}

/// Encode a linear value as an 8-bit sRGB code value: clamp, transfer, round.
/// NaN maps to 0 so a stray sample cannot poison a display image.
#[inline]
pub fn linear_to_srgb8(x: f32) -> u8 {
    let c = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    (linear_to_srgb(c) * 255.0 + 0.5) as u8
}

/// Tonemap a linear image for display: multiply by `2^exposure_stops`, sRGB-encode, clamp.
pub fn to_rgb8(img: &Image, exposure_stops: f32) -> image::RgbImage {
    let k = exposure_stops.exp2();
    let mut out = image::RgbImage::new(img.width, img.height);
    for (dst, src) in out.pixels_mut().zip(&img.pixels) {
        let p = *src * k;
        *dst = image::Rgb([
            linear_to_srgb8(p.x),
            linear_to_srgb8(p.y),
            linear_to_srgb8(p.z),
        ]);
    }
    out
}

/// Prefix of the temporary siblings of `path`: `.NAME.tmp-`, followed by `PID-N`.
fn temp_prefix(path: &Path) -> String {
    let name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "image".into());
    format!(".{name}.tmp-")
}

/// The folder `path` is written into ("." for a bare file name).
fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    }
}

/// Hidden temporary sibling of `path`; pid + a process-wide counter keep concurrent writers
/// (other processes, or other threads of this one) from sharing a temp file.
fn temp_path(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp = format!("{}{}-{n}", temp_prefix(path), std::process::id());
    parent_dir(path).join(tmp)
}

/// Whether process `pid` may still be running. Without a `/proc` to ask, every process is
/// assumed alive, so that no temp file of a concurrent writer is ever removed.
fn process_may_be_alive(pid: u32) -> bool {
    let proc = Path::new("/proc");
    !proc.join("self").exists() || proc.join(pid.to_string()).exists()
}

/// Remove the temporary files that earlier, killed runs left beside `path` (`.NAME.tmp-PID-N`
/// whose process is gone). Those of running processes, this one included, are kept. Returns
/// the files removed; a folder that cannot be listed removes nothing.
pub fn remove_stale_temps(path: &Path) -> Vec<PathBuf> {
    let prefix = temp_prefix(path);
    let Ok(entries) = std::fs::read_dir(parent_dir(path)) else {
        return Vec::new();
    };
    let mut removed = Vec::new();
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(rest) = name.to_str().and_then(|n| n.strip_prefix(&prefix)) else {
            continue;
        };
        let Some(pid) = rest
            .split_once('-')
            .and_then(|(p, _)| p.parse::<u32>().ok())
        else {
            continue;
        };
        if pid == std::process::id() || process_may_be_alive(pid) {
            continue;
        }
        let is_file = entry.file_type().is_ok_and(|t| t.is_file());
        if is_file && std::fs::remove_file(entry.path()).is_ok() {
            removed.push(entry.path());
        }
    }
    removed
}

/// Check, before any work is spent on it, that [`write_image`] can write `path`: a supported
/// extension, not a folder, in an existing folder where files can be created (probed by
/// creating and removing a temp file there).
pub fn check_output_path(path: &Path) -> anyhow::Result<()> {
    if path.is_dir() {
        bail!("cannot write {}: it is a folder", path.display());
    }
    let ext = extension(path);
    if !WRITE_EXTENSIONS.contains(&ext.as_str()) {
        let what = if ext.is_empty() {
            "it has no extension".to_string()
        } else {
            format!("unsupported extension .{ext}")
        };
        bail!(
            "cannot write {}: {what} (supported: {})",
            path.display(),
            WRITE_EXTENSIONS
                .iter()
                .map(|e| format!(".{e}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let dir = parent_dir(path);
    if !dir.exists() {
        bail!(
            "cannot write {}: folder {} does not exist",
            path.display(),
            dir.display()
        );
    }
    if !dir.is_dir() {
        bail!(
            "cannot write {}: {} is not a folder",
            path.display(),
            dir.display()
        );
    }
    let probe = temp_path(path);
    match std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
    {
        Ok(f) => {
            drop(f);
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => bail!(
            "cannot write {}: cannot create files in {}: {e}",
            path.display(),
            dir.display()
        ),
    }
}

/// How a write may be interrupted.
#[derive(Clone, Copy, Debug, Default)]
pub struct WriteControl<'a> {
    /// Once set (by a signal handler, say), the write stops at the next chunk: the temp file is
    /// removed, the destination left as it was, and [`WriteCancelled`] returned.
    pub cancel: Option<&'a AtomicBool>,
    /// Pause after each chunk, ended early by `cancel`: a test hook that holds a write open
    /// until it is interrupted.
    pub chunk_pause: Duration,
}

/// A write abandoned because [`WriteControl::cancel`] was set.
#[derive(Debug, thiserror::Error)]
#[error("writing {} was interrupted; the file is unchanged", path.display())]
pub struct WriteCancelled {
    /// The destination that was not written.
    pub path: PathBuf,
}

/// Bytes written between two looks at [`WriteControl::cancel`].
const WRITE_CHUNK: usize = 1 << 20;

/// Write `bytes` to `path` atomically (temp file in the same directory, then rename).
/// On error the temp file is removed and an existing `path` is left untouched.
pub fn write_bytes_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    write_bytes_atomic_with(path, bytes, &WriteControl::default())
}

/// [`write_bytes_atomic`] that gives up, cleanly, when `ctl.cancel` is set.
pub fn write_bytes_atomic_with(
    path: &Path,
    bytes: &[u8],
    ctl: &WriteControl,
) -> anyhow::Result<()> {
    let cancelled = || ctl.cancel.is_some_and(|c| c.load(Ordering::SeqCst));
    let tmp = temp_path(path);
    let result = (|| -> anyhow::Result<()> {
        let mut f = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)?;
        for chunk in bytes.chunks(WRITE_CHUNK) {
            if cancelled() {
                bail!(WriteCancelled { path: path.into() });
            }
            f.write_all(chunk)?;
            // The pause ends early on a cancel, so a test can park a write and interrupt it.
            let pause_end = Instant::now() + ctl.chunk_pause;
            while !cancelled() && Instant::now() < pause_end {
                std::thread::sleep(Duration::from_millis(1).min(ctl.chunk_pause));
            }
        }
        f.sync_all()?;
        drop(f);
        if cancelled() {
            bail!(WriteCancelled { path: path.into() });
        }
        std::fs::rename(&tmp, path)?;
        Ok(())
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        if e.is::<WriteCancelled>() {
            return Err(e);
        }
        return Err(e.context(format!("cannot write {}", path.display())));
    }
    Ok(())
}

/// Encode an 8-bit RGB image as PNG in memory.
pub fn encode_png(img: &image::RgbImage) -> anyhow::Result<Vec<u8>> {
    let mut buf = Cursor::new(Vec::new());
    img.write_to(&mut buf, image::ImageFormat::Png)
        .context("encoding PNG")?;
    Ok(buf.into_inner())
}

/// Write an 8-bit RGB image as PNG, atomically.
pub fn save_png_atomic(img: &image::RgbImage, path: &Path) -> anyhow::Result<()> {
    write_bytes_atomic(path, &encode_png(img)?)
}

/// Write `img` to `path`, the format chosen by the extension:
/// `.exr` (linear f32 RGB), `.pfm` (linear f32 RGB) or `.png` (8-bit sRGB of `img·2^exposure`;
/// the exposure is ignored by the linear formats). NaN/Inf pixels are written as black, with
/// one warning on stderr giving their count. The write is atomic (see the module docs).
pub fn write_image(img: &Image, path: &Path, exposure_stops: f32) -> anyhow::Result<()> {
    write_image_with(img, path, exposure_stops, &WriteControl::default())
}

/// [`write_image`] that gives up, cleanly, when `ctl.cancel` is set.
pub fn write_image_with(
    img: &Image,
    path: &Path,
    exposure_stops: f32,
    ctl: &WriteControl,
) -> anyhow::Result<()> {
    write_image_tagged(img, path, exposure_stops, &[], ctl)
}

/// [`write_image_with`] that also stores text `attributes` (name, value) in the header; only
/// EXR has one, so other formats with attributes are an error.
pub fn write_image_tagged(
    img: &Image,
    path: &Path,
    exposure_stops: f32,
    attributes: &[(&str, String)],
    ctl: &WriteControl,
) -> anyhow::Result<()> {
    let ext = extension(path);
    if !WRITE_EXTENSIONS.contains(&ext.as_str()) {
        check_output_path(path)?;
    }
    if !attributes.is_empty() && ext != "exr" {
        bail!(
            "cannot write {}: only .exr files carry the header this image needs",
            path.display()
        );
    }
    let expected = img.width as usize * img.height as usize;
    if img.pixels.len() != expected {
        bail!(
            "cannot write {}: image claims {}x{} but holds {} pixels",
            path.display(),
            img.width,
            img.height,
            img.pixels.len()
        );
    }
    // Sanitise once here so every format (and every viewer) sees the same finite data.
    let bad = img.count_non_finite();
    let sanitized;
    let img = if bad > 0 {
        eprintln!(
            "warning: {}: {bad} pixel(s) with NaN/Inf written as black",
            path.display()
        );
        let mut copy = img.clone();
        for p in &mut copy.pixels {
            if !p.is_finite() {
                *p = Rgb::ZERO;
            }
        }
        sanitized = copy;
        &sanitized
    } else {
        img
    };
    let bytes = match ext.as_str() {
        "exr" => encode_exr(img, attributes),
        "pfm" => Ok(encode_pfm(img)),
        _ => encode_png(&to_rgb8(img, exposure_stops)),
    }
    .with_context(|| format!("encoding {}", path.display()))?;
    write_bytes_atomic_with(path, &bytes, ctl)
}

/// OpenEXR, three f32 channels, default (lossless) compression, text `attributes` in the
/// layer header.
fn encode_exr(img: &Image, attributes: &[(&str, String)]) -> anyhow::Result<Vec<u8>> {
    use exr::prelude::{AttributeValue, SpecificChannels, Text, Vec2, WritableImage};
    let w = img.width as usize;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let p = img.pixels[y * w + x];
        (p.x, p.y, p.z)
    });
    let mut image = exr::image::Image::from_channels((w, img.height as usize), channels);
    // Chunks in increasing row order, however the compressing threads finish: the same image
    // is the same file, byte for byte.
    image.layer_data.encoding.line_order = exr::meta::attribute::LineOrder::Increasing;
    for (name, value) in attributes {
        let text = |s: &str| {
            Text::new_or_none(s).ok_or_else(|| anyhow::anyhow!("EXR attribute {s:?} is not text"))
        };
        image
            .layer_data
            .attributes
            .other
            .insert(text(name)?, AttributeValue::Text(text(value)?));
    }
    let mut buf = Cursor::new(Vec::new());
    image.write().to_buffered(&mut buf)?;
    Ok(buf.into_inner())
}

/// Portable float map: "PF", little-endian (negative scale), rows bottom to top.
fn encode_pfm(img: &Image) -> Vec<u8> {
    let header = format!("PF\n{} {}\n-1.0\n", img.width, img.height);
    let mut out = Vec::with_capacity(header.len() + img.pixels.len() * 12);
    out.extend_from_slice(header.as_bytes());
    let w = img.width as usize;
    if w > 0 {
        for row in img.pixels.chunks_exact(w).rev() {
            for p in row {
                for c in [p.x, p.y, p.z] {
                    out.extend_from_slice(&c.to_le_bytes());
                }
            }
        }
    }
    out
}

/// Read an image as linear RGB. `.exr`, `.pfm` (colour "PF" or grey "Pf", either byte order)
/// and `.hdr` are linear already; `.png`, `.tga`, `.jpg` are sRGB-decoded to linear.
pub fn read_image(path: &Path) -> anyhow::Result<Image> {
    let ext = extension(path);
    if !READ_EXTENSIONS.contains(&ext.as_str()) {
        bail!(
            "cannot read {}: unsupported extension {:?} (supported: {})",
            path.display(),
            ext,
            READ_EXTENSIONS.join(", ")
        );
    }
    if let Some(why) = not_a_file(path) {
        bail!("cannot read {}: {why}", path.display());
    }
    let result = match ext.as_str() {
        "exr" => read_exr(path),
        "pfm" => std::fs::read(path)
            .map_err(anyhow::Error::from)
            .and_then(|b| decode_pfm(&b)),
        "hdr" => read_with_image_crate(path, false),
        _ => read_with_image_crate(path, true),
    };
    result.with_context(|| format!("reading {}", path.display()))
}

/// Whether the image file at `path` has colour (R, G, B) channels rather than one grey
/// channel (with or without alpha): read from its header, without decoding it. The readers
/// replicate a grey channel to RGB, which is right for textures and wrong for data such as
/// normal maps, which pbrt-v4 refuses without all three.
pub fn has_color_channels(path: &Path) -> anyhow::Result<bool> {
    let inner = || -> anyhow::Result<bool> {
        Ok(match extension(path).as_str() {
            "exr" => {
                let meta = exr::meta::MetaData::read_from_file(path, false)
                    .map_err(|e| anyhow::anyhow!("{e}"))?;
                let h = meta
                    .headers
                    .first()
                    .ok_or_else(|| anyhow::anyhow!("no layers"))?;
                ["R", "G", "B"]
                    .iter()
                    .all(|c| h.channels.list.iter().any(|ch| ch.name.to_string() == *c))
            }
            "pfm" => {
                let mut magic = [0u8; 2];
                std::io::Read::read_exact(&mut std::fs::File::open(path)?, &mut magic)?;
                &magic == b"PF"
            }
            _ => {
                use image::ImageDecoder;
                image::ImageReader::open(path)?
                    .with_guessed_format()?
                    .into_decoder()?
                    .color_type()
                    .has_color()
            }
        })
    };
    inner().with_context(|| format!("reading {}", path.display()))
}

/// Why `path` cannot be opened as a file ("file not found", "a folder, not a file"), or
/// `None` when it is a file: loaders say this instead of the bare OS error.
pub fn not_a_file(path: &Path) -> Option<&'static str> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => Some("a folder, not a file"),
        Ok(_) => None,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Some("file not found"),
        // Permission and other errors are left to the reader, which reports them.
        Err(_) => None,
    }
}

/// Decode via the `image` crate; `srgb` selects whether code values are sRGB-linearised.
fn read_with_image_crate(path: &Path, srgb: bool) -> anyhow::Result<Image> {
    let reader = image::ImageReader::open(path)?.with_guessed_format()?;
    // The header alone says how large the image claims to be: a limit hit while decoding is
    // reported with that size, so a truncated or hostile header is told from a real big image.
    let (w, h) = image::ImageReader::open(path)?
        .with_guessed_format()?
        .into_dimensions()?;
    let dynamic = match reader.decode() {
        Err(image::ImageError::Limits(e)) => bail!(
            "the file declares {w}x{h} pixels, more than the image reader's memory limit allows ({e})"
        ),
        other => other?,
    };
    let rgb = dynamic.to_rgb32f();
    let (w, h) = rgb.dimensions();
    let lin = |v: f32| if srgb { srgb_to_linear(v) } else { v };
    let pixels = rgb
        .pixels()
        .map(|p| Rgb::new(lin(p[0]), lin(p[1]), lin(p[2])))
        .collect();
    Ok(Image {
        width: w,
        height: h,
        pixels,
    })
}

/// Largest image the readers accept (16384², 3 GB as linear RGB).
pub const MAX_READ_PIXELS: usize = 1 << 28;

/// The most uncompressed bytes one byte of an EXR file can hold under `compression`: the
/// format's worst case, so that no real file is refused (deflate expands at most 1032:1, EXR's
/// RLE 64:1 (128 bytes from a count and a value), PXR24 stores a float in 3 bytes before
/// deflating, B44A a flat 4×4 half block in 3 bytes, DWA run-length codes then deflates).
/// `None` for the methods the reader cannot decode.
fn exr_max_expansion(compression: exr::compression::Compression) -> Option<u64> {
    use exr::compression::Compression::*;
    match compression {
        Uncompressed => Some(1),
        RLE => Some(64),
        // PIZ's Huffman stage spends ≥ 9 bits on a run of ≤ 255 samples (~453:1).
        ZIP1 | ZIP16 | PIZ => Some(1032),
        PXR24 => Some(1032 * 4 / 3),
        B44 | B44A => Some(11),
        DWAA(_) | DWAB(_) => Some(64 * 1032),
        _ => None,
    }
}

/// Refuse an EXR whose headers declare more pixels than penumbra reads, or more pixel data
/// than a file of `file_len` bytes can hold: the reader allocates the whole image from the
/// header before it decodes a chunk, so a few hundred bytes could otherwise claim gigabytes
/// (found by fuzz/, target `image`).
fn check_exr_sizes(meta: &exr::meta::MetaData, file_len: u64) -> anyhow::Result<()> {
    for h in &meta.headers {
        let (w, ht) = (h.layer_size.width(), h.layer_size.height());
        if w.saturating_mul(ht) > MAX_READ_PIXELS {
            bail!(
                "the header claims {w}x{ht} pixels, more than the {MAX_READ_PIXELS} penumbra reads"
            );
        }
        let Some(expansion) = exr_max_expansion(h.compression) else {
            bail!("{} compression is not supported", h.compression);
        };
        // Rows and tiles each cost an offset-table entry and a chunk header in the file.
        let min_chunk_bytes = 16u64;
        let chunks = h.chunk_count as u64;
        if chunks.saturating_mul(min_chunk_bytes) > file_len {
            bail!(
                "the header of {w}x{ht} pixels needs {chunks} chunks, at least {} bytes, \
                 but the file has {file_len} bytes",
                chunks.saturating_mul(min_chunk_bytes)
            );
        }
        // Every channel of every pixel must come out of the file's bytes; the linear RGB image
        // made from them is then at most 6 times that (one half channel as RGB f32).
        let per_pixel = (h.channels.bytes_per_pixel as u64).max(1);
        let declared = (w as u64 * ht as u64).saturating_mul(per_pixel);
        let most = file_len.saturating_mul(expansion);
        if declared > most {
            bail!(
                "the header claims {w}x{ht} pixels of {per_pixel} bytes ({declared} bytes), \
                 more than the file's {file_len} bytes can hold (compression: {}, which \
                 expands at most {expansion}:1)",
                h.compression
            );
        }
        // A chunk's stored size is read into memory before it is checked against the file;
        // the decoder bounds it by the uncompressed size of a whole row block or tile, which
        // a tile far larger than the image makes huge (a 4x4 image in 13959232x64 tiles:
        // 1.7 GB).
        let block = (h.max_block_byte_size() as u64).max(1);
        if block > most.max(MAX_EXR_BLOCK_FLOOR) {
            bail!(
                "the header's row blocks or tiles of {block} bytes each are more than the \
                 file's {file_len} bytes can hold (and more than {} MB)",
                MAX_EXR_BLOCK_FLOOR >> 20
            );
        }
    }
    Ok(())
}

/// Row blocks or tiles up to this size are taken without comparing them to the file (a tile
/// may be larger than a small image).
const MAX_EXR_BLOCK_FLOOR: u64 = 256 << 20;

/// First RGB(A) layer of an EXR; falls back to a luminance-only ("Y") layer as grey.
fn read_exr(path: &Path) -> anyhow::Result<Image> {
    use exr::prelude::{RgbaChannels, Vec2, read_first_rgba_layer_from_file};
    let meta =
        exr::meta::MetaData::read_from_file(path, false).map_err(|e| anyhow::anyhow!("{e}"))?;
    check_exr_sizes(&meta, std::fs::metadata(path)?.len())?;
    let rgba = read_first_rgba_layer_from_file(
        path,
        |res: Vec2<usize>, _: &RgbaChannels| GrowingImage::new(res),
        |img: &mut GrowingImage, pos: Vec2<usize>, (r, g, b, _a): (f32, f32, f32, f32)| {
            img.set(pos, Rgb::new(r, g, b))
        },
    );
    // Only a first layer with a luminance channel is worth the second, grey, decode.
    let has_y = meta
        .headers
        .first()
        .is_some_and(|h| h.channels.list.iter().any(|c| c.name.to_string() == "Y"));
    match rgba {
        Ok(img) => img.layer_data.channel_data.pixels.finish(),
        // exr's errors print their io cause in their own message: keep that one only.
        Err(rgba_err) if has_y => read_exr_grey(path).map_err(|_| anyhow::anyhow!("{rgba_err}")),
        Err(rgba_err) => Err(anyhow::anyhow!("{rgba_err}")),
    }
}

/// An EXR image being decoded: it grows as decoded pixels arrive (rows in file order) rather
/// than being allocated whole from the header, so that a file whose chunks are missing or
/// broken fails before it costs the memory its header claims (a 10 kB DWA file may claim
/// 512 MB and pass [`check_exr_sizes`]).
struct GrowingImage {
    width: usize,
    height: usize,
    pixels: Vec<Rgb>,
}

impl GrowingImage {
    fn new(size: exr::math::Vec2<usize>) -> Self {
        GrowingImage {
            width: size.width(),
            height: size.height(),
            pixels: Vec::new(),
        }
    }

    fn set(&mut self, pos: exr::math::Vec2<usize>, value: Rgb) {
        let i = pos.y() * self.width + pos.x();
        if i >= self.pixels.len() {
            self.pixels.resize(i + 1, Rgb::ZERO);
        }
        self.pixels[i] = value;
    }

    fn finish(mut self) -> anyhow::Result<Image> {
        self.pixels.resize(self.width * self.height, Rgb::ZERO);
        Ok(Image {
            width: u32::try_from(self.width)?,
            height: u32::try_from(self.height)?,
            pixels: self.pixels,
        })
    }
}

/// The text attributes of an EXR's first layer header (name, value), sorted by name.
pub fn read_exr_attributes(path: &Path) -> anyhow::Result<Vec<(String, String)>> {
    if let Some(why) = not_a_file(path) {
        bail!("cannot read {}: {why}", path.display());
    }
    let meta = exr::meta::MetaData::read_from_file(path, false)
        .map_err(|e| anyhow::anyhow!("reading {}: {e}", path.display()))?;
    let mut out: Vec<(String, String)> = meta
        .headers
        .first()
        .into_iter()
        .flat_map(|h| h.own_attributes.other.iter())
        .filter_map(|(k, v)| match v {
            exr::meta::attribute::AttributeValue::Text(t) => Some((k.to_string(), t.to_string())),
            _ => None,
        })
        .collect();
    out.sort();
    Ok(out)
}

/// An EXR whose first layer has a "Y" channel, replicated to RGB.
fn read_exr_grey(path: &Path) -> anyhow::Result<Image> {
    use exr::prelude::{ReadChannels, ReadLayers, ReadSpecificChannel, Vec2, read};
    // Decoded like the RGB layer, growing as pixels arrive: the crate's flat-layer reader
    // allocated the whole layer from the header first.
    let img = read()
        .no_deep_data()
        .largest_resolution_level()
        .specific_channels()
        .required("Y")
        .collect_pixels(
            |res: Vec2<usize>, _: &(exr::meta::attribute::ChannelDescription,)| {
                GrowingImage::new(res)
            },
            |img: &mut GrowingImage, pos: Vec2<usize>, (y,): (f32,)| img.set(pos, Rgb::splat(y)),
        )
        .first_valid_layer()
        .all_attributes()
        .from_file(path)?;
    img.layer_data.channel_data.pixels.finish()
}

/// A file's first token for an error message: quoted when it is short printable text, else
/// described, so that binary garbage never reaches the terminal.
fn describe_magic(token: &str) -> String {
    let printable = token.chars().all(|c| c.is_ascii_graphic());
    if printable && token.len() <= 16 {
        format!("{token:?}")
    } else if printable {
        format!("{:?}...", &token[..16])
    } else {
        "binary data".to_string()
    }
}

/// Decode a PFM file held in memory. The header is three whitespace-separated tokens after the
/// magic; a single whitespace byte separates it from the raster, as the format requires.
pub fn decode_pfm(bytes: &[u8]) -> anyhow::Result<Image> {
    let mut pos = 0usize;
    let mut token = || -> anyhow::Result<String> {
        while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while pos < bytes.len() && !bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        if start == pos {
            bail!("truncated PFM header");
        }
        Ok(String::from_utf8_lossy(&bytes[start..pos]).into_owned())
    };
    let magic = token()?;
    let channels = match magic.as_str() {
        "PF" => 3,
        "Pf" => 1,
        other => bail!(
            "not a PFM file (it starts with {}, expected \"PF\" or \"Pf\")",
            describe_magic(other)
        ),
    };
    let width: u32 = token()?.parse().context("bad PFM width")?;
    let height: u32 = token()?.parse().context("bad PFM height")?;
    let scale: f32 = token()?.parse().context("bad PFM scale")?;
    if scale == 0.0 || !scale.is_finite() {
        bail!("bad PFM scale {scale}");
    }
    let little = scale < 0.0;
    pos += 1; // the single whitespace byte ending the header
    let need = (width as usize)
        .checked_mul(height as usize)
        .and_then(|n| n.checked_mul(channels * 4))
        .context("PFM size overflows")?;
    let data = bytes.get(pos..).unwrap_or(&[]);
    if data.len() < need {
        bail!(
            "truncated PFM raster: {width}x{height}x{channels} needs {need} bytes, found {}",
            data.len()
        );
    }
    let floats: Vec<f32> = data[..need]
        .chunks_exact(4)
        .map(|b| {
            let b = [b[0], b[1], b[2], b[3]];
            if little {
                f32::from_le_bytes(b)
            } else {
                f32::from_be_bytes(b)
            }
        })
        .collect();
    let mut img = Image::new(width, height);
    let w = width as usize;
    for (row_from_bottom, row) in floats.chunks_exact(w.max(1) * channels).enumerate() {
        let y = height as usize - 1 - row_from_bottom;
        for (x, px) in row.chunks_exact(channels).enumerate() {
            img.pixels[y * w + x] = if channels == 3 {
                Rgb::new(px[0], px[1], px[2])
            } else {
                Rgb::splat(px[0])
            };
        }
    }
    Ok(img)
}
