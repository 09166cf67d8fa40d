//! Physical and numerical properties of the BSDFs: albedos (white-furnace style, Monte Carlo
//! with 5σ bounds from the measured sample variance), reciprocity, pdf normalisation by
//! quadrature against the measured fraction of kept samples, GGX normalisations, Fresnel, the
//! dielectric's event probabilities, and the material → BSDF mapping.

use glam::{DVec3, Vec2, Vec3};
use penumbra::Rgb;
use penumbra::bsdf::fresnel::{
    diffuse_fresnel_external, diffuse_fresnel_internal, fr_complex, fr_dielectric,
    k_from_reflectance,
};
use penumbra::bsdf::{
    Bsdf, Bxdf, CoatedDiffuse, Conductor, Dielectric, Lambert, LobeSampling, Phong,
    TrowbridgeReitz, named_metal, roughness_to_alpha,
};
use penumbra::geometry::SurfaceHit;
use penumbra::material::{Material, Texture};
use penumbra::sampling::hash::{next_f32, pcg_from_keys};
use std::f64::consts::PI;

/// Outgoing direction at polar angle `deg` degrees, azimuth 30°.
fn wo_at(deg: f32) -> Vec3 {
    let (t, p) = (deg.to_radians(), 30f32.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Monte Carlo estimate of the directional albedo ∫ f cos dωi (delta lobes included through
/// their weights), with the standard error of the mean per channel.
fn albedo_mc(b: &Bsdf, wo: Vec3, n: usize, seed: u64) -> (DVec3, DVec3) {
    let mut rng = pcg_from_keys(&[seed, 77]);
    let (mut s, mut s2) = (DVec3::ZERO, DVec3::ZERO);
    for _ in 0..n {
        let uc = next_f32(&mut rng);
        let u = Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
        if let Some(bs) = b.sample(wo, uc, u) {
            let w = (bs.f * bs.wi.z.abs() / bs.pdf).as_dvec3();
            s += w;
            s2 += w * w;
        }
    }
    let nf = n as f64;
    let mean = s / nf;
    let var = (s2 / nf - mean * mean).max(DVec3::ZERO);
    (mean, (var / nf).map(f64::sqrt))
}

/// Midpoint quadrature of `g` over the upper hemisphere in (cos θ, φ) (dω = dz dφ).
fn hemi_quad(nz: usize, nphi: usize, g: impl Fn(Vec3) -> f64) -> f64 {
    let mut s = 0.0;
    for i in 0..nz {
        let z = (i as f64 + 0.5) / nz as f64;
        let r = (1.0 - z * z).sqrt();
        for j in 0..nphi {
            let phi = (j as f64 + 0.5) / nphi as f64 * 2.0 * PI;
            s += g(Vec3::new(
                (r * phi.cos()) as f32,
                (r * phi.sin()) as f32,
                z as f32,
            ));
        }
    }
    s * 2.0 * PI / (nz * nphi) as f64
}

#[track_caller]
fn assert_within(name: &str, est: f64, sigma: f64, exact: f64, slack: f64) {
    let err = (est - exact).abs();
    eprintln!("{name}: estimate {est:.6} ± {sigma:.2e}, expected {exact:.6}");
    assert!(
        err <= 5.0 * sigma + slack,
        "{name}: |{est} − {exact}| = {err:.3e} > 5σ = {:.3e}",
        5.0 * sigma
    );
}

// ---------------------------------------------------------------- albedos

#[test]
fn lambert_albedo_is_kd() {
    let kd = Rgb::new(0.8, 0.5, 0.2);
    let mut b = Bsdf::Lambert(Lambert::new(kd));
    // Cosine sampling is exact: every weight is kd.
    let mut rng = pcg_from_keys(&[1]);
    for _ in 0..10_000 {
        let u = Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
        if let Some(s) = b.sample(wo_at(40.0), 0.5, u) {
            let w = s.f * s.wi.z / s.pdf;
            assert!((w - kd).abs().max_element() < 1e-5, "weight {w} ≠ kd {kd}");
        }
    }
    b.set_sampling(LobeSampling::Uniform);
    let (m, sd) = albedo_mc(&b, wo_at(40.0), 200_000, 2);
    for c in 0..3 {
        assert!(sd[c] > 0.0);
        assert_within("lambert uniform albedo", m[c], sd[c], kd[c] as f64, 0.0);
    }
}

/// Albedo of the n = 1 modified Phong: kd + ks·[(π − θ) cos θ + sin θ]/π.
///
/// Derivation: the glossy part is ks·(3/2π)∫ max(0, wi·r) max(0, wi·z) dω with r the mirror
/// direction (angle θ from z); the clamped-cosine product integral for two axes at angle γ is
/// (2/3)[(π − γ) cos γ + sin γ] (2π/3 at γ = 0, 2/3 at γ = π/2, 0 at γ = π).
fn phong_n1_albedo(kd: f64, ks: f64, theta: f64) -> f64 {
    kd + ks * ((PI - theta) * theta.cos() + theta.sin()) / PI
}

#[test]
fn phong_n1_albedo_matches_analytic() {
    let (kd, ks) = (0.4f32, 0.6f32);
    let p = Phong::new(Rgb::splat(kd), Rgb::splat(ks), 1.0).unwrap();
    let b = Bsdf::Phong(p);
    for deg in [0.0f32, 30.0, 60.0, 80.0, 89.0] {
        let wo = wo_at(deg);
        let exact = phong_n1_albedo(kd as f64, ks as f64, (deg as f64).to_radians());
        let (m, sd) = albedo_mc(&b, wo, 200_000, deg as u64);
        assert_within(
            &format!("phong n=1 albedo MC {deg}°"),
            m.x,
            sd.x,
            exact,
            0.0,
        );
        let q = hemi_quad(400, 800, |wi| (b.f(wo, wi).x * wi.z) as f64);
        assert_within(
            &format!("phong n=1 albedo quad {deg}°"),
            q,
            0.0,
            exact,
            2e-3,
        );
    }
}

#[test]
fn phong_albedo_at_most_one() {
    for n in [1.0f32, 20.0, 500.0] {
        // Pure glossy at normal incidence: the (n+2)/2π normalisation gives exactly ks = 1.
        let b = Bsdf::Phong(Phong::new(Rgb::ZERO, Rgb::ONE, n).unwrap());
        let (m, sd) = albedo_mc(&b, Vec3::Z, 100_000, 3);
        assert_within(
            &format!("phong kd=0 ks=1 n={n} normal"),
            m.x,
            sd.x,
            1.0,
            1e-5,
        );
        for deg in [45.0f32, 85.0] {
            for (kd, ks) in [(0.0f32, 1.0f32), (0.5, 0.5)] {
                let b = Bsdf::Phong(Phong::new(Rgb::splat(kd), Rgb::splat(ks), n).unwrap());
                let (m, sd) = albedo_mc(&b, wo_at(deg), 100_000, 4);
                eprintln!(
                    "phong kd={kd} ks={ks} n={n} {deg}°: albedo {:.4} ± {:.1e}",
                    m.x, sd.x
                );
                assert!(m.x <= 1.0 + 5.0 * sd.x, "albedo {} > 1", m.x);
            }
        }
    }
}

/// A conductor whose Fresnel is ≈ 1 everywhere (huge extinction), for furnace tests.
fn white_conductor(alpha: Vec2) -> Bsdf {
    Bsdf::Conductor(Conductor::new(Rgb::ONE, Rgb::splat(1e4), alpha))
}

#[test]
fn ggx_conductor_albedo_at_most_one() {
    for alpha in [0.05f32, 0.3, 1.0] {
        for deg in [0.0f32, 45.0, 85.0] {
            let b = white_conductor(Vec2::splat(alpha));
            let (m, sd) = albedo_mc(&b, wo_at(deg), 100_000, 5);
            eprintln!(
                "ggx white α={alpha} {deg}°: albedo {:.4} ± {:.1e}",
                m.x, sd.x
            );
            assert!(m.x <= 1.0 + 5.0 * sd.x, "albedo {} > 1", m.x);
            if alpha <= 0.05 && deg < 60.0 {
                // Single scattering loses almost nothing for a smooth-ish surface.
                assert!(m.x > 0.98, "albedo {} too low for α = {alpha}", m.x);
            }
        }
    }
    // Anisotropic.
    let b = white_conductor(Vec2::new(0.1, 0.5));
    let (m, sd) = albedo_mc(&b, wo_at(60.0), 100_000, 6);
    assert!(m.x <= 1.0 + 5.0 * sd.x && m.x > 0.7, "aniso albedo {}", m.x);
    // α = 1, normal incidence: visible normals are cosine distributed (D = 1/π), half of them
    // (θm > 45°) reflect below the horizon, and the rest carry weight G/G1 = 2cos θi/(1 + cos θi)
    // with θi = 2θm; integrating gives the closed form E = 1 − ln 2.
    let b = white_conductor(Vec2::ONE);
    let (m, sd) = albedo_mc(&b, Vec3::Z, 200_000, 13);
    assert_within(
        "ggx white α=1 normal",
        m.x,
        sd.x,
        1.0 - std::f64::consts::LN_2,
        1e-4,
    );
    // Smooth limit: delta mirror with weight F = 1.
    let b = white_conductor(Vec2::ZERO);
    assert!(b.is_delta());
    let (m, _) = albedo_mc(&b, wo_at(30.0), 100, 7);
    assert!((m.x - 1.0).abs() < 1e-3);
}

#[test]
fn coated_diffuse_albedo() {
    // Smooth coat: F(θo) + (1 − F(θo))·R(1 − F_dr,int)/(1 − R·F_dr,int) (see coated.rs).
    let eta = 1.5f32;
    let fdr = diffuse_fresnel_internal(eta) as f64;
    for r in [1.0f32, 0.5] {
        let b = Bsdf::CoatedDiffuse(CoatedDiffuse::new(Rgb::splat(r), Vec2::ZERO, eta));
        for deg in [0.0f32, 60.0, 85.0] {
            let fo = fr_dielectric(wo_at(deg).z, eta) as f64;
            let r = r as f64;
            let exact = fo + (1.0 - fo) * r * (1.0 - fdr) / (1.0 - r * fdr);
            let (m, sd) = albedo_mc(&b, wo_at(deg), 200_000, 8);
            assert_within(
                &format!("coated smooth R={r} {deg}°"),
                m.x,
                sd.x,
                exact,
                1e-4,
            );
        }
    }
    // Rough coat over a white base: ≤ 1.
    for alpha in [0.1f32, 0.5] {
        let b = Bsdf::CoatedDiffuse(CoatedDiffuse::new(Rgb::ONE, Vec2::splat(alpha), eta));
        for deg in [0.0f32, 60.0, 85.0] {
            let (m, sd) = albedo_mc(&b, wo_at(deg), 100_000, 9);
            eprintln!(
                "coated white α={alpha} {deg}°: albedo {:.4} ± {:.1e}",
                m.x, sd.x
            );
            assert!(m.x <= 1.0 + 5.0 * sd.x, "albedo {} > 1", m.x);
        }
    }
}

// ---------------------------------------------------------------- reciprocity

#[test]
fn reciprocity() {
    let bsdfs = [
        Bsdf::Lambert(Lambert::new(Rgb::new(0.3, 0.5, 0.7))),
        Bsdf::Phong(Phong::new(Rgb::splat(0.3), Rgb::splat(0.6), 30.0).unwrap()),
        Bsdf::Conductor(Conductor::new(
            Rgb::new(0.2, 0.9, 1.1),
            Rgb::new(3.9, 2.4, 2.1),
            Vec2::new(0.1, 0.4),
        )),
        Bsdf::CoatedDiffuse(CoatedDiffuse::new(Rgb::splat(0.6), Vec2::splat(0.3), 1.5)),
    ];
    let mut rng = pcg_from_keys(&[10]);
    for b in &bsdfs {
        let mut checked = 0;
        for _ in 0..20_000 {
            let mut d = || {
                let u = Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
                penumbra::sampling::uniform_hemisphere(u)
            };
            let (a, c) = (d(), d());
            let (fac, fca) = (b.f(a, c), b.f(c, a));
            let scale = fac.max_element().max(fca.max_element()).max(1e-6);
            assert!(
                (fac - fca).abs().max_element() <= 1e-4 * scale,
                "{b:?}: f(a,c) = {fac} ≠ f(c,a) = {fca} for a = {a}, c = {c}"
            );
            checked += 1;
        }
        assert_eq!(checked, 20_000);
    }
}

// ---------------------------------------------------------------- pdf normalisation

/// ∫pdf over the hemisphere by quadrature must equal the measured probability that `sample`
/// returns a (non-delta) direction. It is 1 for Lambert and for every BSDF in Cosine/Uniform
/// mode; below 1 where importance sampling loses samples below the horizon: Phong's glossy lobe
/// around the mirror direction, and GGX reflections (conductor, coat) off steep microfacets.
#[test]
fn pdf_integral_matches_kept_fraction() {
    let cases: Vec<(&str, Bsdf, f32)> = vec![
        ("lambert", Bsdf::Lambert(Lambert::new(Rgb::ONE)), 40.0),
        (
            "phong n=20 0°",
            Bsdf::Phong(Phong::new(Rgb::splat(0.2), Rgb::splat(0.8), 20.0).unwrap()),
            0.0,
        ),
        (
            "phong n=20 70°",
            Bsdf::Phong(Phong::new(Rgb::splat(0.2), Rgb::splat(0.8), 20.0).unwrap()),
            70.0,
        ),
        (
            "phong n=1 85°",
            Bsdf::Phong(Phong::new(Rgb::ZERO, Rgb::ONE, 1.0).unwrap()),
            85.0,
        ),
        ("ggx α=0.3 60°", white_conductor(Vec2::splat(0.3)), 60.0),
        ("ggx α=1 85°", white_conductor(Vec2::splat(1.0)), 85.0),
        (
            "coated α=0.3 70°",
            Bsdf::CoatedDiffuse(CoatedDiffuse::new(Rgb::splat(0.5), Vec2::splat(0.3), 1.5)),
            70.0,
        ),
    ];
    for (name, b, deg) in cases {
        let wo = wo_at(deg);
        let q = hemi_quad(600, 1200, |wi| b.pdf(wo, wi) as f64);
        let n = 200_000;
        let mut rng = pcg_from_keys(&[11]);
        let kept = (0..n)
            .filter(|_| {
                let uc = next_f32(&mut rng);
                let u = Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
                b.sample(wo, uc, u).is_some_and(|s| !s.delta)
            })
            .count() as f64
            / n as f64;
        let sigma = (kept * (1.0 - kept) / n as f64).sqrt();
        eprintln!("{name}: ∫pdf = {q:.5}, kept fraction = {kept:.5}");
        assert!(q <= 1.0 + 2e-3, "{name}: ∫pdf = {q} > 1");
        assert_within(&format!("{name} ∫pdf vs kept"), kept, sigma, q, 2e-3);
    }
}

// ---------------------------------------------------------------- GGX

#[test]
fn ggx_normalisations() {
    for alpha in [Vec2::splat(0.3), Vec2::splat(1.0), Vec2::new(0.2, 0.6)] {
        let d = TrowbridgeReitz::new(alpha);
        // Projected-area normalisation of D.
        let q = hemi_quad(800, 800, |m| (d.d(m) * m.z) as f64);
        assert_within(&format!("∫D cos α={alpha}"), q, 0.0, 1.0, 2e-3);
        // Visible normals integrate to 1 for every view: ties Λ (via G1) to D.
        for deg in [0.0f32, 60.0, 85.0] {
            let w = wo_at(deg);
            let q = hemi_quad(800, 800, |m| d.pdf(w, m) as f64);
            assert_within(&format!("∫D_w α={alpha} {deg}°"), q, 0.0, 1.0, 3e-3);
        }
    }
    assert_eq!(roughness_to_alpha(0.25), 0.5);
    assert_eq!(roughness_to_alpha(-1.0), 0.0);
}

// ---------------------------------------------------------------- Fresnel

#[test]
fn fresnel_values() {
    // Normal incidence: ((n − 1)² + k²) / ((n + 1)² + k²).
    for (n, k) in [(0.2f32, 3.9f32), (1.5, 0.0), (1.1, 2.1)] {
        let exact = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        assert!((fr_complex(1.0, n, k) - exact).abs() < 1e-5);
    }
    // k = 0 reduces to the dielectric formula at every angle.
    for i in 0..=20 {
        let c = i as f32 / 20.0;
        assert!((fr_complex(c, 1.5, 0.0) - fr_dielectric(c, 1.5)).abs() < 1e-5);
    }
    assert!((fr_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
    assert_eq!(
        fr_dielectric(0.2, 1.0 / 1.5),
        1.0,
        "beyond the critical angle: TIR"
    );
    // Reflectance-mode k reproduces r0 at normal incidence.
    let r0 = Rgb::new(0.9, 0.5, 0.05);
    let k = k_from_reflectance(r0);
    for c in 0..3 {
        assert!((fr_complex(1.0, 1.0, k[c]) - r0[c]).abs() < 1e-4);
    }
    // Diffuse Fresnel against a fine Simpson rule.
    for eta in [1.1f32, 1.5, 2.4] {
        let m = 20_000;
        let h = 1.0 / m as f64;
        let g = |mu: f64| fr_dielectric(mu as f32, eta) as f64 * 2.0 * mu;
        let mut s = g(0.0) + g(1.0);
        for i in 1..m {
            s += g(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        let exact = s * h / 3.0;
        let got = diffuse_fresnel_external(eta) as f64;
        assert!(
            (got - exact).abs() < 2e-4,
            "F_dr({eta}) = {got}, Simpson {exact}"
        );
    }
    let fi = diffuse_fresnel_internal(1.5);
    assert!((0.5..0.7).contains(&fi), "internal F_dr(1.5) = {fi}");
}

// ---------------------------------------------------------------- dielectric

#[test]
fn dielectric_event_probabilities_and_energy() {
    let glass = Dielectric {
        eta: 1.5,
        alpha: Vec2::ZERO,
        entering: true,
    };
    let b = Bsdf::Dielectric(glass);
    assert!(b.is_delta());
    for deg in [0.0f32, 45.0, 80.0] {
        let wo = wo_at(deg);
        let r = glass.reflectance(wo) as f64;
        let n = 100_000;
        let mut rng = pcg_from_keys(&[12]);
        let (mut nr, mut nt, mut energy) = (0usize, 0usize, 0.0f64);
        for _ in 0..n {
            let s = b
                .sample(wo, next_f32(&mut rng), Vec2::new(0.5, 0.5))
                .unwrap();
            assert!(s.delta && s.pdf == 1.0);
            let w = (s.f.x * s.wi.z.abs() / s.pdf) as f64;
            if s.wi.z > 0.0 {
                nr += 1;
                assert!((w - 1.0).abs() < 1e-5, "reflection weight {w}");
                assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
            } else {
                nt += 1;
                assert!(
                    (w * 2.25 - 1.0).abs() < 1e-5,
                    "refraction weight {w} ≠ 1/η²"
                );
                // Snell: sin θo = η sin θt, same plane, opposite side.
                let (so, st) = (wo.truncate().length(), s.wi.truncate().length());
                assert!((so - 1.5 * st).abs() < 1e-5);
                assert!(wo.truncate().dot(s.wi.truncate()) <= 0.0);
            }
            // Energy: reflection carries R, transmission T (radiance × η² = flux).
            energy += if s.wi.z > 0.0 { w } else { w * 2.25 };
        }
        assert_eq!(
            nr + nt,
            n,
            "reflect + transmit must account for every sample"
        );
        let fr = nr as f64 / n as f64;
        let sigma = (r * (1.0 - r) / n as f64).sqrt();
        assert_within(
            &format!("glass reflect fraction {deg}°"),
            fr,
            sigma,
            r,
            1e-9,
        );
        assert!(
            (energy / n as f64 - 1.0).abs() < 1e-5,
            "energy {}",
            energy / n as f64
        );
    }
    // Normal incidence, η = 1.5: R = 0.04, T = 0.96.
    assert!((glass.reflectance(Vec3::Z) - 0.04).abs() < 1e-6);
    // From inside, beyond the critical angle (41.8°): total internal reflection.
    let inside = Dielectric {
        entering: false,
        ..glass
    };
    assert!((inside.eta_rel() - 1.0 / 1.5).abs() < 1e-7);
    let s = inside.sample(wo_at(50.0), 0.999, Vec2::ZERO).unwrap();
    assert!(s.wi.z > 0.0 && (s.f.x * s.wi.z - 1.0).abs() < 1e-5);
    // Inside, below the critical angle: refraction leaves with η_rel = 1/1.5 (weight η²).
    let s = inside.sample(wo_at(20.0), 0.999, Vec2::ZERO).unwrap();
    assert!(s.wi.z < 0.0 && (s.f.x * s.wi.z.abs() - 2.25).abs() < 1e-4);
}

#[test]
fn rough_dielectric_energy() {
    // Flux bookkeeping: reflection weight + η²·(radiance weight of transmission) estimates the
    // fraction of energy that single scattering keeps; it can only lose energy (shadowing).
    for entering in [true, false] {
        for alpha in [0.1f32, 0.5] {
            let g = Dielectric {
                eta: 1.5,
                alpha: Vec2::splat(alpha),
                entering,
            };
            assert!(!g.is_delta());
            let eta2 = g.eta_rel().powi(2) as f64;
            for deg in [0.0f32, 60.0] {
                let wo = wo_at(deg);
                let n = 100_000;
                let mut rng = pcg_from_keys(&[14]);
                let (mut s, mut s2) = (0.0f64, 0.0f64);
                for _ in 0..n {
                    let uc = next_f32(&mut rng);
                    let u = Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
                    if let Some(bs) = g.sample(wo, uc, u) {
                        let w = (bs.f.x * bs.wi.z.abs() / bs.pdf) as f64;
                        let w = if bs.wi.z < 0.0 { w * eta2 } else { w };
                        s += w;
                        s2 += w * w;
                    }
                }
                let m = s / n as f64;
                let sd = ((s2 / n as f64 - m * m).max(0.0) / n as f64).sqrt();
                eprintln!(
                    "rough glass α={alpha} entering={entering} {deg}°: energy {m:.4} ± {sd:.1e}"
                );
                assert!(m <= 1.0 + 5.0 * sd, "energy {m} > 1");
                if alpha <= 0.1 && deg < 45.0 {
                    assert!(m > 0.97, "energy {m} too low for α = {alpha}");
                }
            }
        }
    }
}

// ---------------------------------------------------------------- constructors and materials

#[test]
fn phong_validation() {
    assert!(Phong::new(Rgb::splat(0.6), Rgb::splat(0.5), 10.0).is_err());
    assert!(Phong::new(Rgb::splat(0.5), Rgb::splat(0.5), -1.0).is_err());
    assert!(Phong::new(Rgb::splat(0.5), Rgb::splat(0.5), f32::NAN).is_err());
    assert!(Phong::new(Rgb::splat(-0.1), Rgb::splat(0.5), 1.0).is_err());
    assert!(Phong::new(Rgb::splat(0.5), Rgb::splat(0.5), 1.0).is_ok());
    let p = Phong::clamped(Rgb::new(0.8, 0.2, f32::NAN), Rgb::splat(0.4), -3.0);
    assert!(((p.kd + p.ks).max_element() - 1.0).abs() < 1e-6);
    assert!(p.kd.is_finite() && p.n == 0.0);
    assert!(
        (p.kd.x / p.ks.x - 2.0).abs() < 1e-6,
        "scaling keeps the kd:ks ratio"
    );
}

#[test]
fn named_metals() {
    for m in ["Cu", "Au", "Ag", "Al"] {
        let (eta, k) = named_metal(&format!("metal-{m}-eta")).unwrap();
        assert_eq!(named_metal(&format!("metal-{m}-k")), Some((eta, k)));
        assert!(eta.min_element() > 0.0 && k.min_element() > 1.0);
        // Metals reflect strongly at normal incidence.
        let r = fr_complex(1.0, eta.x, k.x);
        assert!(r > 0.5, "{m}: R(650 nm) = {r}");
    }
    assert!(named_metal("metal-Unobtainium-eta").is_none());
    // Gold and copper are red-heavy, silver and aluminium nearly neutral.
    let (eta, k) = named_metal("metal-Au-eta").unwrap();
    assert!(fr_complex(1.0, eta.x, k.x) > fr_complex(1.0, eta.z, k.z) + 0.3);
}

fn hit() -> SurfaceHit {
    SurfaceHit {
        t: 1.0,
        p: Vec3::ZERO,
        ng: Vec3::Z,
        ns: Vec3::Z,
        uv: Vec2::splat(0.5),
        p_error: 0.0,
        prim: 0,
        material: 0,
        light: penumbra::geometry::interaction::NO_LIGHT,
    }
}

#[test]
fn materials_map_to_bsdfs() {
    let h = hit();
    let c = |v: f32| Texture::Constant(Rgb::splat(v));
    let m = Material::Phong {
        kd: c(0.7),
        ks: Rgb::splat(0.7),
        n: 10.0,
    };
    match m.bsdf(&h, true) {
        Bsdf::Phong(p) => assert!((p.kd + p.ks).max_element() <= 1.0 + 1e-6),
        b => panic!("phong → {b:?}"),
    }
    let m = Material::Conductor {
        eta: Rgb::ONE,
        k: Rgb::ONE,
        alpha: Vec2::splat(0.2),
        reflectance: Some(c(0.8)),
    };
    match m.bsdf(&h, true) {
        Bsdf::Conductor(b) => assert!((b.fresnel(1.0).x - 0.8).abs() < 1e-4),
        b => panic!("conductor → {b:?}"),
    }
    assert!(!m.is_delta_only());
    let m = Material::Dielectric {
        eta: 1.5,
        alpha: Vec2::ZERO,
    };
    match m.bsdf(&h, false) {
        Bsdf::Dielectric(d) => assert!(!d.entering),
        b => panic!("dielectric → {b:?}"),
    }
    assert!(m.is_delta_only() && Material::Mirror.is_delta_only());
    assert!(Material::Mirror.bsdf(&h, true).is_delta());
    let m = Material::CoatedDiffuse {
        reflectance: c(2.0),
        alpha: Vec2::splat(0.1),
        eta: 1.5,
        layer: None,
    };
    match m.bsdf(&h, true) {
        Bsdf::CoatedDiffuse(b) => assert_eq!(b.reflectance, Rgb::ONE),
        b => panic!("coated → {b:?}"),
    }
    let mut b = Material::Diffuse {
        reflectance: c(0.5),
    }
    .bsdf(&h, true);
    b.set_sampling(LobeSampling::Uniform);
    assert!((b.pdf(Vec3::Z, Vec3::Z) as f64 - 0.5 / PI).abs() < 1e-6);
}
