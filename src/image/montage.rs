//! Labelled side-by-side panels for the lab: one grid cell per image, label lines beneath.

use super::Image;
use super::font::{draw_text, line_height, text_width};
use super::io::to_rgb8;

pub use super::io::save_png_atomic;

/// Gap between cells and around the border, in pixels.
const PAD: u32 = 8;
/// Label font size in pixels.
const LABEL_PX: f32 = 16.0;
/// Title font size in pixels.
const TITLE_PX: f32 = 22.0;
/// Background: dark grey so black renders and white text both stay visible.
const BACKGROUND: [u8; 3] = [32, 32, 32];
/// Text colour.
const INK: [u8; 3] = [235, 235, 235];

/// Lay out linear `panels` in a grid of `cols` columns (clamped to 1..=panels), each tonemapped
/// with `2^exposure` and sRGB, its label (lines separated by `\n`) centred beneath it, and
/// `title` (if non-empty) above the grid. Cells are sized to the largest panel; smaller panels
/// are centred in theirs.
pub fn montage(panels: &[(Image, String)], cols: usize, exposure: f32, title: &str) -> image::RgbImage {
    let n = panels.len();
    let cols = cols.clamp(1, n.max(1));
    let rows = n.div_ceil(cols);
    let cell_w = panels.iter().map(|(i, _)| i.width).max().unwrap_or(0);
    let cell_h = panels.iter().map(|(i, _)| i.height).max().unwrap_or(0);
    let label_line = line_height(LABEL_PX).ceil() as u32;
    let max_lines = panels
        .iter()
        .map(|(_, l)| if l.is_empty() { 0 } else { l.lines().count() })
        .max()
        .unwrap_or(0) as u32;
    let label_h = if max_lines > 0 { max_lines * label_line + PAD / 2 } else { 0 };
    let title_h = if title.is_empty() { 0 } else { line_height(TITLE_PX).ceil() as u32 + PAD };

    // Cells must also be wide enough for their labels, or text would spill into neighbours.
    let widest_label = panels
        .iter()
        .flat_map(|(_, l)| l.lines())
        .map(|l| text_width(l, LABEL_PX).ceil() as u32)
        .max()
        .unwrap_or(0);
    let cell_w = cell_w.max(widest_label);
    let grid_w = PAD + cols as u32 * (cell_w + PAD);
    let title_w = if title.is_empty() { 0 } else { text_width(title, TITLE_PX).ceil() as u32 + 2 * PAD };
    let width = grid_w.max(title_w).max(1);
    let height = (PAD + title_h + rows as u32 * (cell_h + label_h + PAD)).max(1);

    let mut out = image::RgbImage::from_pixel(width, height, image::Rgb(BACKGROUND));
    if !title.is_empty() {
        let x = (width as f32 - text_width(title, TITLE_PX)) / 2.0;
        draw_text(&mut out, x.max(PAD as f32), PAD as f32, title, TITLE_PX, INK);
    }
    for (k, (img, label)) in panels.iter().enumerate() {
        let (col, row) = ((k % cols) as u32, (k / cols) as u32);
        let cx = PAD + col * (cell_w + PAD);
        let cy = PAD + title_h + row * (cell_h + label_h + PAD);
        let ox = cx + (cell_w - img.width) / 2;
        let oy = cy + (cell_h - img.height) / 2;
        image::imageops::replace(&mut out, &to_rgb8(img, exposure), ox as i64, oy as i64);
        for (i, line) in label.lines().enumerate() {
            let x = cx as f32 + (cell_w as f32 - text_width(line, LABEL_PX)) / 2.0;
            let y = (cy + cell_h + PAD / 4 + i as u32 * label_line) as f32;
            draw_text(&mut out, x, y, line, LABEL_PX, INK);
        }
    }
    out
}
