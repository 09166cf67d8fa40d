//! pbrt-v4 normal maps (`"string normalmap"`: tangent-space RGB = (n + 1)/2 read linearly, the
//! frame x = ∂p/∂u, z = the shading normal) and bump maps (`"texture displacement"`: finite
//! differences of the displacement in u and v). A flat plane whose map encodes a constant
//! tilt must render as a plane of that normal under a distant light: ρ/π · E · cos θ′; a
//! flat map changes nothing bit for bit; bad maps are errors at their line.

mod texture_support;

use glam::{UVec2, Vec3};
use penumbra::Rgb;
use penumbra::image::Image;
use penumbra::image::io::{srgb_to_linear, write_image};
use penumbra::scene::pbrt::parse_pbrt_str;
use std::path::Path;
use texture_support::{MAT, analytic, constant_image, lit_header, render_lit, tmpdir};

/// Height of the camera over the square.
const EYE_Z: f32 = 2.0;

/// The unit square z = 0 seen straight down by the lit view (every pixel sees it), with
/// material line `mat`. `uv` gives the vertices' texture coordinates; `normals` an optional
/// `"normal N"` parameter.
fn render_square(dir: &Path, textures: &str, mat: &str, uv: &str, normals: &str) -> Image {
    let body = format!(
        "{textures}\n{mat}\n\
         Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 1 0 0 1 0] \"point2 uv\" [{uv}] {normals} \
         \"integer indices\" [0 1 2 0 2 3]"
    );
    render_lit(dir, EYE_Z, &body, &["ignored"])
}

/// Texture coordinates u = x, v = y.
const UV: &str = "0 0 1 0 1 1 0 1";
/// Texture coordinates u = y, v = x: ∂p/∂u is +y, so the tangent frame turns with it.
const UV_TURNED: &str = "0 0 0 1 1 1 1 0";

