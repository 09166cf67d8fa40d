//! pbrt-v4's image texture `wrap` modes and MIP-mapped lookups over each hit's pixel footprint
//! (`filter` point / bilinear / trilinear; ewa read as trilinear), the footprint-filtered
//! checkerboard, and textured layer parameters of coated materials.
//!
//! Independent answers: wrap modes against pbrt-v4's `RemapPixelCoords` written out by hand
//! on a 4×4 image of distinct texels; MIP levels against box means of the image; a plane seen
//! far away whose checker squares are much smaller than a pixel renders as the checker's mean
//! (the render of a constant texture of that mean) with a small fraction of the pixel-to-pixel
//! variance of point lookups; a coated material whose `albedo`, `g` and `thickness` are
//! half-and-half image textures evaluates, at each half, exactly the constant-parameter
//! material of that half's values.

mod texture_support;

use glam::{UVec2, Vec2, Vec3};
use penumbra::Rgb;
use penumbra::image::Image;
use penumbra::image::io::write_image;
use penumbra::integrator::{RenderOptions, render};
use penumbra::material::texture::{ImageRgb, MipFilter, MipMap, Wrap, checkerboard_weight};
use penumbra::material::{Material, TexCoord};
use penumbra::scene::pbrt::materials::to_material;
use penumbra::scene::pbrt::parse_pbrt_str;
use std::path::Path;
use std::sync::Arc;
use texture_support::{halves, hit_at, tmpdir};

/// A 4×4 image whose texel (x, y) (row 0 at the top) holds 10·y + x in every channel.
fn numbered() -> ImageRgb {
    ImageRgb {
        width: 4,
        height: 4,
        pixels: (0..16)
            .map(|i| Rgb::splat((10 * (i / 4) + i % 4) as f32))
            .collect(),
    }
}

#[test]
fn wrap_modes_read_pbrts_texels() {
    let img = numbered();
    let v = |x: i64, y: i64, w: Wrap| img.texel(x, y, w).x;
    // Inside, every mode reads the texel itself.
    for w in [
        Wrap::Repeat,
        Wrap::Black,
        Wrap::Clamp,
        Wrap::OctahedralSphere,
    ] {
        assert_eq!(v(2, 1, w), 12.0);
    }
    // repeat: modulo; clamp: the edge; black: zero.
    assert_eq!(v(-1, 0, Wrap::Repeat), 3.0);
    assert_eq!(v(5, 6, Wrap::Repeat), 21.0);
    assert_eq!(v(-1, 0, Wrap::Clamp), 0.0);
    assert_eq!(v(5, 6, Wrap::Clamp), 33.0);
    assert_eq!(v(-1, 0, Wrap::Black), 0.0);
    assert_eq!(v(4, 2, Wrap::Black), 0.0);
    assert_eq!(v(3, 3, Wrap::Black), 33.0);
    // octahedral sphere: x < 0 → (−x, h − 1 − y); x ≥ w → (2w − 1 − x, h − 1 − y);
    // y < 0 → (w − 1 − x, −y); y ≥ h → (w − 1 − x, 2h − 1 − y).
    assert_eq!(v(-1, 0, Wrap::OctahedralSphere), 31.0); // (1, 3)
    assert_eq!(v(4, 1, Wrap::OctahedralSphere), 23.0); // (3, 2)
    assert_eq!(v(1, -1, Wrap::OctahedralSphere), 12.0); // (2, 1)
    assert_eq!(v(0, 4, Wrap::OctahedralSphere), 33.0); // (3, 3)
    // Both at once: (−1, −1) → (1, 4) → (2, 3).
    assert_eq!(v(-1, -1, Wrap::OctahedralSphere), 32.0);
    // Bilinear lookups between texels follow the same addressing: halfway past the left edge
    // of row 0 (uv.y near the top) blends texel (0, 0) with its wrapped neighbour.
    let top = 1.0 - 0.5 / 4.0;
    let left = Vec2::new(0.0, top);
    assert_eq!(img.bilinear_wrapped(left, Wrap::Repeat).x, 1.5); // (0 + 3) / 2
    assert_eq!(img.bilinear_wrapped(left, Wrap::Clamp).x, 0.0);
    assert_eq!(img.bilinear_wrapped(left, Wrap::Black).x, 0.0); // (0 + 0) / 2
    assert_eq!(img.bilinear_wrapped(left, Wrap::OctahedralSphere).x, 15.5); // (0 + 31) / 2
}

