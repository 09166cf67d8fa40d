//! pbrt-v4's stochastic layered BSDF (coated diffuse, coated conductor). Its `f` is an
//! unbiased random-walk estimate and its `pdf` only a MIS density (see `bsdf::layered`), so
//! instead of chi² against a pdf: `f`'s mean over independent walk streams against closed
//! forms (5σ from the measured variance), the sampler's weights against `f` per bin (5σ),
//! energy ≤ 1, and the limits (index-matched coat = bare base; smooth coat over a smooth metal
//! = the Fresnel series; thin scattering slab = single scattering).

use glam::{Vec2, Vec3};
use penumbra::Rgb;
use penumbra::bsdf::coated_conductor::{coated_conductor, layered_diffuse};
use penumbra::bsdf::fresnel::{fr_complex_rgb, fr_dielectric};
use penumbra::bsdf::{Bxdf, CoatedDiffuse, Conductor, LayerParams, Layered};
use penumbra::sampling::hash::uniform_pair;
use std::f32::consts::PI;

fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Mean and standard error of `f` over `n` independent walk streams (luminance).
fn f_mean(b: &Layered, wo: Vec3, wi: Vec3, n: u64) -> (Rgb, f64) {
    let (mut s, mut s2) = (Rgb::ZERO, 0.0f64);
    let mut lum = Vec::with_capacity(n as usize);
    for k in 0..n {
        let v = b.f_seeded(wo, wi, k + 1);
        s += v;
        let l = penumbra::luminance(v) as f64;
        s2 += l * l;
        lum.push(l);
    }
    let mean = s / n as f32;
    let ml = lum.iter().sum::<f64>() / n as f64;
    let var = (s2 / n as f64 - ml * ml).max(0.0);
    (mean, (var / n as f64).sqrt())
}

fn params(thickness: f32) -> LayerParams {
    LayerParams {
        thickness,
        max_depth: 64,
        ..LayerParams::default()
    }
}

#[test]
fn index_matched_coat_is_the_bare_base() {
    // eta = 1: the coat neither reflects nor refracts; with a vanishing slab the layered BSDF
    // is exactly its base (every walk takes the same path).
    let base = Conductor::new(
        Rgb::new(0.2, 0.9, 1.1),
        Rgb::new(3.0, 2.5, 2.0),
        Vec2::splat(0.3),
    );
    let cc = coated_conductor(1.0, Vec2::ZERO, base.eta, base.k, base.alpha, params(1e-7));
    let cd = layered_diffuse(Rgb::new(0.8, 0.5, 0.2), 1.0, Vec2::ZERO, params(1e-7));
    for (to, ti, phi) in [(10.0, 30.0, 0.0), (45.0, 45.0, 180.0), (70.0, 20.0, 90.0)] {
        let (wo, wi) = (dir(to, 0.0), dir(ti, phi));
        let (a, b) = (cc.f(wo, wi), base.f(wo, wi));
        assert!(
            (a - b).abs().max_element() <= 1e-4 * b.max_element().max(1.0),
            "{a} vs {b}"
        );
        let d = cd.f(wo, wi);
        let want = Rgb::new(0.8, 0.5, 0.2) / PI;
        assert!((d - want).abs().max_element() < 1e-5, "{d} vs {want}");
    }
}

#[test]
fn smooth_coat_over_lambert_matches_the_closed_form() {
    // A smooth coat over a Lambertian base has the exact closed form of `CoatedDiffuse`
    // (geometric series of internal reflections); the walk must converge to it.
    for (eta, r) in [(1.5, Rgb::new(0.9, 0.5, 0.1)), (1.33, Rgb::splat(0.7))] {
        let layered = layered_diffuse(r, eta, Vec2::ZERO, params(1e-7));
        let closed = CoatedDiffuse::new(r, Vec2::ZERO, eta);
        for (to, ti) in [(0.0, 30.0), (50.0, 20.0), (75.0, 60.0)] {
            let (wo, wi) = (dir(to, 0.0), dir(ti, 140.0));
            let (m, se) = f_mean(&layered, wo, wi, 4000);
            let want = closed.f(wo, wi);
            let (lm, lw) = (
                penumbra::luminance(m) as f64,
                penumbra::luminance(want) as f64,
            );
            eprintln!("eta {eta} θo {to} θi {ti}: {lm:.5} vs {lw:.5} ± {se:.1e}");
            assert!((lm - lw).abs() <= 5.0 * se + 1e-4, "{lm} vs {lw} ± {se}");
            // Colour: per channel within 2%.
            assert!(
                ((m - want) / want).abs().max_element() < 0.02,
                "{m} vs {want}"
            );
        }
    }
}

