//! The OBJ / MTL / glTF bad-input catalogue (issue 23 items 4–7), plus the pbrt cases of item 4:
//! every case is either an error that names file and line (JSON path for glTF) and says what
//! is wrong, or a load that says what it did with a warning — never a silent black or changed
//! image, never a panic, never panic text on the terminal.

mod gltf_support;

use glam::Vec3;
use gltf_support::base64;
use penumbra::scene::builtin::BuiltinOptions;
use penumbra::scene::load::{LoadOptions, Loaded, load};
use penumbra::scene::view::ViewOptions;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("penumbra-bad-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("create scratch dir");
    d
}

/// What a case must do.
enum Expect {
    /// Fail with an error containing every string.
    Error(&'static [&'static str]),
    /// Load, with one warning containing every string.
    Warning(&'static [&'static str]),
}

struct Case {
    /// Files to write: (name, contents); the first is loaded.
    files: Vec<(&'static str, Vec<u8>)>,
    opts: LoadOptions,
    expect: Expect,
}

fn case(files: Vec<(&'static str, Vec<u8>)>, expect: Expect) -> Case {
    Case {
        files,
        opts: LoadOptions::default(),
        expect,
    }
}

fn text(s: &str) -> Vec<u8> {
    s.as_bytes().to_vec()
}

/// A floor quad and an emissive lamp quad, materials from m.mtl.
const LAMP_OBJ: &str = "mtllib m.mtl\n\
v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\n\
v 0 1 0\nv 0 1 1\nv 1 1 1\nv 1 1 0\n\
usemtl floor\nf 1 4 3 2\n\
usemtl lamp\nf 5 8 7 6\n";

fn lamp_obj(mtl: &str) -> Vec<(&'static str, Vec<u8>)> {
    vec![("s.obj", text(LAMP_OBJ)), ("m.mtl", text(mtl))]
}

const TRI: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

/// pbrt header: camera, then WorldBegin on line 3.
const PBRT: &str =
    "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\nWorldBegin\n";
const PBRT_TRI: &str = "Shape \"trianglemesh\" \"point3 P\" [-1 -1 0 1 -1 0 0 1 0]\n";

/// One triangle (3 × vec3 f32 at 0, 3 × u16 indices at 36) and, if given, a KHR punctual
/// light in front of it: `position` and `indices` are the accessors' JSON, `material` is
/// spliced into the material.
fn gltf(position: &str, indices: &str, material: &str, light: Option<&str>) -> Vec<u8> {
    let mut bin = Vec::new();
    for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for c in v {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    bin.extend_from_slice(&[0, 0]);
    let (nodes, lights, lamp) = match light {
        Some(l) => (
            "[0, 1]".to_string(),
            format!(
                r#""extensionsUsed": ["KHR_lights_punctual"],
  "extensions": {{"KHR_lights_punctual": {{"lights": [{l}]}}}},"#
            ),
            r#", {"translation": [0.2, 0.2, 2], "extensions": {"KHR_lights_punctual": {"light": 0}}}"#,
        ),
        None => ("[0]".to_string(), String::new(), ""),
    };
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": {nodes}}}],
  {lights}
  "nodes": [{{"mesh": 0}}{lamp}],
  "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1, "material": 0}}]}}],
  "materials": [{{"pbrMetallicRoughness": {{"metallicFactor": 0}}{material}}}],
  "buffers": [{{"byteLength": 44, "uri": "data:application/octet-stream;base64,{}"}}],
  "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 6}}],
  "accessors": [{position}, {indices}]
}}"#,
        base64(&bin)
    )
    .into_bytes()
}

