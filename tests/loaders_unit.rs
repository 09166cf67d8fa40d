//! Loader unit tests on small generated files: glTF camera conversion, photometric units,
//! the Ka-emission flag, automatic framing and broken inputs (errors must name the file).

mod gltf_support;

use glam::{Mat4, Quat, UVec2, Vec2, Vec3};
use gltf_support::base64;
use penumbra::lights::Light;
use penumbra::scene::gltf::{LUMENS_PER_WATT, gltf_camera, load_gltf, punctual_light};
use penumbra::scene::load::{LoadOptions, load};
use penumbra::scene::obj::load_obj;
use penumbra::scene::view::{auto_frame, right_handed_look_at};
use std::path::PathBuf;

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("penumbra-loaders-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("create scratch dir");
    d
}

fn write(dir: &std::path::Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).expect("write test file");
    p
}

fn close(a: Vec2, b: Vec2, tol: f32) -> bool {
    (a - b).abs().max_element() < tol
}

// ---------------------------------------------------------------- glTF camera conversion

/// Parent node: translation (1,2,3) and a 90° turn about +y, so the camera looks down world −x
/// and its right (+x local) is world −z.
fn camera_world() -> Mat4 {
    Mat4::from_rotation_translation(
        Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        Vec3::new(1.0, 2.0, 3.0),
    )
}

#[test]
fn gltf_camera_projects_known_points_landscape_and_square() {
    let yfov = 60f32.to_radians();
    let t = (0.5 * yfov).tan();
    let w = camera_world();
    let local = |x: f32, y: f32, z: f32| w.transform_point3(Vec3::new(x, y, z));
    let (cam, res) = gltf_camera(w, yfov, None).expect("camera");
    assert_eq!(res, UVec2::new(512, 512));
    let px = |p: Vec3| cam.project(p, res).expect("in front of the camera");
    assert!(close(
        px(local(0.0, 0.0, -5.0)),
        Vec2::new(256.0, 256.0),
        1e-2
    ));
    // Local +x is image right, local +y is image up (raster y down).
    assert!(close(
        px(local(5.0 * t, 0.0, -5.0)),
        Vec2::new(512.0, 256.0),
        1e-2
    ));
    assert!(close(
        px(local(0.0, 2.5 * t, -5.0)),
        Vec2::new(256.0, 128.0),
        1e-2
    ));
    assert!(
        cam.project(local(0.0, 0.0, 5.0), res).is_none(),
        "behind the camera"
    );

    // Landscape 2:1: yfov stays vertical, film 512×256.
    let (cam, res) = gltf_camera(w, yfov, Some(2.0)).expect("camera");
    assert_eq!(res, UVec2::new(512, 256));
    let p = cam
        .project(local(0.0, 5.0 * t, -5.0), res)
        .expect("visible");
    assert!(close(p, Vec2::new(256.0, 0.0), 1e-2), "top edge: {p}");
    let p = cam
        .project(local(10.0 * t, 0.0, -5.0), res)
        .expect("visible");
    assert!(close(p, Vec2::new(512.0, 128.0), 1e-2), "right edge: {p}");
}

#[test]
fn gltf_camera_portrait_keeps_vertical_fov() {
    // aspect 0.5: our fov spans the (shorter) horizontal axis, so it must be converted.
    let yfov = 60f32.to_radians();
    let t = (0.5 * yfov).tan();
    let w = camera_world();
    let local = |x: f32, y: f32, z: f32| w.transform_point3(Vec3::new(x, y, z));
    let (cam, res) = gltf_camera(w, yfov, Some(0.5)).expect("camera");
    assert_eq!(res, UVec2::new(256, 512));
    let top = cam
        .project(local(0.0, 5.0 * t, -5.0), res)
        .expect("visible");
    assert!(close(top, Vec2::new(128.0, 0.0), 1e-2), "top edge: {top}");
    let right = cam
        .project(local(2.5 * t, 0.0, -5.0), res)
        .expect("visible");
    assert!(
        close(right, Vec2::new(256.0, 256.0), 1e-2),
        "right edge: {right}"
    );
}

#[test]
fn gltf_camera_rejects_bad_yfov() {
    assert!(gltf_camera(Mat4::IDENTITY, f32::NAN, None).is_err());
    assert!(gltf_camera(Mat4::IDENTITY, 0.0, None).is_err());
}

// ---------------------------------------------------------------- photometric conversion

