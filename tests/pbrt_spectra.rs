//! Spectrum parameters from pbrt-v4's named spectra and `.spd` files (relative to the scene),
//! with errors that name the file and line.

use penumbra::Rgb;
use penumbra::scene::pbrt::materials::MaterialDesc;
use penumbra::scene::pbrt::parse_pbrt;
use penumbra::scene::pbrt::textures::TextureDesc;
use std::path::PathBuf;

fn scene_dir(tag: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-spd-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("spds")).unwrap();
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    dir
}

const TRI: &str =
    r#"Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 2]"#;

#[test]
fn spd_files_give_reflectance_and_light_colour() {
    let dir = scene_dir(
        "ok",
        &[
            (
                "spds/red.spd",
                "# a red reflectance\n400 0.05 550 0.05\n600 0.9\n700 0.9\n",
            ),
            (
                "spds/warm.spd",
                "400 0.2\n500 0.6 # comment after numbers\n700 1.0\n",
            ),
            (
                "s.pbrt",
                &format!(
                    "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" \"spds/red.spd\"\n{TRI}\nAttributeBegin\nAreaLightSource \"diffuse\" \"spectrum L\" \"spds/warm.spd\"\n{TRI}\nAttributeEnd\n"
                ),
            ),
        ],
    );
    let s = parse_pbrt(&dir.join("s.pbrt")).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    match &s.materials[0] {
        MaterialDesc::Diffuse {
            reflectance: TextureDesc::Constant(c),
        } => assert!(c.x > 0.5 && c.y < 0.3 && c.z < 0.1, "red: {c}"),
        m => panic!("{m:?}"),
    }
    let l = s.shapes[1].emission.unwrap().l;
    assert!(
        (penumbra::luminance(l) - 1.0).abs() < 2e-3 && l.x > l.z,
        "warm: {l}"
    );
    assert_ne!(l, Rgb::ONE);
}

#[test]
fn bad_spectra_are_errors_with_file_and_line() {
    let cases = [
        (
            "spds/b.spd",
            "400 0.5\n500 x\n",
            "spds/b.spd:2: expected a number",
        ),
        (
            "spds/b.spd",
            "400 0.5\n500\n",
            "spds/b.spd:2: expected (wavelength, value) pairs",
        ),
        (
            "spds/b.spd",
            "500 0.5\n400 0.5\n",
            "spds/b.spd:2: wavelengths must increase",
        ),
    ];
    for (i, (name, text, want)) in cases.iter().enumerate() {
        let dir = scene_dir(
            &format!("bad{i}"),
            &[
                (name, text),
                (
                    "s.pbrt",
                    "WorldBegin\nMaterial \"diffuse\" \"spectrum reflectance\" \"spds/b.spd\"\n",
                ),
            ],
        );
        let e = parse_pbrt(&dir.join("s.pbrt")).unwrap_err().to_string();
        std::fs::remove_dir_all(&dir).ok();
        assert!(e.contains(want), "{want}: {e}");
    }
    let dir = scene_dir(
        "missing",
        &[(
            "s.pbrt",
            "WorldBegin\nMaterial \"conductor\"\n  \"spectrum eta\" \"metal-Unobtainium-eta\"\n",
        )],
    );
    let e = parse_pbrt(&dir.join("s.pbrt")).unwrap_err().to_string();
    std::fs::remove_dir_all(&dir).ok();
    assert!(e.contains("s.pbrt:3:"), "{e}");
    assert!(
        e.contains("neither a named spectrum nor a readable file")
            && e.contains("metal-Au-eta")
            && e.contains("canon_eos_5d_mkiv_r"),
        "{e}"
    );
}
