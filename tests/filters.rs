//! pbrt-v4's pixel filters (gaussian — its default —, mitchell, sinc) sampled through
//! `FilterSampler`: the offsets follow |f|/∫|f| (chi-square against the filter itself, not
//! against the table), the signed weights have mean 1 and make the sample mean of h(offset)
//! equal the filter's own ∫f·h/∫f, and a constant-radiance render stays constant.

use glam::{UVec2, Vec2};
use penumbra::integrator::film::FilterSampler;
use penumbra::integrator::{RenderOptions, render};
use penumbra::sampling::chi2::{Chi2Config, chi2_points};
use penumbra::sampling::hash::{next_f32, pcg_from_keys};
use penumbra::scene::Filter;
use penumbra::scene::pbrt::parse_pbrt_str;
use std::path::Path;

/// The filters of the tests: pbrt-v4's defaults and variants with anisotropic radii and
/// stronger negative lobes.
fn filters() -> Vec<(&'static str, Filter)> {
    vec![
        (
            "gaussian default",
            Filter::Gaussian {
                radius: Vec2::splat(1.5),
                sigma: 0.5,
            },
        ),
        (
            "gaussian 2x1 sigma 0.8",
            Filter::Gaussian {
                radius: Vec2::new(2.0, 1.0),
                sigma: 0.8,
            },
        ),
        (
            "mitchell default",
            Filter::Mitchell {
                radius: Vec2::splat(2.0),
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
            },
        ),
        (
            "mitchell B0 C0.5 (Catmull-Rom)",
            Filter::Mitchell {
                radius: Vec2::new(2.0, 1.5),
                b: 0.0,
                c: 0.5,
            },
        ),
        (
            "sinc default",
            Filter::Sinc {
                radius: Vec2::splat(4.0),
                tau: 3.0,
            },
        ),
        (
            "sinc 3x2 tau 2",
            Filter::Sinc {
                radius: Vec2::new(3.0, 2.0),
                tau: 2.0,
            },
        ),
    ]
}

/// ∫ g(x)·x^k over the profile of `axis`, and the same of |g|, by composite Simpson with
/// 20 000 intervals (independent of the sampler's table).
fn moments(f: &Filter, axis: usize, k: i32) -> (f64, f64) {
    let r = f.radius()[axis] as f64;
    let n = 20_000;
    let h = 2.0 * r / n as f64;
    let (mut s, mut sa) = (0.0, 0.0);
    for i in 0..=n {
        let x = -r + i as f64 * h;
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let g = f.profile(axis, x);
        s += w * g * x.powi(k);
        sa += w * g.abs() * x.powi(k);
    }
    (s * h / 3.0, sa * h / 3.0)
}

#[test]
fn profiles_are_pbrt_v4s_definitions() {
    // Values worked by hand from pbrt-v4's formulas.
    let m = Filter::Mitchell {
        radius: Vec2::splat(2.0),
        b: 1.0 / 3.0,
        c: 1.0 / 3.0,
    };
    // Mitchell1D(0) = (6 − 2B)/6; Mitchell1D(2·1.5/2 = 1.5) = (−B−6C)1.5³ + (6B+30C)1.5²
    // + (−12B−48C)1.5 + (8B+24C), all over 6.
    assert!((m.profile(0, 0.0) - 8.0 / 9.0).abs() < 1e-6);
    let (b, c, x) = (1.0 / 3.0, 1.0 / 3.0, 1.5f64);
    let want = ((-b - 6.0 * c) * x.powi(3)
        + (6.0 * b + 30.0 * c) * x * x
        + (-12.0 * b - 48.0 * c) * x
        + (8.0 * b + 24.0 * c))
        / 6.0;
    assert!((m.profile(0, 1.5) - want).abs() < 1e-6 && want < 0.0);
    // sinc(0.5)·sinc(0.5/3) = (2/π)·(sin(π/6)/(π/6)).
    let s = Filter::Sinc {
        radius: Vec2::splat(4.0),
        tau: 3.0,
    };
    let want = (2.0 / std::f64::consts::PI) * (0.5 / (std::f64::consts::PI / 6.0));
    assert!((s.profile(0, 0.5) - want).abs() < 1e-9);
    assert_eq!(s.profile(0, 4.0), 0.0);
    // Gaussian minus its value at the radius: zero at the radius, G(0) − G(r) at the centre.
    let g = Filter::Gaussian {
        radius: Vec2::splat(1.5),
        sigma: 0.5,
    };
    let gauss = |x: f64| (-x * x / 0.5).exp() / (2.0 * std::f64::consts::PI * 0.25).sqrt();
    assert!((g.profile(0, 0.0) - (gauss(0.0) - gauss(1.5))).abs() < 1e-12);
    assert!(g.profile(1, 1.4999).abs() < 1e-5 && g.profile(1, 1.5) == 0.0);
}

