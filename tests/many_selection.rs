//! Light selection (issue 6): every strategy's pmf is a distribution over the lights, `sample`
//! draws from it (chi² on the light indices), `sample` and `pmf` agree, renders agree with
//! uniform selection within noise, and the light BVH never loses a light that contributes.

mod selection_support;

use glam::{UVec2, Vec2, Vec3};
use penumbra::Rgb;
use penumbra::camera::Camera;
use penumbra::integrator::{RenderOptions, render};
use penumbra::light_selection::bvh::BvhSelector;
use penumbra::light_selection::defensive::{DEFENSIVE_FLOOR, Defensive, ProbeConfig};
use penumbra::light_selection::{
    ExhaustiveSelector, FiniteSelector, LightSelector, LightSet, PowerSelector, SelectorKind,
    ShadingPoint, SpatialSelector, make_selector,
};
use penumbra::lights::{
    Light, LightBounds, LightSource, PointLight, QuadLight, SpotLight, TriangleLight,
    UniformInfiniteLight,
};
use penumbra::material::{Material, Texture};
use penumbra::sampling::chi2::{Chi2Config, chi2_discrete};
use penumbra::sampling::hash::{next_f32, pcg_from_keys};
use penumbra::scene::{AreaEmission, FilmSpec, Filter, Scene, SceneBuilder};
use rand_pcg::Pcg32;
use selection_support::{mean_and_variance, u, unit};

/// Chi² tests in this file (Šidák correction): 2 shading points × every strategy.
const NUM_CHI2: usize = 2 * 7;

/// A small many-light scene: a floor, two boxes, 150 area lights of random size, orientation
/// and power (some two-sided), a point light, a spot light and a dim uniform sky.
fn test_scene() -> Scene {
    let mut rng = pcg_from_keys(&[77]);
    let mut b = SceneBuilder::new();
    let grey = b.add_material(Material::Diffuse {
        reflectance: Texture::Constant(Rgb::splat(0.5)),
    });
    b.add_quad(
        Vec3::new(-6.0, 0.0, -6.0),
        Vec3::Z * 12.0,
        Vec3::X * 12.0,
        grey,
        None,
    )
    .unwrap();
    b.add_quad(
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::Y * 2.0,
        Vec3::X * 2.0,
        grey,
        None,
    )
    .unwrap();
    b.add_quad(
        Vec3::new(2.0, 0.0, -2.0),
        Vec3::Y * 1.5,
        Vec3::Z * 1.0,
        grey,
        None,
    )
    .unwrap();
    for i in 0..150 {
        let p = Vec3::new(
            u(&mut rng, -5.0, 5.0),
            u(&mut rng, 0.2, 3.0),
            u(&mut rng, -5.0, 5.0),
        );
        let mut n = unit(&mut rng);
        if n.y > 0.3 {
            n.y = -n.y;
        }
        let t = n.any_orthonormal_vector();
        let s = n.cross(t);
        let size = u(&mut rng, 0.05, 0.5);
        let power = (u(&mut rng, -2.0, 1.0) * std::f32::consts::LN_10).exp();
        let col = Rgb::new(
            u(&mut rng, 0.2, 1.0),
            u(&mut rng, 0.2, 1.0),
            u(&mut rng, 0.2, 1.0),
        );
        let e = AreaEmission {
            l: col * power,
            two_sided: i % 7 == 0,
        };
        if i % 2 == 0 {
            b.add_quad(p, t * size, s * size, grey, Some(e)).unwrap();
        } else {
            let mesh = penumbra::scene::TriangleMesh {
                positions: vec![p, p + t * size, p + s * size],
                normals: None,
                uvs: None,
                indices: vec![0, 1, 2],
                flip_normals: false,
            };
            b.add_mesh(mesh, grey, Some(e)).unwrap();
        }
    }
    b.add_light(Light::Point(PointLight::new(
        Vec3::new(0.0, 2.5, -3.0),
        Rgb::splat(2.0),
    )));
    b.add_light(Light::Spot(SpotLight::new(
        Vec3::new(3.0, 3.0, 3.0),
        Vec3::new(-1.0, -2.0, -1.0),
        Rgb::splat(5.0),
        0.9,
        0.8,
    )));
    b.add_light(Light::UniformInfinite(UniformInfiniteLight::new(
        Rgb::splat(0.05),
    )));
    let camera = Camera::look_at(
        Vec3::new(0.0, 4.0, -8.0),
        Vec3::new(0.0, 0.5, 0.0),
        Vec3::Y,
        60.0,
    )
    .unwrap();
    let film = FilmSpec {
        resolution: UVec2::new(48, 36),
        filter: Filter::Box {
            radius: Vec2::splat(0.5),
        },
        filename: None,
        spp: None,
        sensor: Default::default(),
    };
    b.build(camera, film).unwrap()
}

