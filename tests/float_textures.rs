//! pbrt-v4 float `imagemap` textures: the first channel × `scale`, then `invert`
//! (max(0, 1 − v)), 8-bit files decoded by `encoding` (sRGB default for PNG, `linear`,
//! `gamma γ`), float files linear; used for roughness (a textured conductor renders as the
//! constant-roughness conductor of each texel's value) and as the factor of a spectrum `scale`
//! texture (a diffuse plane of reflectance 0.2 | 0.8 under irradiance π renders 0.2 | 0.8).

mod texture_support;

use glam::{UVec2, Vec2, Vec3};
use penumbra::Rgb;
use penumbra::image::Image;
use penumbra::image::io::{srgb_to_linear, write_image};
use penumbra::integrator::{RenderOptions, render};
use penumbra::material::{FloatTexture, Material, Texture};
use penumbra::scene::pbrt::materials::to_material;
use penumbra::scene::pbrt::{PbrtScene, parse_pbrt_str};
use std::path::Path;
use texture_support::{halves, hit_at, tmpdir};

fn parse(src: &str, dir: &Path) -> PbrtScene {
    parse_pbrt_str("t.pbrt", src, dir).unwrap_or_else(|e| panic!("{e:#}"))
}

fn material(s: &PbrtScene, i: usize) -> Material {
    let mut w = Vec::new();
    to_material(&s.materials[i], &s.images, &mut w).unwrap()
}

/// The float texture behind diffuse material `i`'s reflectance (white × float).
fn float_of(s: &PbrtScene, i: usize) -> FloatTexture {
    match material(s, i) {
        Material::Diffuse {
            reflectance: Texture::Product(a, b),
        } => match (*a, *b) {
            (Texture::Constant(c), Texture::Float(f)) if c == Rgb::ONE => f,
            other => panic!("{other:?}"),
        },
        m => panic!("{m:?}"),
    }
}

#[test]
fn encoding_scale_and_invert_follow_pbrt_v4() {
    let d = tmpdir("enc");
    // Code value 128 in every channel of an 8-bit PNG (written from its sRGB-linear value).
    let c = 128.0 / 255.0f32;
    let mut img = Image::new(2, 2);
    img.pixels.fill(Rgb::splat(srgb_to_linear(c)));
    write_image(&img, &d.join("g.png"), 0.0).unwrap();
    // The same linear 0.3 in a float file, which no encoding changes.
    img.pixels.fill(Rgb::new(0.3, 0.9, 0.9));
    write_image(&img, &d.join("g.exr"), 0.0).unwrap();
    let cases: [(&str, f32); 7] = [
        ("\"string filename\" \"g.png\"", srgb_to_linear(c)),
        (
            "\"string filename\" \"g.png\" \"string encoding\" \"linear\"",
            c,
        ),
        (
            "\"string filename\" \"g.png\" \"string encoding\" \"gamma 2.2\"",
            c.powf(2.2),
        ),
        (
            "\"string filename\" \"g.png\" \"string encoding\" \"linear\" \"float scale\" 0.5 \"bool invert\" true",
            1.0 - 0.5 * c,
        ),
        (
            "\"string filename\" \"g.png\" \"string encoding\" \"linear\" \"float scale\" 4 \"bool invert\" true",
            0.0,
        ),
        // First channel only (0.3, not the mean 0.7).
        (
            "\"string filename\" \"g.exr\" \"string encoding\" \"gamma 2.2\"",
            0.3,
        ),
        ("\"string filename\" \"g.exr\" \"float scale\" 3", 0.9),
    ];
    for (params, want) in cases {
        let src = format!(
            "WorldBegin\nTexture \"f\" \"float\" \"imagemap\" {params}\n\
             Texture \"c\" \"spectrum\" \"scale\" \"rgb tex\" [1 1 1] \"texture scale\" \"f\"\n\
             Material \"diffuse\" \"texture reflectance\" \"c\"\n\
             Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n"
        );
        let s = parse(&src, &d);
        let got = float_of(&s, 0).eval(Vec2::new(0.3, 0.6));
        assert!((got - want).abs() < 1e-5, "{params}: {got} vs {want}");
    }
    // A spectrum imagemap's inversion also comes after its scale: max(0, 1 − 0.5·c).
    let s = parse(
        "WorldBegin\nTexture \"c\" \"spectrum\" \"imagemap\" \"string filename\" \"g.png\" \
         \"string encoding\" \"linear\" \"float scale\" 0.5 \"bool invert\" true\n\
         Material \"diffuse\" \"texture reflectance\" \"c\"\n\
         Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n",
        &d,
    );
    let r = material(&s, 0).bsdf(&hit_at(Vec2::splat(0.5)), true);
    let want = 1.0 - 0.5 * c;
    let f = r.f_pdf(Vec3::Z, Vec3::Z).0 * std::f32::consts::PI;
    assert!((f.x - want).abs() < 1e-5, "{f} vs {want}");
    // Bad encodings are errors at their line.
    let e = parse_pbrt_str(
        "t.pbrt",
        "WorldBegin\nTexture \"f\" \"float\" \"imagemap\" \"string filename\" \"g.png\" \"string encoding\" \"gamma x\"\n",
        &d,
    )
    .unwrap_err();
    assert!(
        format!("{e:#}").contains("t.pbrt:2") && format!("{e:#}").contains("unknown encoding"),
        "{e:#}"
    );
}