#[test]
fn chi2_filter_offsets_follow_the_filter_magnitude() {
    let all = filters();
    for (name, f) in &all {
        let s = FilterSampler::new(f).unwrap();
        let r = f.radius();
        let norm = moments(f, 0, 0).1 * moments(f, 1, 0).1;
        let cfg = Chi2Config {
            samples: 1_000_000,
            res: (32, 32),
            num_tests: all.len(),
            ..Default::default()
        };
        let res = chi2_points(
            &cfg,
            [-r.x, r.x, -r.y, r.y],
            |u| Some(s.sample(UVec2::new(3, 5), Vec2::new(u[0], u[1])).0 - Vec2::new(3.5, 5.5)),
            |p| f.eval(p).abs() / norm,
        );
        assert!(res.passed, "{name}: {}", res.summary());
    }
}

#[test]
fn chi2_rejects_the_old_triangle_approximation_and_a_wrong_filter() {
    // Negative controls: what penumbra did before (a tent of the gaussian's radius) and the
    // mitchell filter's samples, each tested against pbrt-v4's default gaussian.
    let g = Filter::Gaussian {
        radius: Vec2::splat(1.5),
        sigma: 0.5,
    };
    let norm = moments(&g, 0, 0).1 * moments(&g, 1, 0).1;
    for wrong in [
        Filter::Triangle {
            radius: Vec2::splat(1.5),
        },
        Filter::Mitchell {
            radius: Vec2::splat(1.5),
            b: 1.0 / 3.0,
            c: 1.0 / 3.0,
        },
    ] {
        let s = FilterSampler::new(&wrong).unwrap();
        let cfg = Chi2Config {
            samples: 200_000,
            res: (16, 16),
            ..Default::default()
        };
        let res = chi2_points(
            &cfg,
            [-1.5, 1.5, -1.5, 1.5],
            |u| Some(s.sample(UVec2::ZERO, Vec2::new(u[0], u[1])).0 - Vec2::splat(0.5)),
            |p| g.eval(p).abs() / norm,
        );
        assert!(!res.passed, "{wrong:?}: {}", res.summary());
    }
}

#[test]
fn weights_have_mean_one_and_reproduce_the_signed_filter() {
    // Monte Carlo over 2M uniform draws: E[w] = 1 and E[w·x²] = ∫f·x²/∫f (the filter's own
    // second moment, which unit weights on |f| would miss wherever f has negative lobes),
    // each within 5σ of the measured spread.
    for (name, f) in filters() {
        let s = FilterSampler::new(&f).unwrap();
        let (m0, a0) = moments(&f, 0, 0);
        let (m2, a2) = moments(&f, 0, 2);
        let want_x2 = m2 / m0;
        let unsigned_x2 = a2 / a0;
        let mut rng = pcg_from_keys(&[42]);
        let n = 2_000_000;
        let (mut sw, mut sw2, mut sx, mut sx2) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for _ in 0..n {
            let u = Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
            let (p, w) = s.sample(UVec2::ZERO, u);
            let x = (p.x - 0.5) as f64;
            let w = w as f64;
            sw += w;
            sw2 += w * w;
            let v = w * x * x;
            sx += v;
            sx2 += v * v;
        }
        let nf = n as f64;
        let (mw, mx) = (sw / nf, sx / nf);
        let sew = ((sw2 / nf - mw * mw).max(0.0) / nf).sqrt();
        let sex = ((sx2 / nf - mx * mx) / nf).sqrt();
        if m0 == a0 {
            // No negative lobe: every weight is exactly 1.
            assert_eq!(sw, nf, "{name}");
        }
        assert!(
            (mw - 1.0).abs() <= 5.0 * sew + 1e-6,
            "{name}: E[w] = {mw} ± {sew}"
        );
        assert!(
            (mx - want_x2).abs() <= 5.0 * sex + 1e-4,
            "{name}: E[w x²] = {mx} ± {sex}, filter's {want_x2}"
        );
        if (unsigned_x2 - want_x2).abs() > 1e-3 {
            // The test can tell signed from unsigned weights for this filter.
            assert!((mx - unsigned_x2).abs() > 5.0 * sex, "{name}");
        }
        // The API's pdf·weight integrates to 1 (exact quadrature over the table's bins).
        let r = f.radius();
        let steps = 400;
        let (hx, hy) = (2.0 * r.x / steps as f32, 2.0 * r.y / steps as f32);
        let mut total = 0.0f64;
        for i in 0..steps {
            for j in 0..steps {
                let p = Vec2::new(-r.x + (i as f32 + 0.5) * hx, -r.y + (j as f32 + 0.5) * hy);
                total += (s.pdf(p) * s.weight(p)) as f64 * (hx * hy) as f64;
            }
        }
        assert!((total - 1.0).abs() < 2e-3, "{name}: ∫pdf·w = {total}");
    }
}

