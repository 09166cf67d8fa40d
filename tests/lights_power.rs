//! Power Φ against Monte Carlo estimates (spot, point, uniform sky, environment map), and the
//! conventions the integrator relies on: constructors reject degenerate input, one-sided
//! emission, delta/infinite classification, and shadow-ray endpoints of lights at infinity.

mod lights_support;

use glam::{Mat4, Vec2, Vec3};
use lights_support::check_estimate;
use penumbra::geometry::Transform;
use penumbra::lights::{
    DiskLight, DistantLight, Emitter, EnvMapLight, Light, LightSampleContext, LightSource,
    PointLight, QuadLight, SamplingMode, SphereLight, SpotLight, TriangleLight,
    UniformInfiniteLight,
};
use penumbra::luminance;
use penumbra::material::texture::ImageRgb;
use penumbra::sampling::hash::{next_f32, pcg_from_keys};
use penumbra::sampling::uniform_sphere;
use std::f64::consts::PI;
use std::sync::Arc;

/// 4π · mean of `f` over uniform directions, with its standard error.
fn sphere_integral(f: impl Fn(Vec3) -> f64, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = pcg_from_keys(&[seed, 0x90e]);
    let (mut s1, mut s2) = (0.0, 0.0);
    for _ in 0..n {
        let w = uniform_sphere(Vec2::new(next_f32(&mut rng), next_f32(&mut rng)));
        let x = 4.0 * PI * f(w);
        s1 += x;
        s2 += x * x;
    }
    let nn = n as f64;
    let mean = s1 / nn;
    (mean, ((s2 / nn - mean * mean).max(0.0) / (nn - 1.0)).sqrt())
}

#[test]
fn power_spot_and_point_vs_monte_carlo() {
    let spot = SpotLight::new(
        Vec3::ZERO,
        Vec3::new(0.2, -0.3, 1.0),
        Vec3::new(1.0, 2.0, 3.0),
        25f32.to_radians().cos(),
        45f32.to_radians().cos(),
    );
    let est = sphere_integral(|w| luminance(spot.intensity_toward(w)) as f64, 400_000, 1);
    check_estimate("spot power", est, spot.power() as f64);
    let point = PointLight::new(Vec3::ONE, Vec3::splat(2.0));
    assert!((point.power() as f64 - 8.0 * PI).abs() < 1e-5);
}

#[test]
fn power_infinite_lights_vs_monte_carlo() {
    let r = 3.0f32;
    // Φ = 4πr² · π · mean radiance over the sphere.
    let flux = |mean_l: f64| 4.0 * PI * (r as f64).powi(2) * PI * mean_l;
    let mut sky = Light::UniformInfinite(UniformInfiniteLight::new(Vec3::splat(0.5)));
    sky.preprocess(Vec3::ZERO, r);
    assert!((sky.power() as f64 - flux(0.5)).abs() < 1e-4 * flux(0.5));

    // A smooth map, so that the bilinear radiance and the per-pixel mean used by power()
    // agree to well below the Monte Carlo error.
    let (w, h) = (64u32, 32u32);
    let pixels = (0..h)
        .flat_map(|y| {
            (0..w).map(move |x| Vec3::splat(1.0 + 0.5 * ((x as f32) * 0.1).sin() + 0.02 * y as f32))
        })
        .collect();
    let image = ImageRgb {
        width: w,
        height: h,
        pixels,
    };
    let mut env = Light::EnvMap(Box::new(
        EnvMapLight::new(
            Arc::new(image),
            Vec3::ONE,
            Transform::new(Mat4::from_rotation_y(0.3)).unwrap(),
        )
        .unwrap(),
    ));
    env.preprocess(Vec3::ZERO, r);
    let (m, se) = sphere_integral(
        |d| luminance(env.radiance(Vec3::ZERO, Vec3::ZERO, Vec2::ZERO, d)) as f64,
        200_000,
        2,
    );
    let scale = flux(1.0) / (4.0 * PI);
    check_estimate("envmap power", (m * scale, se * scale), env.power() as f64);
}

