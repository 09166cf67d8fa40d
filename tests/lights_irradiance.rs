//! Irradiance E = ∫ Li cos θ dω at a receiver, estimated as mean(Li·cos θ / pdf) over light
//! samples, against closed forms: Lambert's polygon formula (triangle, rectangle,
//! parallelogram), π L sin²α (sphere), π L r²/(r²+h²) (disk on axis), π L (uniform sky and
//! constant environment map), a brute-force quadrature (non-trivial environment map), and
//! I cos θ / r² (point, spot, distant). Bounds are 5 standard errors from the sample variance.

mod lights_support;

use glam::{DVec3, Mat4, Vec3};
use lights_support::{check_estimate, irradiance};
use penumbra::geometry::Transform;
use penumbra::lights::{
    DiskLight, DistantLight, Emitter, EnvMapLight, Light, LightSampleContext, LightSource,
    PointLight, QuadLight, SamplingMode, SphereLight, SpotLight, TriangleLight,
    UniformInfiniteLight,
};
use penumbra::material::texture::ImageRgb;
use std::f64::consts::PI;
use std::sync::Arc;

const N: usize = 100_000;
const MODES: [SamplingMode; 2] = [SamplingMode::Area, SamplingMode::SolidAngle];

/// Lambert's formula for a uniformly emitting polygon entirely above the receiver's horizon:
/// E = L/2 · |Σ Θᵢ (n · unit(vᵢ × vᵢ₊₁))| with vᵢ the vertices relative to the receiver.
fn lambert_polygon(p: Vec3, n: Vec3, verts: &[Vec3], l: f64) -> f64 {
    let (p, n) = (p.as_dvec3(), n.as_dvec3());
    let v: Vec<DVec3> = verts
        .iter()
        .map(|&x| (x.as_dvec3() - p).normalize())
        .collect();
    let mut s = 0.0;
    for i in 0..v.len() {
        let (a, b) = (v[i], v[(i + 1) % v.len()]);
        let c = a.cross(b);
        let theta = c.length().atan2(a.dot(b));
        s += theta * n.dot(c.normalize());
    }
    0.5 * l * s.abs()
}

#[test]
fn irradiance_triangle() {
    let v = [
        Vec3::new(-0.5, -0.3, 1.0),
        Vec3::new(0.6, -0.2, 1.0),
        Vec3::new(0.1, 0.7, 1.0),
    ];
    let light = Light::Triangle(TriangleLight::new(v, -Vec3::Z, Vec3::splat(2.0), false).unwrap());
    let cases = [
        ("far", Vec3::new(0.3, 0.1, -2.0), Vec3::Z),
        ("near", Vec3::new(0.1, 0.0, 0.9), Vec3::Z),
        (
            "tilted",
            Vec3::new(0.0, 0.0, 0.5),
            Vec3::new(0.3, 0.2, 1.0).normalize(),
        ),
        (
            "grazing",
            Vec3::new(3.0, 0.2, 0.95),
            Vec3::new(-0.05, 0.0, 1.0).normalize(),
        ),
        ("tiny", Vec3::new(5.0, 2.0, -80.0), Vec3::Z),
    ];
    for (name, p, n) in cases {
        let exact = lambert_polygon(p, n, &v, 2.0);
        for mode in MODES {
            let est = irradiance(&light, p, n, mode, N, 1);
            check_estimate(&format!("triangle {name} {mode:?}"), est, exact);
        }
    }
}

#[test]
fn irradiance_quad() {
    let (c, e1) = (Vec3::new(-0.5, -0.4, 1.0), Vec3::new(1.0, 0.0, 0.0));
    for (shape, e2) in [
        ("rectangle", Vec3::new(0.0, 0.7, 0.0)),
        ("parallelogram", Vec3::new(0.4, 0.7, 0.0)),
    ] {
        let light = Light::Quad(QuadLight::new(c, e1, e2, -Vec3::Z, Vec3::ONE, false).unwrap());
        let verts = [c, c + e1, c + e1 + e2, c + e2];
        for (name, p, n) in [
            ("far", Vec3::new(0.2, 0.3, -3.0), Vec3::Z),
            ("near", Vec3::new(0.1, 0.1, 0.9), Vec3::Z),
            (
                "grazing",
                Vec3::new(2.5, 0.0, 0.97),
                Vec3::new(-0.03, 0.0, 1.0).normalize(),
            ),
        ] {
            let exact = lambert_polygon(p, n, &verts, 1.0);
            for mode in MODES {
                let est = irradiance(&light, p, n, mode, N, 2);
                check_estimate(&format!("{shape} {name} {mode:?}"), est, exact);
            }
        }
    }
}