/// Random shading points in the scene's space: on the floor facing up, and in the air with
/// random normals.
fn shading_points(n: usize, seed: u64) -> Vec<ShadingPoint> {
    let mut rng = pcg_from_keys(&[seed]);
    (0..n)
        .map(|i| {
            let (p, nrm) = if i % 2 == 0 {
                (
                    Vec3::new(u(&mut rng, -6.0, 6.0), 0.0, u(&mut rng, -6.0, 6.0)),
                    Vec3::Y,
                )
            } else {
                (
                    Vec3::new(
                        u(&mut rng, -6.0, 6.0),
                        u(&mut rng, 0.0, 3.0),
                        u(&mut rng, -6.0, 6.0),
                    ),
                    unit(&mut rng),
                )
            };
            ShadingPoint { p, n: nrm, wo: nrm }
        })
        .collect()
}

/// Every strategy whose `pmf` is the exact probability of `sample`'s choice (all but `ris`,
/// tested in `tests/ris_selection.rs`).
fn selectors(scene: &Scene) -> Vec<Box<dyn LightSelector>> {
    SelectorKind::ALL
        .iter()
        .filter(|k| k.exact_pmf())
        .map(|&kind| make_selector(kind, scene, 1))
        .collect()
}

#[test]
fn unknown_selector_is_an_error() {
    let err = "nope".parse::<SelectorKind>().expect_err("must fail");
    assert!(err.contains("nope") && err.contains("bvh"), "{err}");
    for kind in SelectorKind::ALL {
        assert_eq!(kind.name().parse::<SelectorKind>(), Ok(kind));
    }
}

/// The pmf sums to 1 over all lights — except for the light BVH, which (like pbrt-v4's) can
/// reach a node whose children both have zero importance although the node itself did not;
/// `sample` then returns `None`, so its pmf sums to P(sample is `Some`) ≤ 1. That loses a
/// little efficiency, never correctness (the chi² test checks the "nowhere" mass too).
#[test]
fn pmf_sums_to_one_over_lights() {
    let scene = test_scene();
    let n = scene.lights.len() as u32;
    for sel in selectors(&scene) {
        let mut worst = 1.0f64;
        for sp in shading_points(20, 5) {
            let sum: f64 = (0..n).map(|l| sel.pmf(&sp, l) as f64).sum();
            let m = 4000;
            let some = (0..m)
                .filter(|&k| sel.sample(&sp, (k as f32 + 0.5) / m as f32).is_some())
                .count() as f64
                / m as f64;
            assert!(sum <= 1.0 + 1e-4, "{}: sum {sum} at {sp:?}", sel.name());
            if sel.name() == "bvh" {
                // Stratified u: P(Some) is known to about 1/m.
                assert!(
                    (sum - some).abs() < 2e-3,
                    "{}: sum {sum} but P(Some) {some}",
                    sel.name()
                );
                assert!(sum > 0.5, "{}: sum {sum} at {sp:?}", sel.name());
            } else if some > 0.0 {
                assert!(
                    (sum - 1.0).abs() < 1e-4,
                    "{}: sum {sum} at {sp:?}",
                    sel.name()
                );
            } else {
                assert!(sum < 1e-6, "{}: sample None but pmf sum {sum}", sel.name());
            }
            worst = worst.min(sum);
        }
        eprintln!("{}: smallest pmf sum {worst:.6}", sel.name());
    }
}

