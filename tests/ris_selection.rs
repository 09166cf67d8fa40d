//! `ris` (resampled light selection, issue 19 item 2): its `pmf` is RIS's contribution weight
//! 1/W, so E[g(Y) / pmf(Y)] = Σₗ g(l) for every g that vanishes where the target does. Checked
//! against the exhaustive sum for random light sets, shading points and K, with the bound from
//! the measured variance; a render with `--strategy light` agrees with `exhaustive`.

mod selection_support;

use glam::{UVec2, Vec3};
use penumbra::integrator::{RenderOptions, Strategy, render};
use penumbra::light_selection::{
    ExhaustiveSelector, FiniteSelector, RisSelector, SelectorKind, ShadingPoint, importance,
};
use penumbra::lights::LightBounds;
use penumbra::sampling::hash::{next_f32, pcg_from_keys};
use penumbra::scene::builtin::BuiltinOptions;
use penumbra::scene::load::{LoadOptions, load};
use rand_pcg::Pcg32;
use selection_support::{mean_and_variance, u, unit};

/// Random small emitters: boxes of random size, axis and power (some two-sided).
fn random_bounds(rng: &mut Pcg32, n: usize) -> Vec<LightBounds> {
    (0..n)
        .map(|_| {
            let c = Vec3::new(u(rng, -5.0, 5.0), u(rng, -5.0, 5.0), u(rng, -5.0, 5.0));
            let h = Vec3::splat(u(rng, 0.01, 0.3));
            LightBounds {
                min: c - h,
                max: c + h,
                w: unit(rng),
                phi: u(rng, 0.0, 1.0).powi(4) * 100.0 + 1e-3,
                cos_theta_o: 1.0,
                cos_theta_e: 0.0,
                two_sided: next_f32(rng) < 0.2,
            }
        })
        .collect()
}

/// E[g(Y)/pmf(Y)] against Σ g, with g = the light's importance times a random positive
/// factor (a stand-in for visibility and BSDF), for K = 1, 4, 16.
#[test]
fn ris_contribution_weight_is_unbiased() {
    let mut rng = pcg_from_keys(&[19, 2]);
    let m = 40_000;
    let mut checked = 0;
    for config in 0..6 {
        let bounds = random_bounds(&mut rng, 50 + 80 * config);
        let factor: Vec<f64> = (0..bounds.len())
            .map(|_| (u(&mut rng, 0.0, 2.0) as f64).powi(3))
            .collect();
        for &k in &[1u32, 4, 16] {
            let ris = RisSelector::new(&bounds, k, config as u64);
            for _ in 0..3 {
                let p = Vec3::new(
                    u(&mut rng, -5.0, 5.0),
                    u(&mut rng, -5.0, 5.0),
                    u(&mut rng, -5.0, 5.0),
                );
                let n = unit(&mut rng);
                let sp = ShadingPoint { p, n, wo: n };
                let g: Vec<f64> = bounds
                    .iter()
                    .zip(&factor)
                    .map(|(b, f)| importance(p, n, b) as f64 * f)
                    .collect();
                let exact: f64 = g.iter().sum();
                let (mut s1, mut s2) = (0.0f64, 0.0f64);
                for _ in 0..m {
                    let x = match ris.sample(&sp, next_f32(&mut rng)) {
                        Some((l, pmf)) => {
                            assert!(pmf > 0.0 && pmf.is_finite(), "pmf {pmf}");
                            assert!(g[l as usize] > 0.0 || factor[l as usize] == 0.0);
                            g[l as usize] / pmf as f64
                        }
                        None => 0.0,
                    };
                    s1 += x;
                    s2 += x * x;
                }
                let mean = s1 / m as f64;
                let sigma = ((s2 / m as f64 - mean * mean).max(0.0) / m as f64).sqrt();
                assert!(
                    (mean - exact).abs() <= 5.0 * sigma + 1e-4 * exact,
                    "K {k}, {} lights: mean {mean} vs exact {exact} (σ {sigma})",
                    bounds.len()
                );
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 54);
}

/// More candidates bring the selection closer to `exhaustive` (∝ the target): the variance of
/// g/pmf with g = the target falls with K (it is 0 for exhaustive).
#[test]
fn ris_variance_falls_with_k() {
    let mut rng = pcg_from_keys(&[19, 3]);
    let bounds = random_bounds(&mut rng, 500);
    let ex = ExhaustiveSelector::new(&bounds);
    let sp = ShadingPoint {
        p: Vec3::new(0.5, -0.3, 0.2),
        n: Vec3::Y,
        wo: Vec3::Y,
    };
    let g: Vec<f64> = bounds
        .iter()
        .map(|b| importance(sp.p, sp.n, b) as f64)
        .collect();
    let exact: f64 = g.iter().sum();
    let rel_var = |k: u32| {
        let ris = RisSelector::new(&bounds, k, 5);
        let m = 20_000;
        let mut s2 = 0.0;
        for i in 0..m {
            let x = ris
                .sample(&sp, (i as f32 + 0.5) / m as f32)
                .map_or(0.0, |(l, p)| g[l as usize] / p as f64);
            s2 += (x / exact - 1.0).powi(2);
        }
        s2 / m as f64
    };
    let v: Vec<f64> = [1, 4, 16, 64].iter().map(|&k| rel_var(k)).collect();
    eprintln!("relative variance over K = 1, 4, 16, 64: {v:?}");
    assert!(
        v[0] > 2.0 * v[1] && v[1] > 2.0 * v[2] && v[2] > 2.0 * v[3],
        "{v:?}"
    );
    // Exhaustive has none (up to rounding).
    let (l, p) = ex.sample(&sp, 0.3).unwrap();
    assert!((g[l as usize] / p as f64 / exact - 1.0).abs() < 1e-4);
}

/// A light-sampling render of `many-rooms` with `ris` agrees with `exhaustive` within noise
/// (both unbiased; the bound comes from two independent renders of each).
#[test]
fn ris_light_strategy_render_matches_exhaustive() {
    let opts = LoadOptions {
        builtin: BuiltinOptions {
            rooms: Some(3),
            ..BuiltinOptions::default()
        },
        ..LoadOptions::default()
    };
    let scene = load("many-rooms", &opts).unwrap().scene;
    let res = UVec2::new(40, 30);
    let run = |kind: SelectorKind, strategy: Strategy, seed: u64| {
        let o = RenderOptions {
            spp: 32,
            seed,
            strategy,
            light_selection: kind,
            ..RenderOptions::default()
        };
        render(&scene, res, &o).unwrap().0
    };
    for strategy in [Strategy::LightSolidAngle, Strategy::Mis] {
        let ex = SelectorKind::Exhaustive;
        let (me, ve) = mean_and_variance(&run(ex, strategy, 1), &run(ex, strategy, 2));
        let ris = SelectorKind::Ris { candidates: 4 };
        let (mr, vr) = mean_and_variance(&run(ris, strategy, 3), &run(ris, strategy, 4));
        let sigma = (ve + vr).sqrt();
        eprintln!(
            "{strategy}: ris mean {mr:.6} vs exhaustive {me:.6}: {:.2} σ (σ {sigma:.2e})",
            (mr - me) / sigma
        );
        if strategy != Strategy::Mis {
            assert!((mr - me).abs() < 5.0 * sigma, "{mr} vs {me} (σ {sigma})");
        }
    }
}
