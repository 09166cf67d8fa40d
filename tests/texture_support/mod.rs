//! What the texture tests share (`mod texture_support;`): a scratch folder for their image
//! files, a half-and-half and a constant image, a hit at given texture coordinates, and the
//! normal-map tests' lit view: a diffuse surface seen straight down by an orthographic camera
//! under a distant light, whose pixels are ρ/π · E · cos θ′ for the shading normal.
#![allow(dead_code)] // Each test file uses part of this module.

use glam::{DVec3, UVec2, Vec2, Vec3};
use penumbra::Rgb;
use penumbra::geometry::SurfaceHit;
use penumbra::image::Image;
use penumbra::image::io::write_image;
use penumbra::integrator::{RenderOptions, render};
use penumbra::scene::pbrt::parse_pbrt_str;
use std::path::{Path, PathBuf};

/// Direction the distant light of [`lit_header`] comes from (off every axis, so tilts toward
/// u and v and their signs all change the cosine differently).
pub const FROM: [f32; 3] = [0.3, 0.5, 1.0];
/// Irradiance of the distant light on a surface facing it.
pub const E: f64 = 2.0;
/// Diffuse reflectance of [`MAT`].
pub const RHO: f64 = 0.6;
/// The diffuse material's reflectance parameter (ρ = [`RHO`]).
pub const MAT: &str = "\"rgb reflectance\" [0.6 0.6 0.6]";
/// Resolution of the lit view.
pub const RES: UVec2 = UVec2::new(32, 16);

/// Camera and light of the lit view: the rectangle x ∈ [0, 1], y ∈ [0.25, 0.75] of the plane
/// z = 0 seen straight down from height `eye_z` by a 32×16 orthographic camera (box filter),
/// under the distant light from [`FROM`] of irradiance [`E`].
pub fn lit_header(eye_z: f32) -> String {
    format!(
        "LookAt 0.5 0.5 {eye_z}  0.5 0.5 0  0 1 0\nCamera \"orthographic\" \"float screenwindow\" [-0.5 0.5 -0.25 0.25]\n\
         PixelFilter \"box\"\nFilm \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 16\n\
         WorldBegin\nLightSource \"distant\" \"point3 from\" [{} {} {}] \"point3 to\" [0 0 0] \"rgb L\" [1 1 1] \"float scale\" {E}\n",
        FROM[0], FROM[1], FROM[2]
    )
}

/// Render `body` (textures, materials and shapes; files relative to `dir`) under
/// [`lit_header`]`(eye_z)` at 16 spp; no loader warning may contain any of `forbidden`.
pub fn render_lit(dir: &Path, eye_z: f32, body: &str, forbidden: &[&str]) -> Image {
    let src = format!("{}{body}\n", lit_header(eye_z));
    let s = parse_pbrt_str("t.pbrt", &src, dir).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(
        s.warnings
            .iter()
            .all(|w| forbidden.iter().all(|f| !w.contains(f))),
        "{:?}",
        s.warnings
    );
    let (b, cam, film, _) = s.into_builder().unwrap();
    let scene = b.build(cam, film).unwrap();
    let opts = RenderOptions {
        spp: 16,
        ..Default::default()
    };
    render(&scene, RES, &opts).unwrap().0
}

/// ρ/π · E · max(0, n·l) for world normal `n` under the lit view's light.
pub fn analytic(n: DVec3) -> f64 {
    let l = Vec3::from(FROM).normalize().as_dvec3();
    RHO / std::f64::consts::PI * E * n.normalize().dot(l).max(0.0)
}

/// A 4×4 image of one colour (as linear values; for PNG the sRGB-encoded code values are
/// what is stored).
pub fn constant_image(path: &Path, c: Rgb) {
    let mut img = Image::new(4, 4);
    img.pixels.fill(c);
    write_image(&img, path, 0.0).unwrap();
}

/// A fresh scratch folder for one test's texture files (per process, so runs never share one).
pub fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("penumbra-tex-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// An 8×1 image whose left four texels are `a` and right four `b` (all channels).
pub fn halves(path: &Path, a: f32, b: f32) {
    let mut img = Image::new(8, 1);
    for (i, p) in img.pixels.iter_mut().enumerate() {
        *p = Rgb::splat(if i < 4 { a } else { b });
    }
    write_image(&img, path, 0.0).unwrap();
}

/// A hit on the plane z = 0 (normal +z) at the origin with texture coordinates `uv`.
pub fn hit_at(uv: Vec2) -> SurfaceHit {
    SurfaceHit {
        t: 1.0,
        p: Vec3::ZERO,
        ng: Vec3::Z,
        ns: Vec3::Z,
        uv,
        p_error: 0.0,
        prim: 0,
        material: 0,
        light: 0,
    }
}