/// Render a 32×16 view straight down at the unit square z = 0 (u across, v up) under a
/// distant light from +z of irradiance `e`, with material line `mat`.
fn render_square(dir: &Path, textures: &str, mat: &str, e: f32) -> (Image, PbrtScene) {
    let src = format!(
        "LookAt 0.5 0.5 2  0.5 0.5 0  0 1 0\nCamera \"orthographic\" \"float screenwindow\" [-0.5 0.5 -0.25 0.25]\n\
         PixelFilter \"box\"\nFilm \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 16\n\
         WorldBegin\nLightSource \"distant\" \"point3 from\" [0.3 0 1] \"point3 to\" [0 0 0] \"rgb L\" [1 1 1] \"float scale\" {e}\n\
         {textures}\n{mat}\n\
         Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 1 0 0 1 0] \"point2 uv\" [0 0 1 0 1 1 0 1] \
         \"integer indices\" [0 1 2 0 2 3]\n"
    );
    let s = parse(&src, dir);
    let (b, cam, film, _) = parse(&src, dir).into_builder().unwrap();
    let scene = b.build(cam, film).unwrap();
    let opts = RenderOptions {
        spp: 16,
        ..Default::default()
    };
    (render(&scene, UVec2::new(32, 16), &opts).unwrap().0, s)
}

/// Mean red of the pixels whose centres see u in [u0, u1] (the middle rows).
fn mean_over(img: &Image, s: &PbrtScene, u0: f32, u1: f32) -> (f64, usize) {
    let res = UVec2::new(32, 16);
    let (mut sum, mut n) = (0.0f64, 0usize);
    for y in 4..12 {
        for x in 0..32 {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            // The pixel's u: the nearest projection of points along the square's middle row.
            let u = (0..=100)
                .map(|i| i as f32 / 100.0)
                .min_by(|a, b| {
                    let da =
                        (s.camera.project(Vec3::new(*a, 0.5, 0.0), res).unwrap().x - p.x).abs();
                    let db =
                        (s.camera.project(Vec3::new(*b, 0.5, 0.0), res).unwrap().x - p.x).abs();
                    da.total_cmp(&db)
                })
                .unwrap();
            if u >= u0 && u <= u1 {
                sum += img.pixels[y * 32 + x].x as f64;
                n += 1;
            }
        }
    }
    (sum / n.max(1) as f64, n)
}

#[test]
fn float_imagemap_scales_a_reflectance_to_the_analytic_radiance() {
    let d = tmpdir("refl");
    halves(&d.join("h.exr"), 0.2, 0.8);
    // Irradiance of the tilted light: e·cos θ with cos θ = 1/√1.09; radiance ρ·E/π.
    let cos = 1.0 / 1.09f32.sqrt();
    let e = std::f32::consts::PI / cos;
    let (img, s) = render_square(
        &d,
        "Texture \"f\" \"float\" \"imagemap\" \"string filename\" \"h.exr\"\n\
         Texture \"c\" \"spectrum\" \"scale\" \"rgb tex\" [1 1 1] \"texture scale\" \"f\"",
        "Material \"diffuse\" \"texture reflectance\" \"c\"",
        e,
    );
    // Pure texels: u in [1/16, 7/16] is 0.2, [9/16, 15/16] is 0.8 (bilinear between centres).
    let (left, nl) = mean_over(&img, &s, 0.1, 0.4);
    let (right, nr) = mean_over(&img, &s, 0.6, 0.9);
    assert!(nl >= 40 && nr >= 40, "{nl} {nr}");
    assert!((left - 0.2).abs() < 2e-3, "left {left}");
    assert!((right - 0.8).abs() < 2e-3, "right {right}");
}

