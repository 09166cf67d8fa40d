//! Every direct-lighting estimator against analytic answers, with bounds from the measured
//! sample variance: a wrong π, cosine or Jacobian fails these by far more than 5σ.
//!
//! The receiver is a Lambertian plane z = 0 of albedo ρ; its outgoing radiance is ρ·E/π for
//! irradiance E. Deterministic patterns (`fixed`, `grid`) are quadrature rules, not Monte Carlo
//! estimators: they are biased by design (the lecture's point) and are excluded here.

use glam::{UVec2, Vec3};
use penumbra::Rgb;
use penumbra::camera::Camera;
use penumbra::geometry::{Ray, Transform};
use penumbra::integrator::MisHeuristic;
use penumbra::integrator::Strategy;
use penumbra::integrator::stages::Integrator;
use penumbra::light_selection::{SelectorKind, make_selector};
use penumbra::lights::{Light, UniformInfiniteLight};
use penumbra::material::{Material, Texture};
use penumbra::sampling::{PatternKind, make_pattern};
use penumbra::scene::{AreaEmission, FilmSpec, Filter, Scene, SceneBuilder};
use std::f64::consts::PI;

const RHO: f32 = 0.5;

fn film() -> FilmSpec {
    FilmSpec {
        resolution: UVec2::new(8, 8),
        filter: Filter::Box {
            radius: glam::Vec2::splat(0.5),
        },
        filename: None,
        spp: None,
        sensor: Default::default(),
    }
}

fn camera() -> Camera {
    Camera::look_at(Vec3::new(0.0, -5.0, 5.0), Vec3::ZERO, Vec3::Z, 30.0).unwrap()
}

/// A large receiver plane (z = 0, normal +z) plus whatever `add` puts in.
fn scene(add: impl FnOnce(&mut SceneBuilder)) -> Scene {
    let mut b = SceneBuilder::new();
    let m = b.add_material(Material::Diffuse {
        reflectance: Texture::Constant(Rgb::splat(RHO)),
    });
    b.add_quad(
        Vec3::new(-50.0, -50.0, 0.0),
        Vec3::new(100.0, 0.0, 0.0),
        Vec3::new(0.0, 100.0, 0.0),
        m,
        None,
    )
    .unwrap();
    add(&mut b);
    b.build(camera(), film()).unwrap()
}

/// Mean and standard error of the radiance toward a ray hitting the plane at the origin,
/// over `pixels` independent sample sets of `spp` eye samples × `m` light samples.
fn estimate(scene: &Scene, strategy: Strategy, pattern: PatternKind, m: u32) -> (f64, f64) {
    let selector = make_selector(SelectorKind::Uniform, scene, 7);
    let pattern = make_pattern(pattern, 7);
    let spp = 16;
    let est = Integrator {
        scene,
        selector: selector.as_ref(),
        pattern: pattern.as_ref(),
        strategy,
        mis: MisHeuristic::Power,
        eye_rays: spp,
        shadow_rays: m,
        bsdf_sampling: penumbra::bsdf::LobeSampling::Importance,
        mis_light: penumbra::lights::SamplingMode::SolidAngle,
        max_depth: 1,
        roulette: false,
        hide_emitters: false,
    };
    // A ray that reaches the origin from the side, clear of lights above it.
    let o = Vec3::new(0.0, -3.0, 1.0);
    let ray = Ray::new(o, (Vec3::ZERO - o).normalize());
    let pixels = 4000u32;
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for px in 0..pixels {
        let pixel = UVec2::new(px % 64, px / 64);
        // Average the eye samples of a pixel first: the per-pixel means are i.i.d. even when
        // the pattern stratifies within a pixel.
        let mut pm = 0.0f64;
        let px = pattern.pixel(pixel);
        for i in 0..spp {
            let (l, _) = est.li(&px, i, &ray);
            pm += l.x as f64;
        }
        pm /= spp as f64;
        s += pm;
        s2 += pm * pm;
    }
    let n = pixels as f64;
    let mean = s / n;
    let var = (s2 / n - mean * mean).max(0.0) * n / (n - 1.0);
    (mean, (var / n).sqrt())
}

fn assert_close(what: &str, (mean, se): (f64, f64), exact: f64) {
    let tol = 5.0 * se + 1e-4 * exact;
    eprintln!("{what}: {mean:.6} ± {se:.2e} vs exact {exact:.6}");
    assert!(
        (mean - exact).abs() <= tol,
        "{what}: estimate {mean} ± {se} differs from the analytic {exact} by more than 5σ"
    );
}

const RANDOM_PATTERNS: [PatternKind; 4] = [
    PatternKind::Random,
    PatternKind::Stratified,
    PatternKind::Lhs,
    PatternKind::Sobol,
];