#[test]
fn irradiance_sphere() {
    let (c, r, l) = (Vec3::new(0.0, 0.0, 2.0), 0.5f32, 3.0f32);
    let light = Light::Sphere(SphereLight::new(c, r, Vec3::splat(l), false).unwrap());
    for (name, p, tilt) in [
        ("far", Vec3::new(3.0, 4.0, -6.0), 0.0f32),
        ("mid", Vec3::ZERO, 0.4),
        ("near", Vec3::new(0.2, 0.0, 1.35), 0.0),
    ] {
        let to_c = c - p;
        let d = to_c.length();
        let axis = to_c / d;
        // Tilt the receiver by `tilt` radians while keeping the sphere above its horizon:
        // then E = π L sin²α cos(tilt).
        let side = axis.cross(Vec3::X).normalize();
        let n = (axis * tilt.cos() + side * tilt.sin()).normalize();
        let sin2 = (r as f64 / d as f64).powi(2);
        let exact = PI * l as f64 * sin2 * (tilt as f64).cos();
        for mode in MODES {
            let est = irradiance(&light, p, n, mode, N, 3);
            check_estimate(&format!("sphere {name} {mode:?}"), est, exact);
        }
    }
    // An inward sphere seen from inside fills the whole hemisphere: E = π L.
    let inward = Light::Sphere(SphereLight::new(c, r, Vec3::splat(l), true).unwrap());
    let (p, n) = (
        c + Vec3::new(0.1, -0.2, 0.15),
        Vec3::new(0.2, 0.5, 1.0).normalize(),
    );
    for mode in MODES {
        let est = irradiance(&inward, p, n, mode, N, 4);
        check_estimate(&format!("sphere inward {mode:?}"), est, PI * l as f64);
    }
}

#[test]
fn irradiance_disk_on_axis() {
    let (c, n, r) = (
        Vec3::new(0.3, -0.2, 1.0),
        Vec3::new(0.1, 0.2, -1.0).normalize(),
        0.6f32,
    );
    let light = Light::Disk(DiskLight::new(c, n, r, Vec3::ONE, false).unwrap());
    for h in [0.05f32, 0.7, 4.0] {
        let p = c + n * h;
        let (r2, h2) = ((r * r) as f64, (h * h) as f64);
        let exact = PI * r2 / (r2 + h2);
        for mode in MODES {
            let est = irradiance(&light, p, -n, mode, N, 5);
            check_estimate(&format!("disk h = {h} {mode:?}"), est, exact);
        }
    }
}

#[test]
fn irradiance_uniform_infinite() {
    let mut light = Light::UniformInfinite(UniformInfiniteLight::new(Vec3::splat(0.7)));
    light.preprocess(Vec3::ZERO, 10.0);
    let est = irradiance(
        &light,
        Vec3::new(1.0, 2.0, 3.0),
        Vec3::new(0.3, -0.4, 0.2).normalize(),
        SamplingMode::SolidAngle,
        N,
        6,
    );
    check_estimate("uniform infinite", est, PI * 0.7);
}

fn envmap(image: ImageRgb, rot: Mat4) -> Light {
    Light::EnvMap(Box::new(
        EnvMapLight::new(Arc::new(image), Vec3::ONE, Transform::new(rot).unwrap()).unwrap(),
    ))
}

#[test]
fn irradiance_envmap_constant() {
    let image = ImageRgb {
        width: 8,
        height: 4,
        pixels: vec![Vec3::splat(1.5); 32],
    };
    let light = envmap(image, Mat4::from_rotation_x(0.3));
    for n in [Vec3::Z, Vec3::new(0.5, -0.7, 0.1).normalize(), -Vec3::Z] {
        let est = irradiance(&light, Vec3::ZERO, n, SamplingMode::SolidAngle, N, 7);
        check_estimate(&format!("envmap constant n = {n}"), est, PI * 1.5);
    }
}

/// A smooth-ish 24×12 map with a bright patch, so the quadrature below converges quickly.
fn varied_image() -> ImageRgb {
    let (w, h) = (24u32, 12u32);
    let mut pixels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let mut c = Vec3::new(0.5 + 0.02 * x as f32, 0.2 + 0.05 * y as f32, 0.3);
            if (8..10).contains(&x) && (2..4).contains(&y) {
                c *= 30.0;
            }
            pixels.push(c);
        }
    }
    ImageRgb {
        width: w,
        height: h,
        pixels,
    }
}