#[test]
fn sample_and_pmf_agree() {
    let scene = test_scene();
    let mut rng = pcg_from_keys(&[9]);
    for sel in selectors(&scene) {
        for sp in shading_points(10, 6) {
            for _ in 0..200 {
                let Some(s) = sel.sample(&sp, next_f32(&mut rng)) else {
                    continue;
                };
                assert!(s.pmf > 0.0, "{}: zero-pmf sample", sel.name());
                let p = sel.pmf(&sp, s.index);
                assert!(
                    (p - s.pmf).abs() <= 1e-4 * s.pmf,
                    "{}: sample pmf {} vs pmf() {p} for light {}",
                    sel.name(),
                    s.pmf,
                    s.index
                );
            }
        }
    }
}

#[test]
fn chi2_sampled_light_indices_match_pmf() {
    let scene = test_scene();
    let n = scene.lights.len() as u32;
    let cfg = Chi2Config {
        samples: 200_000,
        num_tests: NUM_CHI2,
        ..Default::default()
    };
    for sel in selectors(&scene) {
        for sp in shading_points(2, 11) {
            let pmf: Vec<f64> = (0..n).map(|l| sel.pmf(&sp, l) as f64).collect();
            let r = chi2_discrete(&cfg, &pmf, |u| {
                sel.sample(&sp, u[0]).map(|s| s.index as usize)
            });
            eprintln!("{}: {}", sel.name(), r.summary());
            assert!(r.passed, "{}: {}", sel.name(), r.summary());
        }
    }
}

/// Random light bounds: quads and triangles of random size, orientation and sidedness, plus
/// point and spot lights.
fn random_lights(rng: &mut Pcg32, n: usize) -> Vec<Light> {
    (0..n)
        .map(|i| {
            let p = Vec3::new(u(rng, -4.0, 4.0), u(rng, -4.0, 4.0), u(rng, -4.0, 4.0));
            let nrm = unit(rng);
            let t = nrm.any_orthonormal_vector() * u(rng, 0.01, 1.0);
            let s = nrm.cross(t).normalize() * u(rng, 0.01, 1.0);
            let l = Rgb::splat((u(rng, -3.0, 3.0) * std::f32::consts::LN_10).exp());
            match i % 5 {
                0 | 1 => Light::Quad(QuadLight::new(p, t, s, nrm, l, i % 3 == 0).unwrap()),
                2 | 3 => Light::Triangle(
                    TriangleLight::new([p, p + t, p + s], nrm, l, i % 4 == 0).unwrap(),
                ),
                _ if i % 2 == 0 => Light::Point(PointLight::new(p, l)),
                _ => Light::Spot(SpotLight::new(p, nrm, l, 0.8, 0.5)),
            }
        })
        .collect()
}

/// Whether some point of `light` sends light to a receiver at `p` with normal `n` (above its
/// tangent plane), judged on a grid of points on the light.
fn contributes(light: &Light, p: Vec3, n: Vec3) -> bool {
    let grid = 24;
    let points: Vec<(Vec3, Vec3, bool)> = match light {
        Light::Quad(q) => (0..grid * grid)
            .map(|k| {
                let (a, b) = ((k % grid) as f32 + 0.5, (k / grid) as f32 + 0.5);
                (
                    q.corner + q.e1 * (a / grid as f32) + q.e2 * (b / grid as f32),
                    q.n,
                    q.two_sided,
                )
            })
            .collect(),
        Light::Triangle(t) => (0..grid * grid)
            .filter_map(|k| {
                let (a, b) = ((k % grid) as f32 + 0.5, (k / grid) as f32 + 0.5);
                let (a, b) = (a / grid as f32, b / grid as f32);
                (a + b < 1.0).then(|| {
                    (
                        t.p[0] + (t.p[1] - t.p[0]) * a + (t.p[2] - t.p[0]) * b,
                        t.n,
                        t.two_sided,
                    )
                })
            })
            .collect(),
        Light::Point(l) => return (l.p - p).dot(n) > 0.0,
        Light::Spot(_) => {
            // A spot emits within its cone: use the light's own sampler from here.
            let ctx = penumbra::lights::LightSampleContext { p, n };
            return light
                .sample_li(
                    &ctx,
                    Vec2::splat(0.5),
                    penumbra::lights::SamplingMode::SolidAngle,
                )
                .is_some_and(|s| s.li != Rgb::ZERO && s.wi.dot(n) > 0.0);
        }
        _ => return false,
    };
    points.iter().any(|&(y, ny, two)| {
        let d = y - p;
        d.dot(n) > 1e-4 * d.length() && (two || ny.dot(-d) > 1e-4 * d.length())
    })
}

