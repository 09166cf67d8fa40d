//! Which side of a sphere, disk or cylinder faces out under a mirroring transform, and to which
//! side its one-sided area light emits.
//!
//! The independent answer is pbrt-v4's rule for quadrics (the book's
//! `InteractionFromIntersection`): the object-space normal ∂p/∂u × ∂p/∂v is negated when
//! `ReverseOrientation` XOR the object-to-render transform swaps handedness, and then carried
//! to render space as a normal (inverse transpose), which keeps its side of the surface. So a
//! mirrored sphere's normal points inward and its one-sided light is seen from inside only
//! (ReverseOrientation turns it back out). The light's own samples must agree with what a ray
//! that hits it sees.

mod render_support;

use glam::{Vec2, Vec3};
use penumbra::geometry::{Ray, RayQuery};
use penumbra::lights::{Emitter, LightSampleContext, LightSource, SamplingMode};
use penumbra::scene::Scene;
use render_support::pbrt_world;

/// pbrt-v4's render-space normal: `n_obj` through the inverse transpose of `m`, negated for
/// ReverseOrientation XOR a handedness swap.
fn pbrt_v4_normal(m: glam::Mat3, n_obj: Vec3, reverse: bool) -> Vec3 {
    let n = m.inverse().transpose() * n_obj;
    let swaps = m.determinant() < 0.0;
    if reverse ^ swaps { -n } else { n }.normalize()
}

/// From `eye`, looking at `target` on the shape: the hit normal, the radiance the hit shows
/// toward the eye, and whether the light's own samples from `eye` carry any radiance.
fn look(scene: &Scene, eye: Vec3, target: Vec3) -> (Vec3, f32, f32) {
    let d = (target - eye).normalize();
    let h = scene.geometry.intersect(&Ray::new(eye, d)).expect("hit");
    assert!((h.p - target).length() < 1e-4, "hit {} want {target}", h.p);
    let light = &scene.lights[h.light as usize];
    let seen = light.radiance(h.p, h.ng, h.uv, -d).max_element();
    let ctx = LightSampleContext {
        p: eye,
        n: Vec3::ZERO,
    };
    let mut sampled = 0.0f32;
    for i in 0..64 {
        for j in 0..8 {
            let u = Vec2::new((i as f32 + 0.5) / 64.0, (j as f32 + 0.5) / 8.0);
            for mode in [SamplingMode::Area, SamplingMode::SolidAngle] {
                if let Some(s) = light.sample_li(&ctx, u, mode) {
                    sampled = sampled.max(s.li.max_element() * (s.pdf > 0.0) as i32 as f32);
                }
            }
        }
    }
    (h.ng, seen, sampled)
}

const LIGHT: &str = "AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n";

#[test]
fn mirrored_quadric_lights_follow_pbrt_v4_orientation() {
    // (shape, object-space outward normal at object point q, world target, eye)
    let mirror = glam::Mat3::from_diagonal(Vec3::new(-1.0, 1.0, 1.0));
    let cases = [
        (
            "Shape \"sphere\" \"float radius\" 1",
            (|q: Vec3| q) as fn(Vec3) -> Vec3,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(4.0, 0.0, 0.0),
        ),
        (
            "Shape \"disk\" \"float radius\" 1",
            |_| Vec3::Z,
            Vec3::new(0.2, 0.1, 0.0),
            Vec3::new(0.2, 0.1, 3.0),
        ),
        (
            "Shape \"cylinder\" \"float radius\" 1 \"float zmin\" -1 \"float zmax\" 1",
            |q| Vec3::new(q.x, q.y, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(4.0, 0.0, 0.0),
        ),
    ];
    for (shape, n_obj, target, eye) in cases {
        for (m, xf) in [(glam::Mat3::IDENTITY, ""), (mirror, "Scale -1 1 1\n")] {
            for reverse in [false, true] {
                let ro = if reverse { "ReverseOrientation\n" } else { "" };
                let what = format!("{shape} {xf:?} {ro:?}");
                let (scene, _) = pbrt_world(&format!(
                    "AttributeBegin\n{xf}{ro}{LIGHT}{shape}\nAttributeEnd"
                ));
                let want = pbrt_v4_normal(m, n_obj(m.inverse() * target), reverse);
                let (ng, seen, sampled) = look(&scene, eye, target);
                // The cylinder light is a tessellation: its facets' normals are within
                // π/CYLINDER_LIGHT_SEGMENTS of the analytic one.
                assert!(ng.dot(want) > 0.98, "{what}: normal {ng}, pbrt-v4 {want}");
                let faces_eye = want.dot(eye - target) > 0.0;
                assert_eq!(seen > 0.0, faces_eye, "{what}: radiance seen {seen}");
                assert_eq!(sampled > 0.0, faces_eye, "{what}: light samples {sampled}");
            }
        }
    }
}

#[test]
fn two_sided_sphere_lights_emit_inside_and_out() {
    let (scene, warnings) = pbrt_world(
        "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1] \"bool twosided\" true\n\
         Shape \"sphere\" \"float radius\" 1\nAttributeEnd",
    );
    assert!(
        !warnings.iter().any(|w| w.contains("sphere")),
        "{warnings:?}"
    );
    // From outside: the near side; from the centre: the inside of the far side.
    for (eye, target) in [
        (Vec3::new(4.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0)),
        (Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0)),
    ] {
        let (_, seen, sampled) = look(&scene, eye, target);
        assert!(seen > 0.0 && sampled > 0.0, "eye {eye}: {seen} {sampled}");
    }
}