/// Render a scene lit only by a uniform sky of radiance 0.5 that every camera ray sees.
fn render_sky(filter: &str, spp: u32) -> Vec<f32> {
    let src = format!(
        "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 60\n{filter}\n\
         Film \"rgb\" \"integer xresolution\" 24 \"integer yresolution\" 16\n\
         WorldBegin\nLightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\n"
    );
    let (b, camera, film, _) = parse_pbrt_str("sky.pbrt", &src, Path::new("."))
        .unwrap()
        .into_builder()
        .unwrap();
    let scene = b.build(camera, film).unwrap();
    let opts = RenderOptions {
        spp,
        ..Default::default()
    };
    let (img, _) = render(&scene, scene.film.resolution, &opts).unwrap();
    img.pixels.iter().map(|p| p.x).collect()
}

#[test]
fn constant_radiance_renders_constant() {
    // Positive filters: every weight is 1, so every pixel is exactly the sky's 0.5.
    for f in [
        "",
        "PixelFilter \"gaussian\" \"float sigma\" 0.7",
        "PixelFilter \"box\"",
        "PixelFilter \"triangle\"",
    ] {
        let px = render_sky(f, 16);
        assert!(px.iter().all(|&v| v == 0.5), "{f:?}: {px:?}");
    }
    // Negative lobes: each sample weighs ±∫|f|/∫f, so a pixel is 0.5 only on average; the
    // image mean is within 5σ of 0.5 (σ from the spread of the pixels).
    for f in ["PixelFilter \"mitchell\"", "PixelFilter \"sinc\""] {
        let px = render_sky(f, 64);
        let n = px.len() as f64;
        let mean = px.iter().map(|&v| v as f64).sum::<f64>() / n;
        let var = px.iter().map(|&v| (v as f64 - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let se = (var / n).sqrt();
        assert!((mean - 0.5).abs() <= 5.0 * se + 1e-6, "{f}: {mean} ± {se}");
        assert!(var > 0.0, "{f}: the weights should vary");
    }
}

#[test]
fn pbrt_filters_parse_with_pbrt_v4_defaults() {
    let film = |s: &str| {
        parse_pbrt_str("f.pbrt", &format!("{s}\nWorldBegin"), Path::new(".")).map(|p| p.film.filter)
    };
    // No PixelFilter: pbrt-v4's default gaussian.
    assert_eq!(
        film("").unwrap(),
        Filter::Gaussian {
            radius: Vec2::splat(1.5),
            sigma: 0.5
        }
    );
    assert_eq!(
        film("PixelFilter \"mitchell\" \"float B\" 0.2 \"float C\" 0.4").unwrap(),
        Filter::Mitchell {
            radius: Vec2::splat(2.0),
            b: 0.2,
            c: 0.4
        }
    );
    assert_eq!(
        film("PixelFilter \"sinc\" \"float xradius\" 3").unwrap(),
        Filter::Sinc {
            radius: Vec2::new(3.0, 4.0),
            tau: 3.0
        }
    );
    assert_eq!(
        film("PixelFilter \"triangle\"").unwrap(),
        Filter::Triangle {
            radius: Vec2::splat(2.0)
        }
    );
    for (bad, want) in [
        (
            "PixelFilter \"lanczos\"",
            "f.pbrt:1:13: unknown PixelFilter \"lanczos\"",
        ),
        (
            "PixelFilter \"gaussian\" \"float sigma\" -1",
            "f.pbrt:1:1: PixelFilter \"gaussian\": expected a positive 'sigma'",
        ),
        ("PixelFilter \"sinc\" \"float tau\" 0", "positive 'tau'"),
    ] {
        let e = film(bad).unwrap_err().to_string();
        assert!(e.contains(want), "{bad}: {e}");
    }
    // Mitchell's cubics integrate to 1 for every B and C, sinc windows stay positive: only a
    // broken parameter gets a filter that cannot normalise a pixel.
    let nan = Filter::Mitchell {
        radius: Vec2::splat(2.0),
        b: f32::NAN,
        c: 0.0,
    };
    let e = FilterSampler::new(&nan).unwrap_err().to_string();
    assert!(e.contains("integrates to"), "{e}");
}
