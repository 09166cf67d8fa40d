//! Chi-square tests: every sampled non-delta BSDF draws directions with exactly the density its
//! `pdf` reports, over several outgoing directions including grazing ones (85°). Samples lost
//! below the horizon (`None`) fall in the harness's "nowhere" category, whose expected mass is
//! 1 − ∫pdf, so dropping them is tested too. Sharp lobes are also tested zoomed in around the
//! mirror direction (gnomonic projection, as in tests/sampling_chi2.rs).
//!
//! The family runs at an overall significance of 1% (Šidák-corrected per test).

use glam::{DVec2, Vec2, Vec3};
use penumbra::Rgb;
use penumbra::bsdf::{Bsdf, Bxdf, CoatedDiffuse, Conductor, LobeSampling, Phong};
use penumbra::sampling::Frame;
use penumbra::sampling::chi2::{Chi2Config, Chi2Result, chi2_directions, chi2_points};

/// Number of chi-square tests in this file (for the Šidák correction); keep in sync.
const NUM_TESTS: usize = 63;

fn cfg() -> Chi2Config {
    Chi2Config {
        samples: 200_000,
        res: (32, 64),
        num_tests: NUM_TESTS,
        ..Default::default()
    }
}

/// Outgoing direction at polar angle `deg` degrees, azimuth 30° (off the grid axes).
fn wo_at(deg: f32) -> Vec3 {
    let (t, p) = (deg.to_radians(), 30f32.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Non-delta directions drawn by `bsdf` for `wo` (delta samples count as "nowhere").
fn sampler(bsdf: &Bsdf, wo: Vec3) -> impl FnMut([f32; 3]) -> Option<Vec3> + '_ {
    move |u| {
        bsdf.sample(wo, u[0], Vec2::new(u[1], u[2]))
            .filter(|s| !s.delta)
            .map(|s| s.wi)
    }
}

#[track_caller]
fn check(name: &str, r: &Chi2Result) {
    eprintln!("{name}: {}", r.summary());
    assert!(r.passed, "{name}: {}", r.summary());
}

/// Sphere-grid test of `bsdf` at `wo`.
fn sphere(name: &str, bsdf: &Bsdf, wo: Vec3) {
    let t = std::time::Instant::now();
    let r = chi2_directions(&cfg(), sampler(bsdf, wo), |wi| bsdf.pdf(wo, wi) as f64);
    eprintln!("{name}: {:.2} s", t.elapsed().as_secs_f64());
    check(&format!("{name} sphere"), &r);
}

/// Zoomed test around `axis` with half-width `w` of the tangent-plane window.
fn zoomed(name: &str, bsdf: &Bsdf, wo: Vec3, axis: Vec3, w: f32) {
    let frame = Frame::from_normal(axis);
    let mut sample = sampler(bsdf, wo);
    let r = chi2_points(
        &Chi2Config {
            res: (40, 40),
            ..cfg()
        },
        [-w, w, -w, w],
        |u| {
            let l = frame.to_local(sample(u)?);
            (l.z > 0.0).then(|| Vec2::new(l.x / l.z, l.y / l.z))
        },
        |q| {
            let q = q.as_dvec2();
            let d = frame.to_world(Vec3::new(q.x as f32, q.y as f32, 1.0).normalize());
            bsdf.pdf(wo, d) as f64 * (1.0 + DVec2::length_squared(q)).powf(-1.5)
        },
    );
    check(&format!("{name} zoomed"), &r);
}

fn mirror_dir(wo: Vec3) -> Vec3 {
    Vec3::new(-wo.x, -wo.y, wo.z)
}

fn phong(kd: f32, ks: f32, n: f32, s: LobeSampling) -> Bsdf {
    let mut p = Phong::new(Rgb::splat(kd), Rgb::new(ks, ks * 0.8, ks * 0.6), n).unwrap();
    p.sampling = s;
    Bsdf::Phong(p)
}

// ---------------------------------------------------------------- Phong

#[test]
fn chi2_phong_n1() {
    let b = phong(0.5, 0.5, 1.0, LobeSampling::Importance);
    for deg in [0.0, 45.0, 85.0] {
        sphere(&format!("phong n=1 {deg}°"), &b, wo_at(deg));
    }
}

#[test]
fn chi2_phong_n20() {
    let b = phong(0.3, 0.6, 20.0, LobeSampling::Importance);
    for deg in [10.0, 60.0, 85.0] {
        sphere(&format!("phong n=20 {deg}°"), &b, wo_at(deg));
    }
}

#[test]
fn chi2_phong_n500() {
    let b = phong(0.1, 0.9, 500.0, LobeSampling::Importance);
    for deg in [30.0, 85.0] {
        let wo = wo_at(deg);
        sphere(&format!("phong n=500 {deg}°"), &b, wo);
        // tan α has a standard deviation of about sqrt(2/n) in the lobe: 4σ window.
        zoomed(
            &format!("phong n=500 {deg}°"),
            &b,
            wo,
            mirror_dir(wo),
            4.0 * (2.0f32 / 500.0).sqrt(),
        );
    }
}

#[test]
fn chi2_phong_pure_glossy_grazing() {
    // No diffuse lobe: at 85° roughly half of the glossy lobe falls below the horizon.
    let b = phong(0.0, 1.0, 20.0, LobeSampling::Importance);
    sphere("phong kd=0 n=20 85°", &b, wo_at(85.0));
}

#[test]
fn chi2_phong_cosine_and_uniform_modes() {
    for s in [LobeSampling::Cosine, LobeSampling::Uniform] {
        let b = phong(0.3, 0.6, 20.0, s);
        sphere(&format!("phong n=20 {s:?} 45°"), &b, wo_at(45.0));
    }
}

// ---------------------------------------------------------------- GGX conductor

fn conductor(alpha: Vec2) -> Bsdf {
    Bsdf::Conductor(Conductor::new(
        Rgb::new(0.2, 0.9, 1.1),
        Rgb::new(3.9, 2.4, 2.1),
        alpha,
    ))
}

#[test]
fn chi2_ggx_conductor_alpha_0_05() {
    let b = conductor(Vec2::splat(0.05));
    for deg in [30.0, 85.0] {
        let wo = wo_at(deg);
        sphere(&format!("ggx α=0.05 {deg}°"), &b, wo);
        zoomed(&format!("ggx α=0.05 {deg}°"), &b, wo, mirror_dir(wo), 0.6);
    }
}

#[test]
fn chi2_ggx_conductor_alpha_0_3() {
    let b = conductor(Vec2::splat(0.3));
    for deg in [0.0, 45.0, 85.0] {
        sphere(&format!("ggx α=0.3 {deg}°"), &b, wo_at(deg));
    }
}

#[test]
fn chi2_ggx_conductor_alpha_1() {
    let b = conductor(Vec2::splat(1.0));
    for deg in [20.0, 85.0] {
        sphere(&format!("ggx α=1 {deg}°"), &b, wo_at(deg));
    }
}

#[test]
fn chi2_ggx_conductor_anisotropic() {
    let b = conductor(Vec2::new(0.08, 0.4));
    for deg in [40.0, 85.0] {
        let wo = wo_at(deg);
        sphere(&format!("ggx α=(0.08,0.4) {deg}°"), &b, wo);
        zoomed(
            &format!("ggx α=(0.08,0.4) {deg}°"),
            &b,
            wo,
            mirror_dir(wo),
            1.5,
        );
    }
}

#[test]
fn chi2_ggx_conductor_cosine_and_uniform_modes() {
    for s in [LobeSampling::Cosine, LobeSampling::Uniform] {
        let mut b = conductor(Vec2::splat(0.3));
        b.set_sampling(s);
        sphere(&format!("ggx α=0.3 {s:?} 45°"), &b, wo_at(45.0));
    }
}

// ---------------------------------------------------------------- coated diffuse

#[test]
fn chi2_coated_diffuse_rough() {
    let b = Bsdf::CoatedDiffuse(CoatedDiffuse::new(
        Rgb::new(0.7, 0.4, 0.2),
        Vec2::splat(0.2),
        1.5,
    ));
    for deg in [0.0, 50.0, 85.0] {
        sphere(&format!("coated α=0.2 {deg}°"), &b, wo_at(deg));
    }
    let wo = wo_at(50.0);
    zoomed("coated α=0.2 50°", &b, wo, mirror_dir(wo), 1.2);
}

#[test]
fn chi2_coated_diffuse_anisotropic_and_smooth() {
    let b = Bsdf::CoatedDiffuse(CoatedDiffuse::new(
        Rgb::splat(0.5),
        Vec2::new(0.05, 0.3),
        1.5,
    ));
    sphere("coated α=(0.05,0.3) 60°", &b, wo_at(60.0));
    // Smooth coat: the delta reflection is "nowhere" for the harness (mass 1 − ∫pdf).
    let b = Bsdf::CoatedDiffuse(CoatedDiffuse::new(Rgb::splat(0.5), Vec2::ZERO, 1.5));
    for deg in [30.0, 85.0] {
        sphere(&format!("coated smooth {deg}°"), &b, wo_at(deg));
    }
}

#[test]
fn chi2_lambert_modes() {
    for s in [LobeSampling::Importance, LobeSampling::Uniform] {
        let mut b = Bsdf::Lambert(penumbra::bsdf::Lambert::new(Rgb::splat(0.5)));
        b.set_sampling(s);
        sphere(&format!("lambert {s:?} 45°"), &b, wo_at(45.0));
    }
}

// ---------------------------------------------------------------- rough dielectric

#[test]
fn chi2_rough_dielectric() {
    use penumbra::bsdf::Dielectric;
    for (alpha, entering, deg) in [
        (Vec2::splat(0.3), true, 30.0),
        (Vec2::splat(0.3), true, 80.0),
        (Vec2::splat(0.3), false, 30.0),
        (Vec2::new(0.1, 0.4), true, 60.0),
    ] {
        let b = Bsdf::Dielectric(Dielectric {
            eta: 1.5,
            alpha,
            entering,
        });
        sphere(
            &format!("rough glass α={alpha} entering={entering} {deg}°"),
            &b,
            wo_at(deg),
        );
    }
}

fn glass(eta: f32, alpha: Vec2, entering: bool) -> Bsdf {
    Bsdf::Dielectric(penumbra::bsdf::Dielectric {
        eta,
        alpha,
        entering,
    })
}

#[test]
fn chi2_rough_dielectric_etas_roughnesses_and_sides() {
    // Both lobes over the whole sphere; from inside both below the critical angle (41.8° for
    // η = 1.5, 24.6° for η = 2.4) and beyond it, where microfacet TIR sends most samples back.
    for (eta, alpha, entering, deg) in [
        (1.5, Vec2::splat(0.1), false, 20.0),
        (1.5, Vec2::splat(0.1), false, 60.0),
        (1.33, Vec2::splat(0.7), true, 70.0),
        (2.4, Vec2::splat(0.3), false, 40.0),
        (1.5, Vec2::new(0.05, 0.3), false, 30.0),
    ] {
        let b = glass(eta, alpha, entering);
        sphere(
            &format!("rough glass η={eta} α={alpha} entering={entering} {deg}°"),
            &b,
            wo_at(deg),
        );
    }
}

#[test]
fn chi2_rough_dielectric_sharp_transmission_zoomed() {
    use penumbra::bsdf::dielectric::refract_z;
    // α = 0.05: the transmitted lobe is a few degrees wide; look at it closely, from outside
    // and from inside (the window's outside is the harness's "nowhere", so the mass there is
    // tested too).
    for (entering, deg) in [(true, 45.0), (false, 25.0)] {
        let b = glass(1.5, Vec2::splat(0.05), entering);
        let wo = wo_at(deg);
        let eta = if entering { 1.5 } else { 1.0 / 1.5 };
        let axis = refract_z(wo, eta).expect("below the critical angle");
        let name = format!("rough glass α=0.05 entering={entering} {deg}° transmission");
        zoomed(&name, &b, wo, axis, 0.4);
    }
}

// ---------------------------------------------------------------- dispersive rough dielectric

/// A dispersive glass with channels far enough apart that the mixture of their lobes is
/// visibly three lobes at low roughness.
fn dispersive(alpha: Vec2, entering: bool) -> penumbra::bsdf::DispersiveDielectric {
    penumbra::bsdf::DispersiveDielectric {
        eta: Rgb::new(1.45, 1.6, 1.8),
        alpha,
        entering,
    }
}

#[test]
fn chi2_dispersive_rough_dielectric_per_channel_and_mixed() {
    // Each channel alone is a rough dielectric of its index; the dispersive BSDF samples a
    // channel uniformly, so its density is the mean of the three (what `pdf` reports).
    let d = dispersive(Vec2::splat(0.3), false);
    for c in 0..3 {
        let b = Bsdf::Dielectric(d.channel(c));
        sphere(
            &format!("dispersive channel {c} entering=false 30°"),
            &b,
            wo_at(30.0),
        );
    }
    for (alpha, entering, deg) in [
        (Vec2::splat(0.3), true, 30.0),
        (Vec2::splat(0.2), false, 20.0),
        (Vec2::splat(0.3), false, 60.0),
        (Vec2::new(0.1, 0.4), true, 70.0),
    ] {
        let b = Bsdf::DispersiveDielectric(dispersive(alpha, entering));
        sphere(
            &format!("dispersive rough glass α={alpha} entering={entering} {deg}°"),
            &b,
            wo_at(deg),
        );
    }
}

#[test]
fn chi2_dispersive_rough_dielectric_separate_lobes_zoomed() {
    use penumbra::bsdf::dielectric::refract_z;
    // α = 0.05: three transmitted lobes a few degrees apart, centred on each channel's
    // refraction; the window around the green one holds parts of all three.
    for (entering, deg) in [(true, 50.0), (false, 20.0)] {
        let d = dispersive(Vec2::splat(0.05), entering);
        let eta = d.channel(1).eta_rel();
        let axis = refract_z(wo_at(deg), eta).expect("below the critical angle");
        let name = format!("dispersive rough glass α=0.05 entering={entering} {deg}°");
        zoomed(&name, &Bsdf::DispersiveDielectric(d), wo_at(deg), axis, 0.4);
    }
}

// ---------------------------------------------------------------- diffuse transmission

#[test]
fn chi2_diffuse_transmission() {
    use penumbra::bsdf::DiffuseTransmission;
    // The density does not depend on wo (beyond its side), so one angle per case suffices.
    let dt = |r: f32, t: f32, s: LobeSampling| {
        let mut b = DiffuseTransmission::new(Rgb::new(r, r * 0.5, r), Rgb::new(t, t, t * 0.2));
        b.sampling = s;
        Bsdf::DiffuseTransmission(b)
    };
    for (r, t, s, deg) in [
        (0.3, 0.6, LobeSampling::Importance, 30.0),
        (0.0, 0.5, LobeSampling::Importance, 45.0),
        (0.5, 0.0, LobeSampling::Importance, 45.0),
        (0.7, 0.2, LobeSampling::Uniform, 60.0),
    ] {
        sphere(
            &format!("diffuse transmission R={r} T={t} {s:?} {deg}°"),
            &dt(r, t, s),
            wo_at(deg),
        );
    }
}

// ---------------------------------------------------------------- negative controls

#[test]
fn chi2_negative_control_ggx_alpha_mismatch() {
    // A 10% error in roughness must be caught at this sample count.
    let (b, wrong) = (conductor(Vec2::splat(0.3)), conductor(Vec2::splat(0.33)));
    let wo = wo_at(45.0);
    let r = chi2_directions(&cfg(), sampler(&b, wo), |wi| wrong.pdf(wo, wi) as f64);
    eprintln!("negative control ggx α 0.3 vs 0.33: {}", r.summary());
    assert!(!r.passed, "harness has no power: {}", r.summary());
}

#[test]
fn chi2_negative_control_phong_keeps_lost_samples() {
    // Returning the glossy lobe's below-horizon samples instead of dropping them must be caught:
    // the pdf puts that mass in the "nowhere" category.
    let b = phong(0.0, 1.0, 20.0, LobeSampling::Importance);
    let wo = wo_at(85.0);
    let frame = Frame::from_normal(mirror_dir(wo));
    let r = chi2_directions(
        &cfg(),
        |u| {
            let l = penumbra::sampling::cosine_power_hemisphere(Vec2::new(u[1], u[2]), 20.0);
            Some(frame.to_world(l))
        },
        |wi| b.pdf(wo, wi) as f64,
    );
    eprintln!("negative control phong keeps lost samples: {}", r.summary());
    assert!(!r.passed, "harness has no power: {}", r.summary());
}
