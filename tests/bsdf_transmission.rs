//! Properties of the transmitting BSDFs (rough dielectric, diffuse transmission), by
//! deterministic quadrature over the whole sphere (independent of the samplers) against Monte
//! Carlo with 5σ bounds: the pdf integrates to the fraction of samples kept, `sample` returns
//! exactly `f` and `pdf` at its direction, energy (flux) is conserved up to the rough
//! dielectric's single-scattering loss computed in microfacet-normal space (diffuse
//! transmission: ∫ f |cos| = R + T), and reciprocity for transmission.
//!
//! Reciprocity form tested (Veach 1997, §5.2; pbrt-v4's radiance-mode BTDF): with η_o the index
//! on wo's side and η_i the index on wi's side, f(wo, wi) / η_o² = f(wi, wo) / η_i². Seen from
//! the inside, the integrator flips the frame toward the viewer; here that is the rotation by
//! π about x, (x, y, z) ↦ (x, −y, −z), and `entering = false`.

use glam::{DVec2, Vec2, Vec3};
use penumbra::Rgb;
use penumbra::bsdf::fresnel::fr_dielectric;
use penumbra::bsdf::{
    Bxdf, Dielectric, DiffuseTransmission, LobeSampling, TrowbridgeReitz, reflect,
};
use penumbra::sampling::hash::{next_f32, pcg_from_keys};
use std::f64::consts::PI;

