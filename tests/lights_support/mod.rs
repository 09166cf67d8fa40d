//! Shared helpers of the light tests: ray–shape intersections written independently of the
//! lights, a zoomed chi-square test for small emitters, and a Monte Carlo irradiance estimator
//! with a standard error from the sample variance.

#![allow(dead_code)]

use glam::{DVec3, Vec2, Vec3};
use penumbra::lights::{Emitter, Light, LightSampleContext, LightSource, SamplingMode};
use penumbra::sampling::Frame;
use penumbra::sampling::chi2::{Chi2Config, Chi2Result, chi2_directions, chi2_points};
use penumbra::sampling::hash::{next_f32, pcg_from_keys};

/// The 2D sample of the harness's three uniforms.
pub fn v2(u: [f32; 3]) -> Vec2 {
    Vec2::new(u[1], u[2])
}

/// Print and assert a chi-square result.
#[track_caller]
pub fn check(name: &str, r: &Chi2Result) {
    eprintln!("{name}: {}", r.summary());
    assert!(r.passed, "{name}: {}", r.summary());
}

/// Hit point of the ray `p + t·d` (t > 0) with triangle (a, b, c), f64 Möller–Trumbore.
pub fn hit_triangle(p: Vec3, d: Vec3, v: [Vec3; 3]) -> Option<Vec3> {
    let (o, d) = (p.as_dvec3(), d.as_dvec3());
    let [a, b, c] = v.map(|x| x.as_dvec3());
    let (e1, e2) = (b - a, c - a);
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 {
        return None;
    }
    let t = o - a;
    let u = t.dot(pv) / det;
    let q = t.cross(e1);
    let w = d.dot(q) / det;
    let dist = e2.dot(q) / det;
    (u >= 0.0 && w >= 0.0 && u + w <= 1.0 && dist > 0.0).then(|| (o + d * dist).as_vec3())
}

/// Hit point of a ray with the parallelogram `corner + s·e1 + t·e2`.
pub fn hit_quad(p: Vec3, d: Vec3, corner: Vec3, e1: Vec3, e2: Vec3) -> Option<Vec3> {
    hit_triangle(p, d, [corner, corner + e1, corner + e2])
        .or_else(|| hit_triangle(p, d, [corner + e1 + e2, corner + e2, corner + e1]))
}

/// Hit point of a ray with a disk.
pub fn hit_disk(p: Vec3, d: Vec3, c: Vec3, n: Vec3, r: f32) -> Option<Vec3> {
    let (o, d, c, n) = (p.as_dvec3(), d.as_dvec3(), c.as_dvec3(), n.as_dvec3());
    let t = n.dot(c - o) / n.dot(d);
    if t.is_nan() || t <= 0.0 || !t.is_finite() {
        return None;
    }
    let h: DVec3 = o + d * t;
    ((h - c).length() <= r as f64).then(|| h.as_vec3())
}

