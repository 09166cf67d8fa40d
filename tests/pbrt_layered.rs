//! `coateddiffuse` (thickness, albedo, g, maxdepth, nsamples) and `coatedconductor` read from
//! pbrt files into pbrt-v4's layered BSDF, and a coated-gold sphere rendered with it.

use glam::Vec2;
use penumbra::Rgb;
use penumbra::bsdf::LayerParams;
use penumbra::material::Material;
use penumbra::scene::pbrt::materials::MaterialDesc;
use penumbra::scene::pbrt::{parse_pbrt_str, parse_pbrt_to_builder};
use std::path::Path;

const TRI: &str =
    r#"Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 2]"#;

fn world(body: &str) -> penumbra::scene::pbrt::PbrtScene {
    let src = format!("WorldBegin\n{body}\n");
    parse_pbrt_str("l.pbrt", &src, Path::new(".")).unwrap()
}

#[test]
fn layered_parameters_are_read() {
    let s = world(&format!(
        r#"Material "coateddiffuse" "float thickness" 0.2 "rgb albedo" [0.5 0.6 0.7] "float g" 0.3 "integer maxdepth" 20 "integer nsamples" 2
{TRI}
Material "coatedconductor" "float interface.roughness" 0.1 "float interface.eta" 1.6
    "spectrum conductor.eta" "metal-Au-eta" "spectrum conductor.k" "metal-Au-k"
    "float conductor.uroughness" 0.2 "float conductor.vroughness" 0.3 "bool remaproughness" false
{TRI}
Material "coatedconductor" "rgb reflectance" [0.9 0.6 0.2]
{TRI}"#
    ));
    assert!(
        !s.warnings.iter().any(|w| w.contains("not supported")),
        "nothing dropped: {:?}",
        s.warnings
    );
    match &s.materials[0] {
        MaterialDesc::CoatedDiffuse { layer, .. } => assert_eq!(
            *layer,
            LayerParams {
                thickness: 0.2,
                albedo: Rgb::new(0.5, 0.6, 0.7),
                g: 0.3,
                max_depth: 20,
                n_samples: 2
            }
        ),
        m => panic!("{m:?}"),
    }
    match &s.materials[1] {
        MaterialDesc::CoatedConductor {
            coat_eta,
            coat_roughness,
            roughness,
            remap,
            layer,
            ..
        } => {
            assert_eq!(*coat_eta, 1.6);
            assert_eq!(*coat_roughness, Vec2::splat(0.1));
            assert_eq!(*roughness, Vec2::new(0.2, 0.3));
            assert!(!remap);
            assert_eq!(*layer, LayerParams::default());
        }
        m => panic!("{m:?}"),
    }
    assert!(matches!(
        &s.materials[2],
        MaterialDesc::CoatedConductor {
            reflectance: Some(_),
            ..
        }
    ));
    let e = parse_pbrt_str(
        "l.pbrt",
        "WorldBegin\nMaterial \"coateddiffuse\" \"float g\" 1.5\n",
        Path::new("."),
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("l.pbrt:2:") && e.contains("'g'"), "{e}");
}

#[test]
fn coated_gold_is_gold_under_a_clear_coat() {
    // The conductor of a coatedconductor is gold (not grey), its η/k relative to the coat.
    let dir = std::env::temp_dir().join(format!("penumbra-cc-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("cc.pbrt");
    std::fs::write(
        &p,
        format!(
            "WorldBegin\nMaterial \"coatedconductor\" \"spectrum conductor.eta\" \"metal-Au-eta\" \"spectrum conductor.k\" \"metal-Au-k\" \"float conductor.roughness\" 0.05\n{TRI}\n"
        ),
    )
    .unwrap();
    let (b, _, _, _) = parse_pbrt_to_builder(&p).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    match &b.materials[0] {
        Material::CoatedConductor { eta, k, alpha, .. } => {
            let r = penumbra::bsdf::fresnel::fr_complex_rgb(1.0, *eta, *k);
            assert!(r.x > r.y && r.y > r.z && r.x > 0.9, "gold: {r}");
            assert!(
                (alpha.x - 0.05f32.sqrt()).abs() < 1e-6,
                "remapped roughness"
            );
        }
        m => panic!("{m:?}"),
    }
}