#[test]
fn smooth_coat_over_smooth_metal_is_the_fresnel_series() {
    // All paths specular: the mean sample weight is the Fresnel series
    // F + (1−F)² Fc τ² / (1 − F Fc τ²), τ = e^(−thickness/cos θt), Fc at the refracted angle
    // with the metal's η, k relative to the coat.
    let (eta_c, k_c) = (Rgb::new(0.2, 0.6, 1.2), Rgb::new(3.5, 2.6, 2.0));
    for thickness in [1e-7f32, 0.2] {
        let b = coated_conductor(1.5, Vec2::ZERO, eta_c, k_c, Vec2::ZERO, params(thickness));
        assert!(b.is_delta());
        for theta in [0.0f32, 40.0, 70.0] {
            let wo = dir(theta, 30.0);
            let n = 200_000u32;
            let (mut s, mut s2) = (Rgb::ZERO, 0.0f64);
            for i in 0..n {
                let (uc, ux) = uniform_pair(7, i);
                let (uy, _) = uniform_pair(8, i);
                if let Some(bs) = b.sample(wo, uc, Vec2::new(ux, uy)) {
                    assert!(bs.delta);
                    let w = bs.f * bs.wi.z.abs() / bs.pdf;
                    s += w;
                    s2 += (penumbra::luminance(w) as f64).powi(2);
                }
            }
            let mean = s / n as f32;
            let ml = penumbra::luminance(mean) as f64;
            let se = ((s2 / n as f64 - ml * ml).max(0.0) / n as f64).sqrt();
            let f = fr_dielectric(wo.z, 1.5);
            let cos_t = (1.0 - (1.0 - wo.z * wo.z) / (1.5 * 1.5)).sqrt();
            let fc = fr_complex_rgb(cos_t, eta_c / 1.5, k_c / 1.5);
            let tau2 = (-2.0 * thickness / cos_t).exp();
            let want =
                Rgb::splat(f) + (1.0 - f) * (1.0 - f) * fc * tau2 / (Rgb::ONE - f * fc * tau2);
            let lw = penumbra::luminance(want) as f64;
            eprintln!("t {thickness} θ {theta}: {ml:.5} vs {lw:.5} ± {se:.1e}");
            assert!((ml - lw).abs() <= 5.0 * se + 1e-4, "{mean} vs {want}");
            assert!(
                ((mean - want) / want).abs().max_element() < 0.01,
                "{mean} vs {want}"
            );
        }
    }
}

#[test]
fn thin_scattering_slab_is_single_scattering() {
    // Index-matched coat, black base, one scattering event allowed: the estimate's mean is the
    // single-scattering BRDF of a slab of optical thickness τ:
    // α p(wo, wi) (1 − e^(−τ(1/μo + 1/μi))) / (μo + μi), p Henyey–Greenstein.
    for g in [0.0f32, 0.6, -0.4] {
        let tau = 0.3;
        let albedo = Rgb::new(0.9, 0.6, 0.3);
        let b = layered_diffuse(
            Rgb::ZERO,
            1.0,
            Vec2::ZERO,
            LayerParams {
                thickness: tau,
                albedo,
                g,
                max_depth: 1,
                n_samples: 1,
            },
        );
        for (to, ti, phi) in [(20.0, 30.0, 180.0), (60.0, 10.0, 0.0)] {
            let (wo, wi) = (dir(to, 0.0), dir(ti, phi));
            let (m, se) = f_mean(&b, wo, wi, 200_000);
            let cos = wo.dot(wi);
            let denom = 1.0 + g * g + 2.0 * g * cos;
            let p = (1.0 - g * g) / (4.0 * PI * denom * denom.sqrt());
            let (mo, mi) = (wo.z, wi.z);
            let want = albedo * p * (1.0 - (-tau * (1.0 / mo + 1.0 / mi)).exp()) / (mo + mi);
            let (lm, lw) = (
                penumbra::luminance(m) as f64,
                penumbra::luminance(want) as f64,
            );
            eprintln!("g {g} θo {to} θi {ti}: {lm:.5} vs {lw:.5} ± {se:.1e}");
            assert!((lm - lw).abs() <= 5.0 * se + 1e-5, "{lm} vs {lw} ± {se}");
        }
    }
}