const POS: &str = r#"{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}"#;
const IDX: &str = r#"{"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}"#;
const LIGHT: Option<&str> = Some(r#"{"type": "point", "intensity": 683}"#);

fn tri_gltf(
    name: &'static str,
    position: &str,
    indices: &str,
    material: &str,
    light: Option<&str>,
) -> Vec<(&'static str, Vec<u8>)> {
    vec![(name, gltf(position, indices, material, light))]
}

/// A PFM image (little endian) of `w`×`h` pixels all equal to `c`.
fn pfm(w: u32, h: u32, c: [f32; 3]) -> Vec<u8> {
    let mut out = format!("PF\n{w} {h}\n-1.0\n").into_bytes();
    for _ in 0..w * h {
        for v in c {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

fn catalogue() -> Vec<(&'static str, Case)> {
    let flags = |builtin: BuiltinOptions| LoadOptions {
        builtin,
        ..Default::default()
    };
    vec![
        // ---- item 7: OBJ errors carry the line
        (
            "obj-invalid-utf8",
            case(
                vec![("u.obj", b"v 0 0 0\nv 1 0 0\n\xff\xfe\nf 1 2 3\n".to_vec())],
                Expect::Error(&["u.obj:3:", "UTF-8"]),
            ),
        ),
        (
            "obj-face-index",
            case(
                vec![("i.obj", text(&format!("{TRI}f 1 2 9\n")))],
                Expect::Error(&["i.obj:4:", "out of bounds", "3 vertices", "`f 1 2 9`"]),
            ),
        ),
        (
            "obj-position",
            case(
                vec![("p.obj", text("v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n"))],
                Expect::Error(&["p.obj:2:", "position parse error"]),
            ),
        ),
        (
            "obj-truncated",
            case(
                vec![("t.obj", text("v 0 0 0\nv 1 0 0\nv 0 1"))],
                Expect::Error(&["t.obj:3:", "position parse error"]),
            ),
        ),
        (
            "obj-w-zero",
            case(
                vec![("w.obj", text("v 0 0 0\nv 1 0 0 0\nv 0 1 0\nf 1 2 3\n"))],
                Expect::Error(&["w.obj:2:", "scaling (w) by zero"]),
            ),
        ),
        (
            "obj-texcoord",
            case(
                vec![("vt.obj", text(&format!("{TRI}vt 0.5\nf 1 2 3\n")))],
                Expect::Error(&["vt.obj:4:", "texcoord parse error"]),
            ),
        ),
        (
            "obj-normal",
            case(
                vec![("vn.obj", text(&format!("{TRI}vn 0 a 1\nf 1 2 3\n")))],
                Expect::Error(&["vn.obj:4:", "normal parse error"]),
            ),
        ),
        (
            "obj-face-syntax",
            case(
                vec![("f.obj", text(&format!("{TRI}f 1 2 x\n")))],
                Expect::Error(&["f.obj:4:", "face parse error"]),
            ),
        ),
        (
            "obj-texcoord-index",
            case(
                vec![("ti.obj", text(&format!("{TRI}vt 0 0\nf 1/1 2/5 3/1\n")))],
                Expect::Error(&[
                    "ti.obj:5:",
                    "texture coordinate index out of bounds",
                    "1 'vt'",
                ]),
            ),
        ),
        (
            "obj-normal-index",
            case(
                vec![(
                    "ni.obj",
                    text(&format!("{TRI}vn 0 0 1\nf 1//1 2//1 3//4\n")),
                )],
                Expect::Error(&["ni.obj:5:", "normal index out of bounds"]),
            ),
        ),
        (
            "obj-usemtl-without-name",
            case(
                vec![("um.obj", text(&format!("{TRI}usemtl\nf 1 2 3\n")))],
                Expect::Error(&["um.obj:4:", "material parse error"]),
            ),
        ),
        (
            "obj-empty",
            case(
                vec![("e.obj", Vec::new())],
                Expect::Error(&["e.obj:1:", "no faces"]),
            ),
        ),
        (
            "obj-no-faces",
            case(
                vec![("nf.obj", text(TRI))],
                Expect::Error(&["nf.obj:3:", "no faces"]),
            ),
        ),
        (
            "mtl-bad-number",
            case(
                lamp_obj("newmtl floor\nKd 0.5 0.5 0.5\nNs abc\nnewmtl lamp\nKe 1 1 1\n"),
                Expect::Warning(&["m.mtl:3:", "material library not loaded", "`Ns abc`"]),
            ),
        ),
        (
            "mtl-missing",
            case(
                vec![("s.obj", text(LAMP_OBJ))],
                Expect::Warning(&["s.obj:1:", "m.mtl not found"]),
            ),
        ),
        // `Kd 0.5` (one value = grey) made tobj panic.
        (
            "mtl-one-value-colour",
            case(
                lamp_obj("newmtl floor\nKd 0.5\nnewmtl lamp\nKe 1 1 1\n"),
                Expect::Warning(&[]),
            ),
        ),
        (
            "mtl-two-value-colour",
            case(
                lamp_obj("newmtl floor\nKd 0.5 0.5\nnewmtl lamp\nKe 1 1 1\n"),
                Expect::Warning(&["m.mtl:2:", "Kd needs 1 or 3 values"]),
            ),
        ),
        // ---- item 4: black images get a word
        (
            "obj-no-lights",
            case(
                lamp_obj("newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 1 1 1\n"),
                Expect::Warning(&["s.obj", "no lights", "black"]),
            ),
        ),
        (
            "obj-ka-hint",
            case(
                lamp_obj("newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKa 20 20 20\n"),
                Expect::Warning(&["no lights", "--obj-ka-emission"]),
            ),
        ),
        (
            "obj-ke-nan",
            case(
                lamp_obj("newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKe nan 1 1\n"),
                Expect::Warning(&["m.mtl:4:", "'lamp'", "Ke", "not finite", "does not emit"]),
            ),
        ),
        (
            "obj-ke-overflow",
            case(
                lamp_obj("newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKe 1e39 1e39 1e39\n"),
                Expect::Warning(&["m.mtl:4:", "Ke inf inf inf", "not finite"]),
            ),
        ),
        (
            "obj-ke-negative",
            case(
                lamp_obj("newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKe -1 2 2\n"),
                Expect::Warning(&["m.mtl:4:", "Ke -1 2 2", "negative"]),
            ),
        ),
        (
            "gltf-emissive-overflow",
            case(
                tri_gltf(
                    "eo.gltf",
                    POS,
                    IDX,
                    r#", "emissiveFactor": [1e39, 1e39, 1e39]"#,
                    LIGHT,
                ),
                Expect::Warning(&[
                    "eo.gltf",
                    "materials[0]",
                    "emissiveFactor",
                    "not finite",
                    "does not emit",
                ]),
            ),
        ),
        (
            "gltf-emissive-negative",
            case(
                tri_gltf(
                    "en.gltf",
                    POS,
                    IDX,
                    r#", "emissiveFactor": [-1, 0.5, 0.5]"#,
                    LIGHT,
                ),
                Expect::Warning(&["en.gltf", "materials[0]", "emissiveFactor", "negative"]),
            ),
        ),
        (
            "gltf-no-lights",
            case(
                tri_gltf("nl.gltf", POS, IDX, "", None),
                Expect::Warning(&["nl.gltf", "no lights"]),
            ),
        ),
        (
            "gltf-light-zero",
            case(
                tri_gltf(
                    "lz.gltf",
                    POS,
                    IDX,
                    "",
                    Some(r#"{"type": "point", "intensity": 0}"#),
                ),
                Expect::Warning(&["lz.gltf", "none of its 1 lights emits"]),
            ),
        ),
        (
            "gltf-light-negative",
            case(
                tri_gltf(
                    "ln.gltf",
                    POS,
                    IDX,
                    "",
                    Some(r#"{"type": "point", "intensity": -5}"#),
                ),
                Expect::Warning(&["ln.gltf", "lights[0]", "intensity -5", "black"]),
            ),
        ),
        (
            "pbrt-no-lights",
            case(
                vec![("nl.pbrt", text(&format!("{PBRT}{PBRT_TRI}")))],
                Expect::Warning(&["nl.pbrt", "no lights", "black"]),
            ),
        ),
        (
            "pbrt-negative-area-light",
            case(
                vec![(
                    "na.pbrt",
                    text(&format!(
                        "{PBRT}AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [-1 -1 -1]\n{PBRT_TRI}AttributeEnd\n"
                    )),
                )],
                Expect::Error(&["na.pbrt:5:", "\"L\"", "negative"]),
            ),
        ),
        (
            "pbrt-negative-point-light",
            case(
                vec![(
                    "np.pbrt",
                    text(&format!(
                        "{PBRT}LightSource \"point\" \"rgb I\" [1 -2 1]\n{PBRT_TRI}"
                    )),
                )],
                Expect::Error(&["np.pbrt:4:", "\"I\"", "negative"]),
            ),
        ),
        (
            "pbrt-negative-envmap",
            case(
                vec![
                    (
                        "ne.pbrt",
                        text(&format!(
                            "{PBRT}LightSource \"infinite\" \"string filename\" \"neg.pfm\"\n{PBRT_TRI}"
                        )),
                    ),
                    ("neg.pfm", pfm(8, 4, [-1.0, -2.0, -0.5])),
                ],
                Expect::Warning(&["ne.pbrt:4:", "neg.pfm", "no pixel with positive radiance"]),
            ),
        ),
        // ---- item 5: no silent misreads
        (
            "gltf-position-vec2",
            case(
                tri_gltf("v2.gltf", &POS.replace("VEC3", "VEC2"), IDX, "", LIGHT),
                Expect::Error(&[
                    "v2.gltf",
                    "POSITION",
                    "VEC2 of FLOAT",
                    "requires VEC3 of FLOAT",
                ]),
            ),
        ),
        (
            "gltf-position-ubyte",
            case(
                tri_gltf("ub.gltf", &POS.replace("5126", "5121"), IDX, "", LIGHT),
                Expect::Error(&["ub.gltf", "POSITION", "VEC3 of UNSIGNED_BYTE"]),
            ),
        ),
        (
            "gltf-indices-float",
            case(
                tri_gltf("fi.gltf", POS, &IDX.replace("5123", "5126"), "", LIGHT),
                Expect::Error(&["fi.gltf", "indices", "SCALAR of FLOAT"]),
            ),
        ),
        (
            "gltf-short-stride",
            case(
                vec![(
                    "st.gltf",
                    text(
                        &String::from_utf8_lossy(&gltf(POS, IDX, "", LIGHT)).replacen(
                            r#""byteOffset": 0, "byteLength": 36}"#,
                            r#""byteOffset": 0, "byteLength": 36, "byteStride": 4}"#,
                            1,
                        ),
                    ),
                )],
                Expect::Error(&["st.gltf", "byteStride 4", "shorter than one element"]),
            ),
        ),
        (
            "flag-light-count-obj",
            Case {
                opts: flags(BuiltinOptions {
                    light_count: Some(9),
                    ..Default::default()
                }),
                ..case(
                    lamp_obj("newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKe 1 1 1\n"),
                    Expect::Warning(&["--light-count ignored", "only built-in scenes"]),
                )
            },
        ),
        (
            "flag-rooms-cornell",
            Case {
                opts: flags(BuiltinOptions {
                    rooms: Some(3),
                    ..Default::default()
                }),
                ..case(Vec::new(), Expect::Warning(&["cornell", "--rooms ignored"]))
            },
        ),
        // ---- item 6: the crate's crash
        (
            "gltf-position-accessor-missing",
            case(
                vec![(
                    "crash.gltf",
                    text(
                        r#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]}"#,
                    ),
                )],
                Expect::Error(&[
                    "crash.gltf",
                    "meshes[0].primitives[0].attributes.POSITION",
                    "accessor 0 does not exist",
                ]),
            ),
        ),
    ]
}

/// Load a case: built-in scene `cornell` when it has no files.
fn run(name: &str, c: &Case) -> (String, anyhow::Result<Loaded>) {
    if c.files.is_empty() {
        return ("cornell".to_string(), load("cornell", &c.opts));
    }
    let d = scratch(name);
    for (f, bytes) in &c.files {
        std::fs::write(d.join(f), bytes).expect("write case file");
    }
    let p = d.join(c.files[0].0);
    let spec = p.to_str().expect("utf8").to_string();
    let r = load(&spec, &c.opts);
    (spec, r)
}

#[test]
fn catalogue_every_case_errors_or_warns_as_listed() {
    let mut failures = Vec::new();
    let cases = catalogue();
    assert!(cases.len() >= 30, "only {} cases", cases.len());
    for (name, c) in &cases {
        let (_, r) = run(name, c);
        match (&c.expect, r) {
            (Expect::Error(want), Err(e)) => {
                let msg = format!("{e:#}");
                if let Some(w) = want.iter().find(|w| !msg.contains(*w)) {
                    failures.push(format!("{name}: error lacks '{w}': {msg}"));
                }
                if msg.contains("panicked") || msg.contains(".rs:") {
                    failures.push(format!("{name}: panic text in the error: {msg}"));
                }
            }
            (Expect::Error(_), Ok(l)) => failures.push(format!(
                "{name}: loaded (warnings {:?}) but must be an error",
                l.warnings
            )),
            (Expect::Warning(_), Err(e)) => failures.push(format!("{name}: refused: {e:#}")),
            (Expect::Warning(want), Ok(l)) => {
                if !want.is_empty()
                    && !l
                        .warnings
                        .iter()
                        .any(|w| want.iter().all(|p| w.contains(p)))
                {
                    failures.push(format!(
                        "{name}: no warning with {want:?}; warnings: {:?}",
                        l.warnings
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn mtl_single_value_colour_is_grey() {
    use penumbra::material::{Material, Texture};
    let d = scratch("kd-one");
    for (f, b) in lamp_obj("newmtl floor\nKd 0.25\nnewmtl lamp\nKe 1 1 1\n") {
        std::fs::write(d.join(f), b).expect("write");
    }
    let l = load(
        d.join("s.obj").to_str().expect("utf8"),
        &LoadOptions::default(),
    )
    .expect("load");
    match &l.scene.materials[0] {
        Material::Diffuse {
            reflectance: Texture::Constant(c),
        } => assert_eq!(*c, Vec3::splat(0.25)),
        other => panic!("expected a grey diffuse, got {other:?}"),
    }
}

#[test]
fn fov_flag_applies_to_a_pbrt_camera() {
    let d = scratch("fov");
    let p = d.join("f.pbrt");
    std::fs::write(
        &p,
        format!("{PBRT}LightSource \"point\" \"point3 from\" [0 0 2]\n{PBRT_TRI}"),
    )
    .expect("write");
    let opts = LoadOptions {
        view: ViewOptions {
            fov: Some(20.0),
            ..Default::default()
        },
        ..Default::default()
    };
    let l = load(p.to_str().expect("utf8"), &opts).expect("load");
    assert_eq!(
        l.scene.camera.fov_deg, 20.0,
        "--fov must apply to the file's camera"
    );
    // Moving the eye keeps the file camera's handedness and looks at the scene.
    let opts = LoadOptions {
        view: ViewOptions {
            look_from: Some(Vec3::new(0.0, 0.0, 8.0)),
            ..Default::default()
        },
        ..Default::default()
    };
    let l = load(p.to_str().expect("utf8"), &opts).expect("load");
    let eye = l.scene.camera.camera_to_world.point(Vec3::ZERO);
    assert!(
        (eye - Vec3::new(0.0, 0.0, 8.0)).length() < 1e-5,
        "eye {eye}"
    );
    assert!(!l.scene.camera.camera_to_world.swaps_handedness());
    let res = glam::UVec2::new(64, 64);
    let right = l
        .scene
        .camera
        .project(Vec3::new(0.5, 0.0, 0.0), res)
        .expect("visible");
    // pbrt's LookAt from +z toward −z with +y up puts world +x on the image's left.
    assert!(right.x < 32.0, "+x projects to {right}");
}

/// Deterministic 64-bit LCG (fuzzing must be reproducible).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
}

#[test]
fn mutated_gltf_and_obj_files_never_crash_a_parser() {
    let d = scratch("fuzz");
    let mut rng = Lcg(5);
    let sources: [(&str, Vec<u8>); 2] = [
        (
            "f.gltf",
            gltf(POS, IDX, r#", "emissiveFactor": [1, 1, 1]"#, LIGHT),
        ),
        (
            "f.obj",
            text(&format!(
                "{LAMP_OBJ}vt 0 0\nvn 0 1 0\nf 1/1/1 2/1/1 3/1/1\n"
            )),
        ),
    ];
    let alphabet = b"[]{}\",:-.e0123456789 \n/fvnt";
    let mut crashed = Vec::new();
    for (name, src) in &sources {
        for k in 0..150 {
            let mut s = src.clone();
            if k % 3 == 0 {
                s.truncate((rng.next() as usize) % s.len());
            } else {
                for _ in 0..1 + rng.next() % 4 {
                    let i = (rng.next() as usize) % s.len();
                    s[i] = alphabet[(rng.next() as usize) % alphabet.len()];
                }
            }
            let p = d.join(name);
            std::fs::write(&p, &s).expect("write");
            if let Err(e) = load(p.to_str().expect("utf8"), &LoadOptions::default()) {
                let msg = format!("{e:#}");
                assert!(msg.contains(name), "error does not name the file: {msg}");
                if msg.contains("crashed") {
                    crashed.push(format!("{name} #{k}: {msg}"));
                }
            }
        }
    }
    assert!(crashed.is_empty(), "\n{}", crashed.join("\n"));
}

#[test]
fn cli_shows_no_panic_text_for_the_gltf_crash_file() {
    let d = scratch("cli-crash");
    let p = d.join("crash.gltf");
    std::fs::write(
        &p,
        r#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]}"#,
    )
    .expect("write");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(["render", p.to_str().expect("utf8"), "-q", "-o"])
        .arg(d.join("x.png"))
        .env("RUST_BACKTRACE", "1")
        .output()
        .expect("run penumbra");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "a broken file must fail");
    assert!(
        !stderr.contains("panicked") && !stderr.contains("stack backtrace"),
        "panic text reached the terminal:\n{stderr}"
    );
    assert!(stderr.contains("crash.gltf"), "{stderr}");
}

#[test]
fn broken_files_keep_their_names_in_errors() {
    // The file name is in every error (the catalogue checks the line); here the path form.
    let p = Path::new("/nonexistent/dir/x.obj");
    let e = load(p.to_str().expect("utf8"), &LoadOptions::default())
        .err()
        .expect("missing file");
    assert!(format!("{e:#}").contains("x.obj"));
}
