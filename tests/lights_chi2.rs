//! Chi-square tests of every area and infinite light: the directions `sample_li` draws must
//! follow `pdf_li`, in both sampling modes, from receivers far, near and at grazing angles.
//! The hit point passed to `pdf_li` comes from ray–shape intersections written in the test.
//!
//! The whole family runs at an overall significance of 1% (Šidák-corrected per test).

mod lights_support;

use glam::{Mat4, Vec2, Vec3};
use lights_support::{check, chi2_light, hit_disk, hit_quad, hit_triangle, v2};
use penumbra::geometry::Transform;
use penumbra::lights::{
    DiskLight, Emitter, EnvMapLight, Light, LightSampleContext, LightSource, QuadLight,
    SamplingMode, SphereLight, TriangleLight,
};
use penumbra::material::texture::ImageRgb;
use penumbra::sampling::Frame;
use penumbra::sampling::chi2::Chi2Config;
use penumbra::sampling::chi2::{chi2_directions, chi2_points};
use std::f64::consts::PI;
use std::sync::Arc;

/// Number of chi-square tests in this file (for the Šidák correction); keep in sync.
const NUM_TESTS: usize = 22;

fn cfg() -> Chi2Config {
    Chi2Config {
        samples: 200_000,
        res: (24, 48),
        num_tests: NUM_TESTS,
        ..Default::default()
    }
}

const MODES: [SamplingMode; 2] = [SamplingMode::Area, SamplingMode::SolidAngle];
const SA: [SamplingMode; 1] = [SamplingMode::SolidAngle];

fn tri_vertices() -> [Vec3; 3] {
    [
        Vec3::new(-0.5, -0.3, 0.0),
        Vec3::new(0.6, -0.2, 0.0),
        Vec3::new(0.1, 0.7, 0.0),
    ]
}

fn chi2_triangle(name: &str, p: Vec3, two_sided: bool, modes: &[SamplingMode]) {
    let v = tri_vertices();
    let light = Light::Triangle(TriangleLight::new(v, Vec3::Z, Vec3::ONE, two_sided).unwrap());
    let centre = (v[0] + v[1] + v[2]) / 3.0;
    for &mode in modes {
        chi2_light(
            name,
            &cfg(),
            &light,
            p,
            mode,
            |p, d| hit_triangle(p, d, v),
            centre,
            &v,
        );
    }
}

#[test]
fn chi2_triangle_light() {
    // Far above (Ω ≈ 0.04 sr: spherical sampling), close above (Ω ≈ 2π·0.9: full sphere),
    // grazing, and so far away that Ω < 1e-4 sr and solid-angle mode falls back to area.
    chi2_triangle("triangle far", Vec3::new(0.2, 0.1, 3.0), false, &MODES);
    chi2_triangle("triangle near", Vec3::new(0.1, 0.0, 0.05), false, &MODES);
    chi2_triangle("triangle grazing", Vec3::new(2.0, 0.5, 0.05), false, &MODES);
    chi2_triangle("triangle tiny", Vec3::new(3.0, 2.0, 60.0), false, &SA);
    // Two-sided, seen from below.
    chi2_triangle(
        "triangle two-sided below",
        Vec3::new(0.3, -0.2, -0.4),
        true,
        &SA,
    );
}

fn chi2_quad(name: &str, p: Vec3, e2: Vec3, modes: &[SamplingMode]) {
    let (c, e1) = (Vec3::new(-0.5, -0.5, 1.0), Vec3::new(1.0, 0.0, 0.0));
    let light = Light::Quad(QuadLight::new(c, e1, e2, -Vec3::Z, Vec3::ONE, false).unwrap());
    let outline = [c, c + e1, c + e2, c + e1 + e2];
    let centre = c + 0.5 * (e1 + e2);
    for &mode in modes {
        chi2_light(
            name,
            &cfg(),
            &light,
            p,
            mode,
            |p, d| hit_quad(p, d, c, e1, e2),
            centre,
            &outline,
        );
    }
}