fn layered_cases() -> Vec<(&'static str, Layered)> {
    let metal = (Rgb::new(0.18, 0.42, 1.37), Rgb::new(3.42, 2.35, 1.77));
    let p = LayerParams {
        max_depth: 10,
        ..LayerParams::default()
    };
    vec![
        (
            "coateddiffuse rough",
            layered_diffuse(Rgb::new(0.8, 0.4, 0.2), 1.5, Vec2::splat(0.3), p),
        ),
        (
            "coatedconductor smooth coat, rough metal",
            coated_conductor(1.5, Vec2::ZERO, metal.0, metal.1, Vec2::splat(0.25), p),
        ),
        (
            "coatedconductor rough coat, rough metal",
            coated_conductor(
                1.5,
                Vec2::new(0.2, 0.35),
                metal.0,
                metal.1,
                Vec2::splat(0.3),
                p,
            ),
        ),
        (
            "coateddiffuse scattering slab",
            layered_diffuse(
                Rgb::splat(0.5),
                1.5,
                Vec2::splat(0.2),
                LayerParams {
                    thickness: 0.5,
                    albedo: Rgb::splat(0.8),
                    g: 0.3,
                    ..p
                },
            ),
        ),
    ]
}

#[test]
fn sampler_weights_are_unbiased_against_f_per_bin() {
    // For each of 6×4 (θ, φ) bins: Σ weights / N of the non-delta samples landing in the bin
    // against ∫_bin f cos dω (midpoint quadrature of the walk-averaged f); 5σ of both
    // estimates plus 2% for the quadrature. Before the inner-direction MIS density fix in
    // `Layered::f`, the rough-coat cases failed here with f 5–10% above the sampler.
    let (nt, np) = (6usize, 4usize);
    for (name, b) in layered_cases() {
        let wo = dir(35.0, 0.0);
        let n = 400_000u32;
        let mut sum = vec![0.0f64; nt * np];
        let mut sum2 = vec![0.0f64; nt * np];
        let bin = |w: Vec3| {
            let ct = w.z.clamp(0.0, 1.0);
            let t = (((1.0 - ct * ct) * nt as f32) as usize).min(nt - 1); // equal-area in sin²θ
            let phi = w.y.atan2(w.x).rem_euclid(2.0 * PI);
            let p = ((phi / (2.0 * PI) * np as f32) as usize).min(np - 1);
            t * np + p
        };
        for i in 0..n {
            let (uc, ux) = uniform_pair(11, i);
            let (uy, _) = uniform_pair(12, i);
            if let Some(bs) = b.sample(wo, uc, Vec2::new(ux, uy))
                && !bs.delta
            {
                let w = penumbra::luminance(bs.f * bs.wi.z.abs() / bs.pdf) as f64;
                let k = bin(bs.wi);
                sum[k] += w;
                sum2[k] += w * w;
            }
        }
        let q = 8usize;
        for t in 0..nt {
            for p in 0..np {
                let mut integral = 0.0f64;
                let mut var_integral = 0.0f64;
                for a in 0..q {
                    for c in 0..q {
                        let s2 = (t as f64 + (a as f64 + 0.5) / q as f64) / nt as f64;
                        let phi =
                            2.0 * std::f64::consts::PI * (p as f64 + (c as f64 + 0.5) / q as f64)
                                / np as f64;
                        let (st, ct) = (s2.sqrt(), (1.0 - s2).sqrt());
                        let wi =
                            Vec3::new((st * phi.cos()) as f32, (st * phi.sin()) as f32, ct as f32);
                        // dω = d(sin²θ) dφ / (2 cos θ); f cos dω = f d(sin²θ) dφ / 2.
                        let fs: Vec<f64> = (0..16)
                            .map(|s| penumbra::luminance(b.f_seeded(wo, wi, 100 + s)) as f64)
                            .collect();
                        let f = fs.iter().sum::<f64>() / 16.0;
                        let vf = fs.iter().map(|x| (x - f) * (x - f)).sum::<f64>() / 15.0 / 16.0;
                        let dw = 0.5
                            * (1.0 / nt as f64 / q as f64)
                            * (2.0 * std::f64::consts::PI / np as f64 / q as f64);
                        integral += f * dw;
                        var_integral += vf * dw * dw;
                    }
                }
                let k = t * np + p;
                let mean = sum[k] / n as f64;
                let se = ((sum2[k] / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
                let sigma = (se * se + var_integral).sqrt();
                assert!(
                    (mean - integral).abs() <= 5.0 * sigma + 0.02 * integral,
                    "{name}: bin ({t}, {p}): sampler {mean:.5} vs ∫f cos {integral:.5} (σ {sigma:.1e})"
                );
            }
        }
    }
}

#[test]
fn energy_is_at_most_one_and_pdf_is_a_density() {
    for (name, b) in layered_cases() {
        for theta in [0.0f32, 45.0, 80.0] {
            let wo = dir(theta, 10.0);
            let n = 100_000u32;
            let (mut s, mut s2) = (0.0f64, 0.0f64);
            for i in 0..n {
                let (uc, ux) = uniform_pair(21, i);
                let (uy, _) = uniform_pair(22, i);
                if let Some(bs) = b.sample(wo, uc, Vec2::new(ux, uy)) {
                    let w = (bs.f * bs.wi.z.abs() / bs.pdf).max_element() as f64;
                    assert!(w.is_finite() && w >= 0.0, "{name}: weight {w}");
                    s += w;
                    s2 += w * w;
                }
            }
            let m = s / n as f64;
            let se = ((s2 / n as f64 - m * m).max(0.0) / n as f64).sqrt();
            assert!(m <= 1.0 + 5.0 * se, "{name} θ {theta}: albedo {m} ± {se}");
            // The MIS pdf integrates to ≤ 1 over the hemisphere and is positive where f is.
            let mut integral = 0.0f64;
            let k = 64;
            for a in 0..k {
                for c in 0..k {
                    let s2 = (a as f32 + 0.5) / k as f32;
                    let phi = 2.0 * PI * (c as f32 + 0.5) / k as f32;
                    let wi = Vec3::new(
                        s2.sqrt() * phi.cos(),
                        s2.sqrt() * phi.sin(),
                        (1.0 - s2).sqrt(),
                    );
                    let pdf = b.pdf(wo, wi);
                    if b.f(wo, wi).max_element() > 0.0 {
                        assert!(pdf > 0.0, "{name}: pdf 0 where f > 0");
                    }
                    integral += (pdf / (2.0 * wi.z)) as f64
                        * (1.0 / k as f64)
                        * (2.0 * std::f64::consts::PI / k as f64);
                }
            }
            assert!(
                integral <= 1.02 && integral > 0.5,
                "{name} θ {theta}: ∫pdf = {integral}"
            );
        }
    }
}

#[test]
fn f_is_a_deterministic_function_of_its_arguments() {
    for (_, b) in layered_cases() {
        let (wo, wi) = (dir(30.0, 0.0), dir(50.0, 120.0));
        assert_eq!(b.f(wo, wi).to_array(), b.f(wo, wi).to_array());
        let s1 = b.sample(wo, 0.7, Vec2::new(0.3, 0.9)).map(|s| (s.wi, s.f));
        let s2 = b.sample(wo, 0.7, Vec2::new(0.3, 0.9)).map(|s| (s.wi, s.f));
        assert_eq!(format!("{s1:?}"), format!("{s2:?}"));
    }
    eprintln!(
        "size_of::<Bsdf>() = {} bytes, size_of::<Layered>() = {}",
        std::mem::size_of::<penumbra::bsdf::Bsdf>(),
        std::mem::size_of::<Layered>()
    );
}
