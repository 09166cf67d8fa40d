//! MIS with light selection is exact for every selector: at one Lambertian receiver under 30
//! triangle lights of very different power, one light sample plus one BSDF sample, each
//! weighted by its technique's MIS weight, has expectation Lambert's polygon integral, and the
//! two weights of every direction sum to 1. `ris` and `ris-bvh` divide their light sample by
//! RIS's contribution weight (a random number, not a probability); their MIS weights must use
//! a deterministic pmf that the BSDF side can compute for the same direction.

use super::MisHeuristic;
use super::estimator::{Techniques, emission_weight, light_estimate, nee_pdf};
use crate::Rgb;
use crate::bsdf::{Bxdf, Lambert};
use crate::geometry::SurfaceHit;
use crate::light_selection::{
    BvhSelector, FiniteSelector, LightSelector, LightSet, PowerSelector, RisBvhSelector,
    RisSelector, Selector, SelectorKind, ShadingPoint,
};
use crate::lights::{Emitter, Light, LightSampleContext, LightSource, SamplingMode, TriangleLight};
use crate::sampling::Frame;
use crate::sampling::hash::{next_f32, pcg_from_keys};
use glam::{Vec2, Vec3};

const ALBEDO: f32 = 0.8;

/// 30 one-sided triangles above the receiver at the origin (normal +z), facing it, with
/// radiances spread over two decades (so power, bounds and RIS targets all disagree).
fn lights() -> Vec<Light> {
    let mut rng = pcg_from_keys(&[19, 30]);
    let mut u = || next_f32(&mut rng);
    (0..30)
        .map(|_| {
            let c = Vec3::new(6.0 * u() - 3.0, 6.0 * u() - 3.0, 0.5 + 2.5 * u());
            let mut corner = || c + Vec3::new(u() - 0.5, u() - 0.5, 0.3 * (u() - 0.5));
            let p = [corner(), corner(), corner()];
            let mut n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
            // Emitting toward the receiver.
            if n.dot(-c) < 0.0 {
                n = -n;
            }
            let l = Rgb::splat(0.05 * 100f32.powf(u()));
            Light::Triangle(TriangleLight::new(p, n, l, false).expect("a triangle with area"))
        })
        .collect()
}

/// ∫ cos θ dω over triangle `v` seen from the origin with normal +z (Lambert's formula).
fn projected_solid_angle(v: &[Vec3; 3]) -> f64 {
    let v = v.map(|p| p.as_dvec3().normalize());
    (0..3)
        .map(|i| {
            let (a, b) = (v[i], v[(i + 1) % 3]);
            let g = a.dot(b).clamp(-1.0, 1.0).acos();
            g * a.cross(b).normalize().z
        })
        .sum::<f64>()
        .abs()
        / 2.0
}

/// Where the ray from the origin along `d` meets triangle `v` (Möller–Trumbore), if it does.
fn hit_triangle(d: Vec3, v: &[Vec3; 3]) -> Option<Vec3> {
    let (d, v) = (d.as_dvec3(), v.map(|p| p.as_dvec3()));
    let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
    let q = d.cross(e2);
    let det = e1.dot(q);
    if det.abs() < 1e-12 {
        return None;
    }
    let s = -v[0];
    let b1 = s.dot(q) / det;
    let r = s.cross(e1);
    let b2 = d.dot(r) / det;
    let t = e2.dot(r) / det;
    (b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 && t > 0.0).then(|| (d * t).as_vec3())
}

fn selectors(lights: &[Light]) -> Vec<(&'static str, Selector)> {
    let set = || LightSet::new(lights);
    let b = set().bounds;
    let make = |kind, finite: Box<dyn FiniteSelector>| Selector::new(kind, set(), finite);
    vec![
        (
            "power",
            make(SelectorKind::Power, Box::new(PowerSelector::new(&b))),
        ),
        (
            "bvh",
            make(SelectorKind::Bvh, Box::new(BvhSelector::new(&b))),
        ),
        (
            "ris",
            make(
                SelectorKind::Ris { candidates: 8 },
                Box::new(RisSelector::new(&b, 8, 5)),
            ),
        ),
        (
            "ris-bvh",
            make(
                SelectorKind::RisBvh { candidates: 4 },
                Box::new(RisBvhSelector::new(&b, 4, 5)),
            ),
        ),
    ]
}

