//! pbrt-v4's cameras: the thin lens (a point on the plane of focus images to one point, an
//! edge off it blurs by the circle of confusion R·|1/z − 1/f| in the image plane), the
//! orthographic camera (an object's image does not depend on its distance) and the
//! spherical camera (pbrt-v4's equal-area and equirectangular mappings, round trip).

use glam::{UVec2, Vec2, Vec3};
use penumbra::camera::{Camera, CameraRays, Lens, Projection, SphericalMapping};
use penumbra::geometry::Ray;
use penumbra::integrator::{RenderOptions, render};
use penumbra::sampling::hash::{next_f32, pcg_from_keys};
use penumbra::scene::pbrt::parse_pbrt_str;
use std::f32::consts::{PI, TAU};
use std::path::Path;

fn camera(projection: Projection, lens: Lens) -> Camera {
    let mut c = Camera::look_at(
        Vec3::new(0.3, 1.0, -4.0),
        Vec3::new(0.1, 0.8, 0.0),
        Vec3::Y,
        35.0,
    )
    .unwrap();
    c.projection = projection;
    c.lens = lens;
    c
}

fn rng_vec2(rng: &mut rand_pcg::Pcg32) -> Vec2 {
    Vec2::new(next_f32(rng), next_f32(rng))
}

/// Distance from point `p` to the line of `ray`.
fn line_distance(ray: &Ray, p: Vec3) -> f32 {
    let v = p - ray.o;
    (v - ray.d * v.dot(ray.d)).length()
}

#[test]
fn pinhole_rays_through_the_lens_path_are_bit_identical() {
    let res = UVec2::new(97, 61);
    let rays = camera(Projection::Perspective, Lens::PINHOLE).rays(res);
    let mut rng = pcg_from_keys(&[1]);
    for _ in 0..10_000 {
        let p = rng_vec2(&mut rng) * res.as_vec2();
        let a = rays.generate(p);
        let b = rays.generate_lens(p, rng_vec2(&mut rng));
        assert_eq!(
            [a.o, a.d].map(|v| v.to_array().map(f32::to_bits)),
            [b.o, b.d].map(|v| v.to_array().map(f32::to_bits))
        );
    }
}

#[test]
fn thin_lens_rays_of_one_film_point_meet_on_the_plane_of_focus() {
    // Every lens point's ray through raster position p passes through the point where p's
    // pinhole ray meets the plane of focus: that point images to p alone.
    let res = UVec2::new(64, 48);
    let lens = Lens {
        radius: 0.25,
        focal_distance: 6.0,
    };
    for projection in [Projection::Perspective, Projection::Orthographic] {
        let cam = camera(projection, lens);
        let rays = cam.rays(res);
        let pin = camera(projection, Lens::PINHOLE).rays(res);
        let view = cam.camera_to_world.vector(Vec3::Z).normalize();
        let mut rng = pcg_from_keys(&[2]);
        for _ in 0..200 {
            let p = rng_vec2(&mut rng) * res.as_vec2();
            let chief = pin.generate_lens(p, Vec2::splat(0.5));
            // The focal plane is at view-axis depth f from the lens plane.
            let t = lens.focal_distance / chief.d.dot(view);
            let focus = chief.o + chief.d * t;
            assert!(
                (cam.project(focus, res).unwrap() - p).length() < 1e-3,
                "{projection:?}"
            );
            let mut spread = 0.0f32;
            for _ in 0..64 {
                let r = rays.generate_lens(p, rng_vec2(&mut rng));
                assert!((r.d.length() - 1.0).abs() < 1e-5);
                assert!(line_distance(&r, focus) < 1e-4 * t, "{projection:?}");
                spread = spread.max((r.o - chief.o).length());
            }
            // The rays do leave different points of the lens (of radius 0.25).
            assert!(spread > 0.15 && spread <= 0.25 + 1e-5, "{spread}");
        }
    }
}

/// Render an emissive half-plane x > 0 at depth 10 (camera at the origin looking down +z)
/// with a box filter; `columns` of the 64×32 image, averaged over rows.
fn render_edge(camera: &str, spp: u32) -> Vec<f64> {
    let src = format!(
        "LookAt 0 0 0  0 0 1  0 1 0\n{camera}\nPixelFilter \"box\"\n\
         Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 32\nWorldBegin\n\
         AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n\
         Shape \"trianglemesh\" \"point3 P\" [0 -100 10  100 -100 10  100 100 10  0 100 10] \
         \"integer indices\" [0 2 1 0 3 2]\n"
    );
    let (b, cam, film, _) = parse_pbrt_str("edge.pbrt", &src, Path::new("."))
        .unwrap()
        .into_builder()
        .unwrap();
    let scene = b.build(cam, film).unwrap();
    let opts = RenderOptions {
        spp,
        ..Default::default()
    };
    let (img, _) = render(&scene, UVec2::new(64, 32), &opts).unwrap();
    (0..64)
        .map(|x| {
            (0..32)
                .map(|y| img.pixels[y * 64 + x].x as f64)
                .sum::<f64>()
                / 32.0
        })
        .collect()
}

