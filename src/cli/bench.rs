//! `penumbra bench`: rays/s and time per image on the standard scenes (a benchmark, not a test).
//! `penumbra bench --many-lights`: every light-selection strategy on the many-light scenes at
//! equal samples, scored by relMSE against a cached high-spp reference.

use anyhow::Context;
use glam::UVec2;
use penumbra::image::{compare, read_image, write_image};
use penumbra::integrator::{RenderOptions, Strategy, render};
use penumbra::light_selection::{LightSet, SelectorKind, bvh::BvhSelector, make_selector};
use penumbra::scene::builtin::{self, BuiltinOptions};
use penumbra::scene::load::{LoadOptions, load};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `penumbra bench`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Eye rays per pixel (default 64; with --many-lights 8).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Resolution WxH (default 512x512; with --many-lights 160x120).
    #[arg(long, value_parser = super::render::parse_res)]
    pub res: Option<UVec2>,
    /// Only these scenes (comma separated); default: the standard set (or the many-* scenes).
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<String>,
    /// Compare the light-selection strategies on the many-light scenes instead.
    #[arg(long)]
    pub many_lights: bool,
    /// With --many-lights: only these strategies (comma separated); default all.
    #[arg(long, value_delimiter = ',')]
    pub selectors: Vec<SelectorKind>,
    /// With --many-lights: reference spp = this × --spp.
    #[arg(long, default_value_t = 32)]
    pub reference_factor: u32,
    /// With --many-lights: run `exhaustive` (O(N) per sample) only up to this many lights.
    #[arg(long, default_value_t = 2000)]
    pub max_exhaustive_lights: usize,
    /// Number of lights of the many-light built-in scenes.
    #[arg(long)]
    pub light_count: Option<u32>,
    /// Rooms per side of `many-rooms`.
    #[arg(long)]
    pub rooms: Option<u32>,
}

/// The scenes benchmarked by default.
const STANDARD: &[&str] = &["cornell", "dense"];

/// Run the command.
pub fn run(args: Args) -> anyhow::Result<()> {
    if args.many_lights {
        return run_many(&args);
    }
    let spp = args.spp.unwrap_or(64);
    let res = args.res.unwrap_or(UVec2::new(512, 512));
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
                spp,
                strategy,
                ..RenderOptions::default()
            };
            let (_, stats) = render(&scene, res, &opts)?;
            let samples = res.x as f64 * res.y as f64 * spp as f64;
            println!(
                "| {} | {} | {:.3} | {} | {} | {:.3} | {:.1} | {:.2} |",
                name,
                scene.geometry.len(),
                scene.geometry.build_time.as_secs_f64(),
                strategy,
                spp,
                stats.time.as_secs_f64(),
                stats.mrays_per_s(),
                samples / stats.time.as_secs_f64() / 1e6
            );
        }
    }
    path_section(&names, spp, res)
}

/// Path-traced rows: the default Cornell box's path tracing (MIS, max depth 65, pbrt-v4's
/// file's) on each scene, with the rays of each kind and the Mrays/s of their queries alone
/// (the time inside the camera packets' closest-hit queries, the shadow rays' any-hit packet
/// queries and the continuing BSDF rays' one-ray closest-hit queries), so the cost of
/// incoherence is visible.
fn path_section(names: &[String], spp: u32, res: UVec2) -> anyhow::Result<()> {
    use penumbra::integrator::IntegratorKind;
    use penumbra::integrator::stages::TIME_QUERIES;
    use std::sync::atomic::Ordering;
    println!();
    println!(
        "| scene | path, max depth | spp | time (s) | Mrays/s (all) | camera: rays, Mrays/s per thread | shadow: rays, Mrays/s per thread | secondary: rays, Mrays/s per thread | emitter-gather rays |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for name in names {
        let scene = load(name, &LoadOptions::default())?.scene;
        let opts = RenderOptions {
            spp,
            integrator: IntegratorKind::Path,
            max_depth: 65,
            ..RenderOptions::default()
        };
        TIME_QUERIES.store(true, Ordering::Relaxed);
        let r = render(&scene, res, &opts);
        TIME_QUERIES.store(false, Ordering::Relaxed);
        let (_, stats) = r?;
        let k = &stats.by_kind;
        let m = |n: u64| n as f64 / 1e6;
        println!(
            "| {name} | mis, {} | {spp} | {:.3} | {:.1} | {:.2}M, {:.1} | {:.2}M, {:.1} | {:.2}M, {:.1} | {:.2}M |",
            opts.max_depth,
            stats.time.as_secs_f64(),
            stats.mrays_per_s(),
            m(k.timed.camera.rays),
            k.timed.camera.mrays_per_s(),
            m(k.timed.shadow.rays),
            k.timed.shadow.mrays_per_s(),
            m(k.timed.secondary.rays),
            k.timed.secondary.mrays_per_s(),
            m(k.gather),
        );
    }
    Ok(())
}