#[test]
fn punctual_lights_convert_photometric_units() {
    use gltf::khr_lights_punctual::Kind;
    let color = Vec3::new(1.0, 0.5, 0.25);
    let w = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0));
    // 2 × 683 cd → 2 W/sr.
    match punctual_light(Kind::Point, color, 2.0 * LUMENS_PER_WATT, w) {
        Light::Point(p) => {
            assert!(
                (p.intensity - 2.0 * color).abs().max_element() < 1e-6,
                "{}",
                p.intensity
            );
            assert!((p.p - Vec3::new(1.0, 2.0, 3.0)).length() < 1e-6);
        }
        other => panic!("expected a point light, got {other:?}"),
    }
    // Spot pointing down world −y (node rotated −90° about x turns −z into −y).
    let ws = w * Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2);
    match punctual_light(
        Kind::Spot {
            inner_cone_angle: 0.2,
            outer_cone_angle: 0.5,
        },
        color,
        LUMENS_PER_WATT,
        ws,
    ) {
        Light::Spot(s) => {
            assert!((s.intensity - color).abs().max_element() < 1e-6);
            assert!((s.dir - Vec3::NEG_Y).length() < 1e-5, "dir {}", s.dir);
            assert!((s.cos_falloff_start - 0.2f32.cos()).abs() < 1e-6);
            assert!((s.cos_total_width - 0.5f32.cos()).abs() < 1e-6);
        }
        other => panic!("expected a spot light, got {other:?}"),
    }
    // 683 lux shining down −y → 1 W/m² arriving from +y.
    match punctual_light(Kind::Directional, Vec3::ONE, LUMENS_PER_WATT, ws) {
        Light::Distant(d) => {
            assert!((d.l - Vec3::ONE).abs().max_element() < 1e-6);
            assert!(
                (d.w_light - Vec3::Y).length() < 1e-5,
                "w_light {}",
                d.w_light
            );
        }
        other => panic!("expected a distant light, got {other:?}"),
    }
}

// ---------------------------------------------------------------- automatic framing

#[test]
fn auto_framing_keeps_the_box_in_the_image() {
    let boxes = [
        (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 2.0, 1.0)),
        (Vec3::new(0.0, 0.0, 0.0), Vec3::new(552.8, 548.8, 559.2)),
        (Vec3::new(-100.0, 5.0, 3.0), Vec3::new(-99.0, 50.0, 3.5)),
    ];
    for (lo, hi) in boxes {
        let cam = auto_frame(lo, hi, 40.0).expect("framing");
        for res in [UVec2::new(64, 64), UVec2::new(128, 48), UVec2::new(40, 100)] {
            let mut max_extent: f32 = 0.0;
            for i in 0..8 {
                let c = Vec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                );
                let p = cam.project(c, res).expect("corner in front of the camera");
                assert!(
                    p.x >= 0.0 && p.y >= 0.0 && p.x <= res.x as f32 && p.y <= res.y as f32,
                    "corner {c} of box {lo}..{hi} projects to {p}, outside {res}"
                );
                max_extent = max_extent.max((p - res.as_vec2() * 0.5).abs().max_element());
            }
            // Not absurdly small either: the box spans a good part of the shorter axis.
            let short = res.x.min(res.y) as f32;
            assert!(
                max_extent > 0.15 * short,
                "box {lo}..{hi} is tiny in the image"
            );
        }
        // Centre of the box at the image centre.
        let c = cam
            .project(0.5 * (lo + hi), UVec2::new(64, 64))
            .expect("centre");
        assert!(
            close(c, Vec2::new(32.0, 32.0), 1e-2),
            "centre projects to {c}"
        );
    }
}

#[test]
fn right_handed_look_at_puts_plus_x_on_the_right() {
    // Looking from +z toward the origin with +y up (OpenGL default view): +x is image right.
    let cam =
        right_handed_look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 40.0).expect("camera");
    let res = UVec2::new(64, 64);
    let p = cam.project(Vec3::new(1.0, 0.0, 0.0), res).expect("visible");
    assert!(
        p.x > 32.5 && (p.y - 32.0).abs() < 1e-3,
        "+x projects to {p}"
    );
    let p = cam.project(Vec3::new(0.0, 1.0, 0.0), res).expect("visible");
    assert!(p.y < 31.5, "+y projects to {p}");
    assert!(right_handed_look_at(Vec3::ZERO, Vec3::ZERO, Vec3::Y, 40.0).is_err());
    assert!(right_handed_look_at(Vec3::Z, Vec3::ZERO, Vec3::Z, 40.0).is_err());
}

// ---------------------------------------------------------------- OBJ

const QUAD_OBJ: &str = "mtllib m.mtl\n\
v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\n\
v 0 1 0\nv 0 1 1\nv 1 1 1\nv 1 1 0\n\
usemtl floor\nf 1 4 3 2\n\
usemtl lamp\nf 5 8 7 6\n";

#[test]
fn obj_ka_emission_flag_turns_ambient_into_lights() {
    let d = scratch("ka");
    write(
        &d,
        "m.mtl",
        b"newmtl floor\nKd 0.5 0.5 0.5\nKa 0 0 0\nnewmtl lamp\nKd 0 0 0\nKa 3 2 1\n",
    );
    let p = write(&d, "s.obj", QUAD_OBJ.as_bytes());
    let off = load_obj(&p, &LoadOptions::default()).expect("load");
    assert_eq!(off.scene.lights.len(), 0);
    let on = load_obj(
        &p,
        &LoadOptions {
            obj_ka_emission: true,
            ..Default::default()
        },
    )
    .expect("load");
    assert_eq!(
        on.scene.lights.len(),
        2,
        "one light per triangle of the lamp quad"
    );
    for l in &on.scene.lights {
        match l {
            Light::Triangle(t) => {
                assert_eq!(t.l, Vec3::new(3.0, 2.0, 1.0));
                assert!(!t.two_sided);
            }
            other => panic!("expected triangle lights, got {other:?}"),
        }
    }
}

