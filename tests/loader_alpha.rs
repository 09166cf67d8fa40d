//! Cut-outs from the glTF and OBJ loaders. glTF `alphaMode`: a `MASK` material whose
//! base-colour texture is transparent on its left half is a cut-out there (rays pass) and
//! solid on the right; a `BLEND` material of factor alpha 0.25 stops 0.25 of the rays (5σ
//! binomial bound); `OPAQUE` ignores the texture's alpha, as the spec says. MTL: `d 0.25`
//! stops 0.25; `map_d` cuts where the mask is 0, read from the alpha channel of an RGBA image
//! or the grey level of a grey one; `d 0` is said, with its line.

mod gltf_support;

use glam::Vec3;
use gltf_support::base64;
use penumbra::geometry::{Ray, RayQuery};
use penumbra::scene::Scene;
use penumbra::scene::gltf::load_gltf;
use penumbra::scene::load::LoadOptions;
use penumbra::scene::obj::load_obj;
use std::path::{Path, PathBuf};

/// A 4 × 1 PNG, 0 in the left two texels and 255 in the right two: in the alpha channel of a
/// white RGBA image (`rgba`), or as the grey level of a grey image.
fn half_png(rgba: bool) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    let level = |x: u32| if x < 2 { 0 } else { 255 };
    if rgba {
        image::RgbaImage::from_fn(4, 1, |x, _| image::Rgba([255, 255, 255, level(x)]))
            .write_to(&mut out, image::ImageFormat::Png)
    } else {
        image::GrayImage::from_fn(4, 1, |x, _| image::Luma([level(x)]))
            .write_to(&mut out, image::ImageFormat::Png)
    }
    .expect("encode png");
    out.into_inner()
}

/// A fresh scratch folder for this test process.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("penumbra-alpha-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch dir");
    d
}

/// The unit quad [0, 1]² at z = 0 (uv = (x, 1 − y), glTF's top-left origin) with material
/// parameters `material` (JSON object members after `pbrMetallicRoughness`), as a `.gltf` file
/// with embedded buffer and image.
fn quad_file(name: &str, material: &str) -> PathBuf {
    let mut bin = Vec::new();
    for p in [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ] {
        bin.extend(p.iter().flat_map(|c| c.to_le_bytes()));
    }
    for t in [[0.0f32, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]] {
        bin.extend(t.iter().flat_map(|c| c.to_le_bytes()));
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend(i.to_le_bytes());
    }
    let json = format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2, "material": 0}}]}}],
  "materials": [{{"pbrMetallicRoughness": {{"metallicFactor": 0, {material}}}],
  "textures": [{{"source": 0}}],
  "images": [{{"uri": "data:image/png;base64,{png}"}}],
  "buffers": [{{"byteLength": {len}, "uri": "data:application/octet-stream;base64,{buf}"}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
    {{"buffer": 0, "byteOffset": 48, "byteLength": 32}},
    {{"buffer": 0, "byteOffset": 80, "byteLength": 12}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
    {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}}
  ]
}}"#,
        png = base64(&half_png(true)),
        len = bin.len(),
        buf = base64(&bin),
    );
    let p = scratch(name).join("quad.gltf");
    std::fs::write(&p, json).expect("write glTF");
    p
}

/// The scene of glTF file `file`.
fn gltf(file: &Path) -> Scene {
    load_gltf(file, &LoadOptions::default())
        .expect("loads")
        .scene
}

/// For rays straight down through the points (x, y) of the quad, whether each hits.
fn hits(scene: &Scene, points: &[(f32, f32)]) -> Vec<bool> {
    points
        .iter()
        .map(|&(x, y)| {
            let r = Ray::new(Vec3::new(x, y, 1.0), Vec3::new(0.0, 0.0, -1.0));
            scene.geometry.intersect(&r).is_some()
        })
        .collect()
}

/// A 21 × 21 grid of points with x in `xs` (inside texel runs, away from the bilinear ramps).
fn grid(xs: (f32, f32)) -> Vec<(f32, f32)> {
    let mut v = Vec::new();
    for i in 0..21 {
        for j in 0..21 {
            let x = xs.0 + (xs.1 - xs.0) * i as f32 / 20.0;
            v.push((x, 0.02 + 0.96 * j as f32 / 20.0));
        }
    }
    v
}