#[test]
fn chi2_quad_light() {
    let e2 = Vec3::new(0.0, 0.7, 0.0);
    // Area sampling of quads is covered by the parallelogram (which always falls back to it).
    chi2_quad("quad far", Vec3::new(0.3, 0.2, -2.0), e2, &SA);
    chi2_quad("quad near", Vec3::new(0.1, 0.2, 0.75), e2, &SA);
    chi2_quad("quad grazing", Vec3::new(2.5, 0.2, 0.9), e2, &SA);
    // A skewed parallelogram: solid-angle mode must fall back to area sampling consistently.
    chi2_quad(
        "parallelogram",
        Vec3::new(0.1, 0.2, 0.3),
        Vec3::new(0.4, 0.7, 0.0),
        &SA,
    );
}

fn chi2_sphere(name: &str, p: Vec3, inward: bool, modes: &[SamplingMode]) {
    let (c, r) = (Vec3::new(0.0, 0.0, 2.0), 0.5);
    let light = Light::Sphere(SphereLight::new(c, r, Vec3::ONE, inward).unwrap());
    let to_c = c - p;
    let d = to_c.length();
    for &mode in modes {
        if mode == SamplingMode::Area && d > r {
            // Area sampling from outside: the solid-angle pdf r²/cos has an integrable
            // singularity at the silhouette that quadrature cannot resolve, so test the sampled
            // points on the sphere instead: uniform by area (1/4π over outward normals) on the
            // visible cap n·(p − c) > r, and nothing on the hidden side.
            let ctx = LightSampleContext { p, n: Vec3::ZERO };
            let bad = std::cell::Cell::new(0usize);
            let r2 = chi2_directions(
                &cfg(),
                |u| {
                    let s = light.sample_li(&ctx, v2(u), mode)?;
                    let q = light.pdf_li(&ctx, s.wi, s.p_light, Vec3::ZERO, mode);
                    // f32 rounding grows near the silhouette (cos → 0): count, do not assert.
                    if (q - s.pdf).abs() > 1e-2 * s.pdf {
                        bad.set(bad.get() + 1);
                    }
                    Some((s.p_light - c).normalize())
                },
                |n| if n.dot(p - c) > r { 0.25 / PI } else { 0.0 },
            );
            check(&format!("{name} [Area, points]"), &r2);
            assert!(
                bad.get() <= cfg().samples / 1000,
                "{name}: {} pdf mismatches",
                bad.get()
            );
            continue;
        }
        // Silhouette circle seen from p (for the zoomed plot); a far point from inside.
        let outline: Vec<Vec3> = if d > r {
            let f = Frame::from_normal(to_c / d);
            let (sa, ca) = (r / d, (1.0 - (r / d) * (r / d)).sqrt());
            (0..32)
                .map(|k| {
                    let phi = k as f32 * std::f32::consts::TAU / 32.0;
                    p + f.to_world(Vec3::new(sa * phi.cos(), sa * phi.sin(), ca))
                })
                .collect()
        } else {
            vec![p - to_c]
        };
        // pdf_li recomputes the hit point from wi, so any point will do.
        chi2_light(
            name,
            &cfg(),
            &light,
            p,
            mode,
            |p, d| Some(p + d),
            c,
            &outline,
        );
    }
}

#[test]
fn chi2_sphere_light() {
    chi2_sphere("sphere far", Vec3::new(4.0, 3.0, 1.0), false, &SA);
    chi2_sphere("sphere mid", Vec3::ZERO, false, &MODES);
    chi2_sphere("sphere near", Vec3::new(0.3, 0.0, 1.3), false, &MODES);
    chi2_sphere("sphere inward, inside", Vec3::new(0.1, 0.2, 2.1), true, &SA);
}

fn chi2_disk(name: &str, p: Vec3, modes: &[SamplingMode]) {
    let (c, n, r) = (
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.2, 0.0, -1.0).normalize(),
        0.6,
    );
    let light = Light::Disk(DiskLight::new(c, n, r, Vec3::ONE, false).unwrap());
    let f = Frame::from_normal(n);
    let outline: Vec<Vec3> = (0..32)
        .map(|k| {
            let phi = k as f32 * std::f32::consts::TAU / 32.0;
            c + r * (f.s * phi.cos() + f.t * phi.sin())
        })
        .collect();
    for &mode in modes {
        chi2_light(
            name,
            &cfg(),
            &light,
            p,
            mode,
            |p, d| hit_disk(p, d, c, n, r),
            c,
            &outline,
        );
    }
}

