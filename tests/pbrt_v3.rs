//! pbrt-v3 files read through pbrt-v4's `--upgrade` mapping (`scene::pbrt::upgrade`): each v3
//! material, light and film becomes the v4 one `pbrt --upgrade` writes, with one warning per kind.

mod render_support;

use glam::{UVec2, Vec2};
use penumbra::Rgb;
use penumbra::integrator::{RenderOptions, render};
use penumbra::scene::pbrt::materials::MaterialDesc;
use penumbra::scene::pbrt::textures::TextureDesc;
use penumbra::scene::pbrt::{load_pbrt, parse_pbrt_str};
use render_support::rel_mse;
use std::path::{Path, PathBuf};

const TRI: &str = r#"Shape "trianglemesh" "point P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 2]"#;

fn world(body: &str) -> penumbra::scene::pbrt::PbrtScene {
    let src = format!("Camera \"perspective\"\nWorldBegin\n{body}\nWorldEnd\n");
    parse_pbrt_str("v3.pbrt", &src, Path::new(".")).unwrap()
}

#[test]
fn v3_materials_map_as_pbrt_v4_upgrade_does() {
    let s = world(&format!(
        r#"Material "matte" "color Kd" [0.1 0.2 0.3]
{TRI}
Material "plastic" "color Kd" [0.4 0.4 0.4] "color Ks" [0.5 0.5 0.5] "float roughness" 0.1
{TRI}
Material "plastic" "color Kd" [0.4 0.4 0.4] "color Ks" [0 0 0]
{TRI}
Material "substrate" "color Kd" [0.6 0.5 0.4] "float uroughness" 0.2 "float vroughness" 0.3
{TRI}
Material "uber" "color Kd" [0.2 0.2 0.2] "color Ks" [0 0 0] "float index" 1.7
{TRI}
Material "glass" "float index" 1.33
{TRI}
Material "metal" "float roughness" 0.05
{TRI}
Material "mirror"
{TRI}"#
    ));
    let m = &s.materials;
    assert_eq!(m.len(), 8);
    assert_eq!(
        m[0],
        MaterialDesc::Diffuse {
            reflectance: TextureDesc::Constant(Rgb::new(0.1, 0.2, 0.3))
        }
    );
    assert!(
        matches!(&m[1], MaterialDesc::CoatedDiffuse { reflectance: TextureDesc::Constant(c), roughness, .. }
            if *c == Rgb::splat(0.4) && *roughness == Vec2::splat(0.1)),
        "{:?}",
        m[1]
    );
    assert!(
        matches!(&m[2], MaterialDesc::Diffuse { .. }),
        "Ks = 0 plastic is diffuse"
    );
    assert!(
        matches!(&m[3], MaterialDesc::CoatedDiffuse { roughness, .. } if *roughness == Vec2::new(0.2, 0.3)),
        "{:?}",
        m[3]
    );
    assert!(matches!(&m[4], MaterialDesc::Diffuse { .. }), "{:?}", m[4]);
    assert!(
        matches!(&m[5], MaterialDesc::Dielectric { eta, .. } if *eta == 1.33),
        "{:?}",
        m[5]
    );
    assert!(
        matches!(&m[6], MaterialDesc::Conductor { roughness, .. } if *roughness == Vec2::splat(0.05))
    );
    assert!(
        matches!(&m[7], MaterialDesc::Conductor { roughness, reflectance: None, .. } if *roughness == Vec2::ZERO)
    );
    // One warning per kind, each naming the file and line, one "warning:" prefix.
    let w = &s.warnings;
    for (ty, to) in [
        ("matte", "diffuse"),
        ("plastic", "coateddiffuse"),
        ("substrate", "coateddiffuse"),
        ("glass", "dielectric"),
        ("metal", "conductor"),
        ("mirror", "conductor"),
    ] {
        let hits: Vec<&String> = w
            .iter()
            .filter(|x| x.contains(&format!("material \"{ty}\" read as pbrt-v4 \"{to}\"")))
            .collect();
        assert_eq!(hits.len(), 1, "{ty}: {w:?}");
        assert!(hits[0].starts_with("v3.pbrt:"), "{}", hits[0]);
        assert_eq!(hits[0].matches("warning:").count(), 1, "{}", hits[0]);
    }
    assert!(
        w.iter()
            .any(|x| x.contains("\"Ks\" has no pbrt-v4 equivalent")),
        "plastic's Ks dropped with a warning: {w:?}"
    );
}

