//! The integrator's inline uniform light pick (`UniformSelector::pick` over the scene's lights,
//! used when the selector's kind is `SelectorKind::Uniform`) must pick exactly what the
//! selector itself picks; and only the uniform selector may say it is uniform.

use glam::Vec3;
use penumbra::light_selection::{
    LightSelector, SelectorKind, ShadingPoint, UniformSelector, make_selector,
};
use penumbra::scene::builtin::{BuiltinOptions, find};

#[test]
fn inline_uniform_pick_matches_the_selector() {
    let ctx = ShadingPoint {
        p: Vec3::ZERO,
        n: Vec3::Z,
        wo: Vec3::Z,
    };
    for count in [0u32, 1, 2, 3, 7, 1000] {
        let sel = UniformSelector { count };
        assert_eq!(sel.kind(), SelectorKind::Uniform);
        // Every 1/4096 step plus the values next to 1, where the index clamps.
        let us = (0..4096)
            .map(|i| i as f32 / 4096.0)
            .chain([1.0 - f32::EPSILON / 2.0, 1.0 - f32::EPSILON]);
        for u in us {
            let inline = UniformSelector::pick(count, u);
            assert_eq!(inline, sel.sample(&ctx, u), "count {count}, u {u}");
            if let Some(s) = inline {
                assert!(s.index < count, "count {count}, u {u}: index {}", s.index);
                assert_eq!(s.pmf, sel.pmf(&ctx, s.index));
            }
        }
    }
}

#[test]
fn only_the_uniform_selector_claims_to_be_uniform() {
    let builtin = find("cornell").expect("cornell is built in");
    let scene = (builtin.build)(&BuiltinOptions::default()).expect("cornell builds");
    let ctx = ShadingPoint {
        p: Vec3::new(0.0, 0.5, 0.0),
        n: Vec3::Y,
        wo: Vec3::Y,
    };
    let count = scene.lights.len() as u32;
    for kind in SelectorKind::ALL {
        let sel = make_selector(kind, &scene, 1);
        assert_eq!(sel.kind(), kind, "selector {kind}");
        assert_eq!(sel.name(), kind.name());
        if kind == SelectorKind::Uniform {
            // What the integrator's inline pick over the scene's lights assumes.
            for i in 0..64 {
                let u = i as f32 / 64.0;
                assert_eq!(sel.sample(&ctx, u), UniformSelector::pick(count, u));
            }
        }
    }
}