#[test]
fn roughness_imagemap_renders_as_each_texels_constant_roughness() {
    let d = tmpdir("rough");
    halves(&d.join("r.exr"), 0.05, 0.4);
    let metal = |r: &str| {
        format!(
            "Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" {r}"
        )
    };
    let tex = "Texture \"r\" \"float\" \"imagemap\" \"string filename\" \"r.exr\"";
    let (textured, s) = render_square(&d, tex, &metal("\"texture roughness\" \"r\""), 3.0);
    let (smooth, _) = render_square(&d, "", &metal("\"float roughness\" 0.05"), 3.0);
    let (rough, _) = render_square(&d, "", &metal("\"float roughness\" 0.4"), 3.0);
    let parts = |img: &Image| {
        (
            mean_over(img, &s, 0.1, 0.4).0,
            mean_over(img, &s, 0.6, 0.9).0,
        )
    };
    let (tl, tr) = parts(&textured);
    let (sl, sr) = parts(&smooth);
    let (rl, rr) = parts(&rough);
    assert!(
        (tl - sl).abs() <= 1e-3 * sl.abs().max(1e-3),
        "left {tl} vs {sl}"
    );
    assert!(
        (tr - rr).abs() <= 1e-3 * rr.abs().max(1e-3),
        "right {tr} vs {rr}"
    );
    // The two roughnesses do look different from this view (the test can tell them apart).
    assert!((sl - rl).abs() > 0.05 * sl.max(rl), "{sl} vs {rl}");
    assert!((sr - rr).abs() > 0.05 * sr.max(rr), "{sr} vs {rr}");
    // u and v axes may differ: a v roughness texture alone leaves u at its constant.
    let s2 = parse(
        &format!(
            "WorldBegin\n{tex}\n{}\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n",
            metal(
                "\"float uroughness\" 0.2 \"texture vroughness\" \"r\" \"bool remaproughness\" false"
            )
        ),
        &d,
    );
    match material(&s2, 0) {
        Material::Varying(v) => {
            let r = v.roughness.as_ref().unwrap();
            assert_eq!(r.alpha(Vec2::new(0.25, 0.5)), Vec2::new(0.2, 0.05));
            assert_eq!(r.alpha(Vec2::new(0.75, 0.5)), Vec2::new(0.2, 0.4));
        }
        m => panic!("{m:?}"),
    }
}

#[test]
fn uv_mapping_scales_and_offsets_image_and_checkerboard_lookups() {
    // pbrt-v4's UVMapping: the texture sees (su·u + du, sv·v + dv).
    let d = tmpdir("map");
    // 8×1 ramp: texel i is i/8 (bilinear between texel centres).
    let mut img = Image::new(8, 1);
    for (i, p) in img.pixels.iter_mut().enumerate() {
        *p = Rgb::splat(i as f32 / 8.0);
    }
    write_image(&img, &d.join("r.exr"), 0.0).unwrap();
    let raw = FloatTexture::Image {
        image: std::sync::Arc::new(penumbra::material::texture::ImageRgb {
            width: 8,
            height: 1,
            pixels: img.pixels.clone(),
        }),
        scale: 1.0,
        invert: false,
    };
    let map = "\"float uscale\" 3 \"float vscale\" 2 \"float udelta\" 0.3 \"float vdelta\" -0.2";
    let s = parse(
        &format!(
            "WorldBegin\nTexture \"f\" \"float\" \"imagemap\" \"string filename\" \"r.exr\" {map}\n\
             Texture \"c\" \"spectrum\" \"imagemap\" \"string filename\" \"r.exr\" {map}\n\
             Texture \"k\" \"spectrum\" \"checkerboard\" \"float uscale\" 4 \"float vscale\" 4 \"float udelta\" 0.5 \
             \"rgb tex1\" [1 1 1] \"rgb tex2\" [0 0 0]\n\
             Texture \"fc\" \"spectrum\" \"scale\" \"rgb tex\" [1 1 1] \"texture scale\" \"f\"\n\
             Material \"diffuse\" \"texture reflectance\" \"fc\"\n\
             Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n\
             Material \"diffuse\" \"texture reflectance\" \"c\"\n\
             Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n\
             Material \"diffuse\" \"texture reflectance\" \"k\"\n\
             Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n"
        ),
        &d,
    );
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    let f = float_of(&s, 0);
    let tex = |i: usize| match material(&s, i) {
        Material::Diffuse { reflectance } => reflectance,
        m => panic!("{m:?}"),
    };
    let (c, k) = (tex(1), tex(2));
    for uv in [
        Vec2::new(0.1, 0.2),
        Vec2::new(0.37, 0.8),
        Vec2::new(0.9, 0.55),
    ] {
        let st = Vec2::new(3.0 * uv.x + 0.3, 2.0 * uv.y - 0.2);
        let want = raw.eval(st);
        assert!(
            (f.eval(uv) - want).abs() < 1e-6,
            "float at {uv}: {} vs {want}",
            f.eval(uv)
        );
        assert!((c.eval(uv).x - want).abs() < 1e-6, "spectrum at {uv}");
        // The mapped lookup differs from the unmapped one here (the test can tell).
        assert!((raw.eval(uv) - want).abs() > 0.02, "{uv}");
    }
    // Checkerboard: squares of 1/4, shifted by udelta 0.5 (an eighth of a square pair).
    let even = |u: f32, v: f32| ((4.0 * u + 0.5).floor() + (4.0 * v).floor()) as i64 % 2 == 0;
    for uv in [
        Vec2::new(0.05, 0.1),
        Vec2::new(0.2, 0.1),
        Vec2::new(0.6, 0.3),
    ] {
        let want = if even(uv.x, uv.y) { 1.0 } else { 0.0 };
        assert_eq!(k.eval(uv).x, want, "checkerboard at {uv}");
    }
}
