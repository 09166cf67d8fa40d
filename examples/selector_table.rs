//! The light-selection table of docs/many-lights.md: every built-in scene at equal samples,
//! each selector's relMSE against a converged reference that none of the compared renders
//! shares (its own selector or its own seed), its time and its efficiency 1/(relMSE · time).
//!
//! `cargo run --release --example selector_table -- [--spp N] [--reps R] [--threads T]
//!  [--scale S] [--scenes a,b] [--selectors a,b] [--max-exhaustive N]`
//!
//! - Reference: `exhaustive` (every light's importance at every shading point, the yardstick)
//!   at 32× the spp for scenes with at most `--max-exhaustive` lights (default 2000); above
//!   that exhaustive costs O(N) per
//!   sample, so `power` at 128× the spp. Either way with its own seed, and cached in
//!   `target/selector-table/`. The reference's own noise is estimated from the same selector at
//!   the compared spp (relMSE scales as 1/spp) and printed: it is included in every relMSE.
//! - Time: CPU time (user + system, from /proc/self/stat) of the whole `render` call
//!   (selector build and training included) on `--threads` threads, the median of `--reps`
//!   runs interleaved across selectors. CPU time rather than wall time: on a machine shared
//!   with other jobs, wall time mostly measures the wait for a core.
//! - Resolution: the scene's own divided by `--scale` (default 2).

use glam::UVec2;
use penumbra::image::{compare, read_image, write_image};
use penumbra::integrator::{RenderOptions, render};
use penumbra::light_selection::SelectorKind;
use penumbra::scene::load::{LoadOptions, load};
use std::path::PathBuf;

struct Args {
    /// Scenes with more lights than this get a `power` reference instead of `exhaustive`.
    max_exhaustive: usize,
    spp: u32,
    reps: usize,
    threads: usize,
    scale: u32,
    scenes: Vec<String>,
    selectors: Vec<SelectorKind>,
}

fn parse_args() -> anyhow::Result<Args> {
    let mut a = Args {
        max_exhaustive: 2000,
        spp: 16,
        reps: 3,
        threads: 1,
        scale: 2,
        scenes: [
            "cornell",
            "cornell-phong",
            "dense",
            "many-open",
            "many-rooms",
            "many-mesh",
            "many-street",
        ]
        .map(String::from)
        .to_vec(),
        selectors: [
            SelectorKind::Uniform,
            SelectorKind::Power,
            SelectorKind::Bvh,
            SelectorKind::Spatial,
            SelectorKind::Adaptive,
        ]
        .to_vec(),
    };
    let argv: Vec<String> = std::env::args().skip(1).collect();
    let mut it = argv.iter();
    while let Some(k) = it.next() {
        let v = it
            .next()
            .ok_or_else(|| anyhow::anyhow!("{k} needs a value"))?;
        let list = || v.split(',').map(String::from).collect::<Vec<_>>();
        match k.as_str() {
            "--spp" => a.spp = v.parse()?,
            "--reps" => a.reps = v.parse()?,
            "--threads" => a.threads = v.parse()?,
            "--scale" => a.scale = v.parse()?,
            "--max-exhaustive" => a.max_exhaustive = v.parse()?,
            "--scenes" => a.scenes = list(),
            "--selectors" => {
                a.selectors = v
                    .split(',')
                    .map(|s| s.parse().map_err(anyhow::Error::msg))
                    .collect::<anyhow::Result<_>>()?
            }
            _ => anyhow::bail!("unknown option {k}"),
        }
    }
    anyhow::ensure!(a.spp >= 1 && a.reps >= 1 && a.threads >= 1 && a.scale >= 1);
    Ok(a)
}

fn cache_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/selector-table")
}

