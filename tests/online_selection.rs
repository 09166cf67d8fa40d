//! `--light-selection online` (issue 19 item 3): the render in rounds that learns its light
//! selection while it renders is the same image for any thread count, agrees in the mean with
//! power selection (unbiased), and never takes a light's probability away.

mod selection_support;

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
use selection_support::on_threads;

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
            let (img, _) = on_threads(threads, || render(&scene, res, &o)).expect("render");
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

/// A closed diffuse room lit only by a *cove*: a one-sided quad light at 2/3 of the room's
/// height facing the ceiling, plus a 20× more powerful light outside above the roof (power
/// selection gives the cove 1/21 of its samples). The camera sees only the floor and the lower
/// walls, which no light reaches directly: the image is the light the ceiling and upper walls
/// (secondary vertices) pass on. So the classes learn opposite things: primary vertices
/// measure nothing and keep power selection (δ = 1), secondary ones put nearly all their
/// probability on the cove. A light sample and a BSDF sample of the big, close cove overlap
/// strongly, so MIS weights from the wrong class's pmf (the cove's 1/21 instead of ≈ 0.9)
/// count the overlap about twice.
fn cove() -> penumbra::scene::Scene {
    let src = r#"LookAt 0 1.5 -4.5  0 0 0.5  0 1 0
Camera "perspective" "float fov" 50
Film "rgb" "integer xresolution" 48 "integer yresolution" 32
WorldBegin
Material "diffuse" "rgb reflectance" [0.7 0.7 0.7]
Shape "trianglemesh" "point3 P" [-5 0 -5  5 0 -5  5 6 -5  -5 6 -5  -5 0 5  5 0 5  5 6 5  -5 6 5]
  "integer indices" [0 1 2 0 2 3  4 6 5 4 7 6  0 4 5 0 5 1  3 2 6 3 6 7  0 3 7 0 7 4  1 5 6 1 6 2]
AttributeBegin
AreaLightSource "diffuse" "rgb L" [4 4 4]
Shape "trianglemesh" "point3 P" [-2 4 -2  -2 4 2  2 4 2  2 4 -2] "integer indices" [0 1 2 0 2 3]
AttributeEnd
AttributeBegin
AreaLightSource "diffuse" "rgb L" [80 80 80]
Shape "trianglemesh" "point3 P" [-2 10 -2  -2 10 2  2 10 2  2 10 -2] "integer indices" [0 1 2 0 2 3]
AttributeEnd
"#;
    let parsed = penumbra::scene::pbrt::parse_pbrt_str("cove.pbrt", src, std::path::Path::new("."))
        .expect("cove parses");
    let (b, cam, film, _) = parsed.into_builder().expect("cove converts");
    b.build(cam, film).expect("cove builds")
}

/// Mean image luminance over `seeds` seeds and its standard error (from the spread of the
/// seeds' means).
fn mean_over_seeds(
    scene: &penumbra::scene::Scene,
    res: UVec2,
    seeds: u64,
    o: impl Fn(u64) -> RenderOptions,
) -> (f64, f64) {
    let m: Vec<f64> = (0..seeds)
        .map(|s| mean(&render(scene, res, &o(s)).expect("render").0))
        .collect();
    let mu = m.iter().sum::<f64>() / seeds as f64;
    let var = m.iter().map(|x| (x - mu).powi(2)).sum::<f64>() / (seeds - 1) as f64;
    (mu, (var / seeds as f64).sqrt())
}

/// The MIS weight of an emitter that a BSDF ray of a secondary vertex finds must use the
/// secondary class's pmf, as its light sample did: in the cove room the two classes' pmfs of
/// the cove differ by > 10×, and online's mean (paths of depth 2: the BSDF ray of the
/// secondary vertex ends the path and gathers the emitter; depth 3: it continues and the next
/// vertex counts the emission) agrees with power selection's within 5 standard errors of the
/// difference, measured over 12 seeds each. With the primary pmf in either place the mean is
/// off by many standard errors (see docs/many-lights.md).
#[test]
fn online_mis_weights_use_the_vertex_class_pmf() {
    let scene = cove();
    let set = LightSet::new(&scene.lights);
    assert_eq!(set.finite.len(), 4, "two quads of two triangles");
    // The scene does what it is meant to: at the ceiling the first round's classes differ.
    let snap = OnlineLearner::new(&scene, OnlineConfig::new(1)).snapshot(&scene, true);
    let (dp, ds) = snap.shares();
    assert!(
        dp == 1.0 && ds <= 0.5,
        "power shares (primary, secondary) {dp}, {ds}"
    );
    let ceiling = ShadingPoint {
        p: Vec3::new(0.5, 5.9, 0.3),
        n: -Vec3::Y,
        wo: -Vec3::Y,
    };
    // Local lights 0 and 1 are the cove's triangles.
    let (pp, ps) = (
        snap.pmf_at(&ceiling, 0, false),
        snap.pmf_at(&ceiling, 0, true),
    );
    assert!(
        ps > 10.0 * pp,
        "cove pmf at the ceiling: primary {pp}, secondary {ps}"
    );
    let res = UVec2::new(48, 32);
    for depth in [2, 3] {
        let o = |kind| {
            move |s| RenderOptions {
                max_depth: depth,
                ..opts(kind, 16, 500 + s, IntegratorKind::Path)
            }
        };
        let (a, ea) = mean_over_seeds(&scene, res, 12, o(SelectorKind::Online));
        let (b, eb) = mean_over_seeds(&scene, res, 12, o(SelectorKind::Power));
        let se = ea.hypot(eb);
        eprintln!("depth {depth}: online {a:.5} ± {ea:.5}, power {b:.5} ± {eb:.5}");
        assert!(b > 0.01, "depth {depth}: the room is black ({b})");
        assert!(
            se < 0.02 * b,
            "depth {depth}: too noisy to mean anything (standard error {se} of {b})"
        );
        assert!(
            (a - b).abs() <= 5.0 * se,
            "depth {depth}: online mean {a} vs power {b}: {:.1} standard errors",
            (a - b).abs() / se
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

/// On many-mesh no learned distribution beats power selection (docs/many-lights.md): once
/// the primary tables are mature and their probes still keep δ = 1, learning stops and the
/// rest of the render is one round of power selection — fewer rounds than 1, 1, 2, 4, …
/// would take — and the image is still the same on one and two threads.
#[test]
fn online_settles_on_power_where_learning_does_not_pay() {
    let scene = load("many-mesh", &LoadOptions::default())
        .expect("built-in scene")
        .scene;
    // 4800 records per spp: the tables are mature (prior share ≤ ½) after 64 spp.
    let res = UVec2::new(80, 60);
    let o = opts(SelectorKind::Online, 256, 7, IntegratorKind::Direct);
    let run = |threads: usize| {
        let (img, stats) = on_threads(threads, || render(&scene, res, &o)).expect("render");
        (pfm_bytes(&img, &format!("settle-{threads}")), stats.rounds)
    };
    let (one, rounds) = run(1);
    let full = penumbra::integrator::online_rounds(0..256).len() as u32;
    assert!(
        rounds < full,
        "{rounds} rounds of {full}: online never settled"
    );
    let (two, rounds2) = run(2);
    assert_eq!(rounds, rounds2);
    assert!(one == two, "settled online depends on threads");
}
