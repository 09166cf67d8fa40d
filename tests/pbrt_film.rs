//! `Film "rgb"` sensor parameters: pbrt-v4's imaging ratio (exposure × ISO / 100) and white
//! balance reach the scene's `film.sensor` and scale the rendered image.

use glam::{Mat3, UVec2, Vec3};
use penumbra::integrator::{RenderOptions, render};
use penumbra::scene::pbrt::{parse_pbrt_str, parse_pbrt_to_builder};
use std::path::Path;

fn film(params: &str, camera: &str) -> Mat3 {
    let src = format!(
        "Film \"rgb\" {params}\nCamera \"perspective\" {camera}\nWorldBegin\nShape \"sphere\"\n"
    );
    parse_pbrt_str("film.pbrt", &src, Path::new("."))
        .unwrap()
        .film
        .sensor
        .matrix
}

#[test]
fn iso_and_exposure_scale_as_pbrt_v4_imaging_ratio() {
    assert_eq!(film("", ""), Mat3::IDENTITY);
    assert_eq!(
        film("\"float iso\" 100 \"float exposuretime\" 1", ""),
        Mat3::IDENTITY
    );
    assert_eq!(
        film("\"float iso\" 200", ""),
        Mat3::from_diagonal(Vec3::splat(2.0))
    );
    // pbrt-v4 takes the exposure time from the camera's shutter interval.
    assert_eq!(
        film(
            "\"float iso\" 200",
            "\"float shutteropen\" 0 \"float shutterclose\" 0.25"
        ),
        Mat3::from_diagonal(Vec3::splat(0.5))
    );
    let wb = film("\"float whitebalance\" 3000", "");
    assert!(
        wb.x_axis.x < 1.0 && wb.z_axis.z > 1.0,
        "3000 K balance cools: {wb}"
    );
}

#[test]
fn unknown_sensor_is_an_error_and_camera_sensors_warn_once() {
    let e = parse_pbrt_str(
        "film.pbrt",
        "Film \"rgb\" \"string sensor\" \"kodak\"\nWorldBegin\n",
        Path::new("."),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("film.pbrt:1:") && e.contains("unknown sensor"),
        "{e}"
    );
    let s = parse_pbrt_str(
        "film.pbrt",
        "Film \"rgb\" \"string sensor\" \"canon_eos_5d_mkiv\" \"float iso\" 100\nWorldBegin\n",
        Path::new("."),
    )
    .unwrap();
    let w: Vec<_> = s.warnings.iter().filter(|w| w.contains("sensor")).collect();
    assert_eq!(w.len(), 1, "{:?}", s.warnings);
    assert!(
        w[0].starts_with("film.pbrt:1: warning: Film sensor"),
        "{}",
        w[0]
    );
    assert!(
        !s.warnings.iter().any(|w| w.contains("not supported")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn iso_200_doubles_the_rendered_image() {
    let scene = |iso: f32| {
        let src = format!(
            "Film \"rgb\" \"float iso\" {iso} \"integer xresolution\" 16 \"integer yresolution\" 16\n\
             LookAt 0 0 -3 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\n\
             LightSource \"point\" \"point3 from\" [0 0 -3] \"rgb I\" [5 5 5]\nShape \"sphere\"\n"
        );
        let dir = std::env::temp_dir().join(format!("penumbra-film-{}-{iso}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("s.pbrt");
        std::fs::write(&p, src).unwrap();
        let (b, cam, f, _) = parse_pbrt_to_builder(&p).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        b.build(cam, f).unwrap()
    };
    let opts = RenderOptions {
        spp: 4,
        progress: false,
        ..RenderOptions::default()
    };
    let (s1, s2) = (scene(100.0), scene(200.0));
    let (mut a, _) = render(&s1, UVec2::new(16, 16), &opts).unwrap();
    let (mut b, _) = render(&s2, UVec2::new(16, 16), &opts).unwrap();
    s1.film.sensor.apply(&mut a);
    s2.film.sensor.apply(&mut b);
    assert!(a.mean() > 0.0);
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        assert_eq!(*q, *p * 2.0);
    }
}
