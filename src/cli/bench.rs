//! `penumbra bench`: rays/s and time per image on the standard scenes (a benchmark, not a test).
//! `penumbra bench --many-lights`: every light-selection strategy on the many-light scenes at
//! equal samples, scored by relMSE against a cached high-spp reference.

use anyhow::Context;
use glam::UVec2;
use penumbra::image::{compare, read_image, write_image};
use penumbra::integrator::{IntegratorKind, RenderOptions, Strategy, render};
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
    /// Compare the light-selection strategies on the many-light scenes instead. Every render
    /// there, references included, hides the emitters camera rays see directly (`penumbra
    /// render --hide-emitters`): that emission is the same for every selector at equal seed
    /// and spp, and on `many-street` its sub-pixel lamp slivers of radiance ~10^4 decided the
    /// relMSE by whether a camera ray happened to hit one.
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
    /// With --many-lights: also compare at equal time: every strategy renders as many samples
    /// per pixel as fit in SECONDS of CPU time (its time per sample from the equal-spp run).
    #[arg(long, value_name = "SECONDS")]
    pub time: Option<f64>,
    /// With --many-lights: instead of rendering, time each strategy's `sample` and `pmf` per
    /// call on eye-ray shading points (one thread), on the scenes and on `many-open` with each
    /// of --light-counts lights.
    #[arg(long)]
    pub selector_cost: bool,
    /// With --selector-cost: `many-open` light counts to add (comma separated).
    #[arg(long, value_delimiter = ',')]
    pub light_counts: Vec<u32>,
    /// With --many-lights: interleaved repetitions of every timing (the median is reported).
    #[arg(long, default_value_t = 3)]
    pub repeats: u32,
    /// With --many-lights: the light transport of every render, references included
    /// (`direct` or `path`).
    #[arg(long, default_value_t = IntegratorKind::Direct)]
    pub integrator: IntegratorKind,
    /// With --many-lights and `--integrator path`: the paths' max depth.
    #[arg(long, default_value_t = 5)]
    pub max_depth: u32,
}

/// The scenes benchmarked by default.
const STANDARD: &[&str] = &["cornell", "dense"];