#[test]
fn chi2_disk_light() {
    chi2_disk(
        "disk on axis",
        Vec3::new(0.0, 0.0, -0.5),
        &[SamplingMode::Area],
    );
    chi2_disk("disk near", Vec3::new(0.1, 0.1, 0.9), &[SamplingMode::Area]);
    chi2_disk(
        "disk grazing",
        Vec3::new(2.0, 0.3, 1.3),
        &[SamplingMode::Area],
    );
}

/// A 16×8 map with a gradient, a bright spot, a black band and a black pixel.
pub fn test_image() -> ImageRgb {
    let (w, h) = (16u32, 8u32);
    let mut pixels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let mut c = Vec3::new(0.2 + 0.05 * x as f32, 0.3, 0.1 + 0.1 * y as f32);
            if (5..7).contains(&x) && y == 2 {
                c *= 40.0;
            }
            if x == 11 || (x, y) == (2, 6) {
                c = Vec3::ZERO;
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

/// The environment map is tested in its own (u, v) chart, which the test computes from the
/// sampled world direction independently of the light: there the pdf is
/// pdf_ω · 2π² sin θ and piecewise constant across pixels, and a grid aligned with the pixels
/// keeps the quadrature exact and cheap.
#[test]
fn chi2_envmap_light() {
    let rot = Mat4::from_rotation_z(0.7) * Mat4::from_rotation_x(0.5);
    let img = test_image();
    let (w, h) = (img.width as usize, img.height as usize);
    let light = Light::EnvMap(Box::new(
        EnvMapLight::new(Arc::new(img), Vec3::ONE, Transform::new(rot).unwrap()).unwrap(),
    ));
    let inv = rot.inverse();
    let to_uv = |wd: Vec3| {
        let d = inv.transform_vector3(wd).normalize();
        let phi = d.y.atan2(d.x).rem_euclid(std::f32::consts::TAU);
        let theta = d.z.clamp(-1.0, 1.0).acos();
        Vec2::new(phi / std::f32::consts::TAU, theta / std::f32::consts::PI)
    };
    let ctx = LightSampleContext {
        p: Vec3::ZERO,
        n: Vec3::ZERO,
    };
    let bad = std::cell::Cell::new(0usize);
    let r = chi2_points(
        &Chi2Config {
            res: (4 * w, 4 * h),
            ..cfg()
        },
        [0.0, 1.0, 0.0, 1.0],
        |u| {
            let s = light.sample_li(&ctx, v2(u), SamplingMode::SolidAngle)?;
            let q = light.pdf_li(&ctx, s.wi, s.p_light, Vec3::ZERO, SamplingMode::SolidAngle);
            // sin θ is recomputed from the direction: allow f32 rounding near the poles.
            if (q - s.pdf).abs() > 1e-2 * s.pdf {
                bad.set(bad.get() + 1);
            }
            Some(to_uv(s.wi))
        },
        |uv| {
            let (sp, cp) = (uv.x * std::f32::consts::TAU).sin_cos();
            let (st, ct) = (uv.y * std::f32::consts::PI).sin_cos();
            let wd = rot.transform_vector3(Vec3::new(st * cp, st * sp, ct));
            let pdf = light.pdf_li(&ctx, wd, Vec3::ZERO, Vec3::ZERO, SamplingMode::SolidAngle);
            pdf as f64 * 2.0 * PI * PI * st as f64
        },
    );
    check("envmap (u, v)", &r);
    assert!(
        bad.get() <= cfg().samples / 1000,
        "envmap: {} pdf mismatches",
        bad.get()
    );
}

/// Negative control (not counted in `NUM_TESTS`): area-sampled directions toward a sphere
/// judged against the uniform-cone pdf of solid-angle mode must be rejected, so the tests
/// above have power to catch a sampler and pdf that disagree.
#[test]
fn chi2_negative_control_sphere_area_vs_cone() {
    let light =
        Light::Sphere(SphereLight::new(Vec3::new(0.0, 0.0, 2.0), 0.5, Vec3::ONE, false).unwrap());
    let ctx = LightSampleContext {
        p: Vec3::ZERO,
        n: Vec3::ZERO,
    };
    let r = chi2_directions(
        &cfg(),
        |u| Some(light.sample_li(&ctx, v2(u), SamplingMode::Area)?.wi),
        |d| light.pdf_li(&ctx, d, Vec3::ZERO, Vec3::ZERO, SamplingMode::SolidAngle) as f64,
    );
    eprintln!("negative control: {}", r.summary());
    assert!(!r.passed, "harness has no power: {}", r.summary());
}
