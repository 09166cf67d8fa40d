//! pbrt-v4's equal-area octahedral environment maps (`LightSource "infinite" "string
//! filename"` with a square image): directions ↔ texels round trip, the sampler follows its
//! pdf (chi-square on the sphere, binned in (cos θ, φ) independently of the map's chart) and
//! the pdf integrates to 1, a single bright texel lights a plane from exactly its own solid
//! angle (rendered through the pbrt loader), and `illuminance` sets the irradiance of an
//! upward-facing patch.

mod lights_support;

use glam::{Mat4, UVec2, Vec2, Vec3};
use lights_support::{check, check_estimate, irradiance, v2};
use penumbra::Rgb;
use penumbra::geometry::Transform;
use penumbra::integrator::{RenderOptions, render};
use penumbra::lights::{
    Emitter, EnvMapLight, Light, LightSampleContext, LightSource, SamplingMode,
};
use penumbra::material::texture::ImageRgb;
use penumbra::sampling::chi2::{Chi2Config, chi2_directions};
use penumbra::sampling::equal_area_square_to_sphere;
use penumbra::sampling::hash::{next_f32, pcg_from_keys};
use penumbra::scene::pbrt::parse_pbrt_str;
use std::f64::consts::PI;
use std::sync::Arc;

const SA: SamplingMode = SamplingMode::SolidAngle;

fn ctx() -> LightSampleContext {
    LightSampleContext {
        p: Vec3::ZERO,
        n: Vec3::ZERO,
    }
}

/// A 24×24 map with smooth variation, a hot spot and a black band (texels the sampler must
/// never pick).
fn test_image() -> ImageRgb {
    let n = 24;
    let mut pixels = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let (u, v) = (x as f32 / n as f32, y as f32 / n as f32);
            let mut c = Rgb::new(0.2 + u, 0.5 + 0.4 * (6.0 * v).sin(), 0.3 + u * v);
            if (5..8).contains(&x) && (14..16).contains(&y) {
                c *= 40.0;
            }
            if y == 3 {
                c = Rgb::ZERO;
            }
            pixels.push(c);
        }
    }
    ImageRgb {
        width: n,
        height: n,
        pixels,
    }
}

fn rotation() -> Mat4 {
    Mat4::from_rotation_z(0.7) * Mat4::from_rotation_x(-1.1)
}

fn light(img: ImageRgb) -> EnvMapLight {
    EnvMapLight::equal_area(Arc::new(img), Rgb::ONE, Transform::new(rotation()).unwrap()).unwrap()
}

#[test]
fn directions_round_trip_through_texels() {
    let l = light(test_image());
    let n = 24.0;
    let mut rng = pcg_from_keys(&[1]);
    for _ in 0..100_000 {
        let w =
            penumbra::sampling::uniform_sphere(Vec2::new(next_f32(&mut rng), next_f32(&mut rng)));
        let (uv, jac) = l.direction_to_uv(w);
        assert_eq!(jac, 1.0);
        let (back, _) = l.uv_to_direction(uv);
        assert!((back - w).length() < 3e-5, "{w} -> {uv} -> {back}");
        // The texel holding uv holds w: its radiance is the texel's (nearest lookup).
        let (x, y) = (((uv.x * n) as usize).min(23), ((uv.y * n) as usize).min(23));
        let texel = test_image().pixels[y * 24 + x];
        assert_eq!(l.radiance(Vec3::ZERO, Vec3::ZERO, Vec2::ZERO, w), texel);
    }
}

#[test]
fn chi2_equal_area_sampler_and_its_pdf_integrates_to_one() {
    let l = Light::EnvMap(Box::new(light(test_image())));
    let bad = std::cell::Cell::new(0usize);
    let r = chi2_directions(
        &Chi2Config {
            samples: 500_000,
            res: (32, 64),
            ..Default::default()
        },
        |u| {
            let s = l.sample_li(&ctx(), v2(u), SA)?;
            let q = l.pdf_li(&ctx(), s.wi, s.p_light, Vec3::ZERO, SA);
            if (q - s.pdf).abs() > 1e-3 * s.pdf {
                bad.set(bad.get() + 1);
            }
            // Never a black texel.
            assert!(s.li.max_element() > 0.0, "sampled a black texel");
            Some(s.wi)
        },
        |w| l.pdf_li(&ctx(), w, Vec3::ZERO, Vec3::ZERO, SA) as f64,
    );
    check("equal-area envmap", &r);
    // Texel-edge rounding only.
    assert!(
        bad.get() < 1000,
        "{} samples whose pdf differs from pdf_li",
        bad.get()
    );
    // ∫ pdf dω = 1: Monte Carlo over uniform directions, 5σ.
    let mut rng = pcg_from_keys(&[2]);
    let n = 2_000_000;
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let w =
            penumbra::sampling::uniform_sphere(Vec2::new(next_f32(&mut rng), next_f32(&mut rng)));
        let v = l.pdf_li(&ctx(), w, Vec3::ZERO, Vec3::ZERO, SA) as f64 * 4.0 * PI;
        s += v;
        s2 += v * v;
    }
    let mean = s / n as f64;
    let se = ((s2 / n as f64 - mean * mean) / n as f64).sqrt();
    check_estimate("∫ pdf dω", (mean, se), 1.0);
}

