//! `penumbra bench`: rays/s and time per image on the standard scenes (a benchmark, not a test).

use glam::UVec2;
use penumbra::integrator::{RenderOptions, Strategy, render};
use penumbra::scene::builtin;
use penumbra::scene::load::{LoadOptions, load};
use std::time::Instant;

/// Arguments of `penumbra bench`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Eye rays per pixel.
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Resolution WxH.
    #[arg(long, default_value = "512x512", value_parser = super::render::parse_res)]
    pub res: UVec2,
    /// Only these scenes (comma separated); default: the standard set.
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<String>,
}

/// The scenes benchmarked by default.
const STANDARD: &[&str] = &["cornell", "dense"];

/// Run the command.
pub fn run(args: Args) -> anyhow::Result<()> {
    let names: Vec<String> = if args.scenes.is_empty() {
        STANDARD
            .iter()
            .filter(|n| builtin::find(n).is_some())
            .map(|s| s.to_string())
            .collect()
    } else {
        args.scenes.clone()
    };
    println!(
        "| scene | triangles/prims | BVH build (s) | strategy | spp | time (s) | Mrays/s | Msamples/s |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for name in &names {
        let t0 = Instant::now();
        let loaded = load(name, &LoadOptions::default())?;
        let _load_time = t0.elapsed();
        let scene = loaded.scene;
        for strategy in [Strategy::Mis, Strategy::LightArea, Strategy::Bsdf] {
            let opts = RenderOptions {
                spp: args.spp,
                strategy,
                ..RenderOptions::default()
            };
            let (_, stats) = render(&scene, args.res, &opts)?;
            let samples = args.res.x as f64 * args.res.y as f64 * args.spp as f64;
            println!(
                "| {} | {} | {:.3} | {} | {} | {:.3} | {:.1} | {:.2} |",
                name,
                scene.geometry.len(),
                scene.geometry.build_time.as_secs_f64(),
                strategy,
                args.spp,
                stats.time.as_secs_f64(),
                stats.mrays_per_s(),
                samples / stats.time.as_secs_f64() / 1e6
            );
        }
    }
    Ok(())
}
