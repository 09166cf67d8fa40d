//! What the texture tests share (`mod texture_support;`): a scratch folder for their image
//! files, a half-and-half image, and a hit at given texture coordinates.
#![allow(dead_code)] // Each test file uses part of this module.

use glam::{Vec2, Vec3};
use penumbra::Rgb;
use penumbra::geometry::SurfaceHit;
use penumbra::image::Image;
use penumbra::image::io::write_image;
use std::path::{Path, PathBuf};

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