/// Outgoing direction at polar angle `deg` degrees, azimuth 30°.
fn wo_at(deg: f32) -> Vec3 {
    let (t, p) = (deg.to_radians(), 30f32.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Midpoint quadrature of `g` over the whole sphere in (cos θ, φ), `n` × 2n cells per
/// hemisphere.
fn sphere_quad(n: usize, g: impl Fn(Vec3) -> f64) -> f64 {
    let mut s = 0.0;
    for i in 0..2 * n {
        let z = -1.0 + (i as f64 + 0.5) / n as f64;
        let r = (1.0 - z * z).max(0.0).sqrt();
        for j in 0..2 * n {
            let phi = (j as f64 + 0.5) / (2 * n) as f64 * 2.0 * PI;
            s += g(Vec3::new(
                (r * phi.cos()) as f32,
                (r * phi.sin()) as f32,
                z as f32,
            ));
        }
    }
    s * (1.0 / n as f64) * (2.0 * PI / (2 * n) as f64)
}

/// The sphere quadrature with cells refined toward `axis` (a lobe narrower than the grid):
/// (cos, φ) cells in a frame around `axis`, `n` × 2n, with 1 − cos θ growing as t⁴.
fn lobe_quad(axis: Vec3, n: usize, g: impl Fn(Vec3) -> f64) -> f64 {
    let f = penumbra::sampling::Frame::from_normal(axis);
    let mut s = 0.0;
    // 1 − cos θ = 2t⁴ for t ∈ [0, 1]: dz = 8t³ dt, dense near the axis (a transmitted lobe
    // of α = 0.1 is ~α/3 wide; t² spacing still missed 1e-3 of its mass at n = 600).
    for i in 0..n {
        let t = (i as f64 + 0.5) / n as f64;
        let z = 1.0 - 2.0 * t.powi(4);
        let dz = 8.0 * t.powi(3) / n as f64;
        let r = (1.0 - z * z).max(0.0).sqrt();
        for j in 0..2 * n {
            let phi = (j as f64 + 0.5) / (2 * n) as f64 * 2.0 * PI;
            let w = f.to_world(Vec3::new(
                (r * phi.cos()) as f32,
                (r * phi.sin()) as f32,
                z as f32,
            ));
            s += g(w) * dz * (2.0 * PI / (2 * n) as f64);
        }
    }
    s
}

fn glass(eta: f32, alpha: f32, entering: bool) -> Dielectric {
    Dielectric {
        eta,
        alpha: Vec2::splat(alpha),
        entering,
    }
}

/// The cases every property is checked on: (η, α, entering, θo in degrees).
const CASES: [(f32, f32, bool, f32); 8] = [
    (1.5, 0.1, true, 0.0),
    (1.5, 0.1, true, 60.0),
    (1.5, 0.3, false, 20.0),
    (1.5, 0.3, false, 60.0),
    (1.33, 0.5, true, 45.0),
    (2.4, 0.2, true, 30.0),
    (2.4, 0.2, false, 15.0),
    (1.5, 0.7, false, 35.0),
];

/// Quadrature of `g` accurate for the glass lobes: the reflection lobe and the transmission
/// lobe (where it exists) each get a refined grid around their axis, the rest a plain one.
fn glass_quad(g: &Dielectric, wo: Vec3, h: impl Fn(Vec3) -> f64) -> f64 {
    let r_axis = Vec3::new(-wo.x, -wo.y, wo.z);
    let t_axis = penumbra::bsdf::dielectric::refract_z(wo, g.eta_rel());
    // Split the sphere between the two lobe grids by the side of the surface.
    let up = lobe_quad(r_axis, 500, |w| if w.z > 0.0 { h(w) } else { 0.0 });
    let down = match t_axis {
        Some(t) => lobe_quad(t, 500, |w| if w.z < 0.0 { h(w) } else { 0.0 }),
        None => sphere_quad(400, |w| if w.z < 0.0 { h(w) } else { 0.0 }),
    };
    up + down
}

#[test]
fn rough_dielectric_pdf_integrates_to_the_kept_fraction() {
    for (k, (eta, alpha, entering, deg)) in CASES.into_iter().enumerate() {
        let g = glass(eta, alpha, entering);
        let wo = wo_at(deg);
        let integral = glass_quad(&g, wo, |wi| g.pdf(wo, wi) as f64);
        let n = 200_000;
        let mut rng = pcg_from_keys(&[31, k as u64]);
        let kept = (0..n)
            .filter(|_| {
                let uc = next_f32(&mut rng);
                let u = Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
                g.sample(wo, uc, u).is_some()
            })
            .count() as f64
            / n as f64;
        let sigma = (kept * (1.0 - kept) / n as f64).sqrt();
        eprintln!(
            "η={eta} α={alpha} entering={entering} {deg}°: ∫pdf = {integral:.5}, kept {kept:.5} ± {sigma:.1e}"
        );
        assert!(integral <= 1.0 + 1e-4, "∫pdf = {integral} > 1");
        assert!(
            (integral - kept).abs() <= 5.0 * sigma + 1e-4,
            "∫pdf = {integral} but {kept} of the samples are kept"
        );
        if alpha <= 0.1 && deg == 0.0 {
            assert!(integral > 0.995, "∫pdf = {integral} at normal incidence");
        }
    }
}

#[test]
fn rough_dielectric_sample_returns_f_and_pdf_of_its_direction() {
    for (k, (eta, alpha, entering, deg)) in CASES.into_iter().enumerate() {
        let g = glass(eta, alpha, entering);
        let wo = wo_at(deg);
        let mut rng = pcg_from_keys(&[32, k as u64]);
        let (mut nr, mut nt) = (0, 0);
        for _ in 0..20_000 {
            let uc = next_f32(&mut rng);
            let u = Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
            let Some(s) = g.sample(wo, uc, u) else {
                continue;
            };
            assert!(!s.delta);
            let (f, pdf) = (g.f(wo, s.wi).x, g.pdf(wo, s.wi));
            let close = |a: f32, b: f32| (a - b).abs() <= 1e-3 * a.abs().max(b.abs()) + 1e-6;
            assert!(close(s.f.x, f), "sample f {} vs f {f}", s.f.x);
            assert!(close(s.pdf, pdf), "sample pdf {} vs pdf {pdf}", s.pdf);
            if s.wi.z > 0.0 { nr += 1 } else { nt += 1 }
        }
        assert!(nr > 0, "no reflection sampled");
        if g.eta_rel() > 1.0 || deg < 30.0 {
            assert!(nt > 0, "no transmission sampled");
        }
    }
}

/// Single-scattering energy kept by the microfacet model, integrated over microfacet normals
/// instead of incident directions (no Jacobian involved): a normal wm visible from wo
/// (density D_wo) reflects the fraction F and refracts 1 − F, and the scattered light escapes
/// the surface with probability G2(wo, wi) / G1(wo) if it leaves on the right side.
fn energy_by_normals(g: &Dielectric, wo: Vec3) -> f64 {
    let d = TrowbridgeReitz::new(g.alpha);
    let eta = g.eta_rel();
    let g1 = d.g1(wo) as f64;
    let z_axis = Vec3::Z;
    lobe_quad(z_axis, 1000, |wm| {
        if wm.z <= 0.0 {
            return 0.0;
        }
        let dwo = d.pdf(wo, wm) as f64;
        if dwo == 0.0 {
            return 0.0;
        }
        let c = wo.dot(wm);
        let f = fr_dielectric(c, eta) as f64;
        let wr = reflect(wo, wm);
        let mut e = 0.0;
        if wr.z > 0.0 {
            e += f * d.g(wo, wr) as f64 / g1;
        }
        if f < 1.0 {
            // Refraction about wm (Snell), leaving below the macro surface.
            let s2 = (1.0 - c * c).max(0.0) / (eta * eta);
            let wt = (-wo / eta + wm * (c / eta - (1.0 - s2).sqrt())).normalize();
            if wt.z < 0.0 {
                e += (1.0 - f) * d.g(wo, wt) as f64 / g1;
            }
        }
        dwo * e
    })
}

#[test]
fn rough_dielectric_energy_is_conserved_up_to_single_scattering_loss() {
    // Flux: the radiance-mode BTDF carries 1/η_rel², so transmission counts η_rel² · f_t.
    for (eta, alpha, entering, deg) in CASES {
        let g = glass(eta, alpha, entering);
        let wo = wo_at(deg);
        let e2 = (g.eta_rel() as f64).powi(2);
        let by_directions = glass_quad(&g, wo, |wi| {
            let f = g.f(wo, wi).x as f64 * wi.z.abs() as f64;
            if wi.z < 0.0 { f * e2 } else { f }
        });
        let by_normals = energy_by_normals(&g, wo);
        eprintln!(
            "η={eta} α={alpha} entering={entering} {deg}°: ∫(f_r + η²f_t)|cos| = {by_directions:.5}, by normals {by_normals:.5}"
        );
        assert!(by_directions <= 1.0 + 1e-4, "energy {by_directions} > 1");
        assert!(
            (by_directions - by_normals).abs() <= 2e-4,
            "energy over directions {by_directions} ≠ over normals {by_normals}: the \
             transmission Jacobian or the η² factor is off"
        );
        if alpha <= 0.1 && deg == 0.0 {
            assert!(
                by_directions > 0.99,
                "energy {by_directions} at α = {alpha}"
            );
        }
    }
}

#[test]
fn rough_dielectric_transmission_is_reciprocal_with_the_index_ratio() {
    let flip = |w: Vec3| Vec3::new(w.x, -w.y, -w.z);
    for (eta, alpha) in [(1.5f32, 0.1f32), (1.5, 0.4), (2.4, 0.25), (1.33, 0.7)] {
        let outside = glass(eta, alpha, true);
        let inside = glass(eta, alpha, false);
        let mut rng = pcg_from_keys(&[33, eta.to_bits() as u64, alpha.to_bits() as u64]);
        let mut checked = 0;
        for _ in 0..20_000 {
            let u = DVec2::new(next_f32(&mut rng) as f64, next_f32(&mut rng) as f64);
            let v = DVec2::new(next_f32(&mut rng) as f64, next_f32(&mut rng) as f64);
            let dir = |u: DVec2, sign: f64| {
                let z = u.x;
                let r = (1.0 - z * z).sqrt();
                let p = 2.0 * PI * u.y;
                Vec3::new(
                    (r * p.cos()) as f32,
                    (r * p.sin()) as f32,
                    (sign * z) as f32,
                )
            };
            // wo outside (up), wi inside (down), in the outside frame.
            let (wo, wi) = (dir(u, 1.0), dir(v, -1.0));
            // A pair that meets its microfacet at grazing on the outside is just below the
            // critical angle inside, where Fresnel's cos θt = √(1 − sin²θt) cancels: one f32
            // ulp of wm moves T by ~1%. Such pairs are left out (their f is ~1e-3 of the peak).
            let wm = (wi.as_dvec3() * eta as f64 + wo.as_dvec3()).normalize();
            if wo.as_dvec3().dot(wm).abs() < 0.03 {
                continue;
            }
            let f_out = outside.f(wo, wi).x as f64;
            // The same pair with the roles swapped, in the inside viewer's frame.
            let f_in = inside.f(flip(wi), flip(wo)).x as f64;
            // f(wo, wi) / η_o² = f(wi, wo) / η_i² with η_o = 1 (outside), η_i = η.
            let lhs = f_out;
            let rhs = f_in / (eta as f64).powi(2);
            assert!(
                (lhs - rhs).abs() <= 2e-3 * lhs.max(rhs) + 1e-7,
                "η={eta} α={alpha}: f(wo, wi) = {f_out}, f(wi, wo)/η² = {rhs} at wo={wo} wi={wi}"
            );
            // Reflection is symmetric on both sides.
            let (a, b) = (dir(u, 1.0), dir(v, 1.0));
            for g in [&outside, &inside] {
                let (x, y) = (g.f(a, b).x as f64, g.f(b, a).x as f64);
                assert!(
                    (x - y).abs() <= 2e-3 * x.max(y) + 1e-7,
                    "f_r({a}, {b}) {x} ≠ {y}"
                );
            }
            checked += (f_out > 1e-3) as usize;
        }
        assert!(checked > 1000, "only {checked} pairs transmit anything");
    }
}

// ---------------------------------------------------------------- diffuse transmission

#[test]
fn diffuse_transmission_energy_pdf_and_reciprocity() {
    let flip = |w: Vec3| Vec3::new(w.x, -w.y, -w.z);
    for (k, (r, t, mode)) in [
        (
            Rgb::new(0.3, 0.2, 0.1),
            Rgb::new(0.6, 0.5, 0.05),
            LobeSampling::Importance,
        ),
        (Rgb::ZERO, Rgb::splat(0.8), LobeSampling::Importance),
        (Rgb::new(0.9, 0.5, 0.3), Rgb::ZERO, LobeSampling::Uniform),
        (Rgb::splat(0.4), Rgb::splat(0.4), LobeSampling::Uniform),
    ]
    .into_iter()
    .enumerate()
    {
        let mut b = DiffuseTransmission::new(r, t);
        b.sampling = mode;
        assert!(b.transmits());
        for deg in [0.0f32, 50.0, 85.0] {
            let wo = wo_at(deg);
            let what = format!("R={r} T={t} {mode:?} {deg}°");
            // Quadrature, channel by channel: ∫ f |cos| = R + T and ∫ pdf = 1.
            for c in 0..3 {
                let e = sphere_quad(300, |wi| (b.f(wo, wi)[c] * wi.z.abs()) as f64);
                let want = (r[c] + t[c]) as f64;
                assert!(
                    (e - want).abs() < 1e-4,
                    "{what}: ∫f|cos| = {e}, R + T = {want}"
                );
            }
            let p = sphere_quad(300, |wi| b.pdf(wo, wi) as f64);
            assert!((p - 1.0).abs() < 1e-4, "{what}: ∫pdf = {p}");
            // Monte Carlo with the sampler: weights average to R + T; f and pdf as evaluated.
            let n = 50_000;
            let mut rng = pcg_from_keys(&[34, k as u64, deg as u64]);
            let (mut s, mut s2) = (Vec3::ZERO.as_dvec3(), Vec3::ZERO.as_dvec3());
            for _ in 0..n {
                let uc = next_f32(&mut rng);
                let u = Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
                let bs = b.sample(wo, uc, u).expect("R + T > 0 always samples");
                assert!(!bs.delta && bs.wi.z != 0.0);
                assert_eq!(bs.f, b.f(wo, bs.wi), "{what}");
                assert!((bs.pdf - b.pdf(wo, bs.wi)).abs() <= 1e-6 * bs.pdf, "{what}");
                let w = (bs.f * bs.wi.z.abs() / bs.pdf).as_dvec3();
                s += w;
                s2 += w * w;
            }
            for c in 0..3 {
                let m = s[c] / n as f64;
                let sd = ((s2[c] / n as f64 - m * m).max(0.0) / n as f64).sqrt();
                let want = (r[c] + t[c]) as f64;
                assert!(
                    (m - want).abs() <= 5.0 * sd + 1e-6,
                    "{what}: MC albedo {m} ± {sd} vs R + T = {want}"
                );
            }
        }
        // Reciprocity without an index: f(wo, wi) = f(wi, wo), through the sheet seen from
        // the other side (the flipped frame) and on one side.
        let mut rng = pcg_from_keys(&[35, k as u64]);
        for _ in 0..1000 {
            let a = wo_at(next_f32(&mut rng) * 89.0);
            let bb = flip(wo_at(next_f32(&mut rng) * 89.0));
            assert_eq!(b.f(a, bb), b.f(flip(bb), flip(a)));
            let c = wo_at(next_f32(&mut rng) * 89.0);
            assert_eq!(b.f(a, c), b.f(c, a));
        }
    }
    // Both lobes black: nothing to sample, zero density.
    let black = DiffuseTransmission::new(Rgb::ZERO, Rgb::ZERO);
    assert!(black.sample(Vec3::Z, 0.5, Vec2::splat(0.5)).is_none());
    assert_eq!(black.pdf(Vec3::Z, -Vec3::Z), 0.0);
    // Out-of-range and non-finite inputs are clamped as pbrt does.
    let c = DiffuseTransmission::new(Rgb::new(2.0, -1.0, f32::NAN), Rgb::splat(f32::INFINITY));
    assert_eq!((c.r, c.t), (Rgb::new(1.0, 0.0, 0.0), Rgb::ONE));
}

#[test]
fn diffuse_transmission_material_scales_then_clamps() {
    use penumbra::bsdf::Bsdf;
    use penumbra::material::{Material, Texture};
    let hit = penumbra::geometry::SurfaceHit {
        t: 1.0,
        p: Vec3::ZERO,
        ng: Vec3::Z,
        ns: Vec3::Z,
        uv: Vec2::splat(0.5),
        p_error: 0.0,
        prim: 0,
        material: 0,
        light: penumbra::geometry::interaction::NO_LIGHT,
    };
    let m = Material::DiffuseTransmission {
        reflectance: Texture::Constant(Rgb::new(0.2, 0.4, 0.9)),
        transmittance: Texture::Constant(Rgb::splat(0.5)),
        scale: 1.5,
    };
    assert!(!m.is_delta_only());
    for front in [true, false] {
        match m.bsdf(&hit, front) {
            Bsdf::DiffuseTransmission(b) => {
                assert!((b.r - Rgb::new(0.3, 0.6, 1.0)).abs().max_element() < 1e-6);
                assert!((b.t - Rgb::splat(0.75)).abs().max_element() < 1e-6);
            }
            b => panic!("diffusetransmission → {b:?}"),
        }
    }
}
