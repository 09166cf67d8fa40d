//! PNG panels of a warp: the samples in an equal-area view of their domain, and the histogram,
//! integrated pdf and their standardised difference on the chi-square grid.
//!
//! Equal-area views matter: in them a uniform density looks uniform, so every visible
//! clustering is a property of the sampler, not of the projection.

use glam::{Vec2, Vec3};
use image::{Rgb as Px, RgbImage};
use std::path::{Path, PathBuf};

use super::registry::{Domain, Warp};
use super::run::RunResult;
use crate::Rgb;
use crate::image::Image;
use crate::image::colormap::viridis;
use crate::image::io::{save_png_atomic, srgb_to_linear};
use crate::image::montage::montage;

/// Background outside the domain.
const BACKGROUND: [u8; 3] = [40, 40, 40];
/// Outline of the domain.
const OUTLINE: [u8; 3] = [150, 150, 150];
/// Diameter of one hemisphere disk of the scatter panel.
const SCATTER_PX: u32 = 360;
/// Longer side of a planar scatter panel.
const PLANE_PX: u32 = 512;
/// Width the grid panels are scaled to (approximately; cells stay whole pixels).
const GRID_PX: u32 = 512;
/// Residuals beyond this many standard deviations saturate the difference colours.
const RESIDUAL_RANGE: f64 = 4.0;

/// Lambert azimuthal equal-area projection of a unit direction onto the unit disk of its
/// hemisphere: radius √(1 − |z|), i.e. (x, y) / √(1 + |z|). The disk's area π maps to 2π sr,
/// so equal solid angles become equal areas.
pub fn lambert_azimuthal(d: Vec3) -> Vec2 {
    Vec2::new(d.x, d.y) / (1.0 + d.z.abs()).sqrt()
}

/// Where a sample lands in the scatter image, if anywhere.
struct ScatterLayout {
    domain: Domain,
    width: u32,
    height: u32,
}

impl ScatterLayout {
    fn new(domain: Domain) -> Self {
        match domain {
            // Upper hemisphere left, lower hemisphere right.
            Domain::Sphere => Self {
                domain,
                width: 2 * SCATTER_PX,
                height: SCATTER_PX,
            },
            Domain::Plane { rect, .. } => {
                let (w, h) = (rect[1] - rect[0], rect[3] - rect[2]);
                let s = PLANE_PX as f32 / w.max(h).max(f32::MIN_POSITIVE);
                Self {
                    domain,
                    width: ((w * s).round() as u32).clamp(8, PLANE_PX),
                    height: ((h * s).round() as u32).clamp(8, PLANE_PX),
                }
            }
        }
    }

    /// Continuous pixel coordinates of sample `x`.
    fn place(&self, x: Vec3) -> Option<Vec2> {
        match self.domain {
            Domain::Sphere => {
                let p = lambert_azimuthal(x.normalize_or_zero());
                let r = SCATTER_PX as f32 * 0.5;
                let ox = if x.z >= 0.0 { r } else { 3.0 * r };
                // Image y grows downwards; keep +y up as in a plot.
                Some(Vec2::new(ox + p.x * (r - 1.0), r - p.y * (r - 1.0)))
            }
            Domain::Plane { rect, y_down } => {
                let u = (x.x - rect[0]) / (rect[1] - rect[0]);
                let v = (x.y - rect[2]) / (rect[3] - rect[2]);
                let v = if y_down { v } else { 1.0 - v };
                Some(Vec2::new(u * self.width as f32, v * self.height as f32))
            }
        }
    }

    /// Whether pixel (i, j) is inside the domain (drawn with the dark end of the colormap).
    fn inside(&self, i: u32, j: u32) -> bool {
        match self.domain {
            Domain::Sphere => {
                let r = SCATTER_PX as f32 * 0.5;
                let cx = if i < SCATTER_PX { r } else { 3.0 * r };
                let d = Vec2::new(i as f32 + 0.5 - cx, j as f32 + 0.5 - r);
                d.length() <= r - 1.0
            }
            Domain::Plane { .. } => true,
        }
    }
}

