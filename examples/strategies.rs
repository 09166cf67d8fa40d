//! The README's side-by-side figure of the four direct-lighting estimators on `cornell-phong`
//! at equal samples, each labelled with its time and relMSE against a high-spp MIS reference.
//!
//! `cargo run --release --example strategies -- OUT.png [RES] [SPP]`

use glam::UVec2;
use penumbra::image::io::save_png_atomic;
use penumbra::image::metrics::compare;
use penumbra::image::montage::montage;
use penumbra::integrator::{RenderOptions, Strategy, render};
use penumbra::scene::load::{LoadOptions, load};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let out = args.get(1).map(String::as_str).unwrap_or("strategies.png");
    let res: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(192);
    let spp: u32 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(16);
    let res = UVec2::new(res, res);
    let scene = load("cornell-phong", &LoadOptions::default())?.scene;
    let reference = render(
        &scene,
        res,
        &RenderOptions {
            spp: 1024,
            seed: 99,
            ..RenderOptions::default()
        },
    )?
    .0;
    let mut panels = Vec::new();
    for strategy in Strategy::ALL {
        let opts = RenderOptions {
            spp,
            strategy,
            seed: 1,
            ..RenderOptions::default()
        };
        let (img, stats) = render(&scene, res, &opts)?;
        let e = compare(&img, &reference)?;
        let label = format!(
            "{strategy}\n{spp} spp x 1, {:.2} s\nrelMSE {:.2e}",
            stats.time.as_secs_f64(),
            e.rel_mse
        );
        println!("{}", label.replace('\n', " | "));
        panels.push((img, label));
    }
    let m = montage(
        &panels,
        4,
        0.0,
        "cornell-phong: four estimators at equal samples",
    );
    save_png_atomic(&m, std::path::Path::new(out))
}