#[test]
fn chi2_rejects_the_old_lat_long_reading_of_a_square_map() {
    // Negative control: the same square image read as lat-long samples directions that the
    // equal-area pdf does not predict.
    let ea = Light::EnvMap(Box::new(light(test_image())));
    let ll = Light::EnvMap(Box::new(
        EnvMapLight::new(
            Arc::new(test_image()),
            Rgb::ONE,
            Transform::new(rotation()).unwrap(),
        )
        .unwrap(),
    ));
    // Binned in the equal-area square, where the equal-area pdf is 4π·pdf_ω and constant
    // per texel (cells aligned with texels keep the quadrature exact; few cells keep the
    // re-integration of the many implausible ones cheap).
    let r = penumbra::sampling::chi2::chi2_points(
        &Chi2Config {
            samples: 50_000,
            res: (8, 8),
            ..Default::default()
        },
        [0.0, 1.0, 0.0, 1.0],
        |u| {
            let w = ll.sample_li(&ctx(), v2(u), SA)?.wi;
            Some(penumbra::sampling::equal_area_sphere_to_square(
                rotation().inverse().transform_vector3(w),
            ))
        },
        |uv| {
            let w = rotation().transform_vector3(equal_area_square_to_sphere(uv));
            4.0 * PI * ea.pdf_li(&ctx(), w, Vec3::ZERO, Vec3::ZERO, SA) as f64
        },
    );
    assert!(!r.passed, "{}", r.summary());
}

/// The solid angle of texel (x, y) of an n×n map and ∫ cos(n, ω) dω over it, by a 64×64
/// midpoint rule in the square (each sub-cell covers 4π/(64n)² sr): independent of the light.
fn texel_integrals(x: u32, y: u32, n: u32, normal: Vec3) -> (f64, f64) {
    let k = 64;
    let d_omega = 4.0 * PI / ((k * n) as f64).powi(2);
    let (mut omega, mut cos) = (0.0, 0.0);
    for i in 0..k {
        for j in 0..k {
            let uv = Vec2::new(
                (x as f32 + (i as f32 + 0.5) / k as f32) / n as f32,
                (y as f32 + (j as f32 + 0.5) / k as f32) / n as f32,
            );
            let w = equal_area_square_to_sphere(uv);
            omega += d_omega;
            cos += d_omega * normal.dot(w).max(0.0) as f64;
        }
    }
    (omega, cos)
}