#[test]
fn pyramid_levels_are_box_means_and_lookups_pick_pbrts_level() {
    let img = Arc::new(numbered());
    let mip = MipMap::new(img.clone(), Wrap::Repeat, MipFilter::Bilinear);
    assert_eq!(mip.levels.len(), 3);
    let l1 = &mip.levels[1];
    assert_eq!((l1.width, l1.height), (2, 2));
    // Texel (1, 0) of level 1 = mean of texels (2..4, 0..2) = (2 + 3 + 12 + 13) / 4.
    assert_eq!(l1.pixels[1].x, 7.5);
    let mean = img.pixels.iter().map(|p| p.x).sum::<f32>() / 16.0;
    assert_eq!(mip.levels[2].pixels[0].x, mean);
    // An odd size averages the texels that exist.
    let odd = ImageRgb {
        width: 3,
        height: 1,
        pixels: vec![Rgb::splat(1.0), Rgb::splat(2.0), Rgb::splat(6.0)],
    };
    let h = odd.halved();
    assert_eq!((h.width, h.height), (2, 1));
    assert_eq!((h.pixels[0].x, h.pixels[1].x), (1.5, 6.0));

    // Footprint widths: width = 2·max|∂(u,v)|; level = levels − 1 + log2(width).
    let at = |d: f32, f: MipFilter| {
        let m = MipMap::new(img.clone(), Wrap::Repeat, f);
        m.lookup(&TexCoord {
            uv: Vec2::new(0.3, 0.6),
            duvdx: Vec2::new(d, 0.0),
            duvdy: Vec2::new(0.0, d * 0.5),
        })
        .x
    };
    let uv = Vec2::new(0.3, 0.6);
    let b0 = img.bilinear(uv).x;
    let b1 = mip.levels[1].bilinear(uv).x;
    // No footprint and below level 1: level 0.
    assert_eq!(at(0.0, MipFilter::Bilinear), b0);
    assert_eq!(at(0.1, MipFilter::Bilinear), b0); // level 2 + log2(0.2) = -0.32
    // width 0.5 → level 1 exactly; width 0.7 → 1.49: bilinear reads level 1, trilinear blends.
    assert_eq!(at(0.25, MipFilter::Bilinear), b1);
    assert_eq!(at(0.35, MipFilter::Bilinear), b1);
    let t = 2.0 + (0.7f32).log2() - 1.0;
    let want = b1 + (mean - b1) * t;
    assert!((at(0.35, MipFilter::Trilinear) - want).abs() < 1e-4);
    // Trilinear below level 1 is level 0 alone (pbrt-v4's iLevel == 0 case).
    assert_eq!(at(0.15, MipFilter::Trilinear), b0);
    // Width ≥ 1: the coarsest texel.
    assert_eq!(at(0.6, MipFilter::Point), mean);
}

