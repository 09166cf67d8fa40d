//! `ris` and `ris-bvh` (resampled light selection over power- or BVH-sampled candidates, issue
//! 19 item 2): their `pmf` is RIS's contribution weight 1/W, so E[g(Y) / pmf(Y)] = Σₗ g(l) for
//! every g that vanishes where the target does. Checked against the exhaustive sum for random
//! light sets, shading points and K, with the bound from the measured variance; the lights they
//! choose follow RIS's exact selection probability (chi², enumerated over all candidate
//! tuples); a render with `--strategy light` agrees with `exhaustive`; images do not depend on
//! the thread count.

mod selection_support;

use glam::{UVec2, Vec3};
use penumbra::integrator::{RenderOptions, Strategy, render};
use penumbra::light_selection::bvh::BvhSelector;
use penumbra::light_selection::{
    ExhaustiveSelector, FiniteSelector, PowerSelector, RisBvhSelector, RisSelector, SelectorKind,
    ShadingPoint, importance,
};
use penumbra::lights::LightBounds;
use penumbra::sampling::chi2::{Chi2Config, chi2_discrete};
use penumbra::sampling::hash::{next_f32, pcg_from_keys};
use penumbra::scene::Scene;
use penumbra::scene::builtin::BuiltinOptions;
use penumbra::scene::load::{LoadOptions, load};
use rand_pcg::Pcg32;
use selection_support::{mean_and_variance, on_threads, random_point, u, unit};

/// `many-rooms` with three rooms: small enough for a test render.
fn three_rooms() -> Scene {
    let opts = LoadOptions {
        builtin: BuiltinOptions {
            rooms: Some(3),
            ..BuiltinOptions::default()
        },
        ..LoadOptions::default()
    };
    load("many-rooms", &opts).unwrap().scene
}

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

/// The two candidate sources: `ris` (power) and `ris-bvh` (the light BVH).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Source {
    Power,
    Bvh,
}

/// RIS over `source` with `k` candidates.
fn ris_over(source: Source, bounds: &[LightBounds], k: u32, seed: u64) -> Box<dyn FiniteSelector> {
    match source {
        Source::Power => Box::new(RisSelector::new(bounds, k, seed)),
        Source::Bvh => Box::new(RisBvhSelector::new(bounds, k, seed)),
    }
}

/// E[g(Y)/pmf(Y)] against Σ g, with g = the light's importance times a random positive
/// factor (a stand-in for visibility and BSDF), for K = 1, 4, 16, over both sources.
#[test]
fn ris_contribution_weight_is_unbiased() {
    for source in [Source::Power, Source::Bvh] {
        contribution_weight_is_unbiased(source);
    }
}

