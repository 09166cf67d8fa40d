//! The path tracer (`IntegratorKind::Path`): white furnaces with closed-form answers for every
//! strategy with and without Russian roulette, depth 1 equal to direct lighting bit for bit,
//! the same image for any thread count, no NaN/Inf in any strategy × integrator × built-in
//! scene, and the default Cornell box against Mitsuba 3's converged `path` render.

mod render_support;

use glam::UVec2;
use penumbra::image::Image;
use penumbra::image::io::read_image;
use penumbra::integrator::{IntegratorKind, MisHeuristic, RenderOptions, Strategy, render};
use penumbra::scene::Scene;
use penumbra::scene::load::{LoadOptions, load};
use render_support::{STRATEGIES, mean_se, pbrt_scene, rel_mse};
use std::path::{Path, PathBuf};

/// A closed cube (12 triangles, normals either way: the emission is two-sided) of diffuse
/// albedo `rho` emitting radiance 1 everywhere, seen from inside.
fn furnace(rho: f32) -> Scene {
    let src = format!(
        r#"LookAt 0.1 0.2 -0.3  0.5 0.3 1  0 1 0
Camera "perspective" "float fov" 70
Film "rgb" "integer xresolution" 24 "integer yresolution" 24
WorldBegin
AreaLightSource "diffuse" "rgb L" [1 1 1] "bool twosided" true
Material "diffuse" "rgb reflectance" [{rho} {rho} {rho}]
Shape "trianglemesh" "point3 P" [-1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1]
  "integer indices" [0 1 2 0 2 3  4 6 5 4 7 6  0 4 5 0 5 1  3 2 6 3 6 7  0 3 7 0 7 4  1 5 6 1 6 2]
"#
    );
    pbrt_scene(&src)
}

fn path_opts(strategy: Strategy, mis: MisHeuristic, depth: u32, roulette: bool) -> RenderOptions {
    RenderOptions {
        spp: 64,
        seed: 3,
        strategy,
        mis,
        integrator: IntegratorKind::Path,
        max_depth: depth,
        roulette,
        ..RenderOptions::default()
    }
}

#[test]
fn white_furnace_matches_the_geometric_series_for_every_strategy() {
    // Radiance 1 emitted everywhere, albedo ρ: after N bounces L = (1 − ρ^(N+1)) / (1 − ρ),
    // unbounded 1 / (1 − ρ). The bound is 5 standard errors of the pixel mean plus 2e-4 of
    // the answer for the few rays that slip through the cube's edges by rounding.
    let rho = 0.5f64;
    let scene = furnace(rho as f32);
    let res = UVec2::new(24, 24);
    let mut failures = Vec::new();
    for (strategy, mis) in STRATEGIES {
        for (depth, roulette) in [(0, false), (1, false), (3, false), (6, true), (40, true)] {
            let (img, stats) = render(&scene, res, &path_opts(strategy, mis, depth, roulette))
                .expect("furnace renders");
            assert_eq!(stats.non_finite, 0);
            let want = (1.0 - rho.powi(depth as i32 + 1)) / (1.0 - rho);
            let (mean, se) = mean_se(&img);
            let bound = 5.0 * se + 2e-4 * want;
            let ok = (mean - want).abs() <= bound;
            eprintln!(
                "{strategy} {mis:?} depth {depth} roulette {roulette}: {mean:.5} ± {se:.1e} vs {want:.5} {}",
                if ok { "ok" } else { "FAIL" }
            );
            if !ok {
                failures.push(format!("{strategy} {mis:?} depth {depth} rr {roulette}"));
            }
        }
    }
    assert!(failures.is_empty(), "furnace off: {failures:?}");
}

#[test]
fn furnace_with_roulette_is_unbiased_at_a_high_albedo() {
    // ρ = 0.9: paths are long (the mean is 10 of 1 + 0.9 + 0.81 + ...), so roulette plays at
    // almost every vertex.
    let rho = 0.9f64;
    let scene = furnace(rho as f32);
    for strategy in [Strategy::Mis, Strategy::Bsdf] {
        let opts = RenderOptions {
            spp: 256,
            ..path_opts(strategy, MisHeuristic::Power, 400, true)
        };
        let (img, _) = render(&scene, UVec2::new(24, 24), &opts).unwrap();
        let (mean, se) = mean_se(&img);
        let want = (1.0 - rho.powi(401)) / (1.0 - rho);
        eprintln!("ρ 0.9 {strategy}: {mean:.4} ± {se:.1e} vs {want:.4}");
        assert!(
            (mean - want).abs() <= 5.0 * se + 2e-3 * want,
            "{strategy}: {mean} ± {se} vs {want}"
        );
    }
}