#[test]
fn sphere_light_irradiance_is_pi_l_sin2_alpha_for_every_strategy_and_pattern() {
    let (r, h, le) = (0.5f32, 2.0f32, 3.0f32);
    let s = scene(|b| {
        let m = b.add_material(Material::Diffuse {
            reflectance: Texture::Constant(Rgb::ZERO),
        });
        let emission = AreaEmission {
            l: Rgb::splat(le),
            two_sided: false,
        };
        b.add_sphere(
            Transform::translate(Vec3::new(0.0, 0.0, h)),
            r,
            m,
            Some(emission),
            false,
            None,
        )
        .unwrap();
    });
    let sin2 = (r as f64 / h as f64).powi(2);
    let exact = RHO as f64 / PI * PI * le as f64 * sin2;
    for strategy in Strategy::ALL {
        for pattern in RANDOM_PATTERNS {
            let m = if strategy == Strategy::Bsdf { 4 } else { 1 };
            let e = estimate(&s, strategy, pattern, m);
            assert_close(&format!("sphere {strategy} {pattern}"), e, exact);
        }
    }
}

#[test]
fn furnace_diffuse_plane_under_uniform_sky_reflects_rho_le() {
    let le = 2.0f32;
    let s = scene(|b| {
        b.add_light(Light::UniformInfinite(UniformInfiniteLight::new(
            Rgb::splat(le),
        )));
    });
    for strategy in Strategy::ALL {
        let e = estimate(&s, strategy, PatternKind::Stratified, 1);
        assert_close(&format!("furnace {strategy}"), e, (RHO * le) as f64);
    }
}

/// Irradiance at the origin (normal +z) from a uniformly emitting polygon (Lambert's formula).
fn polygon_irradiance(v: &[Vec3], le: f64) -> f64 {
    let mut sum = 0.0f64;
    for i in 0..v.len() {
        let a = v[i].as_dvec3().normalize();
        let b = v[(i + 1) % v.len()].as_dvec3().normalize();
        let theta = a.dot(b).clamp(-1.0, 1.0).acos();
        let c = a.cross(b);
        if c.length() > 0.0 {
            sum += theta * c.normalize().z;
        }
    }
    0.5 * le * sum.abs()
}

#[test]
fn square_light_irradiance_matches_lamberts_polygon_formula() {
    let le = 4.0f32;
    // A 1×1 square at height 1, off-centre so the geometry is not symmetric.
    let corner = Vec3::new(-0.2, -0.4, 1.0);
    let (e1, e2) = (Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 0.0, 0.0));
    let s = scene(|b| {
        let m = b.add_material(Material::Diffuse {
            reflectance: Texture::Constant(Rgb::ZERO),
        });
        // e1 × e2 = −z: emits downward, toward the receiver.
        let emission = AreaEmission {
            l: Rgb::splat(le),
            two_sided: false,
        };
        b.add_quad(corner, e1, e2, m, Some(emission)).unwrap();
    });
    let verts = [corner, corner + e1, corner + e1 + e2, corner + e2];
    let exact = RHO as f64 / PI * polygon_irradiance(&verts, le as f64);
    for strategy in Strategy::ALL {
        let m = if strategy == Strategy::Bsdf { 4 } else { 1 };
        let e = estimate(&s, strategy, PatternKind::Stratified, m);
        assert_close(&format!("square {strategy}"), e, exact);
    }
}

#[test]
fn triangle_mesh_light_irradiance_matches_lamberts_polygon_formula() {
    let le = 4.0f32;
    let v = [
        Vec3::new(-0.5, -0.3, 0.8),
        Vec3::new(0.7, 0.1, 1.2),
        Vec3::new(-0.1, 0.9, 1.0),
    ];
    let s = scene(|b| {
        let m = b.add_material(Material::Diffuse {
            reflectance: Texture::Constant(Rgb::ZERO),
        });
        let emission = AreaEmission {
            l: Rgb::splat(le),
            two_sided: true,
        };
        let mesh = penumbra::scene::TriangleMesh {
            positions: v.to_vec(),
            normals: None,
            uvs: None,
            indices: vec![0, 1, 2],
            flip_normals: false,
        };
        b.add_mesh(mesh, m, Some(emission)).unwrap();
    });
    let exact = RHO as f64 / PI * polygon_irradiance(&v, le as f64);
    for strategy in Strategy::ALL {
        let m = if strategy == Strategy::Bsdf { 4 } else { 1 };
        let e = estimate(&s, strategy, PatternKind::Random, m);
        assert_close(&format!("triangle {strategy}"), e, exact);
    }
}

#[test]
fn one_sided_light_facing_away_gives_nothing() {
    let s = scene(|b| {
        let m = b.add_material(Material::Diffuse {
            reflectance: Texture::Constant(Rgb::ZERO),
        });
        // e2 × e1 = +z: emits upward, away from the receiver.
        let emission = AreaEmission {
            l: Rgb::splat(10.0),
            two_sided: false,
        };
        b.add_quad(
            Vec3::new(-0.5, -0.5, 1.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            m,
            Some(emission),
        )
        .unwrap();
    });
    for strategy in Strategy::ALL {
        let (mean, _) = estimate(&s, strategy, PatternKind::Random, 1);
        assert_eq!(mean, 0.0, "{strategy}: light leaks from its back side");
    }
}
