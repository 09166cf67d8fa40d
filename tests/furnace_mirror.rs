//! Furnaces seen through delta lobes at the path's last vertex. A mirror (smooth conductor
//! with Fresnel 1: η = 1, k = 1000) under a uniform sky of radiance 1 has radiance 1 for every
//! max depth ≥ 1 and every strategy: no light sample can produce the mirror direction, so
//! under the light-only strategies the BSDF ray of a delta lobe must still find the sky (weight
//! 1), also at the last vertex of a path (where the ray does not continue), as it does at the
//! earlier ones. A smooth-glass slab (lossless, two interfaces) seen through the same rule:
//! every strategy must agree with BSDF sampling at the same max depth.

mod render_support;

use glam::UVec2;
use penumbra::integrator::{IntegratorKind, MisHeuristic, RenderOptions, Strategy, render};
use penumbra::scene::Scene;
use render_support::{STRATEGIES, mean_se, pbrt_scene};

fn scene(material: &str, slab: bool) -> Scene {
    let theta = 50f64.to_radians();
    let bottom = if slab {
        r#"Shape "trianglemesh" "point3 P" [ -1000 -1000 -0.2  -1000 1000 -0.2  1000 1000 -0.2  1000 -1000 -0.2 ]
    "integer indices" [ 0 1 2  0 2 3 ]"#
    } else {
        ""
    };
    let src = format!(
        r#"LookAt 0 {y} {z}  0 0 0  0 0 1
Camera "perspective" "float fov" [ 2 ]
Film "rgb" "integer xresolution" [ 8 ] "integer yresolution" [ 8 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
{material}
Shape "trianglemesh" "point3 P" [ -1000 -1000 0  1000 -1000 0  1000 1000 0  -1000 1000 0 ]
    "integer indices" [ 0 1 2  0 2 3 ]
{bottom}
"#,
        y = -10.0 * theta.sin(),
        z = 10.0 * theta.cos(),
    );
    pbrt_scene(&src)
}

fn opts(
    strategy: Strategy,
    mis: MisHeuristic,
    integrator: IntegratorKind,
    depth: u32,
) -> RenderOptions {
    RenderOptions {
        spp: 16,
        seed: 2,
        strategy,
        mis,
        integrator,
        max_depth: depth,
        roulette: false,
        ..RenderOptions::default()
    }
}

#[test]
fn a_mirror_shows_the_sky_under_every_strategy_and_depth() {
    let s = scene(
        r#"Material "conductor" "rgb eta" [ 1 1 1 ] "rgb k" [ 1000 1000 1000 ] "float roughness" [ 0 ]"#,
        false,
    );
    let mut failures = Vec::new();
    for (strategy, mis) in STRATEGIES {
        for (integrator, depth) in [
            (IntegratorKind::Direct, 1),
            (IntegratorKind::Path, 1),
            (IntegratorKind::Path, 3),
        ] {
            let (img, stats) = render(
                &s,
                UVec2::new(8, 8),
                &opts(strategy, mis, integrator, depth),
            )
            .unwrap();
            assert_eq!(stats.non_finite, 0);
            let (mean, _) = mean_se(&img);
            // Every sample sees the sky through the mirror with weight F ≥ 1 − 4·10⁻⁶.
            let ok = (mean - 1.0).abs() < 1e-4;
            eprintln!(
                "mirror {strategy} {mis:?} {integrator} depth {depth}: {mean:.6} {}",
                if ok { "ok" } else { "FAIL" }
            );
            if !ok {
                failures.push(format!(
                    "{strategy} {mis:?} {integrator} depth {depth}: {mean}"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

#[test]
fn a_smooth_glass_slab_agrees_across_strategies_at_every_depth() {
    let s = scene(r#"Material "dielectric" "float eta" [ 1.5 ]"#, true);
    let mut failures = Vec::new();
    for depth in [1, 2, 5] {
        let base = {
            let (img, _) = render(
                &s,
                UVec2::new(8, 8),
                &RenderOptions {
                    spp: 256,
                    ..opts(
                        Strategy::Bsdf,
                        MisHeuristic::Power,
                        IntegratorKind::Path,
                        depth,
                    )
                },
            )
            .unwrap();
            mean_se(&img)
        };
        for (strategy, mis) in STRATEGIES {
            let (img, stats) = render(
                &s,
                UVec2::new(8, 8),
                &RenderOptions {
                    spp: 256,
                    seed: 7,
                    ..opts(strategy, mis, IntegratorKind::Path, depth)
                },
            )
            .unwrap();
            assert_eq!(stats.non_finite, 0);
            let (mean, se) = mean_se(&img);
            let bound = 5.0 * (se * se + base.1 * base.1).sqrt() + 1e-4;
            let ok = (mean - base.0).abs() <= bound;
            eprintln!(
                "glass slab depth {depth} {strategy} {mis:?}: {mean:.5} ± {se:.1e} vs bsdf {:.5} ± {:.1e} {}",
                base.0,
                base.1,
                if ok { "ok" } else { "FAIL" }
            );
            if !ok {
                failures.push(format!(
                    "depth {depth} {strategy} {mis:?}: {mean} vs {}",
                    base.0
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}