/// CPU time (user + system) of this process so far, from /proc/self/stat (Linux, 10 ms ticks).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").expect("/proc/self/stat (Linux)");
    // Fields after the parenthesised command name; utime and stime are the 12th and 13th.
    let rest = stat.rsplit_once(')').map_or("", |r| r.1);
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    f.iter().sum::<f64>() / 100.0
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> anyhow::Result<()> {
    let a = parse_args()?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads)
        .build()?;
    std::fs::create_dir_all(cache_dir())?;
    println!(
        "{} spp; time: CPU seconds, median of {} interleaved runs on {} thread(s), selector build included",
        a.spp, a.reps, a.threads
    );
    println!();
    println!(
        "| scene | lights | res | reference | selector | relMSE | CPU time (s) | efficiency 1/(relMSE·s) | vs uniform | vs best |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    // Per selector: efficiency relative to the best of its scene, for the summary.
    let mut rel_best: Vec<Vec<f64>> = vec![Vec::new(); a.selectors.len()];
    for name in &a.scenes {
        let scene = load(name, &LoadOptions::default())?.scene;
        let n = scene.lights.len();
        let res = (scene.film.resolution / a.scale).max(UVec2::ONE);
        let (ref_sel, factor) = if n <= a.max_exhaustive {
            (SelectorKind::Exhaustive, 32)
        } else {
            (SelectorKind::Power, 128)
        };
        let ref_spp = a.spp * factor;
        // Scene files are named by their path: keep it one file name.
        let stem: String = name
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let path = cache_dir().join(format!(
            "{stem}-{}x{}-{ref_sel}-{ref_spp}spp.pfm",
            res.x, res.y
        ));
        let reference = match read_image(&path) {
            Ok(img) if img.width == res.x && img.height == res.y => img,
            _ => {
                let o = RenderOptions {
                    spp: ref_spp,
                    seed: 0x5eed_0001,
                    light_selection: ref_sel,
                    ..RenderOptions::default()
                };
                eprintln!("reference {name}: {ref_sel} at {ref_spp} spp ...");
                let img = render(&scene, res, &o)?.0;
                write_image(&img, &path, 0.0)?;
                img
            }
        };
        // The reference's noise: its selector at the compared spp, scaled by 1/factor.
        let probe = RenderOptions {
            spp: a.spp,
            light_selection: ref_sel,
            ..RenderOptions::default()
        };
        let probe_rel =
            compare(&pool.install(|| render(&scene, res, &probe))?.0, &reference)?.rel_mse;
        let ref_noise = probe_rel / (factor as f64 + 1.0);
        let mut times = vec![Vec::new(); a.selectors.len()];
        let mut rels = vec![0.0; a.selectors.len()];
        for _ in 0..a.reps {
            for (i, sel) in a.selectors.iter().enumerate() {
                let o = RenderOptions {
                    spp: a.spp,
                    light_selection: *sel,
                    ..RenderOptions::default()
                };
                let c0 = cpu_seconds();
                let img = pool.install(|| render(&scene, res, &o))?.0;
                times[i].push(cpu_seconds() - c0);
                rels[i] = compare(&img, &reference)?.rel_mse;
            }
        }
        let t: Vec<f64> = times.into_iter().map(median).collect();
        let eff: Vec<f64> = (0..t.len()).map(|i| 1.0 / (rels[i] * t[i])).collect();
        let best = eff.iter().copied().fold(0.0, f64::max);
        let uniform = a
            .selectors
            .iter()
            .position(|&s| s == SelectorKind::Uniform)
            .map(|i| eff[i]);
        for (i, sel) in a.selectors.iter().enumerate() {
            let vs_u = uniform.map_or("–".into(), |u| format!("{:.2}", eff[i] / u));
            println!(
                "| {name} | {n} | {}x{} | {ref_sel} {ref_spp} spp (noise ≈ {ref_noise:.1e}) | {sel} | {:.3e} | {:.3} | {:.3e} | {vs_u} | {:.2} |",
                res.x,
                res.y,
                rels[i],
                t[i],
                eff[i],
                eff[i] / best
            );
            rel_best[i].push(eff[i] / best);
        }
    }
    println!();
    println!("| selector | geometric mean of efficiency / best | worst efficiency / best |");
    println!("|---|---|---|");
    for (i, sel) in a.selectors.iter().enumerate() {
        let v = &rel_best[i];
        let gm = (v.iter().map(|x| x.ln()).sum::<f64>() / v.len() as f64).exp();
        let worst = v.iter().copied().fold(f64::INFINITY, f64::min);
        println!("| {sel} | {gm:.2} | {worst:.3} |");
    }
    Ok(())
}