#[test]
fn filtered_checkerboard_is_the_triangle_filtered_square_wave() {
    // Without footprint: 0 on even squares, 1 on odd.
    assert_eq!(
        checkerboard_weight(&TexCoord::point(Vec2::new(0.5, 0.5))),
        0.0
    );
    assert_eq!(
        checkerboard_weight(&TexCoord::point(Vec2::new(1.5, 0.5))),
        1.0
    );
    // A wide footprint: the mean ½ (the triangle filter spans many squares).
    let wide = TexCoord {
        uv: Vec2::new(0.37, 0.81),
        duvdx: Vec2::new(40.0, 0.0),
        duvdy: Vec2::new(0.0, 40.0),
    };
    assert!((checkerboard_weight(&wide) - 0.5).abs() < 2e-3);
    // Against a numerical integral of the triangle filter (half-width r = 1.5·footprint) over
    // the square wave along u (v deep inside a square).
    for (x, f) in [(0.3f32, 0.4f32), (0.9, 0.2), (2.2, 1.1), (-0.7, 0.6)] {
        let tc = TexCoord {
            uv: Vec2::new(x, 0.5),
            duvdx: Vec2::new(f, 0.0),
            duvdy: Vec2::ZERO,
        };
        let r = 1.5 * f as f64;
        let n = 200_000;
        let (mut num, mut den) = (0.0f64, 0.0f64);
        for i in 0..n {
            let t = -r + 2.0 * r * (i as f64 + 0.5) / n as f64;
            let w = r - t.abs();
            let s = x as f64 + t;
            let odd = (s.floor() as i64).rem_euclid(2) as f64;
            num += w * odd;
            den += w;
        }
        let want = num / den;
        let got = checkerboard_weight(&tc) as f64;
        assert!((got - want).abs() < 1e-4, "x {x} f {f}: {got} vs {want}");
    }
}

/// A plane at z = 0 far below a narrow camera, diffuse with reflectance `refl` (a texture
/// clause), lit head-on by a distant light.
fn far_plane(refl: &str) -> String {
    format!(
        "LookAt 0 0 50  0 0 0  0 1 0\n\
         Camera \"perspective\" \"float fov\" 10\n\
         Film \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 32 \"string filename\" \"x.exr\"\n\
         WorldBegin\n\
         LightSource \"distant\" \"point3 from\" [0 0 10] \"point3 to\" [0 0 0] \"rgb L\" [3.14159265 3.14159265 3.14159265]\n\
         Texture \"img\" \"spectrum\" \"imagemap\" \"string filename\" \"checker.pfm\" \
         \"float uscale\" 64 \"float vscale\" 64 \"string filter\" \"trilinear\"\n\
         Texture \"proc\" \"spectrum\" \"checkerboard\" \"float uscale\" 16384 \"float vscale\" 16384 \
         \"rgb tex1\" [0.9 0.9 0.9] \"rgb tex2\" [0.1 0.1 0.1]\n\
         Material \"diffuse\" {refl}\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \
         \"point3 P\" [-10 -10 0  10 -10 0  10 10 0  -10 10 0] \
         \"point2 uv\" [0 0  1 0  1 1  0 1]\n"
    )
}

/// A 256² checker of single texels 0.9 / 0.1 (mean 0.5).
fn write_checker(dir: &Path) {
    let mut img = Image::new(256, 256);
    for (i, p) in img.pixels.iter_mut().enumerate() {
        let (x, y) = (i % 256, i / 256);
        *p = Rgb::splat(if (x + y) % 2 == 0 { 0.9 } else { 0.1 });
    }
    write_image(&img, &dir.join("checker.pfm"), 0.0).unwrap();
}

/// Mean and variance over pixels of the red channel.
fn render_stats(src: &str, dir: &Path, filtering: bool) -> (f64, f64) {
    let parsed = parse_pbrt_str("far.pbrt", src, dir).unwrap_or_else(|e| panic!("{e:#}"));
    let (mut b, cam, film, warnings) = parsed.into_builder().unwrap();
    assert!(
        !warnings.iter().any(|w| w.contains("texture")),
        "{warnings:?}"
    );
    b.set_texture_filtering(filtering);
    let scene = b.build(cam, film).unwrap();
    let opts = RenderOptions {
        spp: 4,
        seed: 3,
        progress: false,
        ..RenderOptions::default()
    };
    let (img, _) = render(&scene, UVec2::new(32, 32), &opts).unwrap();
    let v: Vec<f64> = img.pixels.iter().map(|p| p.x as f64).collect();
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var)
}