/// Run the command.
pub fn run(args: Args) -> anyhow::Result<()> {
    if args.many_lights && args.selector_cost {
        return selector_cost(&args);
    }
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
const MANY: &[&str] = &["many-open", "many-rooms", "many-mesh", "many-street"];

/// The strategies whose high-spp renders are averaged into a scene's reference: three
/// unrelated unbiased estimators (the O(N) `exhaustive` where the scene has few enough lights,
/// else `power`; the `spatial` grid; the light BVH), each with its own seed, so no measured
/// render shares more than a third of its reference's estimator and none its noise.
fn reference_selectors(lights: usize, max_exhaustive: usize) -> [SelectorKind; 3] {
    let first = if lights <= max_exhaustive {
        SelectorKind::Exhaustive
    } else {
        SelectorKind::Power
    };
    [first, SelectorKind::Spatial, SelectorKind::Bvh]
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
    let lopts = many_load_options(args);
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
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    println!(
        "{}x{}, {spp} spp, MIS, {}, direct emission hidden: the selectors do not change it, one thread, CPU time (median of {} interleaved runs), load average {}",
        res.x,
        res.y,
        match args.integrator {
            IntegratorKind::Direct => "direct lighting".to_string(),
            IntegratorKind::Path => format!("path tracing (max depth {})", args.max_depth),
        },
        args.repeats.max(1),
        load_average()
    );
    println!();
    let time_cols = if let Some(t) = args.time {
        format!(" spp in {t} s | relMSE at {t} s | equal-time efficiency vs power |")
    } else {
        String::new()
    };
    println!(
        "| scene | lights | reference | strategy | build (s) | render (s) | relMSE | equal-spp efficiency vs power |{time_cols}"
    );
    println!(
        "|---|---|---|---|---|---|---|---|{}",
        if args.time.is_some() {
            "---|---|---|"
        } else {
            ""
        }
    );
    for name in &names {
        let scene = load(name, &lopts)?.scene;
        let n = scene.lights.len();
        let (reference, ref_name) = many_reference(args, &scene, name, res, spp, &dir)?;
        // Equal spp: every strategy `repeats` times, interleaved; the median CPU time.
        let runnable: Vec<SelectorKind> = selectors
            .iter()
            .copied()
            .filter(|&s| s != SelectorKind::Exhaustive || n <= args.max_exhaustive_lights)
            .collect();
        let mut times: Vec<Vec<(f64, f64)>> = vec![Vec::new(); runnable.len()];
        let mut rel = vec![0.0; runnable.len()];
        for rep in 0..args.repeats.max(1) {
            for (j, &sel) in runnable.iter().enumerate() {
                let opts = RenderOptions {
                    spp,
                    light_selection: sel,
                    ..transport(args)
                };
                let (img, build, t) = pool.install(|| timed_render(&scene, res, &opts))?;
                times[j].push((build, t));
                if rep == 0 {
                    rel[j] = compare(&img, &reference)?.rel_mse;
                }
            }
        }
        let build: Vec<f64> = times
            .iter()
            .map(|t| median(t.iter().map(|x| x.0)))
            .collect();
        let render_t: Vec<f64> = times
            .iter()
            .map(|t| median(t.iter().map(|x| x.1)))
            .collect();
        // Equal time: the spp that fits the budget at the measured time per sample.
        let mut at_time: Vec<Option<(u32, f64, f64)>> = vec![None; runnable.len()];
        if let Some(budget) = args.time {
            for (j, &sel) in runnable.iter().enumerate() {
                let per_spp = render_t[j] / spp as f64;
                let n_spp = (((budget - build[j]) / per_spp).floor() as u32).max(1);
                let opts = RenderOptions {
                    spp: n_spp,
                    seed: 0x7173_0001,
                    light_selection: sel,
                    ..transport(args)
                };
                let (img, b, t) = pool.install(|| timed_render(&scene, res, &opts))?;
                at_time[j] = Some((n_spp, compare(&img, &reference)?.rel_mse, b + t));
            }
        }
        let eff = |b: f64, t: f64, r: f64| 1.0 / (r * (b + t)).max(1e-300);
        let pj = runnable.iter().position(|&s| s == SelectorKind::Power);
        let power = pj.map(|j| eff(build[j], render_t[j], rel[j]));
        let power_t = pj.and_then(|j| at_time[j]).map(|(_, r, t)| eff(0.0, t, r));
        for &sel in &selectors {
            let Some(j) = runnable.iter().position(|&s| s == sel) else {
                println!(
                    "| {name} | {n} | {ref_name} | {sel} | – | – | – | skipped (> {} lights) |",
                    args.max_exhaustive_lights
                );
                continue;
            };
            let (b, t, r) = (build[j], render_t[j], rel[j]);
            let e = power.map_or("–".to_string(), |p| format!("{:.2}", eff(b, t, r) / p));
            let extra = match (at_time[j], power_t) {
                (Some((s, r2, t2)), Some(p)) => {
                    format!(" {s} | {r2:.4e} | {:.2} |", eff(0.0, t2, r2) / p)
                }
                (Some((s, r2, _)), None) => format!(" {s} | {r2:.4e} | – |"),
                _ => String::new(),
            };
            println!(
                "| {name} | {n} | {ref_name} | {sel} | {b:.3} | {t:.3} | {r:.4e} | {e} |{extra}"
            );
        }
    }
    bvh_build_benchmark(100_000)
}

/// The render options of `--many-lights` before spp, seed and selector: MIS, the
/// `--integrator` with its `--max-depth`, and the emitters camera rays see directly hidden.
/// That emission is the same for every selector (same seed, same camera rays, weight 1): it
/// adds only pixel-integral noise, and on `many-street` a lamp seen edge-on (a 10⁻³-pixel
/// sliver of radiance ~10⁴) made the relMSE a coin flip on whether a camera ray hit it, in
/// the measured render and in the reference (docs/many-lights.md, "The many-street firefly").
fn transport(args: &Args) -> RenderOptions {
    RenderOptions {
        integrator: args.integrator,
        max_depth: args.max_depth,
        hide_emitters: true,
        ..RenderOptions::default()
    }
}

/// The built-in options of `--many-lights`.
fn many_load_options(args: &Args) -> LoadOptions {
    LoadOptions {
        builtin: BuiltinOptions {
            light_count: args.light_count,
            rooms: args.rooms,
            triangles: None,
        },
        ..LoadOptions::default()
    }
}

/// The reference of `scene` (cached): the mean of [`reference_selectors`]' renders at
/// `reference_factor × spp` each, with seeds no measured render uses.
fn many_reference(
    args: &Args,
    scene: &penumbra::scene::Scene,
    name: &str,
    res: UVec2,
    spp: u32,
    dir: &std::path::Path,
) -> anyhow::Result<(penumbra::image::Image, String)> {
    let sels = reference_selectors(scene.lights.len(), args.max_exhaustive_lights);
    let ref_spp = spp * args.reference_factor;
    let label = format!(
        "mean of {} at {ref_spp} spp",
        sels.map(|s| s.to_string()).join("+")
    );
    let depth = match args.integrator {
        IntegratorKind::Direct => String::new(),
        IntegratorKind::Path => format!("-path{}", args.max_depth),
    };
    // `-hidden`: the references with direct emission (files without it) are not reused.
    let path = dir.join(format!(
        "{name}-{}x{}-{ref_spp}spp-mix3-{:?}-{:?}{depth}-hidden.pfm",
        res.x, res.y, args.light_count, args.rooms
    ));
    if let Ok(img) = read_image(&path)
        && img.width == res.x
        && img.height == res.y
    {
        return Ok((img, label));
    }
    let mut acc: Option<penumbra::image::Image> = None;
    for (i, &sel) in sels.iter().enumerate() {
        let opts = RenderOptions {
            spp: ref_spp,
            seed: 0x05ee_d4ef + i as u64,
            light_selection: sel,
            ..transport(args)
        };
        let (img, _) = render(scene, res, &opts)?;
        match &mut acc {
            None => acc = Some(img),
            Some(a) => {
                for (x, y) in a.pixels.iter_mut().zip(&img.pixels) {
                    *x += *y;
                }
            }
        }
    }
    let mut img = acc.expect("three references");
    for x in img.pixels.iter_mut() {
        *x /= sels.len() as f32;
    }
    write_image(&img, &path, 0.0)?;
    Ok((img, label))
}

/// Render on the current (one-thread) pool: the image, the selector's build CPU seconds and
/// the render's CPU seconds (all threads of the process, from /proc, nanosecond resolution).
fn timed_render(
    scene: &penumbra::scene::Scene,
    res: UVec2,
    opts: &RenderOptions,
) -> anyhow::Result<(penumbra::image::Image, f64, f64)> {
    let c0 = cpu_ns();
    drop(make_selector(opts.light_selection, scene, opts.seed));
    let c1 = cpu_ns();
    let (img, _) = render(scene, res, opts)?;
    let c2 = cpu_ns();
    // `render` builds its own selector again: subtract that build from its time.
    let build = c1 - c0;
    Ok((img, build, (c2 - c1 - build).max(0.0)))
}

/// Median of some numbers.
fn median(v: impl Iterator<Item = f64>) -> f64 {
    let mut v: Vec<f64> = v.collect();
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// CPU seconds of every thread of this process (sum of /proc/self/task/*/schedstat run times;
/// nanosecond resolution), falling back to [`cpu_seconds`].
fn cpu_ns() -> f64 {
    let sum = std::fs::read_dir("/proc/self/task").ok().map(|d| {
        d.flatten()
            .filter_map(|e| std::fs::read_to_string(e.path().join("schedstat")).ok())
            .filter_map(|s| s.split_whitespace().next()?.parse::<f64>().ok())
            .sum::<f64>()
    });
    match sum {
        Some(ns) if ns > 0.0 => ns * 1e-9,
        _ => cpu_seconds().unwrap_or(0.0),
    }
}

/// The 1-minute load average (Linux), for the report.
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "?".into())
}