#[test]
fn bvh_importance_never_zero_for_contributing_light() {
    let mut rng = pcg_from_keys(&[1234]);
    for config in 0..8 {
        let lights = random_lights(&mut rng, 64 + 50 * config);
        let bounds: Vec<LightBounds> = lights.iter().map(|l| l.bounds().unwrap()).collect();
        let bvh = BvhSelector::new(&bounds);
        let ex = ExhaustiveSelector::new(&bounds);
        for _ in 0..40 {
            let p = Vec3::new(
                u(&mut rng, -5.0, 5.0),
                u(&mut rng, -5.0, 5.0),
                u(&mut rng, -5.0, 5.0),
            );
            let n = unit(&mut rng);
            let sp = ShadingPoint { p, n, wo: n };
            for (i, l) in lights.iter().enumerate() {
                if !contributes(l, p, n) {
                    continue;
                }
                let pb = bvh.pmf(&sp, i as u32);
                let pe = ex.pmf(&sp, i as u32);
                assert!(
                    pe > 0.0,
                    "exhaustive: light {i} ({l:?}) contributes at {p}, n {n}, pmf 0"
                );
                assert!(
                    pb > 0.0,
                    "bvh: light {i} ({l:?}) contributes at {p}, n {n}, pmf 0 (exhaustive {pe})"
                );
            }
        }
    }
}

#[test]
fn bvh_is_compact() {
    let mut rng = pcg_from_keys(&[4321]);
    let lights = random_lights(&mut rng, 5000);
    let bounds: Vec<LightBounds> = lights.iter().map(|l| l.bounds().unwrap()).collect();
    let bvh = BvhSelector::new(&bounds);
    // 8-wide: log8(5000) = 4.1 levels; the collapse leaves small subtrees in partly filled
    // nodes (about 2.8 children per node here, 150 B per light).
    assert!(
        bvh.node_count() <= bounds.len() / 2,
        "{} nodes",
        bvh.node_count()
    );
    assert!(bvh.depth() <= 7, "depth {}", bvh.depth());
    assert!(
        bvh.bytes_per_light() <= 200.0,
        "{} B/light",
        bvh.bytes_per_light()
    );
}

#[test]
fn renders_agree_with_uniform_within_noise() {
    let scene = test_scene();
    let res = UVec2::new(48, 36);
    let run = |kind: SelectorKind, seed: u64| {
        let opts = RenderOptions {
            // Uniform selection has heavy-tailed noise here: give it more samples.
            spp: if kind == SelectorKind::Uniform {
                48
            } else {
                16
            },
            seed,
            light_selection: kind,
            ..RenderOptions::default()
        };
        render(&scene, res, &opts).unwrap().0
    };
    let uniform = SelectorKind::Uniform;
    let (mu, vu) = mean_and_variance(&run(uniform, 1), &run(uniform, 2));
    for name in SelectorKind::ALL.into_iter().filter(|&k| k != uniform) {
        let (m, v) = mean_and_variance(&run(name, 3), &run(name, 4));
        let sigma = (v + vu).sqrt();
        eprintln!(
            "{name}: mean {m:.5} vs uniform {mu:.5}, sigma {sigma:.2e}, noise var ratio {:.3}",
            v / vu
        );
        assert!(
            (m - mu).abs() < 5.0 * sigma,
            "{name}: mean {m} vs uniform {mu} (σ {sigma})"
        );
    }
}