/// P(ξ < a) for ξ the x coordinate of a uniform point in the unit disk.
fn disk_cdf(a: f64) -> f64 {
    let a = a.clamp(-1.0, 1.0);
    0.5 + (a * (1.0 - a * a).sqrt() + a.asin()) / std::f64::consts::PI
}

#[test]
fn thin_lens_edge_is_sharp_in_focus_and_blurred_by_the_circle_of_confusion() {
    let spp = 256;
    // In focus: every column is black left of the edge's image (x = 32) and lit right of it.
    let cols = render_edge(
        "Camera \"perspective\" \"float fov\" 30 \"float lensradius\" 0.5 \"float focaldistance\" 10",
        spp,
    );
    for (x, &v) in cols.iter().enumerate() {
        let want = if x < 32 { 0.0 } else { 1.0 };
        assert!((v - want).abs() <= 2.0 / spp as f64, "column {x}: {v}");
    }
    // Focused at 5: the edge at 10 blurs over a disk of raster radius
    // R·|1/z − 1/f|·(height/2)/tan(fov/2).
    let r_lens = 0.5f64;
    let coc = r_lens * (0.1f64 - 0.2).abs() * 16.0 / (15.0f64.to_radians()).tan();
    let cols = render_edge(
        "Camera \"perspective\" \"float fov\" 30 \"float lensradius\" 0.5 \"float focaldistance\" 5",
        spp,
    );
    let n = (spp * 32) as f64;
    let mut blurred = 0;
    for (x, &v) in cols.iter().enumerate() {
        // The pixel averages the lit fraction P(x_f + r·ξ > 32) over its film points x_f.
        let steps = 2000;
        let want = (0..steps)
            .map(|i| {
                let xf = x as f64 + (i as f64 + 0.5) / steps as f64;
                1.0 - disk_cdf((32.0 - xf) / coc)
            })
            .sum::<f64>()
            / steps as f64;
        let sigma = (want * (1.0 - want) / n).sqrt();
        assert!(
            (v - want).abs() <= 5.0 * sigma + 1e-3,
            "column {x}: {v} vs {want} (coc {coc:.3} px)"
        );
        if want > 0.02 && want < 0.98 {
            blurred += 1;
        }
    }
    // About 2·coc columns are partly lit (a sharp edge has none).
    assert!(blurred >= 4, "{blurred}");
}

#[test]
fn orthographic_image_does_not_depend_on_distance() {
    let render_quad = |z: f32| {
        let src = format!(
            "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"orthographic\" \"float screenwindow\" [-1 1 -1 1]\n\
             PixelFilter \"box\"\nFilm \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 32\n\
             WorldBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1] \"bool twosided\" true\n\
             Shape \"trianglemesh\" \"point3 P\" [-0.5 -0.5 {z}  0.5 -0.5 {z}  0.5 0.5 {z}  -0.5 0.5 {z}] \
             \"integer indices\" [0 1 2 0 2 3]\n"
        );
        let (b, cam, film, _) = parse_pbrt_str("ortho.pbrt", &src, Path::new("."))
            .unwrap()
            .into_builder()
            .unwrap();
        let scene = b.build(cam, film).unwrap();
        // Uniform selection: the light BVH's pmf depends on the distance to the light and moves
        // the direct term by float rounding (~1e-6); this test is about the projection.
        let opts = RenderOptions {
            spp: 16,
            light_selection: penumbra::light_selection::SelectorKind::Uniform,
            ..Default::default()
        };
        render(&scene, UVec2::new(32, 32), &opts).unwrap().0
    };
    let (near, far) = (render_quad(3.0), render_quad(30.0));
    // A unit square in a 2-unit window: 16×16 pixels, wherever it is.
    let lit = |img: &penumbra::image::Image| img.pixels.iter().filter(|p| p.x > 0.0).count();
    assert_eq!(lit(&near), 256);
    let same = near
        .pixels
        .iter()
        .zip(&far.pixels)
        .all(|(a, b)| (*a - *b).abs().max_element() < 1e-6);
    assert!(same, "the images at depth 3 and 30 differ");
    // Parallel rays: one direction, origins spread over the window.
    let rays = camera(Projection::Orthographic, Lens::PINHOLE).rays(UVec2::new(40, 20));
    let a = rays.generate_lens(Vec2::new(0.5, 0.5), Vec2::ZERO);
    let b = rays.generate_lens(Vec2::new(39.5, 19.5), Vec2::ZERO);
    assert!((a.d - b.d).length() < 1e-6 && (a.o - b.o).length() > 1.0);
}

