//! `many-street`, the realistic many-light built-in: tens of thousands of emissive triangles of
//! very different power, most of them hidden from the camera by buildings, generated the same
//! way every time and quickly.

use penumbra::geometry::{Ray, RayQuery};
use penumbra::lights::{Light, LightSource};
use penumbra::scene::builtin::{BuiltinOptions, find};
use std::time::Instant;

fn build(opts: &BuiltinOptions) -> penumbra::scene::Scene {
    (find("many-street")
        .expect("many-street is a built-in")
        .build)(opts)
    .unwrap()
}

#[test]
fn many_street_has_10k_to_100k_triangle_lights_of_very_different_power() {
    let t = Instant::now();
    let scene = build(&BuiltinOptions::default());
    let secs = t.elapsed().as_secs_f64();
    let n = scene.lights.len();
    eprintln!(
        "many-street: {n} lights, {} primitives, built in {secs:.3} s",
        scene.geometry.len()
    );
    assert!((10_000..=100_000).contains(&n), "{n} lights");
    assert!(
        scene.lights.iter().all(|l| matches!(l, Light::Triangle(_))),
        "every emitter is a mesh triangle"
    );
    let powers: Vec<f32> = scene.lights.iter().map(|l| l.power()).collect();
    assert!(powers.iter().all(|&p| p.is_finite() && p > 0.0));
    let (lo, hi) = powers
        .iter()
        .fold((f32::MAX, 0.0f32), |(a, b), &p| (a.min(p), b.max(p)));
    // Tail-light strips to street lamps: several orders of magnitude per triangle.
    eprintln!("many-street: triangle powers {lo:.3} to {hi:.1}");
    assert!(hi / lo > 1e3, "power range {lo}..{hi}");
    // Generous for a loaded machine; alone it takes well under a second (including both BVHs).
    assert!(secs < 5.0, "built in {secs} s");
}

#[test]
fn many_street_is_the_same_scene_every_time() {
    let key = |s: &penumbra::scene::Scene| -> Vec<[u32; 7]> {
        s.lights
            .iter()
            .map(|l| {
                let b = l.bounds().unwrap();
                [
                    l.power().to_bits(),
                    b.min.x.to_bits(),
                    b.min.y.to_bits(),
                    b.min.z.to_bits(),
                    b.max.x.to_bits(),
                    b.max.y.to_bits(),
                    b.max.z.to_bits(),
                ]
            })
            .collect()
    };
    let a = build(&BuiltinOptions::default());
    let b = build(&BuiltinOptions::default());
    assert_eq!(a.geometry.len(), b.geometry.len());
    assert!(key(&a) == key(&b), "two builds differ");
}

#[test]
fn many_street_hides_most_lights_from_the_camera() {
    let scene = build(&BuiltinOptions::default());
    let eye = scene.camera.camera_to_world.point(glam::Vec3::ZERO);
    let mut visible = 0;
    for l in &scene.lights {
        let b = l.bounds().unwrap();
        // Just in front of the emitter's centre, so the emitter itself does not block.
        let target = 0.5 * (b.min + b.max) + b.w * 0.01;
        let d = target - eye;
        let ray = Ray {
            o: eye,
            d: d.normalize(),
            t_max: d.length() * 0.999,
        };
        let faces_eye = b.w.dot(-d) > 0.0;
        if faces_eye && !scene.geometry.occluded(&ray) {
            visible += 1;
        }
    }
    let n = scene.lights.len();
    eprintln!("many-street: {visible} of {n} light centres seen from the eye");
    assert!(visible > 50, "only {visible} lights visible");
    // Looking down a street one sees its facades (about one light in seven); the rest of the
    // city is behind the buildings.
    assert!(visible * 5 < n, "{visible} of {n} lights visible");
    assert!(eye.y > 1.0 && eye.y < 2.0, "eye at street level: {eye}");
}

#[test]
fn many_street_light_count_scales_the_city() {
    let small = build(&BuiltinOptions {
        light_count: Some(1000),
        ..Default::default()
    });
    let large = build(&BuiltinOptions {
        light_count: Some(60_000),
        ..Default::default()
    });
    let (s, l) = (small.lights.len(), large.lights.len());
    assert!((300..3000).contains(&s), "--light-count 1000 gave {s}");
    assert!(
        (40_000..90_000).contains(&l),
        "--light-count 60000 gave {l}"
    );
}
