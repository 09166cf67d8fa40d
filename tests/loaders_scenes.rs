//! The OBJ and glTF scenes under ../shared/scenes load and render plausibly at 64×64.
//! (These tests need ../shared; their assertion messages say so when it is missing.)

use glam::{UVec2, Vec3};
use penumbra::image::Image;
use penumbra::integrator::{RenderOptions, render};
use penumbra::lights::{Light, LightSource};
use penumbra::scene::Scene;
use penumbra::scene::load::{LoadOptions, load};
use penumbra::scene::view::ViewOptions;
use std::path::PathBuf;

fn shared(rel: &str) -> String {
    let p: PathBuf = [env!("CARGO_MANIFEST_DIR"), "..", "shared", "scenes", rel]
        .iter()
        .collect();
    assert!(
        p.exists(),
        "{} is missing: these tests need the shared scenes in ../shared/scenes",
        p.display()
    );
    p.display().to_string()
}

/// Centre of all area lights (their bounding boxes).
fn light_centre(scene: &Scene) -> Vec3 {
    let mut sum = Vec3::ZERO;
    let mut n = 0.0;
    for l in &scene.lights {
        if let Some(b) = l.bounds() {
            sum += 0.5 * (b.min + b.max);
            n += 1.0;
        }
    }
    assert!(n > 0.0, "scene has no bounded lights");
    sum / n
}

/// Render at 64×64, 8 spp and check: finite, not black, brightest 4×4 block near the light.
fn check_render(scene: &Scene, what: &str) {
    let res = UVec2::new(64, 64);
    let opts = RenderOptions {
        spp: 8,
        ..Default::default()
    };
    let (img, stats) = render(scene, res, &opts).expect("render");
    assert_eq!(stats.non_finite, 0, "{what}: non-finite samples");
    assert!(
        img.pixels.iter().all(|p| p.is_finite()),
        "{what}: non-finite pixel"
    );
    let mean: f32 = img.pixels.iter().map(|p| p.x + p.y + p.z).sum::<f32>() / (3.0 * 4096.0);
    eprintln!("{what}: mean {mean}");
    assert!(mean > 1e-3, "{what}: image is black (mean {mean})");
    let (bx, by) = brightest_block(&img, 4);
    let light_px = scene
        .camera
        .project(light_centre(scene), res)
        .expect("light is behind the camera");
    let centre = glam::Vec2::new(bx as f32 + 2.0, by as f32 + 2.0);
    let d = centre.distance(light_px);
    assert!(
        d < 8.0,
        "{what}: brightest block at {centre} but the light projects to {light_px} (distance {d})"
    );
}

/// Top-left corner of the brightest `k`×`k` block.
fn brightest_block(img: &Image, k: u32) -> (u32, u32) {
    let mut best = (f32::MIN, 0, 0);
    for y in 0..=img.height - k {
        for x in 0..=img.width - k {
            let mut s = 0.0;
            for j in 0..k {
                for i in 0..k {
                    let p = img.pixels[((y + j) * img.width + x + i) as usize];
                    s += p.x + p.y + p.z;
                }
            }
            if s > best.0 {
                best = (s, x, y);
            }
        }
    }
    (best.1, best.2)
}

#[test]
fn mcguire_obj_loads_and_renders() {
    let loaded = load(
        &shared("cornell-box-mcguire-obj/CornellBox-Original.obj"),
        &LoadOptions::default(),
    )
    .expect("load");
    // Ke on the light quad only: two triangles, each its own light.
    assert_eq!(loaded.scene.lights.len(), 2);
    assert!(
        loaded
            .scene
            .lights
            .iter()
            .all(|l| matches!(l, Light::Triangle(_)))
    );
    check_render(&loaded.scene, "McGuire OBJ (auto framing)");
}

#[test]
fn tinyobjloader_obj_with_ka_emission_loads_and_renders() {
    let path = shared("cornell-box-tinyobjloader/cornell_box.obj");
    let plain = load(&path, &LoadOptions::default()).expect("load");
    assert_eq!(
        plain.scene.lights.len(),
        0,
        "without the flag Ka is not emission"
    );
    let opts = LoadOptions {
        obj_ka_emission: true,
        // The original Cornell data is viewed from −z (its open side): the classic camera.
        view: ViewOptions {
            look_from: Some(Vec3::new(278.0, 273.0, -800.0)),
            look_at: Some(Vec3::new(278.0, 273.0, 0.0)),
            up: None,
            fov: Some(37.5),
        },
        ..Default::default()
    };
    let loaded = load(&path, &opts).expect("load");
    assert_eq!(
        loaded.scene.lights.len(),
        2,
        "Ka 20 20 20 on the light quad"
    );
    check_render(&loaded.scene, "tinyobjloader OBJ (--obj-ka-emission)");
}

#[test]
fn tinyobjloader_box_auto_framing_looks_into_the_open_side() {
    // No camera in the file and the box is open toward −z: automatic framing must look in.
    let path = shared("cornell-box-tinyobjloader/cornell_box.obj");
    let opts = LoadOptions {
        obj_ka_emission: true,
        ..Default::default()
    };
    let loaded = load(&path, &opts).expect("load");
    check_render(&loaded.scene, "tinyobjloader OBJ (automatic framing)");
    let eye = loaded.scene.camera.camera_to_world.point(Vec3::ZERO);
    assert!(eye.z < 0.0, "the eye {eye} is not on the open (−z) side");
}

#[test]
fn bevy_glb_loads_and_renders() {
    let loaded = load(
        &shared("cornell-box-gltf-bevy/CornellBox.glb"),
        &LoadOptions::default(),
    )
    .expect("load");
    assert!(
        !loaded.scene.lights.is_empty(),
        "emissive light mesh became area lights"
    );
    if let Light::Triangle(t) = &loaded.scene.lights[0] {
        // emissiveFactor 1 × KHR_materials_emissive_strength 100.
        assert!(
            (t.l - Vec3::splat(100.0)).abs().max_element() < 1e-3,
            "emission {}",
            t.l
        );
    } else {
        panic!("expected triangle lights");
    }
    check_render(&loaded.scene, "bevy CornellBox.glb (auto framing)");
}
