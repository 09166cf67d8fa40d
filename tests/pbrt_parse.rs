//! pbrt-v4 loader: one test per directive / parameter kind, checked on the recorded builder
//! calls (`PbrtScene`) so they do not depend on the BVH or renderer.

use glam::{Vec2, Vec3};
use penumbra::Rgb;
use penumbra::scene::Filter;
use penumbra::scene::TriangleMesh;
use penumbra::scene::pbrt::lights::LightDesc;
use penumbra::scene::pbrt::materials::{MaterialDesc, MetalSpectrum};
use penumbra::scene::pbrt::named_spectra;
use penumbra::scene::pbrt::shapes::ShapeGeom;
use penumbra::scene::pbrt::textures::TextureDesc;
use penumbra::scene::pbrt::{PbrtScene, parse_pbrt, parse_pbrt_str};
use std::f32::consts::PI;
use std::path::{Path, PathBuf};

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("penumbra-pbrt-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn parse(src: &str) -> PbrtScene {
    parse_pbrt_str("t.pbrt", src, Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
}

fn world(body: &str) -> PbrtScene {
    parse(&format!("WorldBegin\n{body}"))
}

fn mesh(s: &PbrtScene, i: usize) -> &TriangleMesh {
    match &s.shapes[i].geom {
        ShapeGeom::Mesh(m) => m,
        other => panic!("not a mesh: {other:?}"),
    }
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

const TRI: &str =
    r#"Shape "trianglemesh" "point3 P" [1 0 0  0 1 0  0 0 1] "integer indices" [0 1 2]"#;

#[test]
fn cornell_box_bitterli_parses() {
    let p = Path::new("/work/shared/scenes/cornell-box-bitterli/scene-v4.pbrt");
    let p = if p.exists() {
        p.to_path_buf()
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/scenes/cornell-box-bitterli/scene-v4.pbrt")
    };
    let s = parse_pbrt(&p).unwrap();
    assert_eq!(s.materials.len(), 8);
    assert_eq!(s.shapes.len(), 8);
    let emissive: usize = s
        .shapes
        .iter()
        .filter(|c| c.emission.is_some())
        .map(|c| match &c.geom {
            ShapeGeom::Mesh(m) => m.indices.len() / 3,
            _ => 0,
        })
        .sum();
    assert_eq!(emissive, 2);
    let e = s.shapes.iter().find_map(|c| c.emission).unwrap();
    assert_eq!(e.l, Rgb::new(17.0, 12.0, 4.0));
    assert!(!e.two_sided);
    assert_eq!(s.camera.fov_deg, 19.5);
    assert!(close(
        s.camera.camera_to_world.point(Vec3::ZERO),
        Vec3::new(0.0, 1.0, 6.8)
    ));
    // Camera looks down -z in world (pbrt camera space looks down +z).
    assert!(close(s.camera.camera_to_world.vector(Vec3::Z), -Vec3::Z));
    assert_eq!(s.film.resolution, glam::UVec2::new(1024, 1024));
    assert_eq!(s.film.filter, Filter::Triangle { radius: Vec2::ONE });
    assert_eq!(s.film.spp, Some(64));
    assert_eq!(s.film.filename.as_deref(), Some("cornell-box.png"));
    assert_eq!(s.max_depth, Some(65));
    assert!(
        matches!(&s.materials[0], MaterialDesc::Diffuse { reflectance: TextureDesc::Constant(c) } if *c == Rgb::new(0.725, 0.71, 0.68))
    );
    assert_eq!(mesh(&s, 0).uvs.as_ref().unwrap().len(), 4);
    assert_eq!(mesh(&s, 0).normals.as_ref().unwrap().len(), 4);
}

#[test]
fn defaults_film_1280x720_fov_90_gaussian_filter() {
    let s = parse("WorldBegin");
    assert_eq!(s.film.resolution, glam::UVec2::new(1280, 720));
    assert_eq!(s.camera.fov_deg, 90.0);
    assert_eq!(s.film.spp, None);
    // pbrt-v4's default filter.
    assert!(matches!(s.film.filter, Filter::Gaussian { sigma: 0.5, .. }));
    assert!(s.shapes.is_empty() && s.materials.is_empty());
}

#[test]
fn translate_then_scale_post_multiplies() {
    // pbrt: CTM = T · S, so the point is scaled first.
    let s = world(&format!("Translate 1 0 0\nScale 2 2 2\n{TRI}"));
    assert!(close(mesh(&s, 0).positions[0], Vec3::new(3.0, 0.0, 0.0)));
}

#[test]
fn rotate_is_in_degrees_about_an_axis() {
    let s = world(&format!("Rotate 90 0 0 1\n{TRI}"));
    assert!(close(mesh(&s, 0).positions[0], Vec3::Y));
    assert!(close(mesh(&s, 0).positions[1], -Vec3::X));
}

#[test]
fn transform_and_concat_are_column_major() {
    let s = world(&format!(
        "Transform [1 0 0 0 0 1 0 0 0 0 1 0 5 6 7 1]\nConcatTransform [2 0 0 0 0 2 0 0 0 0 2 0 0 0 0 1]\n{TRI}"
    ));
    assert!(close(mesh(&s, 0).positions[0], Vec3::new(7.0, 6.0, 7.0)));
    // Transform replaces, it does not concatenate.
    let s = world(&format!(
        "Translate 9 9 9\nTransform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1]\n{TRI}"
    ));
    assert!(close(mesh(&s, 0).positions[0], Vec3::X));
}

#[test]
fn identity_resets_the_ctm() {
    let s = world(&format!("Translate 1 2 3\nIdentity\n{TRI}"));
    assert!(close(mesh(&s, 0).positions[0], Vec3::X));
}

#[test]
fn lookat_camera_and_named_camera_coordinate_system() {
    let s = parse(&format!(
        "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 45 \"float screenwindow\" [-1 1 -0.5 0.5]\nWorldBegin\nCoordSysTransform \"camera\"\n{TRI}"
    ));
    let c = &s.camera;
    assert_eq!(c.fov_deg, 45.0);
    assert_eq!(c.screen_window, Some([-1.0, 1.0, -0.5, 0.5]));
    assert!(close(
        c.camera_to_world.point(Vec3::ZERO),
        Vec3::new(0.0, 0.0, -5.0)
    ));
    assert!(close(c.camera_to_world.vector(Vec3::Z), Vec3::Z));
    assert!(close(c.camera_to_world.vector(Vec3::Y), Vec3::Y));
    // Shape in camera space: (1,0,0) camera → world.
    assert!(close(
        mesh(&s, 0).positions[0],
        c.camera_to_world.point(Vec3::X)
    ));
    // WorldBegin resets the CTM: LookAt does not move world geometry.
    let s = parse(&format!("LookAt 0 0 -5  0 0 0  0 1 0\nWorldBegin\n{TRI}"));
    assert!(close(mesh(&s, 0).positions[0], Vec3::X));
}

#[test]
fn coordinate_system_saves_and_restores() {
    let s = world(&format!(
        "Translate 0 0 4\nCoordinateSystem \"lamp\"\nIdentity\nCoordSysTransform \"lamp\"\n{TRI}"
    ));
    assert!(close(mesh(&s, 0).positions[0], Vec3::new(1.0, 0.0, 4.0)));
}

#[test]
fn attribute_blocks_restore_ctm_material_arealight_orientation() {
    let s = world(&format!(
        "Material \"diffuse\" \"rgb reflectance\" [0.1 0.1 0.1]
AttributeBegin
  Translate 5 0 0
  ReverseOrientation
  Material \"diffuse\" \"rgb reflectance\" [0.9 0.9 0.9]
  AreaLightSource \"diffuse\" \"rgb L\" [1 2 3]
  {TRI}
AttributeEnd
{TRI}"
    ));
    assert_eq!(s.shapes.len(), 2);
    assert!(close(mesh(&s, 0).positions[0], Vec3::new(6.0, 0.0, 0.0)));
    assert!(mesh(&s, 0).flip_normals);
    assert_eq!(s.shapes[0].emission.unwrap().l, Rgb::new(1.0, 2.0, 3.0));
    assert!(close(mesh(&s, 1).positions[0], Vec3::X));
    assert!(!mesh(&s, 1).flip_normals);
    assert!(s.shapes[1].emission.is_none());
    assert_ne!(s.shapes[0].material, s.shapes[1].material);
    assert!(matches!(&s.materials[s.shapes[1].material as usize],
        MaterialDesc::Diffuse { reflectance: TextureDesc::Constant(c) } if c.x == 0.1));
}

#[test]
fn transform_begin_end_restores_only_the_ctm() {
    let s = world(&format!(
        "TransformBegin\nTranslate 1 0 0\nReverseOrientation\nTransformEnd\n{TRI}"
    ));
    assert!(close(mesh(&s, 0).positions[0], Vec3::X));
    assert!(mesh(&s, 0).flip_normals);
}

#[test]
fn handedness_swap_and_reverse_orientation_xor() {
    let flip = |body: &str| mesh(&world(&format!("{body}\n{TRI}")), 0).flip_normals;
    assert!(!flip(""));
    assert!(flip("ReverseOrientation"));
    assert!(flip("Scale -1 1 1"));
    assert!(!flip("Scale -1 1 1\nReverseOrientation"));
}

#[test]
fn normals_use_the_inverse_transpose_and_are_normalised() {
    let s = world(
        r#"Scale 2 1 1
Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 0 1 0] "normal N" [1 1 0 1 1 0 1 1 0] "point2 uv" [0 0 1 0 0 1]"#,
    );
    let n = mesh(&s, 0).normals.as_ref().unwrap()[0];
    assert!(close(n, Vec3::new(0.5, 1.0, 0.0).normalize()), "{n}");
    assert_eq!(mesh(&s, 0).uvs.as_ref().unwrap()[1], Vec2::X);
    assert_eq!(
        mesh(&s, 0).indices,
        vec![0, 1, 2],
        "3 vertices need no indices"
    );
}

#[test]
fn zero_area_triangles_are_skipped_with_a_located_warning() {
    let s = world(
        r#"Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 0 1 0 2 0 0] "integer indices" [0 1 2 0 1 3]"#,
    );
    assert_eq!(mesh(&s, 0).indices, vec![0, 1, 2]);
    assert!(
        s.warnings
            .iter()
            .any(|w| w
                .starts_with("t.pbrt:2: warning: trianglemesh: 1 of 2 triangles have zero area")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn sphere_disk_and_bilinear_mesh() {
    let s = world(
        r#"Translate 0 0 1
Shape "sphere" "float radius" 2
ReverseOrientation
Shape "disk" "float radius" 3 "float height" 0.5
Shape "bilinearmesh" "point3 P" [0 0 0 1 0 0 0 1 0 1 1 0] "integer indices" [0 1 2 3]"#,
    );
    match &s.shapes[0].geom {
        ShapeGeom::Sphere { to_world, radius } => {
            assert_eq!(*radius, 2.0);
            assert!(close(to_world.point(Vec3::ZERO), Vec3::Z));
        }
        g => panic!("{g:?}"),
    }
    assert!(!s.shapes[0].reverse_orientation);
    match &s.shapes[1].geom {
        ShapeGeom::Disk { height, radius, .. } => assert_eq!((*height, *radius), (0.5, 3.0)),
        g => panic!("{g:?}"),
    }
    assert!(s.shapes[1].reverse_orientation);
    // The true patch, and its two-triangle stand-in (emitters, cut-outs).
    let m = match &s.shapes[2].geom {
        ShapeGeom::Bilinear { patches, mesh } => {
            assert_eq!(patches.len(), 1);
            assert!(patches[0].2, "flipped by the ReverseOrientation above");
            mesh.as_ref().expect("triangles")
        }
        g => panic!("{g:?}"),
    };
    assert_eq!(m.indices, vec![0, 1, 3, 0, 3, 2]);
    // Both triangles keep the patch orientation (+z).
    for t in m.indices.chunks(3) {
        let p = |i: u32| m.positions[i as usize];
        assert!((p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).z > 0.0);
    }
    assert!((s.shapes.len()) == 3);
}

#[test]
fn unsupported_shape_warns_once_with_file_and_line() {
    let s = world("Shape \"cone\" \"float radius\" 2\nShape \"cone\"\nShape \"hyperboloid\"");
    assert!(s.shapes.is_empty());
    let curve: Vec<_> = s
        .warnings
        .iter()
        .filter(|w| w.contains("\"cone\""))
        .collect();
    assert_eq!(curve.len(), 1, "{:?}", s.warnings);
    assert!(curve[0].starts_with("t.pbrt:2:"));
    assert!(
        s.warnings
            .iter()
            .any(|w| w.starts_with("t.pbrt:4:") && w.contains("hyperboloid"))
    );
}

#[test]
fn object_instances_are_flattened_with_the_instance_transform() {
    let s = world(&format!(
        "ObjectBegin \"tri\"\nTranslate 0 0 1\n{TRI}\nObjectEnd\nTranslate 10 0 0\nObjectInstance \"tri\"\nTranslate 10 0 0\nObjectInstance \"tri\""
    ));
    assert_eq!(s.shapes.len(), 2);
    assert!(close(mesh(&s, 0).positions[0], Vec3::new(11.0, 0.0, 1.0)));
    assert!(close(mesh(&s, 1).positions[0], Vec3::new(21.0, 0.0, 1.0)));
}

#[test]
fn include_and_import_resolve_relative_to_the_including_file() {
    let d = tmpdir("include");
    std::fs::create_dir_all(d.join("sub/deeper")).unwrap();
    std::fs::write(
        d.join("main.pbrt"),
        "WorldBegin\nInclude \"sub/a.pbrt\"\nImport \"sub/deeper/b.pbrt\"\n",
    )
    .unwrap();
    std::fs::write(
        d.join("sub/a.pbrt"),
        format!("Include \"deeper/b.pbrt\"\n{TRI}\n"),
    )
    .unwrap();
    std::fs::write(d.join("sub/deeper/b.pbrt"), format!("# b\n{TRI}\n")).unwrap();
    let s = parse_pbrt(&d.join("main.pbrt")).unwrap();
    assert_eq!(s.shapes.len(), 3);
    assert!(s.shapes[0].loc.to_string().contains("b.pbrt:2:"));
    // Two-file include cycle is an error, not a stack overflow.
    std::fs::write(d.join("x.pbrt"), "WorldBegin\nInclude \"y.pbrt\"\n").unwrap();
    std::fs::write(d.join("y.pbrt"), "\nInclude \"x.pbrt\"\n").unwrap();
    let e = parse_pbrt(&d.join("x.pbrt")).unwrap_err().to_string();
    assert!(e.contains("y.pbrt:2:1: Include cycle"), "{e}");
}

#[test]
fn options_block_directives() {
    let s = parse(
        r#"Sampler "halton" "integer pixelsamples" 8
Film "rgb" "integer xresolution" 320 "integer yresolution" 240 "string filename" "x.exr"
PixelFilter "box" "float xradius" 1 "float yradius" 2
Integrator "volpath" "integer maxdepth" 3
Accelerator "bvh"
Camera "perspective" "float lensradius" 0.1
WorldBegin"#,
    );
    assert_eq!(s.film.spp, Some(8));
    assert_eq!(s.film.resolution, glam::UVec2::new(320, 240));
    assert_eq!(s.film.filename.as_deref(), Some("x.exr"));
    assert_eq!(
        s.film.filter,
        Filter::Box {
            radius: Vec2::new(1.0, 2.0)
        }
    );
    assert_eq!(s.max_depth, Some(3));
    // volpath renders as path, with one warning.
    let spec = s.integrator.clone().expect("Integrator read");
    assert_eq!(spec.kind, penumbra::integrator::IntegratorKind::Path);
    assert_eq!(spec.max_depth, 3);
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("\"volpath\" rendered by penumbra's path tracer"))
    );
    // The thin lens is rendered: no warning about it.
    assert!(!s.warnings.iter().any(|w| w.contains("lensradius")));
    assert_eq!(s.camera.lens.radius, 0.1);
    let s = parse("PixelFilter \"gaussian\"\nWorldBegin");
    assert_eq!(
        s.film.filter,
        Filter::Gaussian {
            radius: Vec2::splat(1.5),
            sigma: 0.5
        }
    );
    assert!(!s.warnings.iter().any(|w| w.contains("gaussian")));
}

#[test]
fn materials_every_type() {
    let s = world(&format!(
        r#"Material "conductor" "spectrum eta" "metal-Au-eta" "spectrum k" "metal-Au-k" "float uroughness" 0.1 "float vroughness" 0.2 "bool remaproughness" false
{TRI}
Material "conductor" "rgb eta" [0.2 0.9 1.1] "rgb k" [3 2 1] "float roughness" 0.3
{TRI}
Material "conductor" "rgb reflectance" [0.9 0.5 0.3]
{TRI}
Material "coateddiffuse" "rgb reflectance" [0.2 0.3 0.4] "float roughness" 0.05 "float eta" 1.4
{TRI}
Material "dielectric" "float eta" 1.33
{TRI}
Material "thindielectric" "spectrum eta" "glass-BK7"
{TRI}
Material "diffusetransmission" "rgb reflectance" [0.3 0.3 0.3]
{TRI}
Material "hair"
{TRI}
Material "interface"
{TRI}"#
    ));
    use MaterialDesc::*;
    let m = &s.materials;
    assert_eq!(m.len(), 8, "interface shapes are not rendered");
    assert_eq!(s.shapes.len(), 8);
    assert_eq!(
        m[0],
        Conductor {
            eta: MetalSpectrum::Spectral(named_spectra::spectrum("metal-Au-eta").unwrap()),
            k: MetalSpectrum::Spectral(named_spectra::spectrum("metal-Au-k").unwrap()),
            reflectance: None,
            roughness: Vec2::new(0.1, 0.2),
            remap: false
        }
    );
    assert_eq!(
        m[1],
        Conductor {
            eta: MetalSpectrum::Rgb(Rgb::new(0.2, 0.9, 1.1)),
            k: MetalSpectrum::Rgb(Rgb::new(3.0, 2.0, 1.0)),
            reflectance: None,
            roughness: Vec2::splat(0.3),
            remap: true
        }
    );
    assert!(
        matches!(&m[2], Conductor { eta: MetalSpectrum::Spectral(e), reflectance: Some(TextureDesc::Constant(_)), .. } if *e == named_spectra::spectrum("metal-Cu-eta").unwrap())
    );
    assert_eq!(
        m[3],
        CoatedDiffuse {
            reflectance: TextureDesc::Constant(Rgb::new(0.2, 0.3, 0.4)),
            roughness: Vec2::splat(0.05),
            eta: 1.4,
            remap: true,
            layer: penumbra::bsdf::LayerParams::default(),
        }
    );
    assert_eq!(
        m[4],
        Dielectric {
            eta: 1.33,
            dispersion: None,
            roughness: Vec2::ZERO,
            remap: true,
            thin: false
        }
    );
    // BK7's index at 550 nm, and one per channel (blue bends most).
    assert!(
        matches!(&m[5], Dielectric { eta, dispersion: Some(d), roughness: Vec2::ZERO, remap: true, thin: true }
            if (eta - 1.51852).abs() < 1e-5 && d.z > d.y && d.y > d.x && (d.y - eta).abs() < 2e-3),
        "{:?}",
        m[5]
    );
    assert_eq!(
        m[6],
        DiffuseTransmission {
            reflectance: TextureDesc::Constant(Rgb::splat(0.3)),
            transmittance: TextureDesc::Constant(Rgb::splat(0.25)),
            scale: 1.0
        }
    );
    assert_eq!(m[7], MaterialDesc::default_diffuse());
    assert!(
        !s.warnings.iter().any(|w| w.contains("diffusetransmission")),
        "{:?}",
        s.warnings
    );
    for kind in ["thindielectric", "hair", "interface"] {
        assert!(
            s.warnings.iter().any(|w| w.contains(kind)),
            "no warning for {kind}: {:?}",
            s.warnings
        );
    }
}

#[test]
fn named_and_mix_materials() {
    let s = world(&format!(
        r#"MakeNamedMaterial "red" "string type" "diffuse" "rgb reflectance" [0.8 0 0]
MakeNamedMaterial "gold" "string type" "conductor"
MakeNamedMaterial "m" "string type" "mix" "string materials" ["red" "gold"] "float amount" 0.8
NamedMaterial "m"
{TRI}
NamedMaterial "red"
{TRI}
{TRI}"#
    ));
    assert_eq!(s.materials.len(), 2);
    assert!(matches!(s.materials[0], MaterialDesc::Conductor { .. }));
    assert_eq!(
        s.shapes[1].material, s.shapes[2].material,
        "one builder material per named material"
    );
}

#[test]
fn textures_constant_scale_checkerboard_imagemap() {
    let d = tmpdir("tex");
    let mut img = penumbra::image::Image::new(4, 2);
    img.pixels[0] = Rgb::ONE;
    penumbra::image::io::write_image(&img, &d.join("wood.png"), 0.0).unwrap();
    let src = format!(
        r#"WorldBegin
Texture "c" "spectrum" "constant" "rgb value" [0.1 0.2 0.3]
Texture "s" "spectrum" "scale" "texture tex" "c" "float scale" 2
Texture "k" "spectrum" "checkerboard" "rgb tex1" [1 0 0] "rgb tex2" [0 0 1] "float uscale" 4 "float vscale" 8
Texture "img" "spectrum" "imagemap" "string filename" "wood.png" "float scale" 0.5
Texture "r" "float" "constant" "float value" 0.25
Material "diffuse" "texture reflectance" "s"
{TRI}
Material "diffuse" "texture reflectance" "k"
{TRI}
Material "diffuse" "texture reflectance" "img"
{TRI}
Material "conductor" "texture roughness" "r"
{TRI}"#
    );
    let s = parse_pbrt_str("t.pbrt", &src, &d).unwrap();
    let refl = |i: usize| match &s.materials[i] {
        MaterialDesc::Diffuse { reflectance } => reflectance.clone(),
        m => panic!("{m:?}"),
    };
    assert!(matches!(refl(0), TextureDesc::Constant(c) if close(c, Rgb::new(0.2, 0.4, 0.6))));
    assert_eq!(
        refl(1),
        TextureDesc::Checkerboard {
            a: Rgb::X,
            b: Rgb::Z,
            freq: Vec2::new(4.0, 8.0)
        }
    );
    assert_eq!(
        refl(2),
        TextureDesc::Image {
            path: d.join("wood.png"),
            scale: Rgb::splat(0.5),
            invert: false,
            encoding: penumbra::scene::pbrt::textures::Encoding::SRgb,
            sampling: Default::default(),
        }
    );
    assert!(
        matches!(&s.materials[3], MaterialDesc::Conductor { roughness, .. } if *roughness == Vec2::splat(0.25))
    );
}

#[test]
fn spectrum_parameter_kinds_for_lights() {
    let s = world(
        r#"AreaLightSource "diffuse" "blackbody L" 3000 "float scale" 2
Shape "sphere"
AreaLightSource "diffuse" "spectrum L" [400 1 700 1]
Shape "sphere"
AreaLightSource "diffuse" "spectrum L" "stdillum-D65"
Shape "sphere""#,
    );
    let l0 = s.shapes[0].emission.unwrap().l;
    assert!(
        (penumbra::luminance(l0) - 2.0).abs() < 1e-3,
        "blackbody normalised to luminance 1 × scale: {l0}"
    );
    assert!(l0.x > l0.z, "3000 K is warm: {l0}");
    let l1 = s.shapes[1].emission.unwrap().l;
    assert!((penumbra::luminance(l1) - 1.0).abs() < 1e-3);
    let d65 = s.shapes[2].emission.unwrap().l;
    assert!(
        (d65 - Rgb::ONE).abs().max_element() < 3e-3,
        "D65 is the sRGB white: {d65}"
    );
}

#[test]
fn area_light_power_and_twosided() {
    // A 2×2 quad (area 4), two-sided: L = Φ / (π · A · 2).
    let s = world(
        r#"AreaLightSource "diffuse" "rgb L" [1 1 1] "float power" 100 "bool twosided" true
Shape "trianglemesh" "point3 P" [0 0 0 2 0 0 2 2 0 0 2 0] "integer indices" [0 1 2 0 2 3]
AreaLightSource "diffuse" "float power" 10
Scale 2 2 2
Shape "sphere" "float radius" 0.5"#,
    );
    let e = s.shapes[0].emission.unwrap();
    assert!(e.two_sided);
    assert!((e.l.x - 100.0 / (PI * 4.0 * 2.0)).abs() < 1e-4, "{}", e.l);
    // Sphere of world radius 1: area 4π.
    let l = s.shapes[1].emission.unwrap().l;
    assert!((l.x - 10.0 / (PI * 4.0 * PI)).abs() < 1e-4, "{l}");
}

#[test]
fn light_sources_point_spot_distant_infinite() {
    let d = tmpdir("lights");
    penumbra::image::io::write_image(&penumbra::image::Image::new(8, 4), &d.join("sky.exr"), 0.0)
        .unwrap();
    let src = r#"WorldBegin
Translate 0 5 0
LightSource "point" "rgb I" [1 2 3] "point3 from" [1 0 0]
LightSource "point" "float power" 100
LightSource "spot" "point3 from" [0 0 0] "point3 to" [0 -1 0] "float coneangle" 30 "float conedelta" 10 "blackbody I" 5000
LightSource "distant" "point3 from" [0 0 0] "point3 to" [0 0 1] "rgb L" [2 2 2] "float scale" 3
LightSource "infinite" "rgb L" [0.5 0.5 0.5] "float illuminance" 3.14159265
LightSource "infinite" "string filename" "sky.exr" "float scale" 2
LightSource "goniometric"
"#;
    let s = parse_pbrt_str("t.pbrt", src, &d).unwrap();
    assert_eq!(s.lights.len(), 6);
    assert_eq!(
        s.lights[0],
        LightDesc::Point {
            p: Vec3::new(1.0, 5.0, 0.0),
            intensity: Rgb::new(1.0, 2.0, 3.0)
        }
    );
    match &s.lights[1] {
        LightDesc::Point { intensity, .. } => {
            assert!((intensity.x - 100.0 / (4.0 * PI)).abs() < 1e-4)
        }
        l => panic!("{l:?}"),
    }
    match &s.lights[2] {
        LightDesc::Spot {
            p,
            dir,
            cos_falloff_start,
            cos_total_width,
            intensity,
        } => {
            assert!(close(*p, Vec3::new(0.0, 5.0, 0.0)));
            assert!(close(*dir, -Vec3::Y));
            assert!((cos_total_width - 30f32.to_radians().cos()).abs() < 1e-6);
            assert!((cos_falloff_start - 20f32.to_radians().cos()).abs() < 1e-6);
            assert!((penumbra::luminance(*intensity) - 1.0).abs() < 1e-3);
        }
        l => panic!("{l:?}"),
    }
    assert_eq!(
        s.lights[3],
        LightDesc::Distant {
            w_toward_light: -Vec3::Z,
            l: Rgb::splat(6.0)
        }
    );
    match &s.lights[4] {
        LightDesc::UniformInfinite { l } => assert!(close(*l, Rgb::splat(0.5))),
        l => panic!("{l:?}"),
    }
    match &s.lights[5] {
        LightDesc::EnvMap {
            path,
            scale,
            layout,
            light_to_world,
        } => {
            assert_eq!(path, &d.join("sky.exr"));
            assert_eq!(*scale, 2.0);
            // 8×4 is not square: read as lat-long, with a warning.
            assert_eq!(*layout, penumbra::lights::envmap::EnvLayout::LatLong);
            assert!(close(
                light_to_world.point(Vec3::ZERO),
                Vec3::new(0.0, 5.0, 0.0)
            ));
        }
        l => panic!("{l:?}"),
    }
    assert!(
        s.warnings
            .iter()
            .any(|w| w.starts_with("t.pbrt:9:") && w.contains("goniometric")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn unsupported_directives_and_parameters_warn_once_each() {
    let s = world(&format!(
        "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\nMediumInterface \"fog\" \"\"\nAttribute \"shape\" \"float radius\" 2\n{TRI} \"float bogus\" 1\n{TRI} \"float bogus\" 2"
    ));
    assert_eq!(s.warnings.iter().filter(|w| w.contains("media")).count(), 1);
    assert_eq!(
        s.warnings.iter().filter(|w| w.contains("bogus")).count(),
        1,
        "{:?}",
        s.warnings
    );
    assert!(
        s.warnings
            .iter()
            .any(|w| w.starts_with("t.pbrt:5:") && w.contains("bogus"))
    );
}

// ---------- PLY ----------

fn ply_header(format: &str, nv: usize, nf: usize, with_n_uv: bool) -> Vec<u8> {
    let mut h = format!(
        "ply\nformat {format} 1.0\ncomment made by the test\nelement vertex {nv}\nproperty float x\nproperty float y\nproperty float z\n"
    );
    if with_n_uv {
        h += "property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n";
    }
    h += &format!("element face {nf}\nproperty list uchar int vertex_indices\nend_header\n");
    h.into_bytes()
}

/// A unit quad (one quad face) and one extra triangle, with normals and uvs.
fn quad_ply(format: &str) -> Vec<u8> {
    let verts: [[f32; 8]; 5] = [
        [0., 0., 0., 0., 0., 1., 0., 0.],
        [1., 0., 0., 0., 0., 1., 1., 0.],
        [1., 1., 0., 0., 0., 1., 1., 1.],
        [0., 1., 0., 0., 0., 1., 0., 1.],
        [0., 0., 1., 0., 0., 1., 0.5, 0.5],
    ];
    let faces: [&[i32]; 2] = [&[0, 1, 2, 3], &[0, 1, 4]];
    let mut out = ply_header(format, 5, 2, true);
    match format {
        "ascii" => {
            for v in verts {
                out.extend(
                    v.iter()
                        .map(|x| x.to_string())
                        .collect::<Vec<_>>()
                        .join(" ")
                        .bytes(),
                );
                out.push(b'\n');
            }
            for f in faces {
                out.extend(
                    format!(
                        "{} {}\n",
                        f.len(),
                        f.iter()
                            .map(|i| i.to_string())
                            .collect::<Vec<_>>()
                            .join(" ")
                    )
                    .bytes(),
                );
            }
        }
        _ => {
            let le = format == "binary_little_endian";
            for v in verts {
                for x in v {
                    out.extend(if le { x.to_le_bytes() } else { x.to_be_bytes() });
                }
            }
            for f in faces {
                out.push(f.len() as u8);
                for &i in f {
                    out.extend(if le { i.to_le_bytes() } else { i.to_be_bytes() });
                }
            }
        }
    }
    out
}

#[test]
fn plymesh_ascii_and_binary_both_endiannesses() {
    let d = tmpdir("ply");
    let mut results = Vec::new();
    for fmt in ["ascii", "binary_little_endian", "binary_big_endian"] {
        std::fs::write(d.join(format!("{fmt}.ply")), quad_ply(fmt)).unwrap();
        let src = format!(
            "WorldBegin\nTranslate 0 0 2\nShape \"plymesh\" \"string filename\" \"{fmt}.ply\""
        );
        let s = parse_pbrt_str("t.pbrt", &src, &d).unwrap_or_else(|e| panic!("{fmt}: {e}"));
        let m = mesh(&s, 0).clone();
        assert_eq!(m.positions.len(), 5, "{fmt}");
        assert_eq!(
            m.indices,
            vec![0, 1, 2, 0, 2, 3, 0, 1, 4],
            "{fmt}: quad split like pbrt"
        );
        assert!(close(m.positions[2], Vec3::new(1.0, 1.0, 2.0)), "{fmt}");
        assert_eq!(m.uvs.as_ref().unwrap()[4], Vec2::splat(0.5), "{fmt}");
        assert!(close(m.normals.as_ref().unwrap()[0], Vec3::Z), "{fmt}");
        results.push(m.positions);
    }
    assert_eq!(results[0], results[1]);
    assert_eq!(results[1], results[2]);
}

#[test]
fn plymesh_without_normals_and_with_uint_indices() {
    let d = tmpdir("ply2");
    let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nproperty uchar red\nelement face 1\nproperty list uchar uint vertex_indices\nproperty int face_indices\nend_header\n".to_vec();
    for v in [[0.0f64, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
        for x in v {
            b.extend(x.to_le_bytes());
        }
        b.push(200);
    }
    b.push(3);
    for i in [0u32, 1, 2] {
        b.extend(i.to_le_bytes());
    }
    b.extend(7i32.to_le_bytes());
    std::fs::write(d.join("t.ply"), b).unwrap();
    let s = parse_pbrt_str(
        "t.pbrt",
        "WorldBegin\nShape \"plymesh\" \"string filename\" \"t.ply\"",
        &d,
    )
    .unwrap();
    let m = mesh(&s, 0);
    assert!(m.normals.is_none() && m.uvs.is_none());
    assert_eq!(m.indices, vec![0, 1, 2]);
    assert_eq!(m.positions[1], Vec3::X);
}

/// Benchmark (not a test by default): parse a ≥ 1M-triangle binary PLY scene.
/// `cargo test --release --test pbrt_parse -- --ignored --nocapture big_ply`
#[test]
#[ignore]
fn big_ply_parse_timing() {
    let d = tmpdir("big");
    let n = 709; // (n−1)² · 2 ≈ 1.0M triangles
    let mut b = ply_header("binary_little_endian", n * n, (n - 1) * (n - 1), false);
    for j in 0..n {
        for i in 0..n {
            for x in [i as f32, j as f32, ((i * j) % 7) as f32 * 0.1] {
                b.extend(x.to_le_bytes());
            }
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v = (j * n + i) as i32;
            b.push(4);
            for k in [v, v + 1, v + 1 + n as i32, v + n as i32] {
                b.extend(k.to_le_bytes());
            }
        }
    }
    std::fs::write(d.join("big.ply"), &b).unwrap();
    std::fs::write(
        d.join("big.pbrt"),
        "WorldBegin\nShape \"plymesh\" \"string filename\" \"big.ply\"\n",
    )
    .unwrap();
    let t = std::time::Instant::now();
    let s = parse_pbrt(&d.join("big.pbrt")).unwrap();
    let secs = t.elapsed().as_secs_f64();
    let tris = mesh(&s, 0).indices.len() / 3;
    println!(
        "parsed {tris} triangles ({} MB PLY) in {secs:.3} s",
        b.len() / 1_000_000
    );
    assert!(tris >= 1_000_000);
    let t = std::time::Instant::now();
    let (builder, cam, film, _) = s.into_builder().unwrap();
    let scene = builder.build(cam, film).unwrap();
    println!("builder + BVH build in {:.3} s", t.elapsed().as_secs_f64());
    assert_eq!(scene.materials.len(), 1);
}