#[test]
fn v3_area_lights_emit_and_v3_blackbody_scales() {
    let s = world(&format!(
        r#"AttributeBegin
AreaLightSource "area" "color L" [2 3 4] "integer nsamples" 4
{TRI}
AttributeEnd
AttributeBegin
AreaLightSource "area" "blackbody L" [6500 3]
{TRI}
AttributeEnd"#
    ));
    assert_eq!(s.shapes[0].emission.unwrap().l, Rgb::new(2.0, 3.0, 4.0));
    let l = s.shapes[1].emission.unwrap().l;
    assert!(
        (penumbra::luminance(l) - 3.0).abs() < 0.01,
        "v3 [T scale]: {l}"
    );
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("area light \"area\" read as pbrt-v4 \"diffuse\"")),
        "{:?}",
        s.warnings
    );
    assert!(!s.warnings.iter().any(|w| w.contains("nsamples")));
}

/// The pbrt-v4 Cornell box written back in pbrt-v3 syntax (`matte`/`Kd`, `color`, `point`,
/// `float uv`, `AreaLightSource "area"`, `Film "image"`, `WorldEnd`).
fn cornell_v3(v4: &str) -> String {
    v4.replace(
        "\"string type\" [ \"diffuse\" ]",
        "\"string type\" [ \"matte\" ]",
    )
    .replace("\"rgb reflectance\"", "\"color Kd\"")
    .replace("AreaLightSource \"diffuse\"", "AreaLightSource \"area\"")
    .replace("\"rgb L\"", "\"color L\"")
    .replace("Film \"rgb\"", "Film \"image\"")
    .replace("\"point2 uv\"", "\"float uv\"")
    .replace("\"point3 P\"", "\"point P\"")
        + "WorldEnd\n"
}

#[test]
fn a_v3_cornell_box_renders_like_the_v4_one() {
    let v4 = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/scenes/cornell-box-bitterli/scene-v4.pbrt");
    assert!(
        v4.exists(),
        "this test needs ../shared/scenes/cornell-box-bitterli/scene-v4.pbrt beside the project root; it is missing at {}",
        v4.display()
    );
    let text = std::fs::read_to_string(&v4).unwrap();
    let dir = std::env::temp_dir().join(format!("penumbra-v3-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let v3 = dir.join("cornell-v3.pbrt");
    std::fs::write(&v3, cornell_v3(&text)).unwrap();
    let opts = RenderOptions {
        spp: 16,
        seed: 3,
        progress: false,
        ..RenderOptions::default()
    };
    let res = UVec2::new(96, 96);
    let (s4, w4) = load_pbrt(&v4).unwrap();
    let (s3, w3) = load_pbrt(&v3).unwrap();
    let (i4, _) = render(&s4, res, &opts).unwrap();
    let (i3, _) = render(&s3, res, &opts).unwrap();
    let e = rel_mse(&i3, &i4);
    eprintln!(
        "v3 vs v4 Cornell box: relMSE {e:.3e}, means {} / {}",
        i3.mean(),
        i4.mean()
    );
    // Same materials and lights, same seed: the two renders are the same image.
    assert!(e < 1e-6, "relMSE {e}");
    assert!(i4.mean() > 0.05, "the v4 box is lit");
    assert!(w3.iter().any(|w| w.contains("\"matte\"")), "{w3:?}");
    assert!(!w4.iter().any(|w| w.contains("pbrt-v3")), "{w4:?}");
    std::fs::remove_dir_all(&dir).ok();
}