/// `penumbra bench --many-lights --selector-cost`: nanoseconds per `sample` and per `pmf`
/// call of every strategy on the shading points of a 128×96 grid of eye rays (4 jittered
/// passes), one thread, median of `--repeats` interleaved runs.
fn selector_cost(args: &Args) -> anyhow::Result<()> {
    use penumbra::light_selection::estimate::{eye_hit, pixel_rng};
    use penumbra::sampling::hash::next_f32;
    let mut cases: Vec<(String, Option<u32>)> = if args.scenes.is_empty() {
        MANY.iter()
            .map(|s| (s.to_string(), args.light_count))
            .collect()
    } else {
        args.scenes
            .iter()
            .map(|s| (s.clone(), args.light_count))
            .collect()
    };
    for &c in &args.light_counts {
        cases.push(("many-open".to_string(), Some(c)));
    }
    let selectors: Vec<SelectorKind> = if args.selectors.is_empty() {
        vec![
            SelectorKind::Uniform,
            SelectorKind::Power,
            SelectorKind::Bvh,
            SelectorKind::RIS,
        ]
    } else {
        args.selectors.clone()
    };
    println!(
        "selector cost: ns per call on eye-ray shading points, one thread, median of {} interleaved runs, load average {}",
        args.repeats.max(1),
        load_average()
    );
    println!();
    println!(
        "| scene | lights | strategy | build (s) | sample (ns) | pmf (ns) | sample / power's |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (name, count) in cases {
        let mut lopts = many_load_options(args);
        lopts.builtin.light_count = count;
        let scene = load(&name, &lopts)?.scene;
        let res = UVec2::new(128, 96);
        let mut points = Vec::new();
        for pass in 0..4 {
            for px in 0..res.x * res.y {
                let mut rng = pixel_rng(7, 0x5e1c, pass, px);
                if let Some(h) = eye_hit(&scene, res, px, &mut rng) {
                    points.push((h.sp, next_f32(&mut rng)));
                }
            }
        }
        let mut built = Vec::new();
        for &sel in &selectors {
            if sel == SelectorKind::Exhaustive && scene.lights.len() > args.max_exhaustive_lights {
                continue;
            }
            let c0 = cpu_ns();
            let s = make_selector(sel, &scene, 0);
            built.push((sel, s, cpu_ns() - c0, Vec::new(), Vec::new()));
        }
        for _ in 0..args.repeats.max(1) {
            for (_, s, _, ts, tp) in built.iter_mut() {
                // Passes over all points until 0.2 s of CPU time: the per-thread clock only
                // advances at scheduler events, so short loops would read zero.
                let picked: Vec<_> = points.iter().map(|&(sp, u)| s.sample(&sp, u)).collect();
                let (mut calls, t0) = (0usize, cpu_ns());
                let mut t1 = t0;
                while t1 - t0 < 0.2 {
                    for &(sp, u) in &points {
                        std::hint::black_box(s.sample(&sp, std::hint::black_box(u)));
                    }
                    calls += points.len();
                    t1 = cpu_ns();
                }
                ts.push((t1 - t0) * 1e9 / calls.max(1) as f64);
                let (mut calls, mut acc) = (0usize, 0.0f32);
                let mut t2 = t1;
                while t2 - t1 < 0.2 {
                    for (&(sp, _), p) in points.iter().zip(&picked) {
                        if let Some(p) = p {
                            acc += s.pmf(&sp, std::hint::black_box(p.index));
                            calls += 1;
                        }
                    }
                    t2 = cpu_ns();
                    if calls == 0 {
                        break;
                    }
                }
                std::hint::black_box(acc);
                tp.push((t2 - t1) * 1e9 / calls.max(1) as f64);
            }
        }
        let n = scene.lights.len();
        let power = built
            .iter()
            .find(|b| b.0 == SelectorKind::Power)
            .map(|b| median(b.3.iter().copied()));
        for (sel, _, build, ts, tp) in &built {
            let (a, b) = (median(ts.iter().copied()), median(tp.iter().copied()));
            let r = power.map_or("–".into(), |p| format!("{:.2}", a / p));
            println!("| {name} | {n} | {sel} | {build:.3} | {a:.0} | {b:.0} | {r} |");
        }
    }
    Ok(())
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