/// Chi-square test of `sample_li` against `pdf_li` from receiver `p`. `hit` maps a direction to
/// the point it hits on the light (needed by area pdfs). Small emitters (every `outline` point
/// within 60° of the direction to `centre`) are tested zoomed in: directions are projected
/// gnomonically onto the plane tangent to that axis and tested as points with the area pdf
/// pdf_ω·cos³θ; samples beyond the plotted square go to the harness's "nowhere" category,
/// whose expected mass is exact, so the test stays valid.
#[allow(clippy::too_many_arguments)]
pub fn chi2_light(
    name: &str,
    cfg: &Chi2Config,
    light: &Light,
    p: Vec3,
    mode: SamplingMode,
    hit: impl Fn(Vec3, Vec3) -> Option<Vec3>,
    centre: Vec3,
    outline: &[Vec3],
) {
    let ctx = LightSampleContext { p, n: Vec3::ZERO };
    let pdf = |d: Vec3| -> f64 {
        let d = d.normalize();
        match hit(p, d) {
            Some(q) => light.pdf_li(&ctx, d, q, Vec3::ZERO, mode) as f64,
            None => 0.0,
        }
    };
    // Samples whose returned pdf disagrees with pdf_li (allowed only for the odd sample that
    // rounds onto the far side of a support edge).
    let mismatches = std::cell::Cell::new(0usize);
    let sample = |u: [f32; 3]| {
        let s = light.sample_li(&ctx, v2(u), mode)?;
        // The shadow-ray target must lie along the sampled direction.
        let to = (s.p_light - p).normalize();
        assert!(
            to.dot(s.wi) > 0.9999,
            "{name}: p_light off wi: {to} vs {}",
            s.wi
        );
        assert!(s.pdf > 0.0 && s.pdf.is_finite(), "{name}: pdf {}", s.pdf);
        let q = pdf(s.wi);
        if (q - s.pdf as f64).abs() > 1e-2 * s.pdf as f64 {
            mismatches.set(mismatches.get() + 1);
        }
        Some(s.wi)
    };
    let frame = Frame::from_normal((centre - p).normalize());
    let small = outline.iter().all(|&v| {
        let l = frame.to_local(v - p);
        l.z > 0.5 * l.length()
    });
    let t0 = std::time::Instant::now();
    let r = if small {
        let mut b = [f32::MAX, f32::MIN, f32::MAX, f32::MIN];
        for &v in outline {
            let l = frame.to_local(v - p);
            let q = Vec2::new(l.x / l.z, l.y / l.z);
            b = [b[0].min(q.x), b[1].max(q.x), b[2].min(q.y), b[3].max(q.y)];
        }
        let m = 0.03 * (b[1] - b[0]).max(b[3] - b[2]);
        let domain = [b[0] - m, b[1] + m, b[2] - m, b[3] + m];
        chi2_points(
            &Chi2Config {
                res: (32, 32),
                ..cfg.clone()
            },
            domain,
            |u| {
                let l = frame.to_local(sample(u)?);
                (l.z > 0.0).then(|| Vec2::new(l.x / l.z, l.y / l.z))
            },
            |q| {
                let q = q.as_dvec2();
                let d = frame.to_world(Vec3::new(q.x as f32, q.y as f32, 1.0));
                let s = 1.0 + q.length_squared();
                pdf(d) / (s * s.sqrt())
            },
        )
    } else {
        chi2_directions(cfg, sample, pdf)
    };
    let bad = mismatches.get();
    assert!(
        bad <= 5 + cfg.samples / 1000,
        "{name} [{mode:?}]: {bad} samples whose pdf differs from pdf_li"
    );
    let label = format!("{name} [{mode:?}{}]", if small { ", zoomed" } else { "" });
    eprintln!("{label}: {:.2} s", t0.elapsed().as_secs_f64());
    check(&label, &r);
}

/// Monte Carlo estimate of irradiance E = ∫ Li cos θ dω at (p, n) from `n_samples` light
/// samples: (mean, standard error of the mean). Failed samples count as zero.
pub fn irradiance(
    light: &Light,
    p: Vec3,
    n: Vec3,
    mode: SamplingMode,
    n_samples: usize,
    seed: u64,
) -> (f64, f64) {
    let ctx = LightSampleContext { p, n };
    let mut rng = pcg_from_keys(&[seed, 0x11e]);
    let (mut s1, mut s2) = (0.0f64, 0.0f64);
    for _ in 0..n_samples {
        let u = Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
        let x = match light.sample_li(&ctx, u, mode) {
            Some(s) if s.pdf > 0.0 => {
                let cos = s.wi.dot(n).max(0.0) as f64;
                s.li.x as f64 * cos / s.pdf as f64
            }
            _ => 0.0,
        };
        s1 += x;
        s2 += x * x;
    }
    let nn = n_samples as f64;
    let mean = s1 / nn;
    let var = (s2 / nn - mean * mean).max(0.0) * nn / (nn - 1.0);
    (mean, (var / nn).sqrt())
}

/// Assert |estimate − exact| < 5σ (plus a 1e-5 relative allowance for f32 rounding, which also
/// keeps zero-variance estimators testable).
#[track_caller]
pub fn check_estimate(name: &str, (mean, se): (f64, f64), exact: f64) {
    let tol = 5.0 * se + 1e-5 * exact.abs();
    eprintln!(
        "{name}: estimate {mean:.6} ± {se:.2e}, exact {exact:.6}, |diff|/σ = {:.2}",
        (mean - exact).abs() / se.max(1e-300)
    );
    assert!(
        (mean - exact).abs() < tol,
        "{name}: estimate {mean} ± {se} vs exact {exact}"
    );
}
