//! Texture-varying alpha cut-outs through the pbrt loader (pbrt-v4's `"texture alpha"`): a roof
//! whose coverage is a float checkerboard (tex1 0.7 / tex2 0.1, mean c = 0.4) or a tiled float
//! image (texels 1, 0, 0.5, 0.2: mean c = 0.425, bilinear with repeat keeps the mean over a
//! period) passes 1 − c of a distant light to the ground below it (shadow rays), and a camera
//! looking down through the same roof (a black one) sees the ground with probability 1 − c,
//! lit through the roof with 1 − c again: (1 − c)² (camera and shadow rays). The patterns are
//! far finer than a pixel, so every pixel's expectation is the pattern's mean; the bounds are
//! 5σ of the measured pixel variance.

mod render_support;

mod texture_support;

use glam::UVec2;
use penumbra::Rgb;
use penumbra::image::Image;
use penumbra::image::io::write_image;
use penumbra::integrator::{RenderOptions, render};
use render_support::{assert_fraction, mean_se, pbrt_scene_in};
use std::path::Path;
use texture_support::tmpdir;

/// The roof's alpha: none, a checkerboard texture, or a tiled 2×2 image.
#[derive(Clone, Copy)]
enum Roof {
    Open,
    Checker,
    Image,
}

/// A diffuse ground at z = 0 under a roof at z = 1 (uv = world xy), a distant light from
/// straight above; the camera below the roof (`above: false`, sees only the ground) or above
/// it looking down through it (`above: true`; the roof is black). `Roof::Open`: no roof.
fn scene(roof: Roof, above: bool) -> String {
    let alpha = match roof {
        Roof::Open => "",
        Roof::Checker => "\"texture alpha\" \"cov\"",
        Roof::Image => "\"texture alpha\" \"img\"",
    };
    let roof = match roof {
        Roof::Open => String::new(),
        _ => format!(
            "Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n\
             Shape \"trianglemesh\" {alpha} \"integer indices\" [0 1 2 0 2 3] \
             \"point3 P\" [-20 -20 1  20 -20 1  20 20 1  -20 20 1] \
             \"point2 uv\" [-20 -20  20 -20  20 20  -20 20]"
        ),
    };
    let eye = if above { "0 0 1.5" } else { "0 0 0.5" };
    format!(
        "LookAt {eye}  0 0 0  0 1 0\n\
         Camera \"perspective\" \"float fov\" 30\n\
         Film \"rgb\" \"integer xresolution\" 24 \"integer yresolution\" 24 \"string filename\" \"x.exr\"\n\
         WorldBegin\n\
         Texture \"cov\" \"float\" \"checkerboard\" \"float uscale\" 1000 \"float vscale\" 1000 \
         \"float tex1\" 0.7 \"float tex2\" 0.1\n\
         Texture \"img\" \"float\" \"imagemap\" \"string filename\" \"cov.pfm\" \
         \"float uscale\" 700 \"float vscale\" 700\n\
         LightSource \"distant\" \"point3 from\" [0 0 10] \"point3 to\" [0 0 0] \"rgb L\" [1 1 1]\n\
         AttributeBegin\n\
         Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \
         \"point3 P\" [-20 -20 0  20 -20 0  20 20 0  -20 20 0]\n\
         AttributeEnd\n\
         {roof}\n"
    )
}

fn write_coverage(dir: &Path) {
    let mut img = Image::new(2, 2);
    for (p, v) in img.pixels.iter_mut().zip([1.0, 0.0, 0.5, 0.2]) {
        *p = Rgb::splat(v);
    }
    write_image(&img, &dir.join("cov.pfm"), 0.0).unwrap();
}

/// Mean of the red channel over the image and its standard error.
fn render_mean(roof: Roof, above: bool, dir: &Path) -> (f64, f64) {
    let (scene, warnings) = pbrt_scene_in(&scene(roof, above), dir);
    assert!(
        !warnings
            .iter()
            .any(|w| w.contains("alpha") || w.contains("texture")),
        "alpha or textures warned about: {warnings:?}"
    );
    let opts = RenderOptions {
        spp: 16,
        seed: 9,
        progress: false,
        ..RenderOptions::default()
    };
    let (img, _) = render(&scene, UVec2::new(24, 24), &opts).unwrap();
    mean_se(&img)
}

/// Assert that the roof passes `want` of the open ground's radiance.
fn check(what: &str, roof: Roof, above: bool, want: f64, dir: &Path) {
    let open = render_mean(Roof::Open, above, dir);
    let under = render_mean(roof, above, dir);
    assert_fraction(what, under, open, want);
}

#[test]
fn checkerboard_alpha_passes_one_minus_its_mean_coverage() {
    let dir = tmpdir("checker");
    write_coverage(&dir);
    check("checker, shadow rays", Roof::Checker, false, 0.6, &dir);
    check(
        "checker, camera + shadow rays",
        Roof::Checker,
        true,
        0.36,
        &dir,
    );
}

#[test]
fn image_alpha_passes_one_minus_its_mean_coverage() {
    let dir = tmpdir("image");
    write_coverage(&dir);
    let c: f64 = 0.425;
    check("image, shadow rays", Roof::Image, false, 1.0 - c, &dir);
    check(
        "image, camera + shadow rays",
        Roof::Image,
        true,
        (1.0 - c).powi(2),
        &dir,
    );
}

/// A coarse checker (one square per unit) is opaque exactly where tex1 = 1 and open where
/// tex2 = 0: the ground under the roof is dark in one square and fully lit in the next.
#[test]
fn coarse_checker_alpha_cuts_where_it_is_zero() {
    let dir = tmpdir("coarse");
    write_coverage(&dir);
    let src = scene(Roof::Checker, false)
        .replace(
            "\"float uscale\" 1000 \"float vscale\" 1000",
            "\"float uscale\" 10 \"float vscale\" 10",
        )
        .replace(
            "\"float tex1\" 0.7 \"float tex2\" 0.1",
            "\"float tex1\" 1 \"float tex2\" 0",
        );
    let (scene, _) = pbrt_scene_in(&src, &dir);
    let opts = RenderOptions {
        spp: 4,
        seed: 1,
        progress: false,
        ..RenderOptions::default()
    };
    let (img, _) = render(&scene, UVec2::new(24, 24), &opts).unwrap();
    // Squares of 0.1 with the camera seeing ±0.134 of the ground: the pixels at (6, 6),
    // (17, 17) lie in diagonal squares around the origin (same parity), (17, 6), (6, 17) in
    // the other two; one parity is opaque (tex1 = 1), the other open (tex2 = 0).
    let at = |x: usize, y: usize| img.pixels[y * 24 + x].x;
    let (a, b) = ((at(6, 6), at(17, 17)), (at(17, 6), at(6, 17)));
    eprintln!("even squares {a:?}, odd squares {b:?}");
    let (dark, lit) = if a.0 < b.0 { (a, b) } else { (b, a) };
    assert!(
        dark.0 < 1e-6 && dark.1 < 1e-6,
        "opaque squares let light through: {dark:?}"
    );
    assert!(lit.0 > 0.1 && lit.1 > 0.1, "open squares are dark: {lit:?}");
}