#[test]
fn one_bright_texel_lights_from_exactly_its_direction() {
    let (n, tx, ty) = (16u32, 11u32, 4u32);
    let mut img = ImageRgb {
        width: n,
        height: n,
        pixels: vec![Rgb::ZERO; (n * n) as usize],
    };
    img.pixels[(ty * n + tx) as usize] = Rgb::splat(100.0);
    let centre = equal_area_square_to_sphere(Vec2::new(
        (tx as f32 + 0.5) / n as f32,
        (ty as f32 + 0.5) / n as f32,
    ));
    // Identity light transform: light space is world space.
    let l = Light::EnvMap(Box::new(
        EnvMapLight::equal_area(Arc::new(img.clone()), Rgb::ONE, Transform::IDENTITY).unwrap(),
    ));
    let (omega, _) = texel_integrals(tx, ty, n, Vec3::Z);
    assert!((omega - 4.0 * PI / (n * n) as f64).abs() < 1e-9);
    // Every sample comes from inside the texel, with pdf 1/Ω.
    let mut rng = pcg_from_keys(&[3]);
    for _ in 0..10_000 {
        let s = l
            .sample_li(
                &ctx(),
                Vec2::new(next_f32(&mut rng), next_f32(&mut rng)),
                SA,
            )
            .unwrap();
        let uv = penumbra::sampling::equal_area_sphere_to_square(s.wi);
        assert_eq!(
            ((uv.x * n as f32) as u32, (uv.y * n as f32) as u32),
            (tx, ty)
        );
        assert!(((s.pdf as f64) * omega - 1.0).abs() < 1e-4);
        assert!(s.wi.dot(centre) > 0.95);
    }
    // Irradiance on planes facing the texel, tilted from it and facing away: 100·∫cos dω.
    for normal in [centre, (centre + Vec3::new(0.6, 0.0, 0.4)).normalize()] {
        let (_, cos) = texel_integrals(tx, ty, n, normal);
        let e = irradiance(&l, Vec3::ZERO, normal, SA, 20_000, 4);
        check_estimate("one-texel irradiance", e, 100.0 * cos);
    }
    assert_eq!(irradiance(&l, Vec3::ZERO, -centre, SA, 1000, 4).0, 0.0);

    // Through the pbrt loader and the renderer: a white diffuse square facing the texel's
    // direction, seen head-on, has radiance ρ/π·E.
    let d = std::env::temp_dir().join(format!("penumbra-envmap-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let mut out = penumbra::image::Image::new(n, n);
    out.pixels.clone_from(&img.pixels);
    penumbra::image::io::write_image(&out, &d.join("texel.exr"), 0.0).unwrap();
    let frame = penumbra::sampling::Frame::from_normal(centre);
    let (a, b) = (frame.s, frame.t);
    let corner = |s: f32, t: f32| a * s + b * t;
    let p: Vec<String> = [
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
    ]
    .iter()
    .map(|v| format!("{} {} {}", v.x, v.y, v.z))
    .collect();
    let eye = centre * 5.0;
    let src = format!(
        "LookAt {} {} {}  0 0 0  {} {} {}\nCamera \"perspective\" \"float fov\" 5\n\
         Film \"rgb\" \"integer xresolution\" 4 \"integer yresolution\" 4\nWorldBegin\n\
         LightSource \"infinite\" \"string filename\" \"texel.exr\"\n\
         Material \"diffuse\" \"rgb reflectance\" [1 1 1]\n\
         Shape \"trianglemesh\" \"point3 P\" [{}] \"integer indices\" [0 1 2 0 2 3]\n",
        eye.x,
        eye.y,
        eye.z,
        b.x,
        b.y,
        b.z,
        p.join("  ")
    );
    let parsed = parse_pbrt_str("texel.pbrt", &src, &d).unwrap();
    assert!(parsed.warnings.is_empty(), "{:?}", parsed.warnings);
    let (builder, cam, film, _) = parsed.into_builder().unwrap();
    let scene = builder.build(cam, film).unwrap();
    let opts = RenderOptions {
        spp: 64,
        strategy: penumbra::integrator::Strategy::LightSolidAngle,
        ..Default::default()
    };
    let (img, _) = render(&scene, UVec2::new(4, 4), &opts).unwrap();
    let (_, cos) = texel_integrals(tx, ty, n, centre);
    let want = 100.0 * cos / PI;
    for px in &img.pixels {
        // Light sampling of a single texel: Li/pdf is constant, only cos varies.
        assert!(
            ((px.x as f64) - want).abs() < 2e-3 * want,
            "{} vs {want}",
            px.x
        );
    }
}

#[test]
fn illuminance_sets_the_irradiance_of_an_upward_patch() {
    // pbrt scenes turn light-space +z to world +y with `Rotate -90 1 0 0`; 'illuminance' 3
    // makes the irradiance of a world +y patch 3 (cosine-weighted Monte Carlo over the
    // light's own radiance lookups, 5σ).
    let d = std::env::temp_dir().join(format!("penumbra-envmap-e-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let img = test_image();
    let mut out = penumbra::image::Image::new(img.width, img.height);
    out.pixels.clone_from(&img.pixels);
    penumbra::image::io::write_image(&out, &d.join("sky.exr"), 0.0).unwrap();
    let src = "WorldBegin\nAttributeBegin\nRotate -90 1 0 0\n\
               LightSource \"infinite\" \"string filename\" \"sky.exr\" \"float illuminance\" 3\n\
               AttributeEnd\n";
    let parsed = parse_pbrt_str("e.pbrt", src, &d).unwrap();
    assert!(parsed.warnings.is_empty(), "{:?}", parsed.warnings);
    let (b, _, _, _) = parsed.into_builder().unwrap();
    let l = &b.lights[0];
    let n = Vec3::Y;
    let frame = penumbra::sampling::Frame::from_normal(n);
    let mut rng = pcg_from_keys(&[5]);
    let count = 400_000;
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for _ in 0..count {
        let local = penumbra::sampling::cosine_hemisphere(Vec2::new(
            next_f32(&mut rng),
            next_f32(&mut rng),
        ));
        let w = frame.to_world(local);
        // E = ∫ L cos dω = π · E_cos[L].
        let v = PI * penumbra::luminance(l.radiance(Vec3::ZERO, Vec3::ZERO, Vec2::ZERO, w)) as f64;
        s += v;
        s2 += v * v;
    }
    let mean = s / count as f64;
    let se = ((s2 / count as f64 - mean * mean) / count as f64).sqrt();
    check_estimate("illuminance", (mean, se), 3.0);
    // Not square: lat-long, said once.
    let mut wide = penumbra::image::Image::new(8, 4);
    wide.pixels.fill(Rgb::ONE);
    penumbra::image::io::write_image(&wide, &d.join("wide.exr"), 0.0).unwrap();
    let parsed = parse_pbrt_str(
        "w.pbrt",
        "WorldBegin\nLightSource \"infinite\" \"string filename\" \"wide.exr\"\n",
        &d,
    )
    .unwrap();
    assert_eq!(parsed.warnings.len(), 1, "{:?}", parsed.warnings);
    assert!(
        parsed.warnings[0].starts_with("w.pbrt:2: warning: environment map")
            && parsed.warnings[0].contains("not square"),
        "{:?}",
        parsed.warnings
    );
}
