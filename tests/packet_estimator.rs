//! `Integrator::li_packet` against `li`: every lane of a full packet (lanes from several
//! pixels, several shadow rays, every strategy, scenes with Phong/GGX, many lights and an
//! environment) gives exactly the single-sample radiance and the same ray count.

use glam::UVec2;
use penumbra::Rgb;
use penumbra::geometry::PACKET;
use penumbra::integrator::dims::DIM_FILTER;
use penumbra::integrator::film::filter_sample;
use penumbra::integrator::queues::CameraPacket;
use penumbra::integrator::stages::{Integrator, Queues};
use penumbra::integrator::{MisHeuristic, Strategy};
use penumbra::light_selection::{SelectorKind, make_selector};
use penumbra::lights::SamplingMode;
use penumbra::sampling::{PatternKind, PixelSamples, make_pattern};
use penumbra::scene::Scene;
use penumbra::scene::load::{LoadOptions, load};

/// Checks every lane; returns (lanes checked, lanes with light).
fn check(
    scene: &Scene,
    strategy: Strategy,
    selection: SelectorKind,
    spp: u32,
    m: u32,
) -> (u32, u32) {
    let selector = make_selector(selection, scene, 3);
    let pattern = make_pattern(PatternKind::Stratified, 3);
    let est = Integrator {
        scene,
        selector: selector.as_ref(),
        pattern: pattern.as_ref(),
        strategy,
        mis: MisHeuristic::Power,
        eye_rays: spp,
        shadow_rays: m,
        bsdf_sampling: penumbra::bsdf::LobeSampling::Importance,
        mis_light: SamplingMode::Area,
        max_depth: 1,
        roulette: false,
        hide_emitters: false,
    };
    let res = UVec2::new(24, 24);
    let camera = scene.camera.rays(res);
    // Lanes walk the pixels of a diagonal band, sample by sample, packing several pixels per
    // packet when spp < PACKET.
    let mut pxs: Vec<PixelSamples> = Vec::new();
    let mut cam = CameraPacket::new();
    // One set of queues for every packet, as a render thread reuses them.
    let mut queues = Queues::new();
    let (mut lanes_checked, mut lit) = (0, 0);
    for p in 0..48u32 {
        let pixel = UVec2::new(p % 24, (p * 7) % 24);
        if pxs.len() == PACKET {
            pxs.clear();
        }
        pxs.push(pattern.pixel(pixel));
        let slot = pxs.len() - 1;
        for i in 0..spp {
            let u = pxs[slot].sample_2d(DIM_FILTER, i, spp);
            let ray = camera.generate(filter_sample(&scene.film.filter, pixel, u));
            cam.push(slot as u8, i, ray);
            if cam.is_full() || (i + 1 == spp && pxs.len() == PACKET) {
                let mut out = [Rgb::ZERO; PACKET];
                let rays = est.li_packet(&pxs, &cam, &mut out, &mut queues);
                let mut rays_single = 0;
                for k in 0..cam.n {
                    let (l, r) = est.li(&pxs[cam.pixel[k] as usize], cam.eye[k], &cam.rays.ray(k));
                    rays_single += r;
                    assert_eq!(
                        l.to_array().map(f32::to_bits),
                        out[k].to_array().map(f32::to_bits),
                        "{strategy:?} {selection} spp {spp} m {m}: lane {k} of pixel {pixel}"
                    );
                    lanes_checked += 1;
                    lit += (l.max_element() > 0.0) as u32;
                }
                assert_eq!(rays, rays_single, "{strategy:?}: ray count");
                cam = CameraPacket::new();
                if pxs.len() == PACKET {
                    let last = pxs.pop();
                    pxs.clear();
                    pxs.extend(last);
                }
            }
        }
    }
    (lanes_checked, lit)
}

/// Not vacuous: many lanes were compared, and many of them carry light.
fn assert_lit((lanes, lit): (u32, u32)) {
    assert!(lanes > 1000 && lit > lanes / 4, "{lanes} lanes, {lit} lit");
}

fn add(a: (u32, u32), b: (u32, u32)) -> (u32, u32) {
    (a.0 + b.0, a.1 + b.1)
}

fn builtin(name: &str) -> Scene {
    load(name, &LoadOptions::default()).unwrap().scene
}

#[test]
fn packet_lanes_equal_single_samples_on_cornell_and_phong() {
    for name in ["cornell", "cornell-phong"] {
        let scene = builtin(name);
        let mut n = (0, 0);
        for s in Strategy::ALL {
            n = add(n, check(&scene, s, SelectorKind::Uniform, 16, 1));
            n = add(n, check(&scene, s, SelectorKind::Uniform, 3, 2));
        }
        assert_lit(n);
    }
}

#[test]
fn packet_lanes_equal_single_samples_with_many_lights() {
    let scene = builtin("many-mesh");
    let mut n = (0, 0);
    for s in [Strategy::Mis, Strategy::Bsdf] {
        n = add(n, check(&scene, s, SelectorKind::Power, 5, 1));
        n = add(n, check(&scene, s, SelectorKind::Bvh, 16, 2));
    }
    assert_lit(n);
}