fn bits(img: &Image) -> Vec<[u32; 3]> {
    img.pixels
        .iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

fn builtin(name: &str) -> Scene {
    load(name, &LoadOptions::default())
        .expect("built-in scene")
        .scene
}

#[test]
fn path_with_max_depth_one_is_direct_lighting_bit_for_bit() {
    for name in ["cornell", "cornell-phong"] {
        let scene = builtin(name);
        for (strategy, mis) in STRATEGIES {
            for shadow_rays in [1, 2] {
                let direct = RenderOptions {
                    spp: 4,
                    shadow_rays,
                    strategy,
                    mis,
                    ..RenderOptions::default()
                };
                let path = RenderOptions {
                    integrator: IntegratorKind::Path,
                    max_depth: 1,
                    ..direct.clone()
                };
                let res = UVec2::new(48, 48);
                let (a, _) = render(&scene, res, &direct).unwrap();
                let (b, _) = render(&scene, res, &path).unwrap();
                assert!(
                    bits(&a) == bits(&b),
                    "{name} {strategy} M={shadow_rays}: path depth 1 differs from direct"
                );
            }
        }
    }
}

#[test]
fn path_images_do_not_depend_on_the_thread_count() {
    let scene = builtin("cornell-phong");
    let opts = RenderOptions {
        spp: 8,
        shadow_rays: 2,
        ..path_opts(Strategy::Mis, MisHeuristic::Power, 8, true)
    };
    let res = UVec2::new(40, 40);
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

#[test]
fn no_nan_or_inf_in_any_strategy_integrator_and_builtin_scene() {
    for b in penumbra::scene::builtin::BUILTINS {
        let opts = LoadOptions {
            builtin: penumbra::scene::builtin::BuiltinOptions {
                light_count: Some(64),
                rooms: Some(2),
                triangles: Some(2000),
            },
            ..Default::default()
        };
        let scene = load(b.name, &opts).unwrap().scene;
        for (strategy, mis) in STRATEGIES {
            for integrator in [IntegratorKind::Direct, IntegratorKind::Path] {
                let o = RenderOptions {
                    spp: 2,
                    ..path_opts(strategy, mis, 6, true)
                };
                let o = RenderOptions { integrator, ..o };
                let (img, stats) = render(&scene, UVec2::new(24, 24), &o).unwrap();
                assert_eq!(stats.non_finite, 0, "{} {strategy} {integrator}", b.name);
                assert!(
                    img.pixels
                        .iter()
                        .all(|p| p.is_finite() && p.min_element() >= 0.0),
                    "{} {strategy} {integrator}: non-finite or negative pixel",
                    b.name
                );
            }
        }
    }
}

#[test]
fn cornell_path_matches_mitsuba_path_reference() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/reference");
    let reference = read_image(&dir.join("cornell-path-4096spp.exr"))
        .expect("this test needs ../shared/reference/cornell-path-4096spp.exr");
    let tol: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("cornell-path-tolerance.json"))
            .expect("cornell-path-tolerance.json"),
    )
    .unwrap();
    let (max_rel_mse, mean_rel) = (
        tol["path"].as_f64().unwrap(),
        tol["mean_rel"].as_f64().unwrap(),
    );
    let scene = builtin("cornell");
    // The file's Integrator: path, maxdepth 65.
    let opts = RenderOptions {
        seed: 1,
        ..path_opts(Strategy::Mis, MisHeuristic::Power, 65, true)
    };
    let (img, stats) = render(&scene, UVec2::new(512, 512), &opts).unwrap();
    assert_eq!(stats.non_finite, 0);
    let e = rel_mse(&img, &reference);
    let (m, mr) = (img.mean(), reference.mean());
    eprintln!(
        "cornell path 64 spp: relMSE {e:.3e} (tolerance {max_rel_mse:.1e}), mean {m:.6} vs {mr:.6} ({:+.3}%), {:.2} s",
        100.0 * (m / mr - 1.0),
        stats.time.as_secs_f64()
    );
    assert!(e <= max_rel_mse, "relMSE {e:.3e} > {max_rel_mse:.1e}");
    assert!(
        (m / mr - 1.0).abs() <= mean_rel,
        "mean {m} vs the reference's {mr}: more than {}% apart",
        mean_rel * 100.0
    );
}

