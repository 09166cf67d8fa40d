//! `RenderOptions::hide_emitters` (`--hide-emitters`, Mitsuba 3's `hide_emitters`): the
//! emission camera rays see directly is left out, and nothing else changes.

mod render_support;

use glam::UVec2;
use penumbra::Rgb;
use penumbra::image::Image;
use penumbra::integrator::{IntegratorKind, RenderOptions, Strategy, render};
use penumbra::light_selection::SelectorKind;
use render_support::pbrt_scene;

const RES: UVec2 = UVec2::new(32, 24);

/// A camera looking straight at a two-sided, black area light standing on a grey floor, with
/// a dim sky around: the light's pixels see only emission, the floor's only lighting (the
/// light's and the sky's), the sky's pixels only the environment's emission.
fn scene() -> penumbra::scene::Scene {
    pbrt_scene(
        "LookAt 0 0.5 6  0 0.2 0  0 1 0\nCamera \"perspective\" \"float fov\" 50\n\
         Film \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 24\nWorldBegin\n\
         LightSource \"infinite\" \"rgb L\" [0.2 0.3 0.4]\n\
         AttributeBegin\n\
         AreaLightSource \"diffuse\" \"rgb L\" [8 6 4] \"bool twosided\" true\n\
         Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n\
         Shape \"trianglemesh\" \"point3 P\" [-1 0 0  1 0 0  1 1.5 0  -1 1.5 0] \
         \"integer indices\" [0 1 2 0 2 3]\n\
         AttributeEnd\n\
         Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n\
         Shape \"trianglemesh\" \"point3 P\" [-6 0 -6  6 0 -6  6 0 6  -6 0 6] \
         \"integer indices\" [0 2 1 0 3 2]\n",
    )
}

fn opts(integrator: IntegratorKind, strategy: Strategy, hide: bool) -> RenderOptions {
    RenderOptions {
        spp: 8,
        seed: 5,
        strategy,
        integrator,
        max_depth: 3,
        light_selection: SelectorKind::Power,
        hide_emitters: hide,
        ..RenderOptions::default()
    }
}

fn bits(p: Rgb) -> [u32; 3] {
    p.to_array().map(f32::to_bits)
}

fn img(scene: &penumbra::scene::Scene, o: &RenderOptions) -> Image {
    render(scene, RES, o).expect("renders").0
}

#[test]
fn hide_emitters_removes_exactly_the_emission_camera_rays_see() {
    let scene = scene();
    for integrator in [IntegratorKind::Direct, IntegratorKind::Path] {
        for strategy in [Strategy::Mis, Strategy::LightArea, Strategy::Bsdf] {
            let what = format!("{integrator} {strategy}");
            let shown = img(&scene, &opts(integrator, strategy, false));
            let hidden = img(&scene, &opts(integrator, strategy, true));
            // What the camera rays see directly, alone: max depth 0 (same camera rays).
            let emission = img(
                &scene,
                &RenderOptions {
                    integrator: IntegratorKind::Path,
                    max_depth: 0,
                    ..opts(integrator, strategy, false)
                },
            );
            let (mut lit, mut seen, mut black) = (0, 0, 0);
            for (i, ((&s, &h), &e)) in shown
                .pixels
                .iter()
                .zip(&hidden.pixels)
                .zip(&emission.pixels)
                .enumerate()
            {
                let at = (i % RES.x as usize, i / RES.x as usize);
                if e == Rgb::ZERO {
                    // No camera ray of the pixel saw an emitter: not one bit changes.
                    assert_eq!(bits(h), bits(s), "{what}: pixel {at:?}");
                    lit += (h.max_element() > 0.0) as u32;
                    continue;
                }
                seen += 1;
                // Otherwise the pixel loses what its camera rays saw and nothing else (up to
                // the order of the additions).
                for c in 0..3 {
                    let (s, h, e) = (s[c] as f64, h[c] as f64, e[c] as f64);
                    assert!(
                        (s - (h + e)).abs() <= 1e-5 * s.abs() + 1e-7,
                        "{what}: pixel {at:?} channel {c}: shown {s}, hidden {h} + emission {e}"
                    );
                }
                // Where every camera ray saw the black light or the sky, only lighting that
                // the pixel never had is left: black.
                black += (h == Rgb::ZERO) as u32;
            }
            eprintln!("{what}: {lit} lit pixels unchanged, {seen} seeing emitters, {black} black");
            assert!(lit > 100, "{what}: only {lit} lit floor pixels");
            assert!(seen > 100, "{what}: only {seen} pixels see an emitter");
            assert!(black > 100, "{what}: only {black} pixels went black");
            // The light's centre and the sky above it: emission shown, black hidden.
            for at in [(16, 10), (16, 1)] {
                let i = at.1 * RES.x as usize + at.0;
                assert!(shown.pixels[i].min_element() > 0.1, "{what}: {at:?} shown");
                assert_eq!(bits(hidden.pixels[i]), [0; 3], "{what}: {at:?} hidden");
            }
        }
    }
}

#[test]
fn hide_emitters_is_off_by_default_and_every_thread_count_renders_the_same() {
    assert!(!RenderOptions::default().hide_emitters);
    let scene = scene();
    let o = opts(IntegratorKind::Path, Strategy::Mis, true);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| img(&scene, &o));
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
        .install(|| img(&scene, &o));
    assert!(
        one.pixels
            .iter()
            .map(|&p| bits(p))
            .eq(two.pixels.iter().map(|&p| bits(p)))
    );
}

#[test]
fn render_hide_emitters_flag_darkens_only_the_pixels_that_see_the_light() {
    let dir = std::env::temp_dir().join(format!("penumbra-hide-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let run = |extra: &[&str], name: &str| -> Image {
        let out = dir.join(name);
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
            .args([
                "render", "cornell", "--res", "24x24", "--spp", "4", "-q", "-o",
            ])
            .arg(&out)
            .args(extra)
            .status()
            .unwrap();
        assert!(status.success(), "{extra:?}");
        penumbra::image::io::read_image(&out).unwrap()
    };
    let shown = run(&[], "shown.pfm");
    let hidden = run(&["--hide-emitters"], "hidden.pfm");
    std::fs::remove_dir_all(&dir).ok();
    let (mut same, mut darker) = (0, 0);
    for (s, h) in shown.pixels.iter().zip(&hidden.pixels) {
        if bits(*s) == bits(*h) {
            same += 1;
        } else {
            // Only the ceiling light's own pixels change: they lose its radiance (~17).
            assert!(s.max_element() > h.max_element() + 1.0, "{s:?} → {h:?}");
            darker += 1;
        }
    }
    assert!(
        darker > 0 && same > 10 * darker,
        "{darker} darker, {same} unchanged"
    );
}
