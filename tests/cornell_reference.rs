//! The built-in Cornell box against Mitsuba 3's converged direct-lighting render
//! (../shared/reference, tolerances from its README: relMSE at 64 spp, mean within 0.5% / 2%).

mod render_support;

use glam::UVec2;
use penumbra::image::Image;
use penumbra::image::io::read_image;
use penumbra::integrator::{RenderOptions, Strategy, render};
use penumbra::scene::load::{LoadOptions, load};
use render_support::rel_mse;
use std::path::PathBuf;

fn reference() -> Image {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/reference/cornell-direct-mis-8192spp.exr");
    assert!(
        p.exists(),
        "this test needs ../shared/reference/cornell-direct-mis-8192spp.exr beside the project root; it is missing at {}",
        p.display()
    );
    read_image(&p).expect("reading the reference EXR")
}

fn check(strategy: Strategy, max_rel_mse: f64, mean_tol: f64) {
    let reference = reference();
    let scene = load("cornell", &LoadOptions::default()).unwrap().scene;
    let opts = RenderOptions {
        spp: 64,
        strategy,
        seed: 1,
        ..RenderOptions::default()
    };
    let (img, stats) = render(&scene, UVec2::new(512, 512), &opts).unwrap();
    assert_eq!(stats.non_finite, 0, "{strategy}: non-finite samples");
    let e = rel_mse(&img, &reference);
    let (m, mr) = (img.mean(), reference.mean());
    eprintln!(
        "{strategy}: relMSE {e:.3e} (tolerance {max_rel_mse:.1e}), mean {m:.6} vs {mr:.6} ({:+.3}%), {:.2} s",
        100.0 * (m / mr - 1.0),
        stats.time.as_secs_f64()
    );
    assert!(
        e <= max_rel_mse,
        "{strategy}: relMSE {e:.3e} > {max_rel_mse:.1e}"
    );
    assert!(
        (m / mr - 1.0).abs() <= mean_tol,
        "{strategy}: mean {m} differs from the reference's {mr} by more than {}%",
        mean_tol * 100.0
    );
}

#[test]
fn cornell_mis_matches_mitsuba_reference() {
    check(Strategy::Mis, 2.7e-4, 0.005);
}

#[test]
fn cornell_light_area_matches_mitsuba_reference() {
    check(Strategy::LightArea, 2.7e-4, 0.005);
}

#[test]
fn cornell_bsdf_matches_mitsuba_reference() {
    check(Strategy::Bsdf, 0.23, 0.02);
}

#[test]
fn cornell_light_solid_angle_matches_mitsuba_reference() {
    check(Strategy::LightSolidAngle, 2.7e-4, 0.005);
}
