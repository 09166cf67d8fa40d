//! relMSE restricted to "smooth" pixels: those whose 3×3 neighbourhood in the reference has no
//! discontinuity (silhouette or emitter edge).
//!
//! With only a few eye rays per pixel, relMSE against a converged reference is dominated by
//! edge aliasing, which is the same for every light-sampling strategy and hides the noise the
//! lecture's figures are about. Penumbrae vary smoothly at the pixel scale, so they stay in.

use crate::image::Image;
use crate::image::metrics::REL_MSE_EPSILON;

/// A neighbour differing from the centre by more than this fraction of their mean
/// (plus a small absolute floor) marks the centre as an edge pixel.
const EDGE_CONTRAST: f64 = 0.25;
/// Absolute floor of the contrast test, in radiance units, so dark noise is no edge.
const EDGE_FLOOR: f64 = 0.02;

/// `true` for pixels of `reference` that lie on or next to a discontinuity.
pub fn edge_mask(reference: &Image) -> Vec<bool> {
    let (w, h) = (reference.width as i64, reference.height as i64);
    let lum = |x: i64, y: i64| {
        let p = reference.get(x as u32, y as u32);
        (p.x as f64 + p.y as f64 + p.z as f64) / 3.0
    };
    let mut mask = vec![false; reference.pixels.len()];
    for y in 0..h {
        for x in 0..w {
            let c = lum(x, y);
            let mut edge = !c.is_finite();
            for (dx, dy) in [
                (-1, -1),
                (0, -1),
                (1, -1),
                (-1, 0),
                (1, 0),
                (-1, 1),
                (0, 1),
                (1, 1),
            ] {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w || ny >= h {
                    continue;
                }
                let n = lum(nx, ny);
                if (n - c).abs() > EDGE_CONTRAST * 0.5 * (n + c) + EDGE_FLOOR {
                    edge = true;
                    break;
                }
            }
            mask[(y * w + x) as usize] = edge;
        }
    }
    mask
}

/// relMSE of `test` against `reference` over the pixels where `mask` is `false`, and the
/// fraction of pixels used. Sizes must agree (the caller compared them already).
pub fn smooth_rel_mse(test: &Image, reference: &Image, mask: &[bool]) -> (f64, f64) {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for ((a, b), &edge) in test.pixels.iter().zip(&reference.pixels).zip(mask) {
        if edge {
            continue;
        }
        for c in 0..3 {
            let (a, b) = (a[c] as f64, b[c] as f64);
            sum += (a - b) * (a - b) / (b * b + REL_MSE_EPSILON);
        }
        n += 1;
    }
    let frac = n as f64 / reference.pixels.len().max(1) as f64;
    (sum / (3 * n).max(1) as f64, frac)
}