#[test]
fn obj_ke_is_emission_and_missing_texture_warns() {
    let d = scratch("ke");
    write(
        &d,
        "m.mtl",
        b"newmtl floor\nKd 0.5 0.5 0.5\nmap_Kd nowhere.png\nnewmtl lamp\nKd 0 0 0\nKe 4 4 4\n",
    );
    let p = write(&d, "s.obj", QUAD_OBJ.as_bytes());
    let loaded = load_obj(&p, &LoadOptions::default()).expect("missing textures only warn");
    assert_eq!(loaded.scene.lights.len(), 2);
    assert!(
        loaded.warnings.iter().any(|w| w.contains("nowhere.png")),
        "warnings: {:?}",
        loaded.warnings
    );
}

#[test]
fn obj_kd_plus_ks_is_clamped_with_a_warning() {
    let d = scratch("ks");
    write(
        &d,
        "m.mtl",
        b"newmtl floor\nKd 0.8 0.8 0.8\nKs 0.5 0.5 0.5\nNs 20\nnewmtl lamp\nKe 1 1 1\n",
    );
    let p = write(&d, "s.obj", QUAD_OBJ.as_bytes());
    let loaded = load_obj(&p, &LoadOptions::default()).expect("load");
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("floor") && w.contains("Kd + Ks")),
        "warnings: {:?}",
        loaded.warnings
    );
}

fn assert_err_names_file(r: anyhow::Result<penumbra::scene::load::Loaded>, p: &std::path::Path) {
    match r {
        Ok(_) => panic!("{} loaded but is broken", p.display()),
        Err(e) => {
            let msg = format!("{e:#}");
            let name = p.file_name().and_then(|n| n.to_str()).expect("name");
            assert!(msg.contains(name), "error does not name {name}: {msg}");
        }
    }
}

#[test]
fn broken_obj_inputs_are_errors_naming_the_file() {
    let d = scratch("broken-obj");
    let missing = d.join("missing.obj");
    assert_err_names_file(load_obj(&missing, &LoadOptions::default()), &missing);
    assert_err_names_file(
        load(missing.to_str().expect("utf8"), &LoadOptions::default()),
        &missing,
    );
    let cases: [(&str, &str); 5] = [
        ("empty.obj", ""),
        ("truncated.obj", "v 0 0 0\nv 1 0 0\nv 0 1"),
        ("badindex.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
        ("nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
        ("degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"),
    ];
    for (name, text) in cases {
        let p = write(&d, name, text.as_bytes());
        assert_err_names_file(load_obj(&p, &LoadOptions::default()), &p);
    }
}

// ---------------------------------------------------------------- glTF files

/// Binary payload: a triangle (3 × vec3 f32) and its u16 indices (padded to 4 bytes).
fn triangle_bin(indices: [u16; 3]) -> Vec<u8> {
    let mut b = Vec::new();
    for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in v {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in indices {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b.extend_from_slice(&[0, 0]);
    b
}

/// glTF JSON with the given buffer entry: a parent node (translated, rotated 90° about y)
/// holding the triangle, a perspective camera (yfov 60°, aspect 0.5) and a 683 cd point light.
fn gltf_json(buffer: &str) -> String {
    let s = std::f32::consts::FRAC_1_SQRT_2;
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "extensionsUsed": ["KHR_lights_punctual"],
  "extensions": {{"KHR_lights_punctual": {{"lights": [{{"type": "point", "color": [1, 1, 1], "intensity": 683}}]}}}},
  "scene": 0,
  "scenes": [{{"nodes": [0]}}],
  "nodes": [
    {{"translation": [1, 2, 3], "rotation": [0, {s}, 0, {s}], "children": [1, 2, 3]}},
    {{"mesh": 0, "translation": [0, 0, -5]}},
    {{"camera": 0}},
    {{"translation": [0, 1, 0], "extensions": {{"KHR_lights_punctual": {{"light": 0}}}}}}
  ],
  "cameras": [{{"type": "perspective", "perspective": {{"yfov": 1.0471976, "aspectRatio": 0.5, "znear": 0.01}}}}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}}],
  "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0.2, 0.4, 0.6, 1], "metallicFactor": 0}}, "emissiveFactor": [0.5, 0.5, 0.5]}}],
  "buffers": [{buffer}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": 36}},
    {{"buffer": 0, "byteOffset": 36, "byteLength": 6}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
    {{"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}}
  ]
}}"#
    )
}

/// A GLB container around `json` and `bin`.
fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let total = 12 + 8 + j.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x4E4F_534Au32.to_le_bytes());
    out.extend_from_slice(&j);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x004E_4942u32.to_le_bytes());
    out.extend_from_slice(bin);
    out
}

