//! pbrt loader through `SceneBuilder::build`: the Bitterli Cornell box builds with 8 materials
//! and 2 emissive triangles, renders the same pixels as the built-in `cornell`, and every
//! light kind converts.

use glam::UVec2;
use penumbra::integrator::{RenderOptions, render};
use penumbra::lights::Light;
use penumbra::scene::load::{LoadOptions, load};
use penumbra::scene::pbrt::{load_pbrt, parse_pbrt_str, parse_pbrt_to_builder};
use std::path::{Path, PathBuf};

fn cornell_path() -> PathBuf {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/scenes/cornell-box-bitterli/scene-v4.pbrt");
    if p.exists() {
        p
    } else {
        PathBuf::from("/work/shared/scenes/cornell-box-bitterli/scene-v4.pbrt")
    }
}

#[test]
fn cornell_builder_has_8_materials_and_2_emissive_triangles() {
    let (b, cam, film, warnings) = parse_pbrt_to_builder(&cornell_path()).unwrap();
    assert_eq!(b.materials.len(), 8);
    let tri_lights = b
        .lights
        .iter()
        .filter(|l| matches!(l, Light::Triangle(_)))
        .count();
    assert_eq!(tri_lights, 2);
    assert_eq!(b.lights.len(), 2);
    assert_eq!(cam.fov_deg, 19.5);
    assert_eq!(film.resolution, UVec2::new(1024, 1024));
    assert!(
        warnings.iter().all(|w| w.contains("warning")),
        "{warnings:?}"
    );
    let scene = b.build(cam, film).unwrap();
    assert_eq!(scene.lights.len(), 2);
}

#[test]
fn cornell_from_file_renders_the_same_pixels_as_builtin() {
    let (from_file, warnings) = load_pbrt(&cornell_path()).unwrap();
    // `Integrator "path"` is rendered as asked: no warning, and the file's depth.
    assert!(
        !warnings.iter().any(|w| w.contains("Integrator")),
        "{warnings:?}"
    );
    let spec = from_file.integrator.clone().expect("the file's Integrator");
    assert_eq!(
        (spec.kind, spec.max_depth),
        (penumbra::integrator::IntegratorKind::Path, 65)
    );
    let builtin = load("cornell", &LoadOptions::default()).unwrap().scene;
    let opts = RenderOptions {
        spp: 4,
        seed: 3,
        progress: false,
        ..RenderOptions::default()
    };
    let res = UVec2::new(48, 48);
    let (a, _) = render(&from_file, res, &opts).unwrap();
    let (b, _) = render(&builtin, res, &opts).unwrap();
    assert!(a.mean() > 0.01, "image is black: {}", a.mean());
    let maxrel = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| ((*p - *q).abs() / (q.abs() + 1e-3)).max_element())
        .fold(0.0f32, f32::max);
    eprintln!("max relative pixel difference {maxrel:e}");
    let differing = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| p != q)
        .count();
    assert_eq!(
        differing,
        0,
        "{differing} of {} pixels differ",
        a.pixels.len()
    );
    // Through the generic loader too.
    let via_load = load(cornell_path().to_str().unwrap(), &LoadOptions::default()).unwrap();
    assert_eq!(via_load.scene.materials.len(), 8);
}

#[test]
fn every_light_kind_and_shape_builds() {
    let d = std::env::temp_dir().join(format!("penumbra-pbrt-build-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let mut sky = penumbra::image::Image::new(16, 8);
    for (i, p) in sky.pixels.iter_mut().enumerate() {
        *p = penumbra::Rgb::splat(0.1 + (i % 5) as f32 * 0.1);
    }
    penumbra::image::io::write_image(&sky, &d.join("sky.exr"), 0.0).unwrap();
    let src = r#"LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective" "float fov" 40
Film "rgb" "integer xresolution" 16 "integer yresolution" 16
WorldBegin
LightSource "point" "rgb I" [1 1 1] "point3 from" [0 2 0]
LightSource "spot" "point3 from" [0 3 0] "point3 to" [0 0 0]
LightSource "distant" "rgb L" [1 1 1]
LightSource "infinite" "rgb L" [0.1 0.1 0.1]
AttributeBegin
  Rotate -90 1 0 0
  LightSource "infinite" "string filename" "sky.exr"
AttributeEnd
Material "diffuse"
Shape "sphere" "float radius" 0.5
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [4 4 4]
  Translate 0 1.5 0
  Shape "disk" "float radius" 0.3
  Translate 1 0 0
  Shape "sphere" "float radius" 0.1
AttributeEnd
Shape "bilinearmesh" "point3 P" [-2 -1 -2 2 -1 -2 -2 -1 2 2 -1 2]
"#;
    let scene = parse_pbrt_str("all.pbrt", src, &d).unwrap();
    assert_eq!(scene.lights.len(), 5);
    let (b, cam, film, _) = scene.into_builder().unwrap();
    let n_lights = b.lights.len();
    assert!(
        n_lights >= 7,
        "5 lights + emissive disk + sphere, got {n_lights}"
    );
    let scene = b.build(cam, film).unwrap();
    assert_eq!(scene.infinite_lights.len(), 2);
    let (img, stats) = render(
        &scene,
        UVec2::new(16, 16),
        &RenderOptions {
            spp: 2,
            progress: false,
            ..RenderOptions::default()
        },
    )
    .unwrap();
    assert_eq!(stats.non_finite, 0);
    assert!(img.mean() > 0.0);
}
