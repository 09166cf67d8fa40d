//! The embedded label font (DejaVu Sans, Bitstream Vera licence, see `assets/fonts/`) and a
//! tiny text rasteriser for 8-bit RGB images.
//!
//! Embedding the font makes montages and plots identical on every machine, with no dependency
//! on system font configuration.

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};

/// DejaVu Sans TrueType bytes.
pub static FONT_TTF: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The embedded font, parsed (cheap: ab_glyph reads tables lazily).
pub fn font() -> FontRef<'static> {
    // The bytes are compiled in and tested, so failure here is a build defect, not bad input.
    FontRef::try_from_slice(FONT_TTF).expect("embedded DejaVuSans.ttf is a valid font")
}

/// Line height (ascent − descent + line gap) in pixels at size `px`.
pub fn line_height(px: f32) -> f32 {
    let f = font();
    let s = f.as_scaled(PxScale::from(px));
    s.ascent() - s.descent() + s.line_gap()
}

/// Advance width in pixels of one line of `text` at size `px` (kerning included).
pub fn text_width(text: &str, px: f32) -> f32 {
    let f = font();
    let s = f.as_scaled(PxScale::from(px));
    let mut w = 0.0;
    let mut prev = None;
    for c in text.chars() {
        let id = s.glyph_id(c);
        if let Some(p) = prev {
            w += s.kern(p, id);
        }
        w += s.h_advance(id);
        prev = Some(id);
    }
    w
}

/// Draw one line of `text` with its top-left at (x, y), blending `color` by glyph coverage.
/// Pixels outside the image are skipped, so text may safely run off an edge.
pub fn draw_text(img: &mut image::RgbImage, x: f32, y: f32, text: &str, px: f32, color: [u8; 3]) {
    let f = font();
    let scale = PxScale::from(px);
    let s = f.as_scaled(scale);
    let baseline = y + s.ascent();
    let mut caret = x;
    let mut prev = None;
    for c in text.chars() {
        let id = s.glyph_id(c);
        if let Some(p) = prev {
            caret += s.kern(p, id);
        }
        let glyph = id.with_scale_and_position(scale, point(caret, baseline));
        caret += s.h_advance(id);
        prev = Some(id);
        let Some(outline) = f.outline_glyph(glyph) else {
            continue; // whitespace has no outline
        };
        let b = outline.px_bounds();
        outline.draw(|gx, gy, cov| {
            let (px_x, px_y) = (b.min.x as i64 + gx as i64, b.min.y as i64 + gy as i64);
            if px_x < 0 || px_y < 0 || px_x >= img.width() as i64 || px_y >= img.height() as i64 {
                return;
            }
            let dst = img.get_pixel_mut(px_x as u32, px_y as u32);
            let a = cov.clamp(0.0, 1.0);
            for k in 0..3 {
                let v = dst[k] as f32 * (1.0 - a) + color[k] as f32 * a;
                dst[k] = (v + 0.5) as u8;
            }
        });
    }
}
