//! White furnace inside an emitting sphere (an inward sphere light, `ReverseOrientation`): a
//! diffuse wall of albedo ρ emitting 1 seen from anywhere inside has radiance
//! (1 − ρ^(N+1)) / (1 − ρ) with max depth N, as the cube furnace of tests/path_tracer.rs, but
//! here next-event estimation samples the sphere light from points on the sphere itself.
//! The light alone: at a point of the wall (normal inward) the whole hemisphere is the
//! sphere, so the irradiance is π L in both sampling modes.

mod render_support;

use glam::{UVec2, Vec2, Vec3};
use penumbra::integrator::{IntegratorKind, RenderOptions, render};
use penumbra::lights::{Emitter, LightSampleContext, LightSource, SamplingMode, SphereLight};
use render_support::{STRATEGIES, mean_se, pbrt_scene};

struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32 / (1u64 << 24) as f32).min(0.999_999_9)
    }
}

#[test]
fn inward_sphere_light_seen_from_its_own_surface_gives_pi_l() {
    let (c, r) = (Vec3::new(0.3, -0.2, 1.0), 1.5f32);
    let light = SphereLight::new(c, r, Vec3::ONE, true).unwrap();
    let mut rng = Rng(3);
    let mut failures = Vec::new();
    // Points on the sphere, as a ray hit leaves them: rounded onto either side.
    for (i, dir) in [
        Vec3::new(0.3, 0.4, 0.5),
        Vec3::new(-0.8, 0.1, 0.2),
        Vec3::new(0.05, -0.9, -0.3),
        Vec3::new(0.6, 0.6, -0.6),
    ]
    .into_iter()
    .enumerate()
    {
        let n_out = dir.normalize();
        let p = c + n_out * r;
        let ctx = LightSampleContext { p, n: -n_out };
        for mode in [SamplingMode::Area, SamplingMode::SolidAngle] {
            let n = 50_000;
            let (mut s, mut s2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let u = Vec2::new(rng.f(), rng.f());
                let Some(ls) = light.sample_li(&ctx, u, mode) else {
                    continue;
                };
                let cos = ls.wi.dot(ctx.n);
                if cos <= 0.0 {
                    continue;
                }
                // The sample's pdf is the one pdf_li reports for its direction (up to the
                // rounding of the recomputed intersection, which grows without bound for the
                // grazing chords to points next to the receiver: checked beyond r/20).
                let pdf = light.pdf_li(&ctx, ls.wi, ls.p_light, Vec3::ZERO, mode);
                let chord = (ls.p_light - p).length();
                assert!(
                    chord < 0.05 * r || (pdf - ls.pdf).abs() <= 1e-3 * ls.pdf,
                    "pdf {} vs pdf_li {pdf}",
                    ls.pdf
                );
                let v = (ls.li.x * cos / ls.pdf) as f64;
                s += v;
                s2 += v * v;
            }
            let mean = s / n as f64;
            let se = ((s2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
            let want = std::f64::consts::PI;
            let ok = (mean - want).abs() <= 5.0 * se + 1e-3;
            eprintln!("point {i} {mode:?}: E = {mean:.5} ± {se:.1e} vs π");
            if !ok {
                failures.push(format!("point {i} {mode:?}: {mean}"));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}

#[test]
fn diffuse_sphere_furnace_for_every_strategy() {
    let rho = 0.5f64;
    let src = format!(
        r#"LookAt 0.1 -0.2 0.3  0.5 0.3 1  0 1 0
Camera "perspective" "float fov" [ 70 ]
Film "rgb" "integer xresolution" [ 16 ] "integer yresolution" [ 16 ]
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
  Material "diffuse" "rgb reflectance" [ {rho} {rho} {rho} ]
  ReverseOrientation
  Shape "sphere" "float radius" [ 1 ]
AttributeEnd
"#
    );
    let scene = pbrt_scene(&src);
    let mut failures = Vec::new();
    for (strategy, mis) in STRATEGIES {
        for (depth, roulette) in [(1, false), (4, false), (12, true)] {
            let opts = RenderOptions {
                spp: 32,
                seed: 4,
                strategy,
                mis,
                integrator: IntegratorKind::Path,
                max_depth: depth,
                roulette,
                ..RenderOptions::default()
            };
            let (img, stats) = render(&scene, UVec2::new(16, 16), &opts).unwrap();
            assert_eq!(stats.non_finite, 0);
            let want = (1.0 - rho.powi(depth as i32 + 1)) / (1.0 - rho);
            let (mean, se) = mean_se(&img);
            let ok = (mean - want).abs() <= 5.0 * se + 5e-4 * want;
            eprintln!(
                "sphere {strategy} {mis:?} depth {depth} rr {roulette}: {mean:.5} ± {se:.1e} vs {want:.5} {}",
                if ok { "ok" } else { "FAIL" }
            );
            if !ok {
                failures.push(format!("{strategy} {mis:?} depth {depth}"));
            }
        }
    }
    assert!(failures.is_empty(), "sphere furnace off: {failures:?}");
}