/// pbrt-v4's spherical-camera direction of image point uv, in camera space.
fn pbrt_spherical(mapping: SphericalMapping, uv: Vec2) -> Vec3 {
    let d = match mapping {
        SphericalMapping::Equirectangular => {
            let (theta, phi) = (PI * uv.y, TAU * uv.x);
            Vec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            )
        }
        SphericalMapping::EqualArea => penumbra::sampling::equal_area_square_to_sphere(uv),
    };
    Vec3::new(d.x, d.z, d.y)
}

#[test]
fn spherical_camera_maps_pixels_per_pbrt_and_round_trips() {
    for (mapping, res) in [
        (SphericalMapping::EqualArea, UVec2::new(64, 64)),
        (SphericalMapping::Equirectangular, UVec2::new(128, 64)),
    ] {
        let cam = camera(Projection::Spherical(mapping), Lens::PINHOLE);
        let rays: CameraRays = cam.rays(res);
        let mut rng = pcg_from_keys(&[9]);
        for _ in 0..20_000 {
            let uv = Vec2::new(
                0.001 + 0.998 * next_f32(&mut rng),
                0.001 + 0.998 * next_f32(&mut rng),
            );
            let p = uv * res.as_vec2();
            let r = rays.generate_lens(p, Vec2::splat(0.5));
            let want = cam
                .camera_to_world
                .vector(pbrt_spherical(mapping, uv))
                .normalize();
            assert!(
                (r.d - want).length() < 1e-5,
                "{mapping:?} {uv}: {} vs {want}",
                r.d
            );
            assert!((r.o - cam.camera_to_world.point(Vec3::ZERO)).length() < 1e-6);
            let back = cam.project(r.o + r.d * 3.0, res).unwrap();
            assert!((back - p).length() < 2e-2, "{mapping:?} {p} -> {back}");
        }
    }
    // Equal-area: every pixel of the square image sees the same solid angle 4π/n² (uniform
    // directions land evenly on the 8×8 image).
    let cam = camera(
        Projection::Spherical(SphericalMapping::EqualArea),
        Lens::PINHOLE,
    );
    let res = UVec2::new(8, 8);
    let mut counts = [0u32; 64];
    let mut rng = pcg_from_keys(&[10]);
    let n = 256_000;
    for _ in 0..n {
        let d = penumbra::sampling::uniform_sphere(rng_vec2(&mut rng));
        let p = cam
            .project(cam.camera_to_world.point(Vec3::ZERO) + d, res)
            .unwrap();
        let (x, y) = ((p.x as usize).min(7), (p.y as usize).min(7));
        counts[y * 8 + x] += 1;
    }
    let mean = n as f64 / 64.0;
    assert!(
        counts
            .iter()
            .all(|&c| (c as f64 - mean).abs() < 5.0 * mean.sqrt())
    );
}

#[test]
fn pbrt_cameras_parse() {
    let cam = |s: &str| {
        parse_pbrt_str("c.pbrt", &format!("{s}\nWorldBegin"), Path::new(".")).map(|p| p.camera)
    };
    let c =
        cam("Camera \"perspective\" \"float lensradius\" 0.1 \"float focaldistance\" 3").unwrap();
    assert_eq!(c.projection, Projection::Perspective);
    assert_eq!(
        c.lens,
        Lens {
            radius: 0.1,
            focal_distance: 3.0
        }
    );
    let c = cam("Camera \"orthographic\" \"float screenwindow\" [-2 2 -1 1]").unwrap();
    assert_eq!(c.projection, Projection::Orthographic);
    assert_eq!(c.screen_window, Some([-2.0, 2.0, -1.0, 1.0]));
    assert_eq!(
        cam("Camera \"spherical\"").unwrap().projection,
        Projection::Spherical(SphericalMapping::EqualArea)
    );
    assert_eq!(
        cam("Camera \"spherical\" \"string mapping\" \"equirectangular\"")
            .unwrap()
            .projection,
        Projection::Spherical(SphericalMapping::Equirectangular)
    );
    // frameaspectratio sets the default screen window.
    assert_eq!(
        cam("Camera \"perspective\" \"float frameaspectratio\" 2")
            .unwrap()
            .screen_window,
        Some([-2.0, 2.0, -1.0, 1.0])
    );
    for (bad, want) in [
        (
            "Camera \"fisheye\"",
            "c.pbrt:1:8: unknown camera \"fisheye\"",
        ),
        (
            "Camera \"spherical\" \"string mapping\" \"cube\"",
            "unknown mapping \"cube\"",
        ),
        (
            "Camera \"perspective\" \"float lensradius\" -1",
            "lensradius must be ≥ 0",
        ),
        (
            "Camera \"perspective\" \"float lensradius\" 1 \"float focaldistance\" 0",
            "focaldistance must be positive",
        ),
    ] {
        let e = cam(bad).unwrap_err().to_string();
        assert!(e.contains(want), "{bad}: {e}");
    }
    // No warning about the lens any more.
    let s = parse_pbrt_str(
        "c.pbrt",
        "Camera \"perspective\" \"float lensradius\" 0.1\nWorldBegin",
        Path::new("."),
    )
    .unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
}