/// E(n) = ∫ L(ω) max(0, n·ω) dω by the midpoint rule on a fine (θ, φ) grid in light space,
/// dω = sin θ dθ dφ, with L from the light's own `radiance` (what sampling must integrate).
fn envmap_quadrature(light: &Light, rot: Mat4, n: Vec3) -> f64 {
    let (nt, np) = (1200usize, 2400usize);
    let (dt, dp) = (PI / nt as f64, 2.0 * PI / np as f64);
    let mut e = 0.0;
    for i in 0..nt {
        let t = (i as f64 + 0.5) * dt;
        let (st, ct) = t.sin_cos();
        for j in 0..np {
            let ph = (j as f64 + 0.5) * dp;
            let d = DVec3::new(st * ph.cos(), st * ph.sin(), ct).as_vec3();
            let w = rot.transform_vector3(d);
            let cos = n.dot(w).max(0.0) as f64;
            if cos > 0.0 {
                let l = light
                    .radiance(Vec3::ZERO, Vec3::ZERO, glam::Vec2::ZERO, w)
                    .x as f64;
                e += l * cos * st;
            }
        }
    }
    e * dt * dp
}

#[test]
fn irradiance_envmap_varied_vs_quadrature() {
    let rot = Mat4::from_rotation_z(0.4) * Mat4::from_rotation_y(-0.6);
    let light = envmap(varied_image(), rot);
    for n in [Vec3::Z, Vec3::new(-0.6, 0.3, 0.2).normalize()] {
        let exact = envmap_quadrature(&light, rot, n);
        let est = irradiance(&light, Vec3::ZERO, n, SamplingMode::SolidAngle, N, 8);
        check_estimate(&format!("envmap varied n = {n}"), est, exact);
    }
}

#[test]
fn irradiance_delta_lights() {
    let ctx = LightSampleContext {
        p: Vec3::new(0.5, 0.0, 0.0),
        n: Vec3::Z,
    };
    let u = glam::Vec2::new(0.3, 0.7);
    // Point: E = I cos θ / r².
    let lp = Vec3::new(1.5, 0.5, 2.0);
    let point = Light::Point(PointLight::new(lp, Vec3::splat(4.0)));
    let s = point.sample_li(&ctx, u, SamplingMode::Area).unwrap();
    let d = lp - ctx.p;
    let exact = 4.0 * d.normalize().z / d.length_squared();
    let got = s.li.x * s.wi.dot(ctx.n) / s.pdf;
    assert!(
        s.delta && (got - exact).abs() < 1e-5 * exact,
        "point: {got} vs {exact}"
    );
    assert_eq!(
        point.pdf_li(&ctx, s.wi, lp, Vec3::Z, SamplingMode::Area),
        0.0
    );

    // Spot pointing down at the receiver from straight above: full intensity inside the
    // inner cone, smoothstep in the band, nothing outside.
    let (c_start, c_end) = (30f32.to_radians().cos(), 40f32.to_radians().cos());
    let spot = Light::Spot(SpotLight::new(
        Vec3::new(0.5, 0.0, 1.0),
        -Vec3::Z,
        Vec3::splat(2.0),
        c_start,
        c_end,
    ));
    for (deg, want_factor) in [(10f32, 1.0f32), (35.0, -1.0), (50.0, 0.0)] {
        let off = deg.to_radians().tan();
        let ctx = LightSampleContext {
            p: Vec3::new(0.5 + off, 0.0, 0.0),
            n: Vec3::Z,
        };
        let r2 = 1.0 + off * off;
        let cos = 1.0 / r2.sqrt();
        let factor = if want_factor >= 0.0 {
            want_factor
        } else {
            let t = (cos - c_end) / (c_start - c_end);
            t * t * (3.0 - 2.0 * t)
        };
        let exact = 2.0 * factor * cos / r2;
        let got = spot
            .sample_li(&ctx, u, SamplingMode::Area)
            .map_or(0.0, |s| s.li.x * s.wi.dot(ctx.n) / s.pdf);
        assert!(
            (got - exact).abs() <= 1e-5 * exact.max(1e-3),
            "spot {deg}°: {got} vs {exact}"
        );
    }

    // Distant: E = L cos θ, and the shadow-ray end lies 2·radius away along wi.
    let w = Vec3::new(0.3, 0.0, 1.0).normalize();
    let mut distant = Light::Distant(DistantLight::new(w, Vec3::splat(5.0)));
    distant.preprocess(Vec3::ZERO, 7.0);
    let s = distant.sample_li(&ctx, u, SamplingMode::Area).unwrap();
    assert!((s.li.x * s.wi.dot(ctx.n) / s.pdf - 5.0 * w.z).abs() < 1e-5);
    assert!(((s.p_light - ctx.p).length() - 14.0).abs() < 1e-4);
}