/// The samples as dots over the domain in an equal-area view. Brightness grows with the number
/// of samples per pixel (1 − e^(−g·count)), with `g` chosen so that a lone dot is visible for
/// small counts and dense regions do not all saturate for large ones.
pub fn scatter(domain: Domain, samples: &[Vec3]) -> RgbImage {
    let layout = ScatterLayout::new(domain);
    let (w, h) = (layout.width, layout.height);
    let mut counts = vec![0.0f32; (w * h) as usize];
    for &s in samples {
        let Some(p) = layout.place(s).filter(|p| p.is_finite()) else {
            continue;
        };
        let (i, j) = (p.x.floor(), p.y.floor());
        if i >= 0.0 && j >= 0.0 && (i as u32) < w && (j as u32) < h {
            counts[(j as u32 * w + i as u32) as usize] += 1.0;
        }
    }
    let area = match domain {
        Domain::Sphere => std::f32::consts::PI * (SCATTER_PX as f32 * 0.5).powi(2),
        Domain::Plane { .. } => (w * h) as f32,
    };
    let gain = (0.25 * area / samples.len().max(1) as f32).min(1.2);
    let mut img = RgbImage::from_fn(w, h, |i, j| {
        if !layout.inside(i, j) {
            return Px(BACKGROUND);
        }
        let c = counts[(j * w + i) as usize];
        Px(to_u8(viridis(1.0 - (-gain * c).exp())))
    });
    draw_rims(&mut img, &layout);
    img
}

/// Outline the hemisphere disks (the plane needs none: its panel is the domain).
fn draw_rims(img: &mut RgbImage, layout: &ScatterLayout) {
    if layout.domain != Domain::Sphere {
        return;
    }
    let r = SCATTER_PX as f32 * 0.5;
    for cx in [r, 3.0 * r] {
        for k in 0..2048 {
            let a = k as f32 / 2048.0 * std::f32::consts::TAU;
            let (x, y) = (cx + (r - 1.0) * a.cos(), r + (r - 1.0) * a.sin());
            if x >= 0.0 && y >= 0.0 && x < img.width() as f32 && y < img.height() as f32 {
                img.put_pixel(x as u32, y as u32, Px(OUTLINE));
            }
        }
    }
}

/// sRGB colour in [0, 1] to 8 bits.
fn to_u8(c: Rgb) -> [u8; 3] {
    [c.x, c.y, c.z].map(|v| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8)
}

/// A `res.0 × res.1` grid (row-major, first index = first coordinate) as an image with the
/// domain's aspect ratio: on the sphere rows are cos θ from +1 (top) to −1 and columns φ from
/// 0 to 2π (the equal-area 2 × 2π map, so 2:1); on the plane columns are x and rows y
/// (upwards unless `y_down`).
fn grid_image(domain: Domain, res: (usize, usize), color: impl Fn(usize) -> [u8; 3]) -> RgbImage {
    let (na, nb) = (res.0.max(1), res.1.max(1));
    let (cols, rows, aspect) = match domain {
        Domain::Sphere => (nb, na, 0.5),
        Domain::Plane { rect, .. } => {
            let a = (rect[3] - rect[2]) / (rect[1] - rect[0]);
            (
                na,
                nb,
                if a.is_finite() {
                    a.clamp(0.1, 10.0)
                } else {
                    1.0
                },
            )
        }
    };
    let (w, h) = if aspect <= 1.0 {
        (GRID_PX, (GRID_PX as f32 * aspect).round().max(1.0) as u32)
    } else {
        ((GRID_PX as f32 / aspect).round().max(1.0) as u32, GRID_PX)
    };
    RgbImage::from_fn(w, h, |x, y| {
        let c = (x as usize * cols / w as usize).min(cols - 1);
        let r = (y as usize * rows / h as usize).min(rows - 1);
        let k = match domain {
            Domain::Sphere => (na - 1 - r) * nb + c,
            Domain::Plane { y_down, .. } => c * nb + if y_down { r } else { nb - 1 - r },
        };
        Px(color(k))
    })
}

/// Histogram and expected counts on one shared viridis scale (0 … the larger maximum).
pub fn histogram_and_pdf(domain: Domain, r: &RunResult) -> (RgbImage, RgbImage) {
    let max = r
        .chi2
        .observed
        .iter()
        .chain(&r.chi2.expected)
        .fold(0.0f64, |m, &v| if v.is_finite() { m.max(v) } else { m })
        .max(f64::MIN_POSITIVE);
    let shade = |v: &[f64]| {
        let v = v.to_vec();
        grid_image(domain, r.chi2.res, move |k| {
            to_u8(viridis((v.get(k).copied().unwrap_or(0.0) / max) as f32))
        })
    };
    (shade(&r.chi2.observed), shade(&r.chi2.expected))
}