/// The learned and grid strategies (`wald`, `spatial`, `adaptive`) are mixed defensively with
/// power selection: every light with power keeps at least `DEFENSIVE_FLOOR` of its power
/// probability at every shading point, so no light the learning missed is starved.
#[test]
fn learned_selectors_keep_a_power_floor() {
    let scene = test_scene();
    let n = scene.lights.len() as u32;
    let power = make_selector(SelectorKind::Power, &scene, 1);
    for kind in [
        SelectorKind::Wald,
        SelectorKind::Spatial,
        SelectorKind::Adaptive,
    ] {
        let sel = make_selector(kind, &scene, 1);
        for sp in shading_points(40, 21) {
            let mut sum = 0.0f64;
            for l in 0..n {
                let (p, pp) = (sel.pmf(&sp, l), power.pmf(&sp, l));
                sum += p as f64;
                assert!(
                    p >= DEFENSIVE_FLOOR * pp * (1.0 - 1e-5),
                    "{kind}: light {l} pmf {p} below the floor of power's {pp} at {sp:?}"
                );
            }
            assert!((sum - 1.0).abs() < 1e-4, "{kind}: pmf sum {sum} at {sp:?}");
        }
    }
}

/// A table that piles its probability on one light is judged by the probes and replaced by
/// power selection; the spatial grid, which helps on this scene, is kept (δ < 1).
#[test]
fn probes_reject_a_bad_table_and_keep_a_good_one() {
    struct OneLight(PowerSelector);
    impl FiniteSelector for OneLight {
        fn sample(&self, _: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
            self.0.pick(u)
        }
        fn pmf(&self, _: &ShadingPoint, i: u32) -> f32 {
            self.0.prob(i)
        }
    }
    let scene = test_scene();
    let set = LightSet::new(&scene.lights);
    let mut w = vec![1e-4f32; set.finite.len()];
    w[0] = 1.0;
    let cfg = ProbeConfig::new(3, 0.05);
    let bad = Defensive::new(
        &scene,
        &set,
        OneLight(PowerSelector::from_weights(&w)),
        &cfg,
    );
    assert_eq!(
        bad.share(),
        1.0,
        "a one-light table must fall back to power"
    );
    let good = Defensive::new(&scene, &set, SpatialSelector::new(&scene, &set), &cfg);
    eprintln!("spatial share of power: {}", good.share());
    assert!(good.share() < 1.0, "spatial should beat power here");
}

/// The mixture at a fixed share draws from its pmf (chi²), whatever the probes would choose.
#[test]
fn chi2_defensive_mixture_matches_pmf() {
    let scene = test_scene();
    let set = LightSet::new(&scene.lights);
    let n = set.finite.len();
    let power = PowerSelector::new(&set.bounds);
    let mix = Defensive::with_share(SpatialSelector::new(&scene, &set), power, 0.3);
    let cfg = Chi2Config {
        samples: 200_000,
        num_tests: 2,
        ..Default::default()
    };
    for sp in shading_points(2, 13) {
        let pmf: Vec<f64> = (0..n as u32).map(|l| mix.pmf(&sp, l) as f64).collect();
        let sum: f64 = pmf.iter().sum();
        assert!((sum - 1.0).abs() < 1e-4, "pmf sum {sum}");
        let r = chi2_discrete(&cfg, &pmf, |u| {
            mix.sample(&sp, u[0]).map(|(i, _)| i as usize)
        });
        eprintln!("defensive spatial 0.3: {}", r.summary());
        assert!(r.passed, "{}", r.summary());
    }
}

/// The probes (and so the learned selectors' pmfs) are the same on one thread and on four.
#[test]
fn learned_selectors_do_not_depend_on_threads() {
    let scene = test_scene();
    let n = scene.lights.len() as u32;
    let pmfs = |threads: usize, kind: SelectorKind| -> Vec<u32> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let sel = make_selector(kind, &scene, 7);
            shading_points(10, 31)
                .iter()
                .flat_map(|sp| (0..n).map(|l| sel.pmf(sp, l).to_bits()).collect::<Vec<_>>())
                .collect()
        })
    };
    for kind in [
        SelectorKind::Wald,
        SelectorKind::Spatial,
        SelectorKind::Adaptive,
    ] {
        assert!(
            pmfs(1, kind) == pmfs(4, kind),
            "{kind}: pmf depends on threads"
        );
    }
}
