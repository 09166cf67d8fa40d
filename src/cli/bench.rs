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
    bvh_section(&names)?;
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

/// BVH section: build time and closest-/any-hit Mrays/s of both backends on random rays
/// (origins in the scene box, uniform directions; one thread).
fn bvh_section(names: &[String]) -> anyhow::Result<()> {
    use glam::Vec3;
    use penumbra::geometry::{Backend, Ray, RayQuery};
    use penumbra::sampling::{PatternKind, make_pattern};
    println!("| scene | backend | prims | build (s) | closest Mrays/s | any-hit Mrays/s |");
    println!("|---|---|---|---|---|---|");
    const N: u32 = 1_000_000;
    for name in names {
        let scene = load(name, &LoadOptions::default())?.scene;
        let (lo, hi) = scene.geometry.bounds();
        let pat = make_pattern(PatternKind::Random, 1);
        let rays: Vec<Ray> = (0..N)
            .map(|i| {
                let px = UVec2::new(i, 0);
                let (a, b, c) = (
                    pat.sample_2d(px, 0, 0, 1),
                    pat.sample_2d(px, 1, 0, 1),
                    pat.sample_1d(px, 2, 0, 1),
                );
                let o = lo + (hi - lo) * Vec3::new(a.x, a.y, b.x);
                let z = 1.0 - 2.0 * b.y;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = std::f32::consts::TAU * c;
                Ray::new(o, Vec3::new(r * phi.cos(), r * phi.sin(), z))
            })
            .collect();
        for backend in [Backend::Own, Backend::Obvhs] {
            let g = scene.geometry.rebuild(backend);
            let t = Instant::now();
            let hits = rays.iter().filter(|r| g.intersect(r).is_some()).count();
            let closest = N as f64 / t.elapsed().as_secs_f64() / 1e6;
            let t = Instant::now();
            let blocked = rays.iter().filter(|r| g.occluded(r)).count();
            let any = N as f64 / t.elapsed().as_secs_f64() / 1e6;
            anyhow::ensure!(
                hits == blocked || backend == Backend::Obvhs,
                "{name}: any-hit {blocked} != closest {hits}"
            );
            println!(
                "| {name} | {backend:?} | {} | {:.3} | {closest:.1} | {any:.1} |",
                g.len(),
                g.build_time.as_secs_f64()
            );
        }
    }
    println!();
    Ok(())
}