/// BVH section: build time and closest-/any-hit Mrays/s of both backends on random rays
/// (origins in the scene box, uniform directions; one thread).
fn bvh_section(names: &[String]) -> anyhow::Result<()> {
    use penumbra::geometry::{Backend, RayQuery, random_query_rays};
    println!("| scene | backend | prims | build (s) | closest Mrays/s | any-hit Mrays/s |");
    println!("|---|---|---|---|---|---|");
    const N: u32 = 1_000_000;
    for name in names {
        let scene = load(name, &LoadOptions::default())?.scene;
        let rays = random_query_rays(scene.geometry.bounds(), N);
        for backend in [Backend::Own, Backend::Obvhs, Backend::Wide] {
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

/// The scenes of `--many-lights`.
const MANY: &[&str] = &["many-open", "many-rooms", "many-mesh"];

/// The strategy the reference of `scene` is rendered with (the best one there, at high spp).
fn reference_selector(scene: &str) -> SelectorKind {
    if scene == "many-rooms" {
        SelectorKind::Adaptive
    } else {
        SelectorKind::Bvh
    }
}

/// Where references are cached: `target/many-bench/` next to the executable's target dir when
/// there is one, else the system temp dir.
fn cache_dir() -> PathBuf {
    let base = std::env::current_exe()
        .ok()
        .and_then(|e| {
            e.ancestors()
                .find(|a| a.file_name().is_some_and(|n| n == "target"))
                .map(|p| p.to_path_buf())
        })
        .unwrap_or_else(std::env::temp_dir);
    base.join("many-bench")
}

/// `penumbra bench --many-lights`.
fn run_many(args: &Args) -> anyhow::Result<()> {
    let spp = args.spp.unwrap_or(8);
    let res = args.res.unwrap_or(UVec2::new(160, 120));
    let bopts = BuiltinOptions {
        light_count: args.light_count,
        rooms: args.rooms,
        triangles: None,
    };
    let lopts = LoadOptions {
        builtin: bopts.clone(),
        ..LoadOptions::default()
    };
    let names: Vec<String> = if args.scenes.is_empty() {
        MANY.iter().map(|s| s.to_string()).collect()
    } else {
        args.scenes.clone()
    };
    let selectors: Vec<SelectorKind> = if args.selectors.is_empty() {
        SelectorKind::ALL.to_vec()
    } else {
        args.selectors.clone()
    };
    let dir = cache_dir();
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    println!(
        "{}x{}, {spp} spp, MIS, reference {}x spp",
        res.x, res.y, args.reference_factor
    );
    println!();
    println!(
        "| scene | lights | strategy | build (s) | render (s) | relMSE | efficiency vs power |"
    );
    println!("|---|---|---|---|---|---|---|");
    for name in &names {
        let scene = load(name, &lopts)?.scene;
        let n = scene.lights.len();
        let ref_sel = reference_selector(name);
        let ref_path = dir.join(format!(
            "{name}-{}x{}-{}spp-{ref_sel}-{:?}-{:?}.pfm",
            res.x,
            res.y,
            spp * args.reference_factor,
            args.light_count,
            args.rooms
        ));
        let reference = match read_image(&ref_path) {
            Ok(img) if img.width == res.x && img.height == res.y => img,
            _ => {
                let opts = RenderOptions {
                    spp: spp * args.reference_factor,
                    seed: 0x05ee_d4ef,
                    light_selection: ref_sel,
                    ..RenderOptions::default()
                };
                let (img, _) = render(&scene, res, &opts)?;
                write_image(&img, &ref_path, 0.0)?;
                img
            }
        };
        let mut rows = Vec::new();
        for &sel in &selectors {
            if sel == SelectorKind::Exhaustive && n > args.max_exhaustive_lights {
                rows.push((sel, None));
                continue;
            }
            let t0 = Instant::now();
            make_selector(sel, &scene, 0);
            let build = t0.elapsed().as_secs_f64();
            let opts = RenderOptions {
                spp,
                light_selection: sel,
                ..RenderOptions::default()
            };
            let (img, stats) = render(&scene, res, &opts)?;
            let rel = compare(&img, &reference)?.rel_mse;
            rows.push((sel, Some((build, stats.time.as_secs_f64(), rel))));
        }
        let eff = |b: f64, t: f64, r: f64| 1.0 / (r * (b + t)).max(1e-300);
        let power = rows
            .iter()
            .find(|(s, _)| *s == SelectorKind::Power)
            .and_then(|(_, r)| *r)
            .map(|(b, t, r)| eff(b, t, r));
        for (sel, r) in rows {
            match r {
                None => println!(
                    "| {name} | {n} | {sel} | – | – | – | skipped (> {} lights) |",
                    args.max_exhaustive_lights
                ),
                Some((b, t, rel)) => {
                    let e =
                        power.map_or("–".to_string(), |p| format!("{:.2}", eff(b, t, rel) / p));
                    println!("| {name} | {n} | {sel} | {b:.3} | {t:.3} | {rel:.4e} | {e} |");
                }
            }
        }
    }
    bvh_build_benchmark(100_000)
}

/// Build time and memory of the light BVH over the lights of `many-open` with `count` lights.
fn bvh_build_benchmark(count: u32) -> anyhow::Result<()> {
    let opts = LoadOptions {
        builtin: BuiltinOptions {
            light_count: Some(count),
            ..BuiltinOptions::default()
        },
        ..LoadOptions::default()
    };
    let scene = load("many-open", &opts)?.scene;
    let set = LightSet::new(&scene.lights);
    let (t0, c0) = (Instant::now(), cpu_seconds());
    let bvh = BvhSelector::new(&set.bounds);
    let t = t0.elapsed().as_secs_f64();
    let cpu = cpu_seconds().zip(c0).map_or(f64::NAN, |(a, b)| a - b);
    println!();
    println!(
        "light BVH over {} lights: build {t:.3} s wall ({cpu:.3} s CPU, all threads), {} nodes, {:.1} bytes/light",
        set.bounds.len(),
        bvh.node_count(),
        bvh.bytes_per_light()
    );
    Ok(())
}

/// CPU time (user + system) of this process so far, from /proc (Linux); `None` elsewhere. Wall
/// time alone misleads on a shared machine.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the parenthesised command name; utime and stime are the 12th and 13th.
    let rest = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}
