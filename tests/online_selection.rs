//! `--light-selection online` (issue 19 item 3): the render in rounds that learns its light
//! selection while it renders is the same image for any thread count, agrees in the mean with
//! power selection (unbiased), and never takes a light's probability away.

use glam::{UVec2, Vec3};
use penumbra::image::{Image, write_image};
use penumbra::integrator::{IntegratorKind, RenderOptions, render};
use penumbra::light_selection::online::{LearnRecord, OnlineConfig, OnlineLearner};
use penumbra::light_selection::{
    FiniteSelector, LightSet, PowerSelector, SelectorKind, ShadingPoint,
};
use penumbra::sampling::hash::{next_f32, pcg_from_keys};
use penumbra::scene::builtin::BuiltinOptions;
use penumbra::scene::load::{LoadOptions, load};

fn scene(name: &str, lights: u32) -> penumbra::scene::Scene {
    let opts = LoadOptions {
        builtin: BuiltinOptions {
            light_count: Some(lights),
            ..BuiltinOptions::default()
        },
        ..LoadOptions::default()
    };
    load(name, &opts).expect("built-in scene").scene
}

fn opts(kind: SelectorKind, spp: u32, seed: u64, integrator: IntegratorKind) -> RenderOptions {
    RenderOptions {
        spp,
        seed,
        light_selection: kind,
        integrator,
        max_depth: 3,
        ..RenderOptions::default()
    }
}

fn pfm_bytes(img: &Image, name: &str) -> Vec<u8> {
    let path = std::env::temp_dir().join(format!("online-{}-{name}.pfm", std::process::id()));
    write_image(img, &path, 0.0).expect("write pfm");
    let bytes = std::fs::read(&path).expect("read pfm");
    let _ = std::fs::remove_file(&path);
    bytes
}

/// The rounds merge their tiles' records in tile order: one thread and two give the same
/// PFM bytes, for direct lighting and for paths (whose secondary vertices learn too).
#[test]
fn online_is_the_same_image_on_one_and_two_threads() {
    let scene = scene("many-open", 200);
    let res = UVec2::new(48, 32);
    for integrator in [IntegratorKind::Direct, IntegratorKind::Path] {
        let o = opts(SelectorKind::Online, 6, 3, integrator);
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool");
            let (img, _) = pool.install(|| render(&scene, res, &o)).expect("render");
            pfm_bytes(&img, &format!("{integrator}-{threads}"))
        };
        assert!(run(1) == run(2), "{integrator}: online depends on threads");
    }
}

/// Mean luminance of an image.
fn mean(img: &Image) -> f64 {
    img.pixels
        .iter()
        .map(|p| penumbra::luminance(*p) as f64)
        .sum::<f64>()
        / img.pixels.len() as f64
}

/// Each round is unbiased for the distribution it samples: the image mean of online selection
/// agrees with power selection's within 4.5 standard errors measured over independent seeds,
/// for direct lighting and for paths.
#[test]
fn online_agrees_with_power_in_the_mean() {
    let scene = scene("many-open", 60);
    let res = UVec2::new(24, 16);
    let seeds = 6;
    for integrator in [IntegratorKind::Direct, IntegratorKind::Path] {
        let stats = |kind: SelectorKind| {
            let m: Vec<f64> = (0..seeds)
                .map(|s| {
                    let o = opts(kind, 16, 100 + s, integrator);
                    mean(&render(&scene, res, &o).expect("render").0)
                })
                .collect();
            let mu = m.iter().sum::<f64>() / seeds as f64;
            let var = m.iter().map(|x| (x - mu).powi(2)).sum::<f64>() / (seeds - 1) as f64;
            (mu, var / seeds as f64)
        };
        let (a, va) = stats(SelectorKind::Online);
        let (b, vb) = stats(SelectorKind::Power);
        let se = (va + vb).sqrt();
        assert!(a > 0.0 && b > 0.0, "{integrator}: black images");
        assert!(
            (a - b).abs() <= 4.5 * se + 1e-4 * b,
            "{integrator}: online mean {a} vs power {b} (standard error {se})"
        );
    }
}

/// However lopsided the records (one light measured bright everywhere, every other light
/// measured occluded), every light with power keeps at least the defensive floor of its power
/// probability, at primary and at secondary vertices.
#[test]
fn online_keeps_every_light_with_power() {
    let scene = scene("many-open", 100);
    let set = LightSet::new(&scene.lights);
    let power = PowerSelector::new(&set.bounds);
    let mut learner = OnlineLearner::new(&scene, OnlineConfig::new(5));
    let (lo, hi) = scene.geometry.bounds();
    let mut rng = pcg_from_keys(&[9]);
    let mut point = || {
        let t = Vec3::new(next_f32(&mut rng), next_f32(&mut rng), next_f32(&mut rng));
        lo + (hi - lo) * t
    };
    let records: Vec<LearnRecord> = (0..20_000)
        .map(|i| {
            let light = set.finite[i % set.finite.len()];
            LearnRecord {
                p: point(),
                light,
                value: if light == set.finite[0] { 1e3 } else { 0.0 },
                secondary: i % 2 == 1,
            }
        })
        .collect();
    let d = learner.digest(&records);
    learner.merge([&d]);
    let snap = learner.snapshot(&scene, true);
    for _ in 0..50 {
        let sp = ShadingPoint {
            p: point(),
            n: Vec3::Y,
            wo: Vec3::Y,
        };
        for secondary in [false, true] {
            for i in 0..set.finite.len() as u32 {
                let pp = power.prob(i);
                if pp > 0.0 {
                    let p = snap.pmf_at(&sp, i, secondary);
                    assert!(
                        p >= 0.99 * penumbra::light_selection::defensive::DEFENSIVE_FLOOR * pp,
                        "light {i} (secondary {secondary}): pmf {p} below the floor of {pp}"
                    );
                }
            }
        }
    }
}