/// Diverging colour for a standardised residual t ∈ [−1, 1]: blue below, red above, dark at 0.
fn diverging(t: f64) -> [u8; 3] {
    let t = if t.is_nan() {
        0.0
    } else {
        t.clamp(-1.0, 1.0) as f32
    };
    let mid = Rgb::splat(0.12);
    let end = if t >= 0.0 {
        Rgb::new(1.0, 0.25, 0.2)
    } else {
        Rgb::new(0.25, 0.5, 1.0)
    };
    to_u8(mid.lerp(end, t.abs()))
}

/// Per-cell Pearson residual (O − E)/√E (E floored at 1 so that empty cells stay finite),
/// clamped at ±[`RESIDUAL_RANGE`] σ.
pub fn difference(domain: Domain, r: &RunResult) -> RgbImage {
    let (o, e) = (&r.chi2.observed, &r.chi2.expected);
    grid_image(domain, r.chi2.res, |k| {
        let (o, e) = (
            o.get(k).copied().unwrap_or(0.0),
            e.get(k).copied().unwrap_or(0.0),
        );
        diverging((o - e) / e.max(1.0).sqrt() / RESIDUAL_RANGE)
    })
}

/// 8-bit sRGB image to a linear [`Image`] (the montage tonemaps back to sRGB).
fn linear(img: &RgbImage) -> Image {
    Image::from_fn(img.width(), img.height(), |x, y| {
        let p = img.get_pixel(x, y).0;
        Rgb::new(
            srgb_to_linear(p[0] as f32 / 255.0),
            srgb_to_linear(p[1] as f32 / 255.0),
            srgb_to_linear(p[2] as f32 / 255.0),
        )
    })
}

/// Write `NAME_samples.png`, `NAME_histogram.png`, `NAME_pdf.png`, `NAME_difference.png` and
/// the labelled overview `NAME.png` into `dir`; returns the paths written.
pub fn write_plots(
    dir: &Path,
    warp: &Warp,
    r: &RunResult,
    note: &str,
) -> anyhow::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)
        .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", dir.display()))?;
    let samples = scatter(warp.domain, &r.samples);
    let (hist, pdf) = histogram_and_pdf(warp.domain, r);
    let diff = difference(warp.domain, r);
    let grid_axes = match warp.domain {
        Domain::Sphere => "rows cos θ +1 → −1, columns φ 0 → 2π",
        Domain::Plane { y_down: true, .. } => "x →, y ↓",
        Domain::Plane { .. } => "x →, y ↑",
    };
    let scatter_label = match warp.domain {
        Domain::Sphere => "samples, Lambert equal-area\nleft z ≥ 0, right z < 0".to_string(),
        _ => "samples".to_string(),
    };
    let panels = [
        (
            &samples,
            "samples",
            format!("{scatter_label}\n{} of {}", r.samples.len(), r.attempts),
        ),
        (&hist, "histogram", format!("histogram\n{grid_axes}")),
        (&pdf, "pdf", "integrated pdf (same scale)".to_string()),
        (
            &diff,
            "difference",
            format!("(O − E)/√E, ±{RESIDUAL_RANGE}σ\nblue: too few, red: too many"),
        ),
    ];
    let mut written = Vec::new();
    for (img, suffix, _) in &panels {
        let path = dir.join(format!("{}_{suffix}.png", warp.name));
        save_png_atomic(img, &path)?;
        written.push(path);
    }
    let linear_panels: Vec<(Image, String)> = panels
        .iter()
        .map(|(img, _, l)| (linear(img), l.clone()))
        .collect();
    let mut title = format!("{} — {}", warp.label, r.chi2.summary());
    if !note.is_empty() {
        title.push_str(&format!(" ({note})"));
    }
    let overview = montage(&linear_panels, 2, 0.0, &title);
    let path = dir.join(format!("{}.png", warp.name));
    save_png_atomic(&overview, &path)?;
    written.push(path);
    Ok(written)
}