fn contribution_weight_is_unbiased(source: Source) {
    let mut rng = pcg_from_keys(&[19, 2]);
    let m = 40_000;
    let mut checked = 0;
    for config in 0..6 {
        let bounds = random_bounds(&mut rng, 50 + 80 * config);
        let factor: Vec<f64> = (0..bounds.len())
            .map(|_| (u(&mut rng, 0.0, 2.0) as f64).powi(3))
            .collect();
        for &k in &[1u32, 4, 16] {
            let ris = ris_over(source, &bounds, k, config as u64);
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
                    "{source:?} K {k}, {} lights: mean {mean} vs exact {exact} (σ {sigma})",
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
    let rel_var = |source: Source, k: u32| {
        let ris = ris_over(source, &bounds, k, 5);
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
    let v: Vec<f64> = [1, 4, 16, 64]
        .iter()
        .map(|&k| rel_var(Source::Power, k))
        .collect();
    eprintln!("ris: relative variance over K = 1, 4, 16, 64: {v:?}");
    assert!(
        v[0] > 2.0 * v[1] && v[1] > 2.0 * v[2] && v[2] > 2.0 * v[3],
        "{v:?}"
    );
    // Over the BVH: K = 1 is the BVH's own distribution; more candidates bring it closer to
    // the target, and at every K it is closer than power's candidates.
    let vb: Vec<f64> = [1, 4, 16, 64]
        .iter()
        .map(|&k| rel_var(Source::Bvh, k))
        .collect();
    eprintln!("ris-bvh: relative variance over K = 1, 4, 16, 64: {vb:?}");
    assert!(vb[0] > vb[1] && vb[1] > vb[2] && vb[2] > vb[3], "{vb:?}");
    assert!(vb.iter().zip(&v).all(|(b, p)| b < p), "{vb:?} vs {v:?}");
    // Exhaustive has none (up to rounding).
    let (l, p) = ex.sample(&sp, 0.3).unwrap();
    assert!((g[l as usize] / p as f64 / exact - 1.0).abs() < 1e-4);
}

/// A light-sampling render of `many-rooms` with `ris` and with `ris-bvh` agrees with
/// `exhaustive` within noise (all unbiased; the bound comes from two independent renders of
/// each). Under MIS their estimated pmf makes them consistent only: printed, not asserted.
#[test]
fn ris_light_strategy_render_matches_exhaustive() {
    let scene = three_rooms();
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
        for ris in [
            SelectorKind::Ris { candidates: 4 },
            SelectorKind::RisBvh { candidates: 4 },
        ] {
            let (mr, vr) = mean_and_variance(&run(ris, strategy, 3), &run(ris, strategy, 4));
            let sigma = (ve + vr).sqrt();
            eprintln!(
                "{strategy}: {ris} mean {mr:.6} vs exhaustive {me:.6}: {:.2} σ (σ {sigma:.2e})",
                (mr - me) / sigma
            );
            if strategy != Strategy::Mis {
                assert!(
                    (mr - me).abs() < 5.0 * sigma,
                    "{ris}: {mr} vs {me} (σ {sigma})"
                );
            }
        }
    }
}

/// `ris-bvh:1` keeps its single BVH candidate: its pmf is the BVH's own probability.
#[test]
fn ris_bvh_with_one_candidate_is_the_bvh() {
    let mut rng = pcg_from_keys(&[19, 4]);
    let bounds = random_bounds(&mut rng, 300);
    let bvh = BvhSelector::new(&bounds);
    let ris = RisBvhSelector::new(&bounds, 1, 3);
    for _ in 0..20 {
        let sp = random_point(&mut rng, 5.0);
        for _ in 0..50 {
            if let Some((l, p)) = ris.sample(&sp, next_f32(&mut rng)) {
                let q = bvh.pmf(&sp, l);
                assert!((p / q - 1.0).abs() < 1e-5, "light {l}: {p} vs bvh {q}");
                assert!((ris.pmf(&sp, l) / q - 1.0).abs() < 1e-5);
            }
        }
    }
}

/// RIS's exact probability of choosing each light, by enumerating every tuple of K candidates
/// (the source's "nowhere" outcome included, with weight 0): P(y) = Σ over tuples of
/// Π q(xᵢ) · Σ_{i: xᵢ = y} wᵢ / Σ wᵢ.
fn exact_ris_probability(q: &[f64], target: &[f64], k: u32) -> Vec<f64> {
    let n = q.len();
    let nowhere = (1.0 - q.iter().sum::<f64>()).max(0.0);
    let w: Vec<f64> = (0..n)
        .map(|l| if q[l] > 0.0 { target[l] / q[l] } else { 0.0 })
        .collect();
    let mut p = vec![0.0; n];
    let outcomes = n + 1; // index n: nowhere
    let mut tuple = vec![0usize; k as usize];
    loop {
        let prob: f64 = tuple
            .iter()
            .map(|&x| if x == n { nowhere } else { q[x] })
            .product();
        let sum: f64 = tuple.iter().map(|&x| if x == n { 0.0 } else { w[x] }).sum();
        if prob > 0.0 && sum > 0.0 {
            for &x in tuple.iter().filter(|&&x| x < n) {
                p[x] += prob * w[x] / sum;
            }
        }
        // Next tuple (odometer).
        let mut d = 0;
        loop {
            if d == tuple.len() {
                return p;
            }
            tuple[d] += 1;
            if tuple[d] < outcomes {
                break;
            }
            tuple[d] = 0;
            d += 1;
        }
    }
}

/// RIS's selection probability with `ris-bvh`'s stratified candidates: candidate j is the
/// source's choice for (j + o)/K with one offset o ~ U[0, 1) for all, and the final choice
/// keeps j with probability wⱼ/Σw, so P(y) = ∫₀¹ Σ_{j: xⱼ(o) = y} wⱼ/Σw do — integrated on a
/// grid of `grid` offsets (its error, a few cells per boundary of the source's map, is far
/// below what the chi² can see).
fn stratified_ris_probability(
    draw: impl Fn(f32) -> Option<(u32, f32)>,
    target: &[f64],
    k: u32,
    grid: usize,
) -> Vec<f64> {
    let mut p = vec![0.0; target.len()];
    let mut cands = Vec::with_capacity(k as usize);
    for m in 0..grid {
        let o = (m as f64 + 0.5) / grid as f64;
        cands.clear();
        for j in 0..k {
            let v = ((j as f64 + o) / k as f64) as f32;
            if let Some((l, q)) = draw(v) {
                let w = if q > 0.0 {
                    target[l as usize] / q as f64
                } else {
                    0.0
                };
                cands.push((l as usize, w));
            }
        }
        let sum: f64 = cands.iter().map(|c| c.1).sum();
        if sum > 0.0 {
            for &(l, w) in &cands {
                p[l] += w / sum / grid as f64;
            }
        }
    }
    p
}

/// Chi² of the lights `ris` and `ris-bvh` choose against RIS's exact selection probability
/// (their `pmf` is 1/W, not that probability, so the every-selector chi² in
/// `tests/many_selection.rs` skips them): `ris`'s candidates hashed from u and the point
/// behave as i.i.d. draws from power, `ris-bvh`'s as the stratified draws above, and the
/// final choice keeps one ∝ w.
#[test]
fn chi2_ris_choices_match_the_exact_ris_probability() {
    let mut rng = pcg_from_keys(&[19, 5]);
    let cfg = Chi2Config {
        samples: 200_000,
        num_tests: 2 * 2 * 3,
        ..Default::default()
    };
    let bounds = random_bounds(&mut rng, 40);
    let power = PowerSelector::new(&bounds);
    let bvh = BvhSelector::new(&bounds);
    for source in [Source::Power, Source::Bvh] {
        for k in [2u32, 3] {
            let ris = ris_over(source, &bounds, k, 11);
            for _ in 0..3 {
                let sp = random_point(&mut rng, 3.0);
                let q: Vec<f64> = (0..bounds.len() as u32)
                    .map(|l| match source {
                        Source::Power => power.prob(l) as f64,
                        Source::Bvh => bvh.pmf(&sp, l) as f64,
                    })
                    .collect();
                let target: Vec<f64> = bounds
                    .iter()
                    .map(|b| importance(sp.p, sp.n, b) as f64)
                    .collect();
                let exact = match source {
                    Source::Power => exact_ris_probability(&q, &target, k),
                    Source::Bvh => {
                        stratified_ris_probability(|v| bvh.sample(&sp, v), &target, k, 1 << 18)
                    }
                };
                let r = chi2_discrete(&cfg, &exact, |u| {
                    ris.sample(&sp, u[0]).map(|(l, _)| l as usize)
                });
                eprintln!("{source:?} K {k}: {}", r.summary());
                assert!(r.passed, "{source:?} K {k}: {}", r.summary());
            }
        }
    }
}

/// `ris-bvh` renders the same image on one thread and on two (its candidates come from a hash
/// of the sample number and the shading point, not from a thread's state).
#[test]
fn ris_bvh_is_the_same_image_on_one_and_two_threads() {
    let scene = three_rooms();
    let run = |threads: usize| {
        let o = RenderOptions {
            spp: 4,
            seed: 9,
            light_selection: SelectorKind::RisBvh { candidates: 4 },
            ..RenderOptions::default()
        };
        on_threads(threads, || {
            render(&scene, UVec2::new(40, 30), &o).unwrap().0
        })
    };
    let (a, b) = (run(1), run(2));
    assert!(
        a.pixels
            .iter()
            .zip(&b.pixels)
            .all(|(x, y)| (0..3).all(|c| x[c].to_bits() == y[c].to_bits())),
        "ris-bvh image depends on the thread count"
    );
}

/// The light BVH's batched walk (what `ris-bvh` draws its candidates with) returns, for every
/// number, exactly what `sample` returns for it, in ascending and in any order.
#[test]
fn bvh_sample_many_is_sample_bit_for_bit() {
    let mut rng = pcg_from_keys(&[19, 6]);
    for n in [1usize, 7, 64, 3000] {
        let bounds = random_bounds(&mut rng, n);
        let bvh = BvhSelector::new(&bounds);
        for _ in 0..20 {
            let sp = random_point(&mut rng, 5.0);
            let mut us: Vec<f32> = (0..17).map(|_| next_f32(&mut rng)).collect();
            for sorted in [false, true] {
                if sorted {
                    us.sort_by(f32::total_cmp);
                }
                let mut out = vec![None; us.len()];
                bvh.sample_many(&sp, &us, &mut out);
                for (&v, o) in us.iter().zip(&out) {
                    let one = bvh.sample(&sp, v);
                    assert_eq!(
                        o.map(|(l, p, _)| (l, p.to_bits())),
                        one.map(|(l, p)| (l, p.to_bits())),
                        "{n} lights, u {v}"
                    );
                    // The third number is the light's own importance, as the pmf's walk
                    // scores it, and the scalar importance up to rounding.
                    if let Some((l, p, t)) = *o {
                        let (q, t2) = bvh.pmf_and_importance(&sp, l);
                        assert_eq!((p.to_bits(), t.to_bits()), (q.to_bits(), t2.to_bits()));
                        let s = importance(sp.p, sp.n, &bounds[l as usize]);
                        assert!((t - s).abs() <= 1e-4 * s, "{t} vs scalar {s}");
                    }
                }
            }
        }
    }
}

/// `ris-bvh` and `ris-bvh:K` parse, print back and reject a K out of range.
#[test]
fn ris_bvh_names_parse() {
    assert_eq!("ris-bvh".parse::<SelectorKind>(), Ok(SelectorKind::RIS_BVH));
    let k16 = SelectorKind::RisBvh { candidates: 16 };
    assert_eq!("ris-bvh:16".parse::<SelectorKind>(), Ok(k16));
    assert_eq!(k16.to_string(), "ris-bvh:16");
    assert_eq!(SelectorKind::RIS_BVH.to_string(), "ris-bvh");
    assert!(!k16.exact_pmf());
    for bad in ["ris-bvh:0", "ris-bvh:257", "ris-bvh:x", "ris-bvh:"] {
        let err = bad.parse::<SelectorKind>().expect_err(bad);
        assert!(err.contains("ris-bvh:K"), "{bad}: {err}");
    }
    // `ris` is untouched by the new prefix.
    assert_eq!(
        "ris:32".parse::<SelectorKind>(),
        Ok(SelectorKind::Ris { candidates: 32 })
    );
}