#[test]
fn mis_with_every_selector_is_unbiased_and_its_weights_sum_to_one() {
    let lights = lights();
    let n = Vec3::Z;
    let exact: f64 = lights
        .iter()
        .map(|l| match l {
            Light::Triangle(t) => {
                ALBEDO as f64 / std::f64::consts::PI * t.l.x as f64 * projected_solid_angle(&t.p)
            }
            _ => unreachable!(),
        })
        .sum();
    let bsdf = Lambert::new(Rgb::splat(ALBEDO));
    let frame = Frame::from_normal(n);
    let wo = Vec3::new(0.3, -0.2, 1.0).normalize();
    let wo_local = frame.to_local(wo);
    let ctx = LightSampleContext { p: Vec3::ZERO, n };
    let at = ShadingPoint {
        p: Vec3::ZERO,
        n,
        wo,
    };
    let hit = SurfaceHit {
        t: 1.0,
        p: Vec3::ZERO,
        ng: n,
        ns: n,
        uv: Vec2::ZERO,
        p_error: 1e-6,
        prim: 0,
        material: 0,
        light: u32::MAX,
    };
    let h = MisHeuristic::Power;
    let mode = SamplingMode::SolidAngle;
    const N: usize = 1_600_000;
    for (name, selector) in selectors(&lights) {
        let mut rng = pcg_from_keys(&[19, 31]);
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        let mut worst_weights = 0.0f32;
        for _ in 0..N {
            let mut value = 0.0f64;
            // Light sampling, unshadowed (the reference ignores the lights' mutual shadows too).
            if let Some(sel) = selector.sample(&at, next_f32(&mut rng)) {
                let u = Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
                let light = &lights[sel.index as usize];
                if let Some(ls) = light.sample_li(&ctx, u, mode) {
                    let est = light_estimate(
                        &ls,
                        sel.pmf,
                        sel.mis_pmf,
                        &bsdf,
                        &frame,
                        wo_local,
                        &ctx,
                        &hit,
                        Some(h),
                    );
                    if let Some((_, v, w_light)) = est {
                        value += v.x as f64;
                        // The BSDF side's weight for this very direction.
                        let p_b = bsdf.pdf(wo_local, frame.to_local(ls.wi));
                        let Light::Triangle(t) = light else {
                            unreachable!()
                        };
                        let w_bsdf = emission_weight(Techniques::Mis(h), false, || {
                            let p_l = nee_pdf(
                                &selector, false, light, sel.index, &at, ls.wi, ls.p_light, t.n,
                                mode,
                            );
                            (p_b, p_l)
                        });
                        worst_weights = worst_weights.max((w_light + w_bsdf - 1.0).abs());
                    }
                }
            }
            // BSDF sampling: the emission of every light the direction meets.
            let u = Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
            if let Some(bs) = bsdf.sample(wo_local, next_f32(&mut rng), u) {
                let wi = frame.to_world(bs.wi).normalize();
                let weight = bs.f.x * bs.wi.z.abs() / bs.pdf;
                for (i, light) in lights.iter().enumerate() {
                    let Light::Triangle(t) = light else {
                        unreachable!()
                    };
                    let Some(p) = hit_triangle(wi, &t.p) else {
                        continue;
                    };
                    let le = light.radiance(p, t.n, Vec2::ZERO, -wi).x;
                    let w = emission_weight(Techniques::Mis(h), false, || {
                        (
                            bs.pdf,
                            nee_pdf(&selector, false, light, i as u32, &at, wi, p, t.n, mode),
                        )
                    });
                    value += (weight * le * w) as f64;
                }
            }
            sum += value;
            sum2 += value * value;
        }
        let mean = sum / N as f64;
        let sigma = ((sum2 / N as f64 - mean * mean) / N as f64).sqrt();
        let z = (mean - exact) / sigma;
        eprintln!(
            "{name}: mean {mean:.6} exact {exact:.6} ({z:+.2} sigma), worst |w_L + w_B - 1| {worst_weights:.2e}"
        );
        assert!(
            worst_weights < 1e-4,
            "{name}: MIS weights sum to 1 off by {worst_weights}"
        );
        assert!(
            z.abs() < 5.0,
            "{name}: mean {mean} vs exact {exact}: {z:.1} sigma"
        );
    }
}