fn check_generated_scene(loaded: &penumbra::scene::load::Loaded) {
    let scene = &loaded.scene;
    assert_eq!(
        scene.film.resolution,
        UVec2::new(256, 512),
        "aspect 0.5 film"
    );
    // One emissive triangle + the point light.
    assert_eq!(scene.lights.len(), 2);
    let point = scene
        .lights
        .iter()
        .find_map(|l| match l {
            Light::Point(p) => Some(*p),
            _ => None,
        })
        .expect("point light");
    // Node chain: parent translation (1,2,3) ∘ rot_y(90°) ∘ translation (0,1,0).
    assert!(
        (point.p - Vec3::new(1.0, 3.0, 3.0)).length() < 1e-5,
        "light at {}",
        point.p
    );
    assert!((point.intensity - Vec3::ONE).abs().max_element() < 1e-6);
    // The triangle's first vertex sits 5 units straight ahead of the camera: image centre.
    let w = camera_world();
    let v0 = w.transform_point3(Vec3::new(0.0, 0.0, -5.0));
    let p = scene
        .camera
        .project(v0, scene.film.resolution)
        .expect("visible");
    assert!(
        close(p, Vec2::new(128.0, 256.0), 1e-2),
        "vertex 0 projects to {p}"
    );
}

#[test]
fn gltf_file_with_external_buffer_hierarchy_camera_and_light() {
    let d = scratch("gltf-ext");
    write(&d, "tri data.bin", &triangle_bin([0, 1, 2]));
    let p = write(
        &d,
        "s.gltf",
        gltf_json(r#"{"byteLength": 44, "uri": "tri%20data.bin"}"#).as_bytes(),
    );
    let loaded = load(p.to_str().expect("utf8"), &LoadOptions::default()).expect("load");
    check_generated_scene(&loaded);
}

#[test]
fn gltf_file_with_data_uri_and_glb_agree() {
    let d = scratch("gltf-embedded");
    let bin = triangle_bin([0, 1, 2]);
    let uri = format!(
        r#"{{"byteLength": 44, "uri": "data:application/octet-stream;base64,{}"}}"#,
        base64(&bin)
    );
    let p = write(&d, "s.gltf", gltf_json(&uri).as_bytes());
    check_generated_scene(&load_gltf(&p, &LoadOptions::default()).expect("load data uri"));
    let p = write(&d, "s.glb", &glb(&gltf_json(r#"{"byteLength": 44}"#), &bin));
    check_generated_scene(&load_gltf(&p, &LoadOptions::default()).expect("load glb"));
}

#[test]
fn broken_gltf_inputs_are_errors_naming_the_file() {
    let d = scratch("broken-gltf");
    let missing = d.join("missing.glb");
    assert_err_names_file(load_gltf(&missing, &LoadOptions::default()), &missing);
    let good = glb(
        &gltf_json(r#"{"byteLength": 44}"#),
        &triangle_bin([0, 1, 2]),
    );
    for cut in [10, good.len() / 2, good.len() - 8] {
        let p = write(&d, &format!("truncated{cut}.glb"), &good[..cut]);
        assert_err_names_file(load_gltf(&p, &LoadOptions::default()), &p);
    }
    let p = write(
        &d,
        "badindex.glb",
        &glb(
            &gltf_json(r#"{"byteLength": 44}"#),
            &triangle_bin([0, 1, 7]),
        ),
    );
    assert_err_names_file(load_gltf(&p, &LoadOptions::default()), &p);
    let p = write(
        &d,
        "nobin.gltf",
        gltf_json(r#"{"byteLength": 44, "uri": "absent.bin"}"#).as_bytes(),
    );
    assert_err_names_file(load_gltf(&p, &LoadOptions::default()), &p);
    let p = write(&d, "garbage.gltf", b"{ this is not json");
    assert_err_names_file(load_gltf(&p, &LoadOptions::default()), &p);
}

// ---------------------------------------------------------------- material mapping

#[test]
fn obj_ks_maps_to_energy_conserving_phong() {
    use penumbra::material::{Material, Texture};
    let d = scratch("phong");
    write(&d, "m.mtl", b"newmtl floor\nKd 0.8 0.8 0.8\nKs 0.5 0.5 0.5\nNs 20\nnewmtl lamp\nKd 0.3 0.2 0.1\nKe 1 1 1\n");
    let p = write(&d, "s.obj", QUAD_OBJ.as_bytes());
    let loaded = load_obj(&p, &LoadOptions::default()).expect("load");
    match &loaded.scene.materials[0] {
        Material::Phong {
            kd: Texture::Constant(kd),
            ks,
            n,
        } => {
            assert!(
                (*kd - Vec3::splat(0.8 / 1.3)).abs().max_element() < 1e-6,
                "kd {kd}"
            );
            assert!(
                (*ks - Vec3::splat(0.5 / 1.3)).abs().max_element() < 1e-6,
                "ks {ks}"
            );
            assert_eq!(*n, 20.0);
        }
        other => panic!("expected Phong, got {other:?}"),
    }
    match &loaded.scene.materials[1] {
        Material::Diffuse {
            reflectance: Texture::Constant(c),
        } => {
            assert_eq!(*c, Vec3::new(0.3, 0.2, 0.1))
        }
        other => panic!("expected diffuse, got {other:?}"),
    }
}

#[test]
fn gltf_metallic_roughness_mapping() {
    use penumbra::material::{Material, Texture};
    let d = scratch("gltf-materials");
    write(&d, "t.bin", &triangle_bin([0, 1, 2]));
    let base = gltf_json(r#"{"byteLength": 44, "uri": "t.bin"}"#);
    let with = |metallic: &str| {
        let json = base.replace(
            r#""metallicFactor": 0"#,
            &format!(r#""metallicFactor": {metallic}, "roughnessFactor": 0.6"#),
        );
        let p = write(&d, &format!("m{metallic}.gltf"), json.as_bytes());
        load_gltf(&p, &LoadOptions::default())
            .expect("load")
            .scene
            .materials[0]
            .clone()
    };
    let c = Vec3::new(0.2, 0.4, 0.6);
    match with("0") {
        Material::Diffuse {
            reflectance: Texture::Constant(r),
        } => assert_eq!(r, c),
        other => panic!("metallic 0 should be diffuse, got {other:?}"),
    }
    match with("0.25") {
        Material::CoatedDiffuse {
            reflectance: Texture::Constant(r),
            alpha,
            eta,
            layer: None,
        } => {
            assert!((r - 0.75 * c).abs().max_element() < 1e-6);
            assert!(
                (alpha - Vec2::splat(0.36)).abs().max_element() < 1e-6,
                "alpha {alpha}"
            );
            assert_eq!(eta, 1.5);
        }
        other => panic!("metallic 0.25 should be coated diffuse, got {other:?}"),
    }
    match with("1") {
        Material::Conductor {
            alpha,
            reflectance: Some(Texture::Constant(r)),
            ..
        } => {
            assert_eq!(r, c);
            assert!(
                (alpha - Vec2::splat(0.36)).abs().max_element() < 1e-6,
                "alpha {alpha}"
            );
        }
        other => panic!("metallic 1 should be a conductor, got {other:?}"),
    }
}

// ---------------------------------------------------------------- image textures

/// A 1×2 PNG: top pixel sRGB (255, 128, 0), bottom (0, 0, 255).
fn two_pixel_png() -> Vec<u8> {
    let mut img = image::RgbImage::new(1, 2);
    img.put_pixel(0, 0, image::Rgb([255, 128, 0]));
    img.put_pixel(0, 1, image::Rgb([0, 0, 255]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .expect("encode png");
    out.into_inner()
}

/// The texture of material `i`, checked to be an sRGB-decoded copy of [`two_pixel_png`].
fn check_two_pixel_texture(m: &penumbra::material::Material, scale: Vec3) {
    use penumbra::material::{Material, Texture};
    let tex = match m {
        Material::Diffuse { reflectance } => reflectance,
        other => panic!("expected diffuse, got {other:?}"),
    };
    match tex {
        Texture::Image { image, scale: s } => {
            assert_eq!((image.width, image.height), (1, 2));
            assert!((*s - scale).abs().max_element() < 1e-6, "scale {s}");
            // sRGB 128 → linear 0.2158; v = 1 is the top row (pbrt convention).
            let top = tex.eval(Vec2::new(0.5, 0.75)) / scale;
            assert!(
                (top - Vec3::new(1.0, 0.2158, 0.0)).abs().max_element() < 1e-3,
                "top {top}"
            );
            let bottom = tex.eval(Vec2::new(0.5, 0.25)) / scale;
            assert!(
                (bottom - Vec3::Z).abs().max_element() < 1e-3,
                "bottom {bottom}"
            );
        }
        other => panic!("expected an image texture, got {other:?}"),
    }
}

#[test]
fn obj_map_kd_becomes_an_image_texture() {
    let d = scratch("map-kd");
    write(&d, "tex.png", &two_pixel_png());
    write(
        &d,
        "m.mtl",
        b"newmtl floor\nKd 1 1 1\nmap_Kd tex.png\nnewmtl lamp\nKe 1 1 1\n",
    );
    let p = write(&d, "s.obj", QUAD_OBJ.as_bytes());
    let loaded = load_obj(&p, &LoadOptions::default()).expect("load");
    assert!(
        loaded.warnings.is_empty(),
        "warnings: {:?}",
        loaded.warnings
    );
    check_two_pixel_texture(&loaded.scene.materials[0], Vec3::ONE);
}

#[test]
fn gltf_base_color_texture_from_a_data_uri() {
    let d = scratch("gltf-texture");
    write(&d, "t.bin", &triangle_bin([0, 1, 2]));
    let json = gltf_json(r#"{"byteLength": 44, "uri": "t.bin"}"#)
        .replace(
            r#""metallicFactor": 0}"#,
            r#""metallicFactor": 0, "baseColorTexture": {"index": 0}}"#,
        )
        .replace(
            r#""buffers":"#,
            &format!(
                r#""textures": [{{"source": 0}}], "images": [{{"uri": "data:image/png;base64,{}"}}], "buffers":"#,
                base64(&two_pixel_png())
            ),
        );
    let p = write(&d, "s.gltf", json.as_bytes());
    let loaded = load_gltf(&p, &LoadOptions::default()).expect("load");
    check_two_pixel_texture(&loaded.scene.materials[0], Vec3::new(0.2, 0.4, 0.6));
    // A missing image only warns and falls back to the factor.
    let broken = json.replace("data:image/png;base64,", "missing.png#");
    let p = write(&d, "broken.gltf", broken.as_bytes());
    let loaded = load_gltf(&p, &LoadOptions::default()).expect("missing images only warn");
    assert!(
        loaded.warnings.iter().any(|w| w.contains("image 0")),
        "{:?}",
        loaded.warnings
    );
}

// ---------------------------------------------------------------- camera flags and framing

/// An open box (no wall on −z) with an emissive lamp under its ceiling, as OBJ.
const OPEN_BOX_OBJ: &str = "mtllib m.mtl\n\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
v 0.4 0.99 0.4\nv 0.6 0.99 0.4\nv 0.6 0.99 0.6\nv 0.4 0.99 0.6\n\
usemtl wall\n\
f 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n\
usemtl lamp\nf 9 10 11 12\n";

fn open_box(dir: &std::path::Path) -> PathBuf {
    write(
        dir,
        "m.mtl",
        b"newmtl wall\nKd 0.7 0.7 0.7\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n",
    );
    write(dir, "box.obj", OPEN_BOX_OBJ.as_bytes())
}

/// The `--look-from/--look-at/--up/--fov` values of a note.
fn flags_of(note: &str) -> penumbra::scene::view::ViewOptions {
    let words: Vec<&str> = note.split_whitespace().collect();
    let get = |flag: &str| -> &str {
        let i = words
            .iter()
            .position(|w| *w == flag)
            .unwrap_or_else(|| panic!("{flag} missing in '{note}'"));
        words[i + 1]
    };
    let v3 = |s: &str| {
        let c: Vec<f32> = s.split(',').map(|x| x.parse().expect("number")).collect();
        Vec3::new(c[0], c[1], c[2])
    };
    penumbra::scene::view::ViewOptions {
        look_from: Some(v3(get("--look-from"))),
        look_at: Some(v3(get("--look-at"))),
        up: Some(v3(get("--up"))),
        fov: Some(get("--fov").parse().expect("fov")),
    }
}

#[test]
fn automatic_framing_looks_into_the_open_side_and_prints_pasteable_flags() {
    let d = scratch("open-box");
    let p = open_box(&d);
    let l = load_obj(&p, &LoadOptions::default()).expect("load");
    // The box is open toward −z: the eye must be there, looking at the centre.
    let eye = l.scene.camera.camera_to_world.point(Vec3::ZERO);
    assert!(eye.z < 0.0 && (eye.x - 0.5).abs() < 1e-4, "eye {eye}");
    assert_eq!(l.notes.len(), 1, "{:?}", l.notes);
    let note = &l.notes[0];
    assert!(note.contains("from -z"), "{note}");
    // Pasting the printed flags gives the same camera.
    let again = load_obj(
        &p,
        &LoadOptions {
            view: flags_of(note),
            ..Default::default()
        },
    )
    .expect("load with the printed flags");
    let (a, b) = (
        l.scene.camera.camera_to_world.m,
        again.scene.camera.camera_to_world.m,
    );
    assert!(
        a.abs_diff_eq(b, 1e-3),
        "printed flags give another camera:\n{a}\n{b}"
    );
    assert_eq!(l.scene.camera.fov_deg, again.scene.camera.fov_deg);
}

#[test]
fn automatic_framing_with_nothing_lit_keeps_the_plus_z_view() {
    let d = scratch("unlit");
    write(
        &d,
        "m.mtl",
        b"newmtl wall\nKd 0.7 0.7 0.7\nnewmtl lamp\nKd 0 0 0\n",
    );
    let p = write(&d, "box.obj", OPEN_BOX_OBJ.as_bytes());
    let l = load_obj(&p, &LoadOptions::default()).expect("load");
    let eye = l.scene.camera.camera_to_world.point(Vec3::ZERO);
    assert!(eye.z > 1.0 && (eye.x - 0.5).abs() < 1e-4, "eye {eye}");
    // The same scene twice gives the same camera (the probe is deterministic).
    let again = load_obj(&p, &LoadOptions::default()).expect("load");
    assert_eq!(
        l.scene.camera.camera_to_world.m,
        again.scene.camera.camera_to_world.m
    );
}

#[test]
fn camera_flags_refine_a_gltf_files_own_camera() {
    use penumbra::scene::view::ViewOptions;
    let d = scratch("gltf-flags");
    write(&d, "t.bin", &triangle_bin([0, 1, 2]));
    let p = write(
        &d,
        "s.gltf",
        gltf_json(r#"{"byteLength": 44, "uri": "t.bin"}"#).as_bytes(),
    );
    let plain = load_gltf(&p, &LoadOptions::default()).expect("load");
    assert!(plain.notes.is_empty(), "{:?}", plain.notes);
    let fov = load_gltf(
        &p,
        &LoadOptions {
            view: ViewOptions {
                fov: Some(25.0),
                ..Default::default()
            },
            ..Default::default()
        },
    )
    .expect("load");
    // --fov alone keeps the file's eye and direction and changes the field of view.
    assert_eq!(fov.scene.camera.fov_deg, 25.0);
    assert_eq!(
        fov.scene.camera.camera_to_world.m,
        plain.scene.camera.camera_to_world.m
    );
    assert!(fov.notes[0].contains("--fov 25"), "{:?}", fov.notes);
}

#[test]
fn scene_builder_repairs_meshes_and_notes_it() {
    use penumbra::material::{Material, Texture};
    use penumbra::scene::{SceneBuilder, TriangleMesh};
    let mut b = SceneBuilder::new();
    let m = b.add_material(Material::Diffuse {
        reflectance: Texture::Constant(Vec3::splat(0.5)),
    });
    let tri = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    b.add_mesh(
        TriangleMesh {
            positions: tri.clone(),
            normals: Some(vec![Vec3::NAN, Vec3::Z, Vec3::Z]),
            uvs: None,
            indices: vec![0, 1, 2],
            flip_normals: false,
        },
        m,
        None,
    )
    .expect("a NaN normal is repaired");
    b.add_mesh(TriangleMesh::default(), m, None)
        .expect("an empty mesh is dropped");
    assert_eq!(b.primitive_count(), 1);
    assert_eq!(b.warnings.len(), 2, "{:?}", b.warnings);
    assert!(b.warnings[0].starts_with("mesh #0: 1 of 3 vertex normals"));
    assert!(b.warnings[1].starts_with("mesh #1: the mesh has no triangles"));
    // Out-of-range indices cannot be repaired: still an error.
    assert!(
        b.add_mesh(
            TriangleMesh {
                positions: tri,
                normals: None,
                uvs: None,
                indices: vec![0, 1, 5],
                flip_normals: false,
            },
            m,
            None,
        )
        .is_err()
    );
}

#[test]
fn builtin_knobs_warn_only_where_unused_and_camera_flags_apply() {
    let with = |light_count: Option<u32>, fov: Option<f32>| LoadOptions {
        builtin: penumbra::scene::builtin::BuiltinOptions {
            light_count,
            ..Default::default()
        },
        view: penumbra::scene::view::ViewOptions {
            fov,
            ..Default::default()
        },
        ..Default::default()
    };
    let l = load("many-open", &with(Some(50), None)).expect("load");
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    let l = load("cornell", &with(Some(50), Some(30.0))).expect("load");
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("--light-count ignored")),
        "{:?}",
        l.warnings
    );
    assert_eq!(l.scene.camera.fov_deg, 30.0);
    assert!(l.notes[0].contains("--fov 30"), "{:?}", l.notes);
}

#[test]
fn warnings_carry_at_most_one_warning_marker() {
    // The pbrt parser writes `file:line: warning: …`, the other loaders `location: …`; the CLI
    // adds `warning:` only where there is none, so no warning may carry two.
    let d = scratch("prefix");
    let p = write(
        &d,
        "w.pbrt",
        b"WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 2 0 0 0 1 0] \"integer indices\" [0 1 2 0 1 3]\n",
    );
    let l = load(p.to_str().expect("utf8"), &LoadOptions::default()).expect("load");
    assert!(!l.warnings.is_empty());
    for w in &l.warnings {
        assert!(w.matches("warning:").count() <= 1, "{w}");
    }
    assert!(
        l.warnings.iter().any(|w| w.ends_with(
            "w.pbrt:2: warning: trianglemesh: 1 of 2 triangles have zero area and are dropped"
        )),
        "{:?}",
        l.warnings
    );
}

/// A 1×1 PNG of code values (200, 128, 230).
fn normal_png() -> Vec<u8> {
    let img = image::RgbImage::from_pixel(1, 1, image::Rgb([200, 128, 230]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .expect("encode png");
    out.into_inner()
}

#[test]
fn gltf_normal_texture_is_linear_scaled_and_follows_the_uv_handedness() {
    use penumbra::material::{Material, NormalPerturbation};
    let d = scratch("gltf-normal");
    write(&d, "t.bin", &triangle_bin([0, 1, 2]));
    // One image as both base colour (sRGB-decoded) and normal texture (linear).
    let json = gltf_json(r#"{"byteLength": 44, "uri": "t.bin"}"#)
        .replace(
            r#""metallicFactor": 0}"#,
            r#""metallicFactor": 0, "baseColorTexture": {"index": 0}}, "normalTexture": {"index": 0, "scale": 0.5}"#,
        )
        .replace(
            r#""buffers":"#,
            &format!(
                r#""textures": [{{"source": 0}}], "images": [{{"uri": "data:image/png;base64,{}"}}], "buffers":"#,
                base64(&normal_png())
            ),
        );
    let p = write(&d, "s.gltf", json.as_bytes());
    let loaded = load_gltf(&p, &LoadOptions::default()).expect("load");
    let v = match &loaded.scene.materials[0] {
        Material::Varying(v) => v,
        m => panic!("expected a normal-mapped material, got {m:?}"),
    };
    match &v.base {
        Material::Diffuse { reflectance } => {
            let c = reflectance.eval(Vec2::splat(0.5)) / Vec3::new(0.2, 0.4, 0.6);
            let want = Vec3::new(200.0, 128.0, 230.0)
                .map(|x| penumbra::image::io::srgb_to_linear(x / 255.0));
            assert!((c - want).abs().max_element() < 1e-4, "{c} vs {want}");
        }
        m => panic!("{m:?}"),
    }
    let n = v.normal.as_ref().expect("normal map");
    match n {
        NormalPerturbation::NormalMap {
            image,
            scale,
            uv_handed,
        } => {
            assert_eq!(*scale, 0.5);
            assert!(*uv_handed);
            let want = Vec3::new(200.0, 128.0, 230.0) / 255.0;
            assert!(
                (image.pixels[0] - want).abs().max_element() < 1e-6,
                "{}",
                image.pixels[0]
            );
        }
        other => panic!("{other:?}"),
    }
    // Tangent-space (2c − 1)·(scale, scale, 1), normalised, in the frame (∂p/∂u, ±n × ∂p/∂u, n).
    let t = (Vec3::new(200.0, 128.0, 230.0) / 255.0 * 2.0 - Vec3::ONE) * Vec3::new(0.5, 0.5, 1.0);
    let t = t.normalize();
    let uv = Vec2::splat(0.5);
    let tc = penumbra::material::TexCoord::point(uv);
    let d = |dpdv: Vec3| penumbra::material::ShadingDerivatives {
        dpdu: Vec3::X,
        dpdv,
        ..Default::default()
    };
    let right = n.shading_normal(&tc, Vec3::Z, Vec3::Z, &d(Vec3::Y));
    assert!((right - t).abs().max_element() < 1e-5, "{right} vs {t}");
    // Mirrored uvs (∂p/∂v = −y): the bitangent, and so the map's green, flips.
    let mirrored = n.shading_normal(&tc, Vec3::Z, Vec3::Z, &d(-Vec3::Y));
    let tm = Vec3::new(t.x, -t.y, t.z);
    assert!(
        (mirrored - tm).abs().max_element() < 1e-5,
        "{mirrored} vs {tm}"
    );
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("normalTexture tangents")),
        "{:?}",
        loaded.warnings
    );
}

#[test]
fn camera_flags_keep_an_orthographic_or_spherical_cameras_projection_and_lens() {
    use penumbra::camera::Projection;
    use penumbra::scene::view::ViewOptions;
    let d = scratch("ortho-flags");
    for (camera, projection) in [
        (
            "\"orthographic\" \"float lensradius\" 0.1 \"float focaldistance\" 4",
            Projection::Orthographic,
        ),
        (
            "\"spherical\"",
            Projection::Spherical(penumbra::camera::SphericalMapping::EqualArea),
        ),
    ] {
        let src = format!(
            "LookAt 0 0 5  0 0 0  0 1 0\nCamera {camera}\nWorldBegin\n\
             LightSource \"point\" \"rgb I\" [1 1 1]\nShape \"sphere\"\n"
        );
        let p = write(&d, "s.pbrt", src.as_bytes());
        let spec = p.to_str().unwrap();
        let plain = load(spec, &LoadOptions::default()).expect("load");
        assert_eq!(
            std::mem::discriminant(&plain.scene.camera.projection),
            std::mem::discriminant(&projection)
        );
        // Moving the eye moves the camera; it stays the file's kind of camera.
        let moved = load(
            spec,
            &LoadOptions {
                view: ViewOptions {
                    look_from: Some(Vec3::new(0.0, 1.0, 5.0)),
                    ..Default::default()
                },
                ..Default::default()
            },
        )
        .expect("load");
        assert_eq!(moved.scene.camera.projection, plain.scene.camera.projection);
        assert_eq!(moved.scene.camera.lens, plain.scene.camera.lens);
        // Only a perspective camera has a field of view: --fov elsewhere is refused, not
        // silently dropped.
        let err = load(
            spec,
            &LoadOptions {
                view: ViewOptions {
                    fov: Some(30.0),
                    ..Default::default()
                },
                ..Default::default()
            },
        )
        .err()
        .map(|e| format!("{e:#}"))
        .unwrap_or_default();
        assert!(
            err.contains("--fov") && err.contains("perspective"),
            "{camera}: {err:?}"
        );
    }
}