#[test]
fn far_checkers_converge_to_their_mean_with_less_variance() {
    let dir = tmpdir("far");
    write_checker(&dir);
    let (flat, flat_var) =
        render_stats(&far_plane("\"rgb reflectance\" [0.5 0.5 0.5]"), &dir, true);
    assert!((flat - 0.5).abs() < 1e-3, "E = π, ρ = 0.5 renders {flat}");
    assert!(flat_var < 1e-8, "{flat_var}");
    for (what, refl) in [
        ("image", "\"texture reflectance\" \"img\""),
        ("checkerboard", "\"texture reflectance\" \"proc\""),
    ] {
        let src = far_plane(refl);
        let (point_mean, point_var) = render_stats(&src, &dir, false);
        let (mip_mean, mip_var) = render_stats(&src, &dir, true);
        // Point lookups: each pixel averages 4 samples of ±0.4 around 0.5 (variance 0.04 for
        // independent samples; the stratified pattern lowers it).
        let se = (point_var / 1024.0).sqrt();
        eprintln!(
            "{what}: point lookups mean {point_mean:.4} var {point_var:.2e}; filtered mean \
             {mip_mean:.5} var {mip_var:.2e}"
        );
        assert!(
            point_var > 1e-3,
            "{what}: the point lookups did not alias: {point_var}"
        );
        assert!(
            (point_mean - 0.5).abs() < 5.0 * se,
            "{what}: point mean {point_mean}"
        );
        assert!(
            mip_var < 0.01 * point_var,
            "{what}: filtered variance {mip_var} is not ≪ {point_var}"
        );
        assert!(
            (mip_mean - 0.5).abs() < 5e-3,
            "{what}: filtered mean {mip_mean} is not the checker's mean 0.5"
        );
    }
}

#[test]
fn wrap_and_filter_are_parsed_and_unknown_ones_rejected() {
    let dir = tmpdir("parse");
    write_checker(&dir);
    let with = |extra: &str| {
        format!(
            "WorldBegin\nTexture \"t\" \"float\" \"imagemap\" \"string filename\" \"checker.pfm\" {extra}\n"
        )
    };
    for ok in [
        "\"string wrap\" \"clamp\"",
        "\"string wrap\" \"black\"",
        "\"string wrap\" \"octahedralsphere\"",
        "\"string filter\" \"point\"",
        "\"string filter\" \"trilinear\"",
    ] {
        let s = parse_pbrt_str("t.pbrt", &with(ok), &dir).unwrap();
        assert!(
            !s.warnings
                .iter()
                .any(|w| w.contains("wrap") || w.contains("filter")),
            "{ok}: {:?}",
            s.warnings
        );
    }
    let s = parse_pbrt_str("t.pbrt", &with("\"string filter\" \"ewa\""), &dir).unwrap();
    assert!(
        s.warnings.iter().any(|w| w.contains("ewa")),
        "{:?}",
        s.warnings
    );
    for bad in ["\"string wrap\" \"mirror\"", "\"string filter\" \"gauss\""] {
        let e = parse_pbrt_str("t.pbrt", &with(bad), &dir).unwrap_err();
        assert!(format!("{e:#}").contains("t.pbrt:2"), "{e:#}");
    }
}

