//! Montage layout and text rendering, convergence plot files.

use std::path::PathBuf;

use penumbra::Rgb;
use penumbra::image::Image;
use penumbra::image::font::{FONT_TTF, text_width};
use penumbra::image::montage::{montage, save_png_atomic};
use penumbra::image::plot::convergence_plot;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-image-mon-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn gradient(w: u32, h: u32) -> Image {
    Image::from_fn(w, h, |x, y| Rgb::new(x as f32 / w as f32, y as f32 / h as f32, 0.25))
}

#[test]
fn montage_dimensions_and_content() {
    let panels = vec![
        (gradient(64, 48), "bsdf\nrelMSE 1.2e-3".to_string()),
        (gradient(64, 48), "light".to_string()),
        (gradient(40, 30), "mis\nrelMSE 3.4e-4".to_string()),
    ];
    let m = montage(&panels, 2, 0.0, "Cornell, 16 spp");
    // 2 columns, 2 rows; cells are at least panel-sized, plus title and two label lines.
    assert!(m.width() >= 2 * 64 + 3 * 8, "{}", m.width());
    assert!(m.height() >= 2 * 48 + 22 + 2 * 2 * 16, "{}", m.height());
    // One column: taller and narrower than two.
    let one = montage(&panels, 1, 0.0, "");
    assert!(one.height() > m.height() && one.width() < m.width());
    // Text was drawn: some near-white pixels exist in the label area below the first panel.
    let bright = (8..72)
        .flat_map(|x| (8 + 30 + 48..m.height()).map(move |y| (x, y)))
        .filter(|&(x, y)| y < m.height() && m.get_pixel(x, y)[0] > 200)
        .count();
    assert!(bright > 10, "no label text rendered");
    // The panel is copied with sRGB encoding: find its top-left pixel's blue channel 0.25 → 137.
    let found = m.pixels().any(|p| p[2] == 137);
    assert!(found, "panel pixels not found");
    // Empty input does not panic.
    let empty = montage(&[], 3, 0.0, "nothing");
    assert!(empty.width() > 0 && empty.height() > 0);

    let dir = scratch("montage");
    let p = dir.join("m.png");
    save_png_atomic(&m, &p).unwrap();
    let back = image::open(&p).unwrap().to_rgb8();
    assert_eq!(back, m);
}

#[test]
fn embedded_font_measures_text() {
    assert!(FONT_TTF.len() > 100_000);
    let w1 = text_width("relMSE", 16.0);
    let w2 = text_width("relMSE relMSE", 16.0);
    assert!(w1 > 30.0 && w2 > 2.0 * w1, "{w1} {w2}");
}

#[test]
fn convergence_plot_writes_svg_and_png() {
    let dir = scratch("plot");
    let series: Vec<(String, Vec<(f64, f64)>)> = vec![
        ("bsdf".into(), (1..=8).map(|k| (k as f64 * 0.1, 1.0 / k as f64)).collect()),
        ("mis".into(), (1..=8).map(|k| (k as f64 * 0.12, 0.1 / k as f64)).collect()),
        // Non-positive points cannot be shown on log axes and must be skipped, not crash.
        ("broken".into(), vec![(0.0, 1.0), (1.0, 0.0), (f64::NAN, 1.0)]),
    ];
    let (svg, png) = (dir.join("c.svg"), dir.join("c.png"));
    convergence_plot(&series, "relMSE vs time", &svg, &png).unwrap();
    let svg_text = std::fs::read_to_string(&svg).unwrap();
    assert!(svg_text.contains("<svg") && svg_text.contains("mis"));
    let img = image::open(&png).unwrap();
    assert!(img.width() > 100 && img.height() > 100);
    // No data at all still yields files (empty axes), not an error or panic.
    convergence_plot(&[], "empty", &svg, &png).unwrap();
    assert!(std::fs::metadata(&png).unwrap().len() > 0);
}
