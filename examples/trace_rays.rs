//! Ray-query micro-benchmark of one BVH backend (for profiling the query path):
//! `cargo run --release --example trace_rays -- SCENE BACKEND [closest|any|render] [RAYS|SPP]`.
//! `render` renders 512² with MIS (area light sampling) and prints the time.

use penumbra::geometry::{Backend, RayQuery, random_query_rays};
use penumbra::scene::load::{LoadOptions, load};
use std::time::Instant;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let scene = args.get(1).map_or("cornell", String::as_str);
    let backend = match args.get(2).map_or("wide", String::as_str) {
        "own" => Backend::Own,
        "obvhs" => Backend::Obvhs,
        _ => Backend::Wide,
    };
    let any = args.get(3).is_some_and(|s| s == "any");
    if args.get(3).is_some_and(|s| s == "render") {
        let mut scene = load(scene, &LoadOptions::default())?.scene;
        scene.geometry = scene.geometry.rebuild(backend);
        let opts = penumbra::integrator::RenderOptions {
            spp: args.get(4).and_then(|s| s.parse().ok()).unwrap_or(64),
            mis_light: penumbra::lights::SamplingMode::Area,
            ..Default::default()
        };
        let (_, stats) = penumbra::integrator::render(&scene, glam::UVec2::new(512, 512), &opts)?;
        println!("render {backend:?}: {:.3} s", stats.time.as_secs_f64());
        return Ok(());
    }
    let n: u32 = args
        .get(4)
        .and_then(|s| s.parse().ok())
        .unwrap_or(2_000_000);
    let g = load(scene, &LoadOptions::default())?
        .scene
        .geometry
        .rebuild(backend);
    println!("prims {}", g.len());
    let rays = random_query_rays(g.bounds(), n);
    if std::env::var("CHECKSUM").is_ok() {
        let sum = rays.iter().fold(0u64, |acc, r| {
            let id = g.intersect(r).map_or(u32::MAX, |h| h.prim);
            acc.wrapping_mul(1_000_003).wrapping_add(id as u64)
        });
        println!("checksum {sum:x}");
    }
    let t = Instant::now();
    let hits = if any {
        rays.iter().filter(|r| g.occluded(r)).count()
    } else {
        rays.iter().filter(|r| g.intersect(r).is_some()).count()
    };
    let s = t.elapsed().as_secs_f64();
    println!(
        "{scene} {backend:?} any={any}: {hits} hits, {:.2} Mrays/s",
        n as f64 / s / 1e6
    );
    Ok(())
}