#[test]
fn textured_layer_parameters_are_the_constant_ones_of_each_half() {
    let dir = tmpdir("layer");
    halves(&dir.join("albedo.pfm"), 0.2, 0.9);
    halves(&dir.join("g.pfm"), -0.3, 0.7);
    halves(&dir.join("thick.pfm"), 0.05, 0.8);
    let tex = "Texture \"alb\" \"spectrum\" \"imagemap\" \"string filename\" \"albedo.pfm\"\n\
               Texture \"g\" \"float\" \"imagemap\" \"string filename\" \"g.pfm\"\n\
               Texture \"th\" \"float\" \"imagemap\" \"string filename\" \"thick.pfm\"\n";
    let mats = [
        "Material \"coateddiffuse\" \"texture albedo\" \"alb\" \"texture g\" \"g\" \"texture thickness\" \"th\" \"rgb reflectance\" [0.6 0.3 0.2] \"float roughness\" 0.2",
        "Material \"coateddiffuse\" \"rgb albedo\" [0.2 0.2 0.2] \"float g\" -0.3 \"float thickness\" 0.05 \"rgb reflectance\" [0.6 0.3 0.2] \"float roughness\" 0.2",
        "Material \"coateddiffuse\" \"rgb albedo\" [0.9 0.9 0.9] \"float g\" 0.7 \"float thickness\" 0.8 \"rgb reflectance\" [0.6 0.3 0.2] \"float roughness\" 0.2",
        "Material \"coatedconductor\" \"texture albedo\" \"alb\" \"texture g\" \"g\" \"texture thickness\" \"th\" \"float interface.roughness\" 0.1 \"float conductor.roughness\" 0.3",
        "Material \"coatedconductor\" \"rgb albedo\" [0.2 0.2 0.2] \"float g\" -0.3 \"float thickness\" 0.05 \"float interface.roughness\" 0.1 \"float conductor.roughness\" 0.3",
        "Material \"coatedconductor\" \"rgb albedo\" [0.9 0.9 0.9] \"float g\" 0.7 \"float thickness\" 0.8 \"float interface.roughness\" 0.1 \"float conductor.roughness\" 0.3",
    ];
    // One shape per material, read back in order.
    let mut src2 = format!("WorldBegin\n{tex}");
    for m in mats {
        src2 += &format!(
            "{m}\nShape \"trianglemesh\" \"integer indices\" [0 1 2] \"point3 P\" [0 0 0 1 0 0 0 1 0]\n"
        );
    }
    let s = parse_pbrt_str("t.pbrt", &src2, &dir).unwrap_or_else(|e| panic!("{e:#}"));
    assert!(
        !s.warnings
            .iter()
            .any(|w| w.contains("albedo") || w.contains("varying")),
        "{:?}",
        s.warnings
    );
    let mut w = Vec::new();
    let m: Vec<Material> = s
        .materials
        .iter()
        .map(|d| to_material(d, &s.images, &mut w).unwrap())
        .collect();
    let dirs = [
        (
            Vec3::new(0.3, 0.2, 0.93).normalize(),
            Vec3::new(-0.5, 0.1, 0.86).normalize(),
        ),
        (
            Vec3::new(0.0, 0.6, 0.8),
            Vec3::new(0.1, -0.7, 0.7).normalize(),
        ),
        (
            Vec3::new(0.7, 0.0, 0.71).normalize(),
            Vec3::new(0.69, 0.0, 0.72).normalize(),
        ),
    ];
    let f = |mat: &Material, uv: Vec2| -> Vec<Rgb> {
        let b = mat.bsdf(&hit_at(uv), true);
        dirs.iter().map(|&(wo, wi)| b.f_pdf(wo, wi).0).collect()
    };
    for base in [0, 3] {
        let (tex_m, left, right) = (&m[base], &m[base + 1], &m[base + 2]);
        let (l, r) = (Vec2::new(0.2, 0.5), Vec2::new(0.8, 0.5));
        assert_eq!(f(tex_m, l), f(left, l), "material {base}: left half");
        assert_eq!(f(tex_m, r), f(right, r), "material {base}: right half");
        let (fl, fr) = (f(left, l), f(right, l));
        let differ = fl
            .iter()
            .zip(&fr)
            .any(|(a, b)| (*a - *b).abs().max_element() > 0.02 * a.max_element().max(1e-3));
        assert!(
            differ,
            "material {base}: the halves' parameters change nothing: {fl:?} {fr:?}"
        );
    }
}
