//! The default light selection (issue 16 item 2) is not uniform, and it gives a light that
//! dominates a scene a sensible share of the samples: one bright lamp among a thousand dim
//! emitters (with uniform it got 1/1001, and the image was fireflies), and a sun among them
//! (Bitterli's lamp scene: the sun got 1/1929 with uniform).

use glam::{UVec2, Vec2, Vec3};
use penumbra::Rgb;
use penumbra::camera::Camera;
use penumbra::integrator::RenderOptions;
use penumbra::light_selection::{SelectorKind, ShadingPoint, make_selector};
use penumbra::lights::{DistantLight, Light, PointLight};
use penumbra::material::{Material, Texture};
use penumbra::scene::{AreaEmission, FilmSpec, Filter, Scene, SceneBuilder, TriangleMesh};

/// Dim emitters: a 40 × 25 grid of small downward-facing triangles 3 units above the floor.
const DIM: usize = 1000;

/// A floor under `DIM` dim triangle lights (radiance 1, area 0.005 each), plus `extra`.
fn lamp_scene(extra: Light) -> Scene {
    let mut b = SceneBuilder::new();
    let grey = b.add_material(Material::Diffuse {
        reflectance: Texture::Constant(Rgb::splat(0.5)),
    });
    b.add_quad(
        Vec3::new(-10.0, 0.0, -10.0),
        Vec3::Z * 20.0,
        Vec3::X * 20.0,
        grey,
        None,
    )
    .unwrap();
    let mut positions = Vec::new();
    for i in 0..DIM {
        let p = Vec3::new(
            -8.0 + 16.0 * (i % 40) as f32 / 39.0,
            3.0,
            -8.0 + 16.0 * (i / 40) as f32 / 24.0,
        );
        // Counter-clockwise seen from below: the emitting side faces the floor.
        positions.extend([p, p + Vec3::X * 0.1, p + Vec3::Z * 0.1]);
    }
    let mesh = TriangleMesh {
        indices: (0..positions.len() as u32).collect(),
        positions,
        normals: None,
        uvs: None,
        flip_normals: false,
    };
    let e = AreaEmission {
        l: Rgb::splat(1.0),
        two_sided: true,
    };
    b.add_mesh(mesh, grey, Some(e)).unwrap();
    b.add_light(extra);
    let camera = Camera::look_at(Vec3::new(0.0, 2.0, -9.0), Vec3::ZERO, Vec3::Y, 60.0).unwrap();
    let film = FilmSpec {
        resolution: UVec2::new(16, 16),
        filter: Filter::Box {
            radius: Vec2::splat(0.5),
        },
        filename: None,
        spp: None,
        sensor: Default::default(),
    };
    b.build(camera, film).unwrap()
}

/// Floor points under the lights, facing up.
fn floor_points() -> Vec<ShadingPoint> {
    [(0.0, 0.0), (3.0, -2.0), (-6.0, 5.0), (7.5, 7.5)]
        .into_iter()
        .map(|(x, z)| ShadingPoint {
            p: Vec3::new(x, 0.0, z),
            n: Vec3::Y,
            wo: Vec3::Y,
        })
        .collect()
}

/// The fraction of 4096 stratified draws of the default selector that pick `light` at `sp`.
fn picked_fraction(scene: &Scene, sp: &ShadingPoint, light: u32) -> f64 {
    let sel = make_selector(RenderOptions::default().light_selection, scene, 1);
    let n = 4096;
    let hits = (0..n)
        .filter(|&i| {
            let u = (i as f32 + 0.5) / n as f32;
            sel.sample(sp, u).is_some_and(|s| s.index == light)
        })
        .count();
    hits as f64 / n as f64
}

#[test]
fn the_default_selection_is_not_uniform() {
    assert_ne!(SelectorKind::DEFAULT, SelectorKind::Uniform);
    assert_eq!(
        RenderOptions::default().light_selection,
        SelectorKind::DEFAULT
    );
    // The CLI's default (when the scene file names no lightsampler) is the same, and --help
    // lists every value.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(["render", "--help"])
        .output()
        .expect("penumbra runs");
    let help = String::from_utf8_lossy(&out.stdout);
    let flag = help
        .split("--light-selection")
        .nth(1)
        .expect("--help documents --light-selection");
    let flag = &flag[..flag.find("\n  -").unwrap_or(flag.len())];
    assert!(
        flag.contains(&format!("else {}", SelectorKind::DEFAULT)),
        "{flag}"
    );
    for kind in SelectorKind::ALL {
        assert!(flag.contains(kind.name()), "--help omits {kind}: {flag}");
    }
}

/// A lamp of 40 W-equivalent intensity among a thousand dim emitters: at every floor point it
/// gives most of the irradiance, so it must get a large share of the light samples (uniform:
/// 1/1001).
#[test]
fn a_bright_lamp_among_dim_lights_gets_a_sensible_probability() {
    let lamp = Light::Point(PointLight::new(Vec3::new(0.0, 2.5, 0.0), Rgb::splat(40.0)));
    let scene = lamp_scene(lamp);
    let lamp_index = scene
        .lights
        .iter()
        .position(|l| matches!(l, Light::Point(_)))
        .expect("the lamp is a light") as u32;
    assert_eq!(scene.lights.len(), DIM + 1);
    let sel = make_selector(RenderOptions::default().light_selection, &scene, 1);
    for sp in floor_points() {
        let pmf = sel.pmf(&sp, lamp_index);
        let picked = picked_fraction(&scene, &sp, lamp_index);
        eprintln!("lamp at {}: pmf {pmf:.3}, picked {picked:.3}", sp.p);
        // Its share of the power is 40·4π / (40·4π + 1000·0.005·π·2) ≈ 0.94; the pmf must be
        // at least a sizeable fraction of that, and sampling must agree.
        assert!(pmf > 0.2, "lamp pmf {pmf} at {}", sp.p);
        assert!((picked - pmf as f64).abs() < 0.01, "{picked} vs {pmf}");
    }
}

/// A sun among the same dim emitters: lights without bounds get a fixed 10 % share (uniform
/// gave it 1/1001).
#[test]
fn a_sun_among_dim_lights_gets_its_fixed_share() {
    let sun = Light::Distant(DistantLight::new(Vec3::new(0.3, 1.0, 0.2), Rgb::splat(3.0)));
    let scene = lamp_scene(sun);
    let sun_index = scene
        .lights
        .iter()
        .position(|l| matches!(l, Light::Distant(_)))
        .expect("the sun is a light") as u32;
    let sel = make_selector(RenderOptions::default().light_selection, &scene, 1);
    for sp in floor_points() {
        let pmf = sel.pmf(&sp, sun_index);
        let picked = picked_fraction(&scene, &sp, sun_index);
        assert!(
            (pmf - penumbra::light_selection::INFINITE_SHARE).abs() < 1e-6,
            "sun pmf {pmf} at {}",
            sp.p
        );
        assert!((picked - pmf as f64).abs() < 0.01, "{picked} vs {pmf}");
    }
}