#[test]
fn integrator_directive_maps_to_path_with_its_depth_and_light_sampler() {
    let parse = |integrator: &str| {
        let src = format!("{integrator}\nWorldBegin\n");
        penumbra::scene::pbrt::parse_pbrt_str("i.pbrt", &src, Path::new(".")).unwrap()
    };
    let s = parse(
        r#"Integrator "path" "integer maxdepth" [ 7 ] "string lightsampler" "power" "bool regularize" true"#,
    );
    let spec = s.integrator.clone().unwrap();
    assert_eq!(spec.kind, IntegratorKind::Path);
    assert_eq!(spec.max_depth, 7);
    assert_eq!(spec.light_selection.map(|k| k.name()), Some("power"));
    assert!(
        s.warnings.iter().any(|w| w.contains("regularize")),
        "{:?}",
        s.warnings
    );
    assert!(!s.warnings.iter().any(|w| w.contains("path tracer")));
    for other in ["volpath", "bdpt", "mlt", "sppm"] {
        let s = parse(&format!(r#"Integrator "{other}""#));
        let spec = s.integrator.clone().unwrap();
        assert_eq!(
            (spec.kind, spec.max_depth),
            (IntegratorKind::Path, 5),
            "{other}"
        );
        let n = s
            .warnings
            .iter()
            .filter(|w| w.contains("path tracer"))
            .count();
        assert_eq!(n, 1, "{other}: {:?}", s.warnings);
    }
    for (name, want) in [
        ("uniform", "uniform"),
        ("bvh", "bvh"),
        ("exhaustive", "exhaustive"),
    ] {
        let s = parse(&format!(
            r#"Integrator "path" "string lightsampler" "{name}""#
        ));
        assert_eq!(
            s.integrator.unwrap().light_selection.map(|k| k.name()),
            Some(want)
        );
    }
}

#[test]
fn cli_flags_override_the_files_integrator() {
    // The furnace (ρ = 0.5, Le = 1) asking for path with maxdepth 0 (emission only): the file
    // gives 1, --max-depth 2 gives 1.75, --integrator direct 1.5.
    let dir = std::env::temp_dir().join(format!("penumbra-pt-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let src = r#"Integrator "path" "integer maxdepth" [ 0 ]
LookAt 0.1 0.2 -0.3  0.5 0.3 1  0 1 0
Camera "perspective" "float fov" 70
Film "rgb" "integer xresolution" 8 "integer yresolution" 8
Sampler "independent" "integer pixelsamples" 16
WorldBegin
AreaLightSource "diffuse" "rgb L" [1 1 1] "bool twosided" true
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "point3 P" [-1 -1 -1  1 -1 -1  1 1 -1  -1 1 -1  -1 -1 1  1 -1 1  1 1 1  -1 1 1]
  "integer indices" [0 1 2 0 2 3  4 6 5 4 7 6  0 4 5 0 5 1  3 2 6 3 6 7  0 3 7 0 7 4  1 5 6 1 6 2]
"#;
    let scene = dir.join("f.pbrt");
    std::fs::write(&scene, src).unwrap();
    for (flags, want) in [
        (&[][..], 1.0),
        (&["--max-depth", "2", "--no-roulette"][..], 1.75),
        (&["--integrator", "direct"][..], 1.5),
    ] {
        let out = dir.join("o.pfm");
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
            .arg("render")
            .arg(&scene)
            .args(flags)
            .args(["--strategy", "bsdf", "-q", "-o"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let (mean, _) = mean_se(&read_image(&out).unwrap());
        // BSDF sampling in this furnace has no variance (every weight is ρ, every Le is 1).
        assert!((mean - want).abs() < 1e-3, "{flags:?}: {mean} vs {want}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
