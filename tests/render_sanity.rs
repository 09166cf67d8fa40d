//! Every built-in scene renders finite pixels under every strategy × pattern, and the CLI's
//! render command writes the image it promises (atomically) with a one-line summary.

use glam::UVec2;
use penumbra::integrator::{RenderOptions, Strategy, render};
use penumbra::sampling::PatternKind;
use penumbra::scene::builtin::{BUILTINS, BuiltinOptions};

#[test]
fn no_nan_or_inf_in_any_strategy_and_pattern_on_builtin_scenes() {
    let opts = BuiltinOptions {
        light_count: Some(200),
        rooms: Some(2),
        triangles: Some(2000),
    };
    for b in BUILTINS {
        let scene = (b.build)(&opts).unwrap_or_else(|e| panic!("{}: {e:#}", b.name));
        for strategy in Strategy::ALL {
            for pattern in PatternKind::ALL {
                let o = RenderOptions {
                    spp: 2,
                    shadow_rays: 2,
                    strategy,
                    pattern,
                    ..RenderOptions::default()
                };
                let (img, stats) = render(&scene, UVec2::new(24, 24), &o).unwrap();
                assert_eq!(stats.non_finite, 0, "{} {strategy} {pattern}", b.name);
                assert!(
                    img.pixels
                        .iter()
                        .all(|p| p.is_finite() && p.min_element() >= 0.0),
                    "{} {strategy} {pattern}: non-finite or negative pixel",
                    b.name
                );
            }
        }
    }
}

#[test]
fn cli_render_writes_the_image_and_reports() {
    let dir = std::env::temp_dir().join(format!("penumbra-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("c.exr");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args([
            "render", "cornell", "--spp", "2", "--res", "32x24", "--quiet", "-o",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let line = String::from_utf8_lossy(&o.stdout);
    assert!(
        line.contains("32x24") && line.contains("Mrays/s"),
        "summary: {line}"
    );
    let img = penumbra::image::io::read_image(&out).unwrap();
    assert_eq!((img.width, img.height), (32, 24));
    // Bad input: a clear error and a non-zero exit, never a panic.
    for args in [
        vec!["render", "no-such-scene"],
        vec!["render", "cornell", "--res", "0x5"],
        vec!["render", "cornell", "--strategy", "magic"],
        vec!["render", "cornell", "--spp", "0"],
        vec![
            "render",
            "cornell",
            "-o",
            "/tmp/x.bmp",
            "--spp",
            "1",
            "--res",
            "4x4",
        ],
    ] {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} should fail");
        assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
        assert!(!err.trim().is_empty(), "{args:?}: no error message");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