#[test]
fn constructors_reject_degenerate_input() {
    let l = Vec3::ONE;
    assert!(TriangleLight::new([Vec3::ZERO, Vec3::X, 2.0 * Vec3::X], Vec3::Z, l, false).is_none());
    assert!(QuadLight::new(Vec3::ZERO, Vec3::X, 2.0 * Vec3::X, Vec3::Z, l, false).is_none());
    assert!(QuadLight::new(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::X, l, false).is_none());
    assert!(QuadLight::new(Vec3::NAN, Vec3::X, Vec3::Y, Vec3::Z, l, false).is_none());
    assert!(SphereLight::new(Vec3::ZERO, 0.0, l, false).is_none());
    assert!(SphereLight::new(Vec3::ZERO, f32::INFINITY, l, false).is_none());
    assert!(DiskLight::new(Vec3::ZERO, Vec3::ZERO, 1.0, l, false).is_none());
    assert!(DiskLight::new(Vec3::ZERO, Vec3::Z, -1.0, l, false).is_none());
    let empty = ImageRgb {
        width: 0,
        height: 0,
        pixels: vec![],
    };
    assert!(EnvMapLight::new(Arc::new(empty), l, Transform::IDENTITY).is_err());
    let one = || {
        Arc::new(ImageRgb {
            width: 1,
            height: 1,
            pixels: vec![Vec3::ONE],
        })
    };
    let shear = Transform::new(Mat4::from_cols_array(&[
        1.0, 0.0, 0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    ]))
    .unwrap();
    assert!(EnvMapLight::new(one(), l, shear).is_err());
    let nan = Arc::new(ImageRgb {
        width: 1,
        height: 1,
        pixels: vec![Vec3::NAN],
    });
    assert!(EnvMapLight::new(nan, l, Transform::IDENTITY).is_err());
    // A black map still samples without panicking (uniform fallback).
    let black = Arc::new(ImageRgb {
        width: 2,
        height: 2,
        pixels: vec![Vec3::ZERO; 4],
    });
    let env = EnvMapLight::new(black, l, Transform::IDENTITY).unwrap();
    let ctx = LightSampleContext {
        p: Vec3::ZERO,
        n: Vec3::Z,
    };
    let s = env
        .sample_li(&ctx, Vec2::new(0.3, 0.6), SamplingMode::SolidAngle)
        .unwrap();
    assert!(s.pdf > 0.0 && s.li == Vec3::ZERO);
}

#[test]
fn conventions() {
    let l = Vec3::ONE;
    // One-sided quad emitting down: radiance only toward -z, nothing sampled from above.
    let quad =
        Light::Quad(QuadLight::new(Vec3::ZERO, Vec3::X, Vec3::Y, -Vec3::Z, l, false).unwrap());
    assert_eq!(quad.radiance(Vec3::ZERO, -Vec3::Z, Vec2::ZERO, -Vec3::Z), l);
    assert_eq!(
        quad.radiance(Vec3::ZERO, -Vec3::Z, Vec2::ZERO, Vec3::Z),
        Vec3::ZERO
    );
    let above = LightSampleContext {
        p: Vec3::new(0.5, 0.5, 1.0),
        n: -Vec3::Z,
    };
    let below = LightSampleContext {
        p: Vec3::new(0.5, 0.5, -1.0),
        n: Vec3::Z,
    };
    for mode in [SamplingMode::Area, SamplingMode::SolidAngle] {
        assert!(quad.sample_li(&above, Vec2::splat(0.5), mode).is_none());
        let s = quad.sample_li(&below, Vec2::splat(0.5), mode).unwrap();
        assert!(s.wi.z > 0.0 && !s.delta);
        assert_eq!(
            quad.pdf_li(&above, Vec3::NEG_Z, Vec3::new(0.5, 0.5, 0.0), Vec3::Z, mode),
            0.0
        );
    }
    // Outward sphere: emits away from its centre; inward: toward it.
    let out = Light::Sphere(SphereLight::new(Vec3::ZERO, 1.0, l, false).unwrap());
    let inw = Light::Sphere(SphereLight::new(Vec3::ZERO, 1.0, l, true).unwrap());
    assert_eq!(out.radiance(Vec3::X, Vec3::X, Vec2::ZERO, Vec3::X), l);
    assert_eq!(
        out.radiance(Vec3::X, Vec3::X, Vec2::ZERO, -Vec3::X),
        Vec3::ZERO
    );
    assert_eq!(inw.radiance(Vec3::X, Vec3::X, Vec2::ZERO, -Vec3::X), l);

    // Classification, and shadow-ray ends outside the scene for lights at infinity.
    let mut lights = vec![
        Light::Point(PointLight::new(Vec3::ZERO, l)),
        Light::Spot(SpotLight::new(Vec3::ZERO, Vec3::Z, l, 0.9, 0.8)),
        Light::Distant(DistantLight::new(Vec3::Z, l)),
        Light::UniformInfinite(UniformInfiniteLight::new(l)),
        quad,
        out,
    ];
    let delta: Vec<bool> = lights.iter().map(|x| x.is_delta()).collect();
    let inf: Vec<bool> = lights.iter().map(|x| x.is_infinite()).collect();
    assert_eq!(delta, [true, true, true, false, false, false]);
    assert_eq!(inf, [false, false, false, true, false, false]);
    for light in &mut lights {
        light.preprocess(Vec3::ZERO, 5.0);
    }
    let ctx = LightSampleContext {
        p: Vec3::new(1.0, 0.0, 0.0),
        n: Vec3::Z,
    };
    for light in &lights[2..4] {
        let s = light
            .sample_li(&ctx, Vec2::new(0.2, 0.3), SamplingMode::SolidAngle)
            .unwrap();
        assert!(((s.p_light - ctx.p).length() - 10.0).abs() < 1e-3);
        assert!(light.bounds().is_none());
    }
    assert!(lights[0].bounds().is_some() && lights[4].bounds().is_some());
}
