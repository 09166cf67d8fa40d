//! Splatting (`RenderOptions::splat`, `render --splat`): each sample, uniform over its pixel,
//! adds its filter-weighted radiance to every pixel the filter reaches and a pixel is the
//! weighted mean of what it received. A constant radiance stays exactly constant (also at the
//! image's edges and across tile borders), the image does not depend on the thread count, and
//! the Cornell box converges to Mitsuba's `path` reference with less error per pixel than
//! filter importance sampling at the same samples.

mod render_support;

use glam::UVec2;
use penumbra::image::Image;
use penumbra::image::io::read_image;
use penumbra::integrator::{IntegratorKind, RenderOptions, render};
use penumbra::scene::Scene;
use penumbra::scene::load::{LoadOptions, load};
use render_support::{pbrt_scene, rel_mse};
use std::path::PathBuf;

/// A closed black cube emitting radiance 1 everywhere, seen from inside: every camera ray
/// finds exactly 1, whatever its pixel position.
fn emitting_cube() -> Scene {
    let src = r#"LookAt 0.1 0.2 -0.3  0.5 0.3 1  0 1 0
Camera "perspective" "float fov" 70
Film "rgb" "integer xresolution" 24 "integer yresolution" 24
WorldBegin
AreaLightSource "diffuse" "rgb L" [1 1 1] "bool twosided" true
Material "diffuse" "rgb reflectance" [0 0 0]
Shape "trianglemesh" "point3 P" [-1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1]
  "integer indices" [0 1 2 0 2 3  4 6 5 4 7 6  0 4 5 0 5 1  3 2 6 3 6 7  0 3 7 0 7 4  1 5 6 1 6 2]
"#;
    pbrt_scene(src)
}

fn splat_path(spp: u32, depth: u32) -> RenderOptions {
    RenderOptions {
        spp,
        seed: 1,
        integrator: IntegratorKind::Path,
        max_depth: depth,
        splat: true,
        ..RenderOptions::default()
    }
}

fn bits(img: &Image) -> Vec<[u32; 3]> {
    img.pixels
        .iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

#[test]
fn constant_radiance_splats_to_exactly_that_constant() {
    let scene = emitting_cube();
    // 37×21: tiles cut at the right and bottom edges, pixels on the image border receive
    // from fewer neighbours.
    let (img, stats) = render(&scene, UVec2::new(37, 21), &splat_path(5, 3)).unwrap();
    assert_eq!(stats.non_finite, 0);
    for (i, p) in img.pixels.iter().enumerate() {
        assert_eq!([p.x, p.y, p.z], [1.0; 3], "pixel {i}");
    }
}

#[test]
fn splatted_images_do_not_depend_on_the_thread_count() {
    let scene = load("cornell", &LoadOptions::default()).unwrap().scene;
    let opts = splat_path(4, 8);
    let res = UVec2::new(40, 36);
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(&scene, res, &opts).unwrap().0)
    };
    let one = bits(&run(1));
    for threads in [2, 3] {
        assert!(
            one == bits(&run(threads)),
            "{threads} threads differ from 1"
        );
    }
}

/// The Cornell box's path-traced image at 512², 64 spp against Mitsuba's 4096-spp `path`
/// render (whose film splats with the same tent): the mean agrees as closely as filter
/// importance sampling's, and the error per pixel is below Mitsuba's own 64-spp render's
/// (1.35e-3, `scripts/compare-mitsuba.sh`); filter importance sampling gives 2.03e-3.
#[test]
fn cornell_path_splatted_matches_mitsuba_path_reference_with_less_error() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/reference");
    let reference = read_image(&dir.join("cornell-path-4096spp.exr"))
        .expect("this test needs ../shared/reference/cornell-path-4096spp.exr");
    let tol: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("cornell-path-tolerance.json"))
            .expect("cornell-path-tolerance.json"),
    )
    .unwrap();
    let mean_rel = tol["mean_rel"].as_f64().unwrap();
    let scene = load("cornell", &LoadOptions::default()).unwrap().scene;
    let (img, stats) = render(&scene, UVec2::new(512, 512), &splat_path(64, 65)).unwrap();
    assert_eq!(stats.non_finite, 0);
    let e = rel_mse(&img, &reference);
    let (m, mr) = (img.mean(), reference.mean());
    eprintln!(
        "cornell path 64 spp, splatted: relMSE {e:.3e}, mean {m:.6} vs {mr:.6} ({:+.3}%)",
        100.0 * (m / mr - 1.0)
    );
    assert!(e <= 1.2e-3, "relMSE {e:.3e} > 1.2e-3");
    assert!(
        (m / mr - 1.0).abs() <= mean_rel,
        "mean {m} vs the reference's {mr}: more than {}% apart",
        mean_rel * 100.0
    );
}

#[test]
fn splat_refuses_renders_in_parts() {
    // A weighted-mean film cannot be combined from parts by sample counts: each such flag must
    // be refused before any work, not give a subtly different image.
    for extra in [
        &["--progressive"][..],
        &["--time", "1"],
        &["--spp-range", "0..4"],
        &["--resume", "part.exr"],
    ] {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
            .args([
                "render", "cornell", "--res", "8x8", "--spp", "4", "--splat", "-q",
            ])
            .args(extra)
            .args(["-o", "/nonexistent-dir/x.exr"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{extra:?}");
        assert!(
            err.contains("--splat") && err.contains("cannot be used"),
            "{extra:?}: {err}"
        );
    }
}
