//! Rough-conductor furnaces. A GGX conductor with Fresnel 1 (η = 1, k = 1000: F ≥ 1 − 4·10⁻⁶)
//! loses only what single scattering loses: its directional albedo
//!
//!   E(μo) = ∫ f(ωo, ωi) μi dωi = ∫ D(ωm) G₂(ωo, ωi) (ωo·ωm) / μo dωm   (ωi = reflect(ωo, ωm), μi > 0)
//!
//! is computed here by quadrature of pbrt-v4's GGX (Trowbridge–Reitz D, height-correlated
//! Smith G₂), written out in f64 independently of `penumbra::bsdf`; the quadrature itself is
//! checked on two identities (∫ D cos θm dωm = 1, ∫ D_ωo(ωm) dωm = 1).
//!
//! - **plane**: a conductor plane under a uniform sky of radiance 1, seen at cos θo = μo, has
//!   radiance E(μo) (one bounce; every strategy, direct and path).
//! - **cavity**: the inside of a sphere of that conductor emitting 1 everywhere (an inward
//!   sphere light), seen from its centre (μo = 1). A chord leaves and arrives at the same angle
//!   to the sphere's normal, so the radiance leaving the wall depends on μ only and obeys
//!   L(μ) = Le + ∫ f(μ, ωi) L(μi) μi dωi; with max depth N it is the Neumann series truncated
//!   after N terms, computed on θ-bins. Multiple bounces, and next-event estimation on the
//!   sphere light from points of the sphere itself.

mod render_support;

use glam::{UVec2, Vec3};
use penumbra::integrator::{IntegratorKind, RenderOptions, render};
use render_support::{STRATEGIES, mean_se, pbrt_scene};
use std::f64::consts::{FRAC_PI_2, PI};

const ALPHA: f64 = 0.3;

/// GGX D(ωm) for cos θm = `c` (isotropic width `a`).
fn ggx_d(a: f64, c: f64) -> f64 {
    if c <= 0.0 {
        return 0.0;
    }
    let c2 = c * c;
    let q = c2 + (1.0 - c2) / (a * a);
    1.0 / (PI * a * a * q * q)
}

/// Smith Λ for a direction at cos θ = `mu`.
fn ggx_lambda(a: f64, mu: f64) -> f64 {
    let mu2 = mu * mu;
    let tan2 = (1.0 - mu2).max(0.0) / mu2;
    0.5 * ((1.0 + a * a * tan2).sqrt() - 1.0)
}

type V = [f64; 3];

fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn dir(theta: f64, phi: f64) -> V {
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

fn wo_at(mu: f64) -> V {
    [(1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu]
}

/// f(ωo, ωi) of the Fresnel-1 GGX conductor (no cosine).
fn f_conductor(a: f64, wo: V, wi: V) -> f64 {
    if wo[2] <= 0.0 || wi[2] <= 0.0 {
        return 0.0;
    }
    let h = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
    let l = dot(h, h).sqrt();
    if l == 0.0 {
        return 0.0;
    }
    let c = h[2] / l;
    let g2 = 1.0 / (1.0 + ggx_lambda(a, wo[2]) + ggx_lambda(a, wi[2]));
    ggx_d(a, c) * g2 / (4.0 * wo[2] * wi[2])
}

/// ∫ over microfacet normals (θm midpoints `nt` on [0, π/2), φm midpoints `np` on [0, π],
/// doubled by symmetry) of `g(ωm)` dωm.
fn over_normals(nt: usize, np: usize, g: impl Fn(V) -> f64) -> f64 {
    let (dt, dp) = (FRAC_PI_2 / nt as f64, PI / np as f64);
    let mut s = 0.0;
    for i in 0..nt {
        let t = (i as f64 + 0.5) * dt;
        let mut row = 0.0;
        for j in 0..np {
            row += g(dir(t, (j as f64 + 0.5) * dp));
        }
        s += row * t.sin();
    }
    2.0 * s * dt * dp
}

/// Directional albedo E(μo) of the Fresnel-1 GGX conductor, by quadrature over ωm.
fn albedo(a: f64, mu_o: f64) -> f64 {
    let wo = wo_at(mu_o);
    let g_o = ggx_lambda(a, mu_o);
    over_normals(4000, 256, |m| {
        let om = dot(wo, m);
        if om <= 0.0 {
            return 0.0;
        }
        let wi = [
            2.0 * om * m[0] - wo[0],
            2.0 * om * m[1] - wo[1],
            2.0 * om * m[2] - wo[2],
        ];
        if wi[2] <= 0.0 {
            return 0.0;
        }
        let g2 = 1.0 / (1.0 + g_o + ggx_lambda(a, wi[2]));
        ggx_d(a, m[2]) * g2 * om / mu_o
    })
}

#[test]
fn quadrature_of_the_ggx_identities() {
    for a in [0.1, ALPHA] {
        let norm = over_normals(4000, 64, |m| ggx_d(a, m[2]) * m[2]);
        assert!((norm - 1.0).abs() < 1e-5, "∫ D cos = {norm}");
        for mu in [1.0, 0.7, 0.3] {
            let wo = wo_at(mu);
            let g1 = 1.0 / (1.0 + ggx_lambda(a, mu));
            let vis = over_normals(4000, 256, |m| {
                g1 / mu * ggx_d(a, m[2]) * dot(wo, m).max(0.0)
            });
            assert!((vis - 1.0).abs() < 1e-4, "α {a} μ {mu}: ∫ D_wo = {vis}");
            let e = albedo(a, mu);
            eprintln!("α {a} μ {mu}: E = {e:.6}");
            // Single scattering loses energy, more at grazing angles and larger widths (GGX's
            // tail: at normal incidence 8 % of the visible normals of α = 0.3 are steeper than
            // 45° and reflect below the horizon).
            assert!(e < 1.0 && e > 0.6, "α {a} μ {mu}: E = {e}");
        }
    }
}

#[test]
fn penumbra_conductor_is_the_ggx_written_here() {
    // The renderer's BSDF against the f64 formula, pointwise (so the furnaces below test the
    // integrator, not a different model).
    use penumbra::bsdf::{Bxdf, Conductor};
    let c = Conductor::new(
        Vec3::ONE,
        Vec3::splat(1000.0),
        glam::Vec2::splat(ALPHA as f32),
    );
    for (mo, mi, phi) in [
        (0.9, 0.8, 0.3),
        (0.5, 0.7, 2.0),
        (0.2, 0.95, 3.0),
        (0.6, 0.1, 0.0),
    ] {
        let wo = wo_at(mo);
        let wi = [
            (1.0f64 - mi * mi).sqrt() * f64::cos(phi),
            (1.0f64 - mi * mi).sqrt() * f64::sin(phi),
            mi,
        ];
        let v = |w: V| Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32);
        let got = c.f(v(wo), v(wi)).x as f64;
        let want = f_conductor(ALPHA, wo, wi);
        assert!(
            (got - want).abs() <= 1e-4 * want + 1e-6,
            "f({mo}, {mi}, {phi}) = {got} vs {want}"
        );
    }
}

const METAL: &str = r#"Material "conductor" "rgb eta" [ 1 1 1 ] "rgb k" [ 1000 1000 1000 ]
    "float roughness" [ 0.3 ] "bool remaproughness" false"#;

#[test]
fn rough_conductor_plane_under_a_uniform_sky_has_its_directional_albedo() {
    let theta = 60f64.to_radians();
    let src = format!(
        r#"LookAt 0 {y} {z}  0 0 0  0 0 1
Camera "perspective" "float fov" [ 2 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
{METAL}
Shape "trianglemesh" "point3 P" [ -1000 -1000 0  1000 -1000 0  1000 1000 0  -1000 1000 0 ]
    "integer indices" [ 0 1 2  0 2 3 ]
"#,
        y = -10.0 * theta.sin(),
        z = 10.0 * theta.cos(),
    );
    let s = pbrt_scene(&src);
    let want = albedo(ALPHA, theta.cos());
    let mut failures = Vec::new();
    for (strategy, mis) in STRATEGIES {
        for integrator in [IntegratorKind::Direct, IntegratorKind::Path] {
            let opts = RenderOptions {
                spp: 64,
                seed: 5,
                strategy,
                mis,
                integrator,
                max_depth: if integrator == IntegratorKind::Path {
                    5
                } else {
                    1
                },
                ..RenderOptions::default()
            };
            let (img, stats) = render(&s, UVec2::new(16, 16), &opts).unwrap();
            assert_eq!(stats.non_finite, 0);
            let (mean, se) = mean_se(&img);
            // The 2° view spans ±1° of angle: E is linear there far below the noise.
            let ok = (mean - want).abs() <= 5.0 * se + 1e-3 * want;
            eprintln!(
                "plane {strategy} {mis:?} {integrator}: {mean:.5} ± {se:.1e} vs E = {want:.5} {}",
                if ok { "ok" } else { "FAIL" }
            );
            if !ok {
                failures.push(format!("{strategy} {mis:?} {integrator}"));
            }
        }
    }
    assert!(failures.is_empty(), "conductor plane off: {failures:?}");
}

/// Radiance leaving the wall of the conductor cavity at cos θ = `mu_o` with max depth `depth`
/// (see the module comment): the Neumann series on `n` θ-bins (L constant per bin), kernel
/// cells by `sub` midpoints in θ and `np` in φ.
fn cavity(a: f64, mu_o: f64, depth: u32, (n, sub, np): (usize, usize, usize)) -> f64 {
    let dt = FRAC_PI_2 / n as f64;
    // K[row][j] = ∫_{bin j} f(ωo(row), ωi) μi dωi.
    let row = |mu: f64| -> Vec<f64> {
        let wo = wo_at(mu);
        (0..n)
            .map(|j| {
                let mut s = 0.0;
                for p in 0..sub {
                    let t = (j as f64 + (p as f64 + 0.5) / sub as f64) * dt;
                    let mut r = 0.0;
                    for q in 0..np {
                        let wi = dir(t, (q as f64 + 0.5) * PI / np as f64);
                        r += f_conductor(a, wo, wi) * wi[2];
                    }
                    s += r * t.sin();
                }
                2.0 * s * (dt / sub as f64) * (PI / np as f64)
            })
            .collect()
    };
    let k: Vec<Vec<f64>> = (0..n).map(|i| row(((i as f64 + 0.5) * dt).cos())).collect();
    let mut l = vec![1.0; n];
    for _ in 1..depth {
        l = k
            .iter()
            .map(|r| 1.0 + r.iter().zip(&l).map(|(x, y)| x * y).sum::<f64>())
            .collect();
    }
    if depth == 0 {
        return 1.0;
    }
    1.0 + row(mu_o).iter().zip(&l).map(|(x, y)| x * y).sum::<f64>()
}

#[test]
fn cavity_expectation_converges() {
    let (coarse, fine) = (
        cavity(ALPHA, 1.0, 6, (90, 3, 96)),
        cavity(ALPHA, 1.0, 6, (180, 3, 192)),
    );
    eprintln!("cavity α {ALPHA} depth 6: {coarse:.5} (90 bins), {fine:.5} (180)");
    assert!((coarse - fine).abs() < 1e-3 * fine, "{coarse} vs {fine}");
    // E(μ) ≤ E(1) (more loss at grazing angles): below 1 + Σ_{k≤6} E(1)^k, and above the
    // same series with E(0.3).
    let bound = |e: f64| (0..=6).map(|k| e.powi(k)).sum::<f64>();
    let (hi, lo) = (bound(albedo(ALPHA, 1.0)), bound(albedo(ALPHA, 0.3)));
    assert!(fine < hi && fine > lo, "{fine} not in ({lo}, {hi})");
}

#[test]
fn rough_conductor_cavity_around_a_sphere_light() {
    let src = format!(
        r#"LookAt 0 0 0  0.3 0.2 1  0 1 0
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
  {METAL}
  ReverseOrientation
  Shape "sphere" "float radius" [ 1 ]
AttributeEnd
"#
    );
    let s = pbrt_scene(&src);
    let depth = 6;
    let want = cavity(ALPHA, 1.0, depth, (180, 3, 192));
    let mut failures = Vec::new();
    for (strategy, mis) in STRATEGIES {
        for roulette in [false, true] {
            let opts = RenderOptions {
                spp: 32,
                seed: 9,
                strategy,
                mis,
                integrator: IntegratorKind::Path,
                max_depth: depth,
                roulette,
                ..RenderOptions::default()
            };
            let (img, stats) = render(&s, UVec2::new(16, 16), &opts).unwrap();
            assert_eq!(stats.non_finite, 0);
            let (mean, se) = mean_se(&img);
            let ok = (mean - want).abs() <= 5.0 * se + 1e-3 * want;
            eprintln!(
                "cavity {strategy} {mis:?} roulette {roulette}: {mean:.5} ± {se:.1e} vs {want:.5} {}",
                if ok { "ok" } else { "FAIL" }
            );
            if !ok {
                failures.push(format!("{strategy} {mis:?} rr {roulette}"));
            }
        }
    }
    assert!(failures.is_empty(), "conductor cavity off: {failures:?}");
}