#[test]
fn mask_cuts_where_the_texture_is_transparent() {
    let texture = r#""baseColorTexture": {"index": 0}}, "alphaMode": "MASK""#;
    let f = quad_file("mask", texture);
    assert!(
        hits(&gltf(&f), &grid((0.15, 0.35))).iter().all(|h| !h),
        "transparent half hit"
    );
    assert!(
        hits(&gltf(&f), &grid((0.65, 0.85))).iter().all(|&h| h),
        "opaque half missed"
    );
    // A cutoff above every α cuts the whole quad; OPAQUE ignores α.
    let f = quad_file(
        "cutoff",
        r#""baseColorTexture": {"index": 0}}, "alphaMode": "MASK", "alphaCutoff": 1.5"#,
    );
    assert!(hits(&gltf(&f), &grid((0.65, 0.85))).iter().all(|h| !h));
    let f = quad_file(
        "opaque",
        r#""baseColorTexture": {"index": 0}}, "alphaMode": "OPAQUE""#,
    );
    assert!(hits(&gltf(&f), &grid((0.15, 0.35))).iter().all(|&h| h));
}

#[test]
fn blend_stops_its_alpha_fraction() {
    let f = quad_file(
        "blend",
        r#""baseColorFactor": [1, 1, 1, 0.25]}, "alphaMode": "BLEND""#,
    );
    check_stopped("glTF BLEND 0.25", &gltf(&f), 0.25);
}

/// The fraction of 40,000 rays spread over the quad that `scene` stops is `want` within 5σ.
fn check_stopped(what: &str, scene: &Scene, want: f64) {
    let mut points = Vec::new();
    for i in 0..200 {
        for j in 0..200 {
            points.push(((i as f32 + 0.5) / 200.0, (j as f32 + 0.5) / 200.0));
        }
    }
    let n = points.len() as f64;
    let hit = hits(scene, &points).iter().filter(|&&h| h).count() as f64 / n;
    let sigma = (want * (1.0 - want) / n).sqrt();
    eprintln!("{what}: stopped {hit:.4} ± {sigma:.4}");
    assert!(
        (hit - want).abs() < 5.0 * sigma,
        "{what}: stopped {hit}, expected {want}"
    );
}

/// The unit quad as an OBJ (uv = (x, y)) with the MTL material body `mtl`, and `mask.png`
/// (see [`half_png`]) beside it; the scene and the loader's warnings.
fn obj_quad(name: &str, mtl: &str, rgba_mask: bool) -> (Scene, Vec<String>) {
    let d = scratch(name);
    std::fs::write(d.join("mask.png"), half_png(rgba_mask)).expect("write mask");
    std::fs::write(
        d.join("q.mtl"),
        format!("newmtl m\nKd 0.5 0.5 0.5\n{mtl}\n"),
    )
    .expect("mtl");
    let obj = "mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
               vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3 4/4\n";
    let p = d.join("q.obj");
    std::fs::write(&p, obj).expect("write obj");
    let loaded = load_obj(&p, &LoadOptions::default()).expect("loads");
    (loaded.scene, loaded.warnings)
}

#[test]
fn mtl_dissolve_and_its_mask_cut_out() {
    let (s, _) = obj_quad("d", "d 0.25", false);
    check_stopped("MTL d 0.25", &s, 0.25);
    for rgba in [false, true] {
        let (s, w) = obj_quad("masked", "map_d mask.png", rgba);
        assert!(!w.iter().any(|w| w.contains("map_d")), "{w:?}");
        assert!(
            hits(&s, &grid((0.15, 0.35))).iter().all(|h| !h),
            "masked half hit ({rgba})"
        );
        assert!(
            hits(&s, &grid((0.65, 0.85))).iter().all(|&h| h),
            "kept half missed ({rgba})"
        );
    }
    // `d` scales the mask: half of the kept half's rays pass.
    let (s, _) = obj_quad("scaled", "d 0.5\nmap_d mask.png", false);
    let kept = hits(&s, &grid((0.65, 0.85)));
    let f = kept.iter().filter(|&&h| h).count() as f64 / kept.len() as f64;
    assert!(
        (f - 0.5).abs() < 5.0 * (0.25 / kept.len() as f64).sqrt(),
        "stopped {f}"
    );
    // A fully transparent material is said, at its line.
    let (_, w) = obj_quad("d0", "d 0", false);
    assert!(
        w.iter().any(|w| w.contains("q.mtl:3") && w.contains("d 0")),
        "{w:?}"
    );
    // A missing mask is said and the material stays opaque.
    let (s, w) = obj_quad("missing", "map_d nothere.png", false);
    assert!(w.iter().any(|w| w.contains("map_d nothere.png")), "{w:?}");
    assert!(hits(&s, &grid((0.15, 0.35))).iter().all(|&h| h));
}