/// Mean and standard error of the red channel over columns `x0..x1` (all rows).
fn mean_sigma(img: &Image, x0: usize, x1: usize) -> (f64, f64) {
    let v: Vec<f64> = (0..16)
        .flat_map(|y| (x0..x1).map(move |x| (x, y)))
        .map(|(x, y)| img.pixels[y * 32 + x].x as f64)
        .collect();
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|a| (a - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

/// The render's mean is the analytic value within 5σ. A delta light on a Lambertian plane
/// has no variance (σ is rounding, ~1e-8), so the bound has a floor of 2e-5 relative: the
/// f32 arithmetic of the frame and of the finite differences.
fn assert_analytic(what: &str, img: &Image, x0: usize, x1: usize, n: Vec3) {
    let (m, s) = mean_sigma(img, x0, x1);
    let want = analytic(n.as_dvec3());
    let bound = (5.0 * s).max(2e-5 * want);
    assert!(
        (m - want).abs() <= bound,
        "{what}: {m} vs analytic {want} (σ {s}, bound {bound})"
    );
}

#[test]
fn constant_tilt_normal_map_renders_as_the_tilted_normal() {
    let d = tmpdir("tilt");
    let flat = render_square(&d, "", &format!("Material \"diffuse\" {MAT}"), UV, "");
    assert_analytic("no map", &flat, 0, 32, Vec3::Z);
    let (flat_mean, _) = mean_sigma(&flat, 0, 32);
    // (tangent-space normal, uv layout, world normal pbrt-v4's frame gives it).
    let (a, b) = (0.35f32, 0.25f32);
    let toward_u = Vec3::new(a.sin(), 0.0, a.cos());
    let toward_v = Vec3::new(0.0, b.sin(), b.cos());
    let away_u = Vec3::new(-a.sin(), 0.0, a.cos());
    let cases = [
        ("toward +u", toward_u, UV, toward_u),
        ("toward +v", toward_v, UV, toward_v),
        ("toward −u", away_u, UV, away_u),
        // u along +y: x of the frame is +y, y of the frame is z × y = −x.
        (
            "toward +u, u = y",
            toward_u,
            UV_TURNED,
            Vec3::new(0.0, a.sin(), a.cos()),
        ),
        (
            "toward +v, u = y",
            toward_v,
            UV_TURNED,
            Vec3::new(-b.sin(), 0.0, b.cos()),
        ),
    ];
    for (i, (what, local, uv, world)) in cases.into_iter().enumerate() {
        let file = format!("n{i}.exr");
        constant_image(&d.join(&file), (local + Vec3::ONE) * 0.5);
        let img = render_square(
            &d,
            "",
            &format!("Material \"diffuse\" {MAT} \"string normalmap\" \"{file}\""),
            uv,
            "",
        );
        assert_analytic(what, &img, 0, 32, world);
        // The tilt is visible: far outside the bound of the flat plane's value.
        let (m, _) = mean_sigma(&img, 0, 32);
        assert!(
            (m - flat_mean).abs() > 0.02 * flat_mean,
            "{what}: {m} vs flat {flat_mean}"
        );
    }
}

#[test]
fn eight_bit_normal_maps_are_read_linearly() {
    // pbrt-v4 reads normal maps with the linear encoding whatever the file type: code value c
    // is c/255, so (128, 128, 255) is the normal (1, 1, 255)/|…| (a tilt of 0.3°), and
    // (200, 128, 230) is (145, 1, 205)/|…|. An sRGB decode would give other normals.
    let d = tmpdir("png");
    for (i, code) in [[128u8, 128, 255], [200, 128, 230]].into_iter().enumerate() {
        let file = format!("c{i}.png");
        let c = Rgb::from_array(code.map(|v| srgb_to_linear(v as f32 / 255.0)));
        constant_image(&d.join(&file), c);
        let img = render_square(
            &d,
            "",
            &format!("Material \"diffuse\" {MAT} \"string normalmap\" \"{file}\""),
            UV,
            "",
        );
        let n = Vec3::from_array(code.map(|v| 2.0 * v as f32 / 255.0 - 1.0));
        assert_analytic(&format!("{code:?}"), &img, 0, 32, n);
    }
}

#[test]
fn flat_normal_map_changes_nothing_bit_for_bit() {
    let d = tmpdir("flat");
    // (0.5, 0.5, 1) is the tangent-space +z exactly (an 8-bit 128 is not 0.5: see above).
    constant_image(&d.join("flat.exr"), Rgb::new(0.5, 0.5, 1.0));
    // Smooth vertex normals that differ (the shading normal is not the geometric one).
    let smooth = "\"normal N\" [0 0 1  0.2 0 1  0.2 0.1 1  0 0.1 1]";
    for (mat, normals) in [
        (format!("Material \"diffuse\" {MAT}"), ""),
        (format!("Material \"diffuse\" {MAT}"), smooth),
        (
            "Material \"conductor\" \"spectrum eta\" \"metal-Cu-eta\" \"spectrum k\" \"metal-Cu-k\" \"float roughness\" 0.3".to_string(),
            smooth,
        ),
        (
            "Material \"coateddiffuse\" \"rgb reflectance\" [0.5 0.3 0.2] \"float roughness\" 0.2"
                .to_string(),
            "",
        ),
    ] {
        let plain = render_square(&d, "", &mat, UV_TURNED, normals);
        let mapped = render_square(
            &d,
            "",
            &format!("{mat} \"string normalmap\" \"flat.exr\""),
            UV_TURNED,
            normals,
        );
        for (i, (a, b)) in plain.pixels.iter().zip(&mapped.pixels).enumerate() {
            assert!(
                a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits),
                "{mat} {normals}: pixel {i}: {a} vs {b}"
            );
        }
    }
}

/// A 64-texel ramp whose bilinear interpolation is k·u (or k·v) exactly between the first
/// and last texel centres.
fn ramp(path: &Path, k: f32, along_v: bool) {
    let (w, h) = if along_v { (1, 64) } else { (64, 1) };
    let mut img = Image::new(w, h);
    for (i, p) in img.pixels.iter_mut().enumerate() {
        // Rows are stored top first and the top row is v = 1.
        let t = if along_v { 63 - i } else { i };
        *p = Rgb::splat(k * (t as f32 + 0.5) / 64.0);
    }
    write_image(&img, path, 0.0).unwrap();
}

#[test]
fn bump_map_of_a_linear_ramp_renders_as_the_tilted_normal() {
    let d = tmpdir("bump");
    let k = 0.4f32;
    ramp(&d.join("u.exr"), k, false);
    ramp(&d.join("v.exr"), k, true);
    // Height k·u raises the surface toward +u, so its normal leans toward −u: (−k, 0, 1).
    let cases = [
        ("u ramp", "u.exr", UV, Vec3::new(-k, 0.0, 1.0)),
        ("v ramp", "v.exr", UV, Vec3::new(0.0, -k, 1.0)),
        // u = y: the height rises along +y.
        ("u ramp, u = y", "u.exr", UV_TURNED, Vec3::new(0.0, -k, 1.0)),
    ];
    for (what, file, uv, n) in cases {
        let img = render_square(
            &d,
            &format!("Texture \"h\" \"float\" \"imagemap\" \"string filename\" \"{file}\""),
            &format!("Material \"diffuse\" {MAT} \"texture displacement\" \"h\""),
            uv,
            "",
        );
        // Columns 0 and 31 see u within half a texel of the edges, where the repeat wrap
        // blends the ramp's ends (when u runs across the image).
        assert_analytic(what, &img, 1, 31, n);
        let (m, _) = mean_sigma(&img, 1, 31);
        assert!(
            (m - analytic(Vec3::Z.as_dvec3())).abs() > 0.02 * m,
            "{what}: {m} looks flat"
        );
    }
    // A constant displacement is no bump at all: the material stays plain.
    let s = parse_pbrt_str(
        "t.pbrt",
        "WorldBegin\nMaterial \"diffuse\" \"float displacement\" 0.3\nShape \"sphere\"\n",
        &d,
    )
    .unwrap();
    assert!(
        matches!(
            s.materials[0],
            penumbra::scene::pbrt::materials::MaterialDesc::Diffuse { .. }
        ),
        "{:?}",
        s.materials[0]
    );
}

#[test]
fn bad_normal_maps_are_errors_at_their_line() {
    let d = tmpdir("bad");
    let grey = image::GrayImage::from_pixel(4, 4, image::Luma([200u8]));
    grey.save(d.join("grey.png")).unwrap();
    let cases = [
        ("missing.png", "file not found"),
        ("grey.png", "one (grey) channel"),
    ];
    for (file, why) in cases {
        let src = format!(
            "WorldBegin\n\nMaterial \"diffuse\"\n  \"string normalmap\" \"{file}\"\nShape \"sphere\"\n"
        );
        let e = parse_pbrt_str("t.pbrt", &src, &d).unwrap_err();
        let msg = format!("{e:#}");
        assert!(
            msg.contains("t.pbrt:4") && msg.contains(why) && msg.contains(file),
            "{msg}"
        );
    }
    // Normal maps on quadrics are applied (tests/quadric_maps.rs), so nothing warns.
    let good = d.join("ok.exr");
    constant_image(&good, Rgb::new(0.5, 0.5, 1.0));
    let s = parse_pbrt_str(
        "t.pbrt",
        "WorldBegin\nMaterial \"diffuse\" \"string normalmap\" \"ok.exr\"\nShape \"sphere\"\nShape \"disk\"\nShape \"cylinder\"\n",
        &d,
    )
    .unwrap();
    assert!(
        s.warnings.iter().all(|w| !w.contains("normal")),
        "{:?}",
        s.warnings
    );
}

/// The (u, v) each pixel centre of `render_square`'s 32×16 view sees (UV layout), found by
/// projecting a fine grid of points of the square.
fn pixel_uvs(dir: &Path) -> Vec<glam::Vec2> {
    let s = parse_pbrt_str("t.pbrt", &lit_header(EYE_Z), dir).unwrap();
    let res = UVec2::new(32, 16);
    let mut best = vec![(f32::INFINITY, glam::Vec2::ZERO); 32 * 16];
    for i in 0..=400 {
        for j in 0..=400 {
            let uv = glam::Vec2::new(i as f32 / 400.0, j as f32 / 400.0);
            let Some(p) = s.camera.project(Vec3::new(uv.x, uv.y, 0.0), res) else {
                continue;
            };
            let (x, y) = (p.x.floor() as i64, p.y.floor() as i64);
            if !(0..32).contains(&x) || !(0..16).contains(&y) {
                continue;
            }
            let k = y as usize * 32 + x as usize;
            let d = (p - (glam::Vec2::new(x as f32, y as f32) + 0.5)).length();
            if d < best[k].0 {
                best[k] = (d, uv);
            }
        }
    }
    best.into_iter().map(|b| b.1).collect()
}

#[test]
fn normal_map_texels_land_where_their_uv_is() {
    // Four quadrants of different tilts: the lookup's u and v orientation (an image row 0 is
    // v = 1) must put each where its uv is, as a constant map cannot tell.
    let d = tmpdir("quad");
    let t = 0.3f32;
    let tilt = |x: f32, y: f32| Vec3::new(x * t.sin(), y * t.sin(), 1.0).normalize();
    // (u < ½ or not, v < ½ or not) → tangent-space normal.
    let quadrant = |u_hi: bool, v_hi: bool| match (u_hi, v_hi) {
        (false, false) => tilt(1.0, 0.0),
        (true, false) => tilt(0.0, 1.0),
        (false, true) => tilt(-1.0, 0.0),
        (true, true) => tilt(0.0, -1.0),
    };
    let mut img = Image::new(8, 8);
    for (k, p) in img.pixels.iter_mut().enumerate() {
        let (i, j) = (k % 8, k / 8);
        // Row j = 0 is the top, v = 1.
        *p = (quadrant(i >= 4, j < 4) + Vec3::ONE) * 0.5;
    }
    write_image(&img, &d.join("q.exr"), 0.0).unwrap();
    let r = render_square(
        &d,
        "",
        &format!("Material \"diffuse\" {MAT} \"string normalmap\" \"q.exr\""),
        UV,
        "",
    );
    let uvs = pixel_uvs(&d);
    let mut checked = [0usize; 4];
    for (k, uv) in uvs.iter().enumerate() {
        // Pure texels only: more than one texel (1/8) from the quadrant borders and the wrap.
        let inner = |c: f32| (0.07..0.43).contains(&c) || (0.57..0.93).contains(&c);
        if !inner(uv.x) || !inner(uv.y) {
            continue;
        }
        let (u_hi, v_hi) = (uv.x > 0.5, uv.y > 0.5);
        let want = analytic(quadrant(u_hi, v_hi).as_dvec3());
        let got = r.pixels[k].x as f64;
        assert!(
            (got - want).abs() <= 2e-5 * want,
            "pixel {k} at uv {uv}: {got} vs {want}"
        );
        checked[u_hi as usize + 2 * v_hi as usize] += 1;
    }
    assert!(checked.iter().all(|&c| c >= 8), "{checked:?}");
}
