//! glTF `alphaMode` through the loader: a `MASK` material whose base-colour texture is
//! transparent on its left half is a cut-out there (rays pass) and solid on the right; a
//! `BLEND` material of factor alpha 0.25 stops 0.25 of the rays (5σ binomial bound); `OPAQUE`
//! ignores the texture's alpha, as the spec says.

mod gltf_support;

use glam::Vec3;
use gltf_support::base64;
use penumbra::geometry::{Ray, RayQuery};
use penumbra::scene::gltf::load_gltf;
use penumbra::scene::load::LoadOptions;
use std::path::PathBuf;

/// A 4 × 1 RGBA PNG, white, alpha 0 in the left two texels and 255 in the right two.
fn half_transparent_png() -> Vec<u8> {
    let mut img = image::RgbaImage::new(4, 1);
    for x in 0..4 {
        let a = if x < 2 { 0 } else { 255 };
        img.put_pixel(x, 0, image::Rgba([255, 255, 255, a]));
    }
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .expect("encode png");
    out.into_inner()
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
        png = base64(&half_transparent_png()),
        len = bin.len(),
        buf = base64(&bin),
    );
    let dir = std::env::temp_dir().join(format!("penumbra-gltf-alpha-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    let p = dir.join(name);
    std::fs::write(&p, json).expect("write glTF");
    p
}

/// For rays straight down through the points (x, y) of the quad, whether each hits.
fn hits(file: &PathBuf, points: &[(f32, f32)]) -> Vec<bool> {
    let loaded = load_gltf(file, &LoadOptions::default()).expect("loads");
    points
        .iter()
        .map(|&(x, y)| {
            let r = Ray::new(Vec3::new(x, y, 1.0), Vec3::new(0.0, 0.0, -1.0));
            loaded.scene.geometry.intersect(&r).is_some()
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
    let f = quad_file("mask.gltf", texture);
    assert!(
        hits(&f, &grid((0.15, 0.35))).iter().all(|h| !h),
        "transparent half hit"
    );
    assert!(
        hits(&f, &grid((0.65, 0.85))).iter().all(|&h| h),
        "opaque half missed"
    );
    // A cutoff above every α cuts the whole quad; OPAQUE ignores α.
    let f = quad_file(
        "cutoff.gltf",
        r#""baseColorTexture": {"index": 0}}, "alphaMode": "MASK", "alphaCutoff": 1.5"#,
    );
    assert!(hits(&f, &grid((0.65, 0.85))).iter().all(|h| !h));
    let f = quad_file(
        "opaque.gltf",
        r#""baseColorTexture": {"index": 0}}, "alphaMode": "OPAQUE""#,
    );
    assert!(hits(&f, &grid((0.15, 0.35))).iter().all(|&h| h));
}

#[test]
fn blend_stops_its_alpha_fraction() {
    let f = quad_file(
        "blend.gltf",
        r#""baseColorFactor": [1, 1, 1, 0.25]}, "alphaMode": "BLEND""#,
    );
    let mut points = Vec::new();
    for i in 0..200 {
        for j in 0..200 {
            points.push(((i as f32 + 0.5) / 200.0, (j as f32 + 0.5) / 200.0));
        }
    }
    let n = points.len() as f64;
    let hit = hits(&f, &points).iter().filter(|&&h| h).count() as f64 / n;
    let sigma = (0.25 * 0.75 / n).sqrt();
    eprintln!("blend 0.25: stopped {hit:.4} ± {sigma:.4}");
    assert!(
        (hit - 0.25).abs() < 5.0 * sigma,
        "stopped {hit}, expected 0.25"
    );
}
