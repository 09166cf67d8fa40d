//! Mesh repair (issue 16 item 4): every mesh source (pbrt trianglemesh / plymesh /
//! bilinearmesh, OBJ, glTF) replaces NaN, infinite or zero-length shading normals by the
//! geometric normal, drops zero-area triangles and triangles with a non-finite vertex, drops
//! empty meshes, and says so in one warning per mesh naming file and line with the counts. A
//! mesh with nothing left is dropped; a scene with nothing left at all is still an error.

mod gltf_support;

use glam::{UVec2, Vec3};
use gltf_support::base64;
use penumbra::geometry::{Ray, RayQuery};
use penumbra::integrator::{RenderOptions, render};
use penumbra::scene::Scene;
use penumbra::scene::load::{LoadOptions, Loaded, load};
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("penumbra-repair-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("create scratch dir");
    d
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).expect("write test file");
    p
}

/// A binary little-endian PLY with positions, normals and triangle faces.
fn ply(positions: &[[f32; 3]], normals: &[[f32; 3]], tris: &[[u32; 3]]) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        positions.len(),
        tris.len()
    )
    .into_bytes();
    for (p, n) in positions.iter().zip(normals) {
        for c in p.iter().chain(n) {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in tris {
        out.push(3);
        for i in t {
            out.extend_from_slice(&(*i as i32).to_le_bytes());
        }
    }
    out
}

/// A 2×2 quad in the z = 0 plane facing +z, as two triangles.
const QUAD_P: [[f32; 3]; 4] = [
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];
const QUAD_T: [[u32; 3]; 2] = [[0, 1, 2], [0, 2, 3]];

/// A camera on +z looking at the origin and a point light in front of the quad.
const HEADER: &str = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n\
Film \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 32\nWorldBegin\n\
LightSource \"point\" \"point3 from\" [0 0 3] \"rgb I\" [5 5 5]\n";

fn load_ok(p: &Path) -> Loaded {
    load(p.to_str().expect("utf8"), &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{} must load (it can be repaired): {e:#}", p.display()))
}

/// The one warning that names `file:line` and contains every part of `want`.
fn warning_at<'a>(l: &'a Loaded, at: &str, want: &[&str]) -> &'a str {
    let hits: Vec<&String> = l
        .warnings
        .iter()
        .filter(|w| w.contains(at) && want.iter().all(|p| w.contains(p)))
        .collect();
    assert_eq!(
        hits.len(),
        1,
        "want exactly one warning at {at} saying {want:?}, got {:?}",
        l.warnings
    );
    hits[0]
}

/// Mean of a small render (finite, and the repaired surfaces are lit).
fn mean_of(scene: &Scene) -> f64 {
    let (img, stats) = render(
        scene,
        UVec2::new(24, 24),
        &RenderOptions {
            spp: 2,
            progress: false,
            ..Default::default()
        },
    )
    .expect("render");
    assert_eq!(stats.non_finite, 0, "non-finite samples");
    img.mean()
}

/// Shading normal seen by a ray from +z at (x, y).
fn normal_at(scene: &Scene, x: f32, y: f32) -> Vec3 {
    let hit = scene
        .geometry
        .intersect(&Ray {
            o: Vec3::new(x, y, 5.0),
            d: Vec3::NEG_Z,
            t_max: f32::INFINITY,
        })
        .expect("the quad is hit");
    hit.ns
}

#[test]
fn plymesh_with_nan_normals_renders_with_the_geometric_normal() {
    // Bitterli's lamp: some PLY vertex normals are NaN.
    let d = scratch("lamp");
    let nan = f32::NAN;
    let normals = [
        [nan, nan, nan],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    write(&d, "lamp.ply", &ply(&QUAD_P, &normals, &QUAD_T));
    let scene = format!("{HEADER}Shape \"plymesh\" \"string filename\" \"lamp.ply\"\n");
    let p = write(&d, "lamp.pbrt", scene.as_bytes());
    let l = load_ok(&p);
    warning_at(
        &l,
        "lamp.pbrt:6:",
        &["lamp.ply", "2 of 4 vertex normals", "geometric normal"],
    );
    for (x, y) in [(-0.9, -0.8), (0.5, 0.5), (0.8, -0.5)] {
        let n = normal_at(&l.scene, x, y);
        assert!(
            (n - Vec3::Z).length() < 1e-4,
            "shading normal {n} at ({x}, {y})"
        );
    }
    assert!(mean_of(&l.scene) > 1e-3, "the repaired lamp renders black");
}

#[test]
fn all_zero_area_plymesh_is_dropped_and_the_rest_renders() {
    // Bitterli's staircase: PLYs whose every triangle has zero area.
    let d = scratch("staircase");
    let flat = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [3.0, 0.0, 0.0],
    ];
    write(&d, "flat.ply", &ply(&flat, &[[0.0, 0.0, 1.0]; 4], &QUAD_T));
    write(
        &d,
        "good.ply",
        &ply(&QUAD_P, &[[0.0, 0.0, 1.0]; 4], &QUAD_T),
    );
    let scene = format!(
        "{HEADER}Shape \"plymesh\" \"string filename\" \"flat.ply\"\n\
         Shape \"plymesh\" \"string filename\" \"good.ply\"\n"
    );
    let p = write(&d, "stairs.pbrt", scene.as_bytes());
    let l = load_ok(&p);
    warning_at(
        &l,
        "stairs.pbrt:6:",
        &["flat.ply", "2 of 2 triangles", "zero area", "dropped"],
    );
    assert!(
        !l.warnings.iter().any(|w| w.contains("stairs.pbrt:7:")),
        "{:?}",
        l.warnings
    );
    assert_eq!(l.scene.geometry.len(), 2, "only the good quad is left");
    assert!(mean_of(&l.scene) > 1e-3);
}

#[test]
fn trianglemesh_and_bilinearmesh_drop_non_finite_and_degenerate_triangles() {
    let d = scratch("trianglemesh");
    // Triangle 0 is fine, 1 references the infinite vertex 4, 2 has zero area.
    let scene = format!(
        "{HEADER}Shape \"trianglemesh\" \"point3 P\" [-1 -1 0 1 -1 0 1 1 0 2 2 0 1e39 0 0]\n\
         \"integer indices\" [0 1 2 0 1 4 0 2 3]\n\
         Shape \"bilinearmesh\" \"point3 P\" [-1 -1 0.5 1 -1 0.5 -1 1 0.5 1 1 0.5]\n\
         \"normal N\" [0 0 0 0 0 1 0 0 1 0 0 1]\n"
    );
    let p = write(&d, "tm.pbrt", scene.as_bytes());
    let l = load_ok(&p);
    warning_at(
        &l,
        "tm.pbrt:6:",
        &[
            "1 of 3 triangles",
            "zero area",
            "1 of 3 triangles",
            "non-finite",
        ],
    );
    warning_at(&l, "tm.pbrt:8:", &["1 of 4 vertex normals"]);
    // The good triangle and the bilinear mesh's one patch (a true bilinear patch, not two
    // triangles).
    assert_eq!(l.scene.geometry.len(), 2);
}

#[test]
fn empty_plymesh_is_dropped_with_a_warning() {
    let d = scratch("empty-ply");
    write(&d, "empty.ply", &ply(&[], &[], &[]));
    write(
        &d,
        "good.ply",
        &ply(&QUAD_P, &[[0.0, 0.0, 1.0]; 4], &QUAD_T),
    );
    let scene = format!(
        "{HEADER}Shape \"plymesh\" \"string filename\" \"empty.ply\"\n\
         Shape \"plymesh\" \"string filename\" \"good.ply\"\n"
    );
    let p = write(&d, "e.pbrt", scene.as_bytes());
    let l = load_ok(&p);
    warning_at(&l, "e.pbrt:6:", &["empty.ply", "no triangles", "dropped"]);
}

#[test]
fn obj_nan_normals_and_degenerate_faces_are_repaired_with_line_numbers() {
    let d = scratch("obj");
    let obj = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nv 2 2 0\n\
               vn nan nan nan\nvn 0 0 1\n\
               o lamp\nf 1//1 2//2 3//2\nf 1//2 3//2 4//2\n\
               o flat\nf 1//2 3//2 5//2\n\
               o good\nv -5 -5 0\nv -4 -5 0\nv -5 -4 0\nf 6 7 8\n";
    let p = write(&d, "r.obj", obj.as_bytes());
    let l = load_ok(&p);
    warning_at(
        &l,
        "r.obj:9:",
        &["lamp", "vertex normal", "geometric normal"],
    );
    warning_at(
        &l,
        "r.obj:12:",
        &["flat", "1 of 1 triangles", "zero area", "dropped"],
    );
    assert_eq!(l.scene.geometry.len(), 3);
    let n = normal_at(&l.scene, 0.5, -0.5);
    assert!((n - Vec3::Z).length() < 1e-4, "shading normal {n}");
}

#[test]
fn obj_with_nothing_left_is_still_an_error() {
    let d = scratch("obj-nothing");
    let p = write(&d, "z.obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    let e = load(p.to_str().expect("utf8"), &LoadOptions::default())
        .err()
        .expect("nothing to render is an error");
    let msg = format!("{e:#}");
    assert!(msg.contains("z.obj:4:"), "{msg}");
}

/// glTF with one triangle-pair primitive: NaN normal on vertex 0, plus a zero-area triangle.
fn gltf_with_bad_normals() -> Vec<u8> {
    let nan = f32::NAN;
    let pos: [[f32; 3]; 5] = [
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
        [2.0, 2.0, 0.0],
    ];
    let nrm: [[f32; 3]; 5] = [
        [nan, nan, nan],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 1.0],
    ];
    let idx: [u16; 9] = [0, 1, 2, 0, 2, 3, 0, 2, 4];
    let mut bin = Vec::new();
    for v in pos.iter().chain(&nrm) {
        for c in v {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in idx {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let b64 = base64(&bin);
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
  "nodes": [{{"mesh": 0}}],
  "meshes": [{{"name": "lamp", "primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1}}, "indices": 2}}]}}],
  "buffers": [{{"byteLength": {}, "uri": "data:application/octet-stream;base64,{b64}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 60}},
                  {{"buffer": 0, "byteOffset": 60, "byteLength": 60}},
                  {{"buffer": 0, "byteOffset": 120, "byteLength": 18}}],
  "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 5, "type": "VEC3", "min": [-1, -1, 0], "max": [2, 2, 0]}},
                {{"bufferView": 1, "componentType": 5126, "count": 5, "type": "VEC3"}},
                {{"bufferView": 2, "componentType": 5123, "count": 9, "type": "SCALAR"}}],
  "extensionsUsed": ["KHR_lights_punctual"],
  "extensions": {{"KHR_lights_punctual": {{"lights": [{{"type": "point", "intensity": 6830}}]}}}}
}}"#,
        bin.len()
    )
    .replace(
        r#""nodes": [{"mesh": 0}]"#,
        r#""nodes": [{"mesh": 0}, {"translation": [0, 0, 3], "extensions": {"KHR_lights_punctual": {"light": 0}}}]"#,
    )
    .replace(r#""scenes": [{"nodes": [0]}]"#, r#""scenes": [{"nodes": [0, 1]}]"#)
    .into_bytes()
}

#[test]
fn gltf_nan_normals_and_degenerate_triangles_are_repaired() {
    let d = scratch("gltf");
    let p = write(&d, "lamp.gltf", &gltf_with_bad_normals());
    let l = load_ok(&p);
    warning_at(
        &l,
        "lamp.gltf",
        &[
            "lamp",
            "1 of 5 vertex normals",
            "1 of 3 triangles",
            "zero area",
        ],
    );
    assert_eq!(l.scene.geometry.len(), 2);
    let n = normal_at(&l.scene, -0.9, -0.5);
    assert!((n - Vec3::Z).length() < 1e-4, "shading normal {n}");
}
