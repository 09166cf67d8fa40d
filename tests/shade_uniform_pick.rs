//! The integrator's inline uniform light pick (`UniformSelector::pick`, used when
//! `LightSelector::uniform_count` says the selector is uniform) must pick exactly what the
//! selector itself picks; and only the uniform selector may claim to be uniform.

use glam::Vec3;
use penumbra::light_selection::{
    LightSelector, SELECTORS, ShadingPoint, UniformSelector, make_selector,
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
        assert_eq!(sel.uniform_count(), Some(count));
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
    for name in SELECTORS {
        let sel = make_selector(name, &scene, 1).expect("known selector");
        let claims = sel.uniform_count().is_some();
        assert_eq!(claims, *name == "uniform", "selector {name}");
        if let Some(n) = sel.uniform_count() {
            assert_eq!(n as usize, scene.lights.len());
        }
    }
}