/// Render a small emissive square (a quarter of a pixel's footprint wide) on the plane z = 10,
/// centred on the chief ray of raster point (40.825, 10.825) of a 64×32 image, so its sharp
/// image spans [40.7, 40.95]² (0.05 pixel from the pixel's edges), through a thin lens of
/// radius 0.5 focused at `focal`; box filter, so a sample only reaches the pixel it is drawn in.
fn render_point(focal: f32, spp: u32) -> Vec<f64> {
    let head = format!(
        "LookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\" \"float fov\" 30 \
         \"float lensradius\" 0.5 \"float focaldistance\" {focal}\nPixelFilter \"box\"\n\
         Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 32\nWorldBegin\n"
    );
    let res = UVec2::new(64, 32);
    let cam = parse_pbrt_str("p.pbrt", &head, Path::new("."))
        .unwrap()
        .camera;
    let mut pin = cam.clone();
    pin.lens = Lens::PINHOLE;
    let chief = pin.rays(res).generate(Vec2::new(40.825, 10.825));
    let c = chief.o + chief.d * ((10.0 - chief.o.z) / chief.d.z);
    // Pixel footprint at depth 10: 2·tan 15°·10 / 32 ≈ 0.167; the square is 0.042 wide.
    let h = 0.25 * 2.0 * 15f32.to_radians().tan() * 10.0 / 32.0 / 2.0;
    let src = format!(
        "{head}AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n\
         Shape \"trianglemesh\" \"point3 P\" [{x0} {y0} 10  {x1} {y0} 10  {x1} {y1} 10  {x0} {y1} 10] \
         \"integer indices\" [0 2 1 0 3 2]\n",
        x0 = c.x - h,
        x1 = c.x + h,
        y0 = c.y - h,
        y1 = c.y + h,
    );
    let (b, cam, film, _) = parse_pbrt_str("p.pbrt", &src, Path::new("."))
        .unwrap()
        .into_builder()
        .unwrap();
    let scene = b.build(cam, film).unwrap();
    let opts = RenderOptions {
        spp,
        ..Default::default()
    };
    let (img, _) = render(&scene, res, &opts).unwrap();
    img.pixels.iter().map(|p| p.x as f64).collect()
}

#[test]
fn thin_lens_focuses_a_point_on_the_plane_of_focus_to_one_pixel() {
    let spp = 1024;
    let sharp = render_point(10.0, spp);
    let lit: Vec<usize> = (0..sharp.len()).filter(|&i| sharp[i] > 0.0).collect();
    assert_eq!(
        lit,
        vec![10 * 64 + 40],
        "in focus, only pixel (40, 10) sees the square"
    );
    // It covers 1/16 of the pixel's footprint, whatever the lens point.
    let v = sharp[10 * 64 + 40];
    let sigma = (0.0625 * (1.0 - 0.0625) / spp as f64).sqrt();
    assert!((v - 0.0625).abs() < 5.0 * sigma, "{v}");
    // A blur of radius 0.27 pixel (focused at 11: 0.5·|1/10 − 1/11|·16/tan 15°) already leaks
    // past the 0.05-pixel margin.
    let near = render_point(11.0, spp);
    let leak: f64 = near.iter().sum::<f64>() - near[10 * 64 + 40];
    assert!(leak > 0.0, "focused at 11, nothing left pixel (40, 10)");
    // Focused at 5 the same square spreads over a disk of radius ≈ 3 pixels, conserving the
    // image's total.
    let blurred = render_point(5.0, spp);
    let lit = blurred.iter().filter(|&&v| v > 0.0).count();
    assert!(lit >= 20, "{lit} pixels lit out of focus");
    let total: f64 = blurred.iter().sum();
    assert!((total - 0.0625).abs() < 0.01, "total {total}");
}
