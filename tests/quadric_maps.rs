//! pbrt-v4 normal and bump maps on quadrics, curves and bilinear patches: the tangent frame
//! x = ∂p/∂u, z = n of the shape's own (u, v) (pbrt-v4's parametric derivatives). A disk and
//! a sphere whose map encodes a constant tilt render, pixel by pixel, as the tilted normal of
//! that frame under a distant light (ρ/π · E · cos θ′); a disk agrees with a finely
//! tessellated mesh of the same uvs, and a flat bilinear patch with the quad mesh of the same
//! corners, bit for bit up to rounding, under a varying normal map and a bump map; a flat
//! map, (0.5, 0.5, 1), changes nothing bit for bit; and the derivatives themselves are
//! the finite differences of each shape's parameterisation.

mod texture_support;

use glam::{DVec3, Mat4, Vec2, Vec3};
use penumbra::Rgb;
use penumbra::geometry::curve::{CurveSegment, CurveType};
use penumbra::geometry::{Quadric, QuadricKind, Transform};
use penumbra::image::Image;
use penumbra::image::io::write_image;
use penumbra::scene::pbrt::parse_pbrt_str;
use std::f32::consts::PI;
use std::path::Path;
use texture_support::{MAT, RES, analytic, constant_image, lit_header, render_lit, tmpdir};

/// Height of the camera over the plane z = 0 (a sphere reaches above it).
const EYE_Z: f32 = 4.0;

/// Render `body` (materials and shapes) in the lit view; no warning may mention a map.
fn render_body(dir: &Path, body: &str) -> Image {
    render_lit(dir, EYE_Z, body, &["normal", "bump", "ignored"])
}

/// World (x, y) of each pixel centre on the plane z = 0 (the orthographic view is affine:
/// inverted from the projections of three points).
fn pixel_points(dir: &Path) -> Vec<Vec2> {
    let s = parse_pbrt_str("t.pbrt", &lit_header(EYE_Z), dir).unwrap();
    let pr = |p: Vec3| s.camera.project(p, RES).expect("in view");
    let (o, ex, ey) = (pr(Vec3::ZERO), pr(Vec3::X), pr(Vec3::Y));
    let m = glam::Mat2::from_cols(ex - o, ey - o).inverse();
    (0..RES.y)
        .flat_map(|j| (0..RES.x).map(move |i| Vec2::new(i as f32 + 0.5, j as f32 + 0.5)))
        .map(|c| m * (c - o))
        .collect()
}

/// The tangent-space normal tilted by `a` from +z toward azimuth `b` in the frame.
fn tilt(a: f32, b: f32) -> Vec3 {
    Vec3::new(a.sin() * b.cos(), a.sin() * b.sin(), a.cos())
}

/// A constant map of the tangent-space normal `local` in `dir`/`file`.
fn tilt_map(dir: &Path, file: &str, local: Vec3) {
    constant_image(&dir.join(file), (local + Vec3::ONE) * 0.5);
}

/// Relative per-pixel differences of `got` from `want` (red channel) over the pixels `keep`
/// selects: (max, mean of the signed ones).
fn rel_errors(got: &Image, want: &[f64], keep: &[bool]) -> (f64, f64, usize) {
    let (mut max, mut sum, mut n) = (0.0f64, 0.0f64, 0usize);
    for ((p, &w), &k) in got.pixels.iter().zip(want).zip(keep) {
        if !k {
            continue;
        }
        let e = (p.x as f64 - w) / w;
        max = max.max(e.abs());
        sum += e;
        n += 1;
    }
    (max, sum / n.max(1) as f64, n)
}

/// Render `shape` under a constant normal map of each tangent-space normal of `tilts` and
/// check every pixel against the analytic shading of that normal in the frame [x, y, n] that
/// `frame` gives at the pixel's point of the plane z = 0 (relative errors: max below
/// `max_bound`, signed mean below `mean_bound`); the images, in the order of `tilts`.
fn assert_tilts_in_frame(
    what: &str,
    d: &Path,
    shape: &str,
    tilts: [Vec3; 3],
    frame: impl Fn(Vec2) -> [DVec3; 3],
    (max_bound, mean_bound): (f64, f64),
) -> Vec<Image> {
    let pts = pixel_points(d);
    let mut images = Vec::new();
    for (i, local) in tilts.into_iter().enumerate() {
        let file = format!("{what}{i}.exr");
        tilt_map(d, &file, local);
        let img = render_body(
            d,
            &format!("Material \"diffuse\" {MAT} \"string normalmap\" \"{file}\"\n{shape}"),
        );
        let l = local.as_dvec3();
        let want: Vec<f64> = pts
            .iter()
            .map(|&p| {
                let [x, y, n] = frame(p);
                analytic(x * l.x + y * l.y + n * l.z)
            })
            .collect();
        let (max, mean, n) = rel_errors(&img, &want, &vec![true; want.len()]);
        eprintln!("{what} tilt {local}: max {max:.2e}, mean {mean:.2e} over {n} pixels");
        assert!(
            max < max_bound && mean.abs() < mean_bound,
            "{what} {local}: {max} {mean}"
        );
        images.push(img);
    }
    images
}

#[test]
fn disk_normal_map_tilts_in_the_disks_own_frame() {
    // A disk centred at (−1.5, −1.5) covering the view: the view sees φ ∈ [0.5, 1.1], where
    // ∂p/∂u = φmax (−y, x, 0) is the tangent and y = n × x points to the centre (∂p/∂v
    // runs inward: v = 1 − r/R).
    let d = tmpdir("disk");
    let shape =
        "AttributeBegin Translate -1.5 -1.5 0 Shape \"disk\" \"float radius\" 10 AttributeEnd";
    let frame = |p: Vec2| {
        let q = (p + Vec2::splat(1.5)).as_dvec2();
        let phi = q.y.atan2(q.x);
        let x = DVec3::new(-phi.sin(), phi.cos(), 0.0);
        [x, DVec3::Z.cross(x), DVec3::Z]
    };
    // The box filter averages the cosine over each pixel (φ turns 0.01 across one): a
    // second-order difference from its centre's value.
    let tilts = [tilt(0.4, 0.0), tilt(0.35, 1.9), tilt(0.5, -2.4)];
    for (img, local) in assert_tilts_in_frame("disk", &d, shape, tilts, frame, (1e-3, 2e-4))
        .iter()
        .zip(tilts)
    {
        // The frame turns across the view: the image is not one value.
        let (lo, hi) = img
            .pixels
            .iter()
            .fold((f32::MAX, 0.0f32), |(a, b), p| (a.min(p.x), b.max(p.x)));
        assert!(hi - lo > 0.005 * hi, "{local}: flat image {lo}..{hi}");
    }
}

/// The annular sector of the disk of radius 10 centred at (−1.5, −1.5) that the view sees,
/// as a mesh of `nphi` × 16 quads with the disk's uvs (φ/2π, 1 − r/10).
fn disk_sector_mesh(nphi: usize) -> String {
    let (r0, r1, p0, p1) = (1.6f32, 3.4f32, 0.35f32, 1.25f32);
    let nr = 16;
    let (mut p, mut uv, mut idx) = (String::new(), String::new(), String::new());
    for i in 0..=nphi {
        for j in 0..=nr {
            let phi = p0 + (p1 - p0) * i as f32 / nphi as f32;
            let r = r0 + (r1 - r0) * j as f32 / nr as f32;
            p += &format!("{} {} 0 ", r * phi.cos() - 1.5, r * phi.sin() - 1.5);
            uv += &format!("{} {} ", phi / (2.0 * PI), 1.0 - r / 10.0);
        }
    }
    let at = |i: usize, j: usize| i * (nr + 1) + j;
    for i in 0..nphi {
        for j in 0..nr {
            // Wound outward along r, then φ: (p1 − p0) × (p2 − p0) is +z, the disk's normal.
            idx += &format!(
                "{} {} {} {} {} {} ",
                at(i, j),
                at(i, j + 1),
                at(i + 1, j + 1),
                at(i, j),
                at(i + 1, j + 1),
                at(i + 1, j)
            );
        }
    }
    format!(
        "Shape \"trianglemesh\" \"point3 P\" [{p}] \"point2 uv\" [{uv}] \"integer indices\" [{idx}]"
    )
}

/// `shape` and `mesh` rendered with the material line `mat`: the relative differences of the
/// shape's image from the mesh's over the pixels `keep` selects (max, signed mean, count), and
/// the largest from the mesh rendered without the map (what the map changes).
fn against_mesh(
    d: &Path,
    mat: &str,
    shape: &str,
    mesh: &str,
    keep: &[bool],
) -> ((f64, f64, usize), f64) {
    let got = render_body(d, &format!("{mat}\n{shape}"));
    let mapped = render_body(d, &format!("{mat}\n{mesh}"));
    let plain = render_body(d, &format!("Material \"diffuse\" {MAT}\n{mesh}"));
    let red = |img: &Image| -> Vec<f64> { img.pixels.iter().map(|p| p.x as f64).collect() };
    let errors = rel_errors(&got, &red(&mapped), keep);
    (errors, rel_errors(&got, &red(&plain), keep).0)
}

#[test]
fn disk_normal_map_shades_as_the_same_map_on_an_equivalent_mesh() {
    // 512 φ-steps over 0.9 rad: each triangle's ∂p/∂u is its chord's, within 0.001 rad of the
    // disk's tangent, so the tilted normals agree within sin(tilt)·0.001.
    let d = tmpdir("diskmesh");
    let local = tilt(0.45, 0.7);
    tilt_map(&d, "t.exr", local);
    let mat = format!("Material \"diffuse\" {MAT} \"string normalmap\" \"t.exr\"");
    let disk =
        "AttributeBegin Translate -1.5 -1.5 0 Shape \"disk\" \"float radius\" 10 AttributeEnd";
    let ((max, mean, n), unmapped) = against_mesh(
        &d,
        &mat,
        disk,
        &disk_sector_mesh(512),
        &vec![true; want_len()],
    );
    eprintln!("disk vs mesh: max {max:.2e}, mean {mean:.2e} over {n} pixels");
    assert!(n == 512 && max < 1e-3 && mean.abs() < 2e-4, "{max} {mean}");
    // …and both differ from the unmapped surface by far more.
    assert!(unmapped > 0.05, "the map changes the shading: {unmapped}");
}

#[test]
fn sphere_normal_map_tilts_in_the_spheres_own_frame() {
    // A sphere of radius 5 whose surface at the view's centre has normal (0, 0.6, 0.8),
    // away from its poles: x = ∂p/∂u/|∂p/∂u| = (−y, x, 0)/ρ, y = n × x (∂p/∂v's direction,
    // toward the north pole).
    let d = tmpdir("sphere");
    let c = DVec3::new(0.5, -2.5, -4.0);
    let shape =
        "AttributeBegin Translate 0.5 -2.5 -4 Shape \"sphere\" \"float radius\" 5 AttributeEnd";
    let frame = |p: Vec2| {
        let (x, y) = (p.x as f64 - c.x, p.y as f64 - c.y);
        let q = DVec3::new(x, y, (25.0 - x * x - y * y).sqrt());
        let n = q / 5.0;
        let fx = DVec3::new(-q.y, q.x, 0.0).normalize();
        [fx, n.cross(fx), n]
    };
    let tilts = [tilt(0.4, 0.0), tilt(0.35, 1.4), tilt(0.5, 3.5)];
    assert_tilts_in_frame("sphere", &d, shape, tilts, frame, (2e-3, 3e-4));
}

/// The unit square z = 0 at x, y ∈ [0, 1] as a bilinear patch or as the quad mesh of the
/// same corners and uvs.
fn square(bilinear: bool) -> &'static str {
    if bilinear {
        "Shape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0] \"integer indices\" [0 1 2 3]"
    } else {
        "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 1 1 0 0 1 0] \"point2 uv\" [0 0 1 0 1 1 0 1] \"integer indices\" [0 1 2 0 2 3]"
    }
}

/// Pixels in the image.
fn want_len() -> usize {
    (RES.x * RES.y) as usize
}

/// A 64-texel ramp along u whose bilinear interpolation is k·u between the texel centres.
fn ramp(path: &Path, k: f32) {
    let mut img = Image::new(64, 1);
    for (i, p) in img.pixels.iter_mut().enumerate() {
        *p = Rgb::splat(k * (i as f32 + 0.5) / 64.0);
    }
    write_image(&img, path, 0.0).unwrap();
}

#[test]
fn bilinear_patch_maps_shade_as_the_equivalent_quad_mesh() {
    let d = tmpdir("patch");
    // Four quadrants of different tilts, so the lookup's u and v both matter.
    let mut img = Image::new(8, 8);
    for (k, p) in img.pixels.iter_mut().enumerate() {
        let (i, j) = (k % 8, k / 8);
        let local = tilt(0.3 + 0.1 * (i / 4) as f32, 1.0 + 2.0 * (j / 4) as f32);
        *p = (local + Vec3::ONE) * 0.5;
    }
    write_image(&img, &d.join("q.exr"), 0.0).unwrap();
    ramp(&d.join("h.exr"), 0.4);
    for mat in [
        format!("Material \"diffuse\" {MAT} \"string normalmap\" \"q.exr\""),
        format!(
            "Texture \"h\" \"float\" \"imagemap\" \"string filename\" \"h.exr\"\nMaterial \"diffuse\" {MAT} \"texture displacement\" \"h\""
        ),
    ] {
        // Columns 0 and 31 see u within half a texel of the edges, where the repeat wrap
        // blends the ramp's ends (over the mesh's filter footprint, wider than the patch's
        // point lookups: quadrics have no pixel footprint).
        let inner: Vec<bool> = (0..want_len()).map(|k| !matches!(k % 32, 0 | 31)).collect();
        let ((max, mean, _), unmapped) =
            against_mesh(&d, &mat, square(true), square(false), &inner);
        // A bump map's slope is a forward difference in f32 over the mesh's footprint step or
        // the patch's fixed 0.0005: rounding of h over the smaller step is ~1e-4 of the tilt.
        let bound = if mat.contains("displacement") {
            1e-4
        } else {
            2e-5
        };
        eprintln!("patch vs mesh: max {max:.2e}, mean {mean:.2e}");
        assert!(max < bound, "{mat}: patch vs mesh {max} (mean {mean})");
        assert!(
            unmapped > 0.02,
            "{mat}: the map changes the shading: {unmapped}"
        );
    }
}

#[test]
fn flat_normal_map_on_quadrics_changes_nothing_bit_for_bit() {
    let d = tmpdir("flat");
    // (0.5, 0.5, 1) is the tangent-space +z exactly.
    constant_image(&d.join("flat.exr"), Rgb::new(0.5, 0.5, 1.0));
    let shapes = [
        "AttributeBegin Translate 0.5 0.5 0 Shape \"sphere\" \"float radius\" 0.3 AttributeEnd",
        "AttributeBegin Translate 0.5 0.5 0 Rotate 30 1 0 0 Shape \"disk\" \"float radius\" 0.4 AttributeEnd",
        "AttributeBegin Translate 0.5 0.5 0 Rotate 70 1 1 0 Shape \"sphere\" \"float radius\" 0.3 \"float zmin\" -0.1 \"float zmax\" 0.25 \"float phimax\" 270 AttributeEnd",
        "AttributeBegin Translate 0.5 0.5 0 Shape \"disk\" \"float radius\" 0.4 \"float innerradius\" 0.1 \"float phimax\" 300 AttributeEnd",
        "AttributeBegin Translate 0.1 0.5 0 Rotate 90 0 1 0 Shape \"cylinder\" \"float radius\" 0.2 \"float zmin\" 0 \"float zmax\" 0.8 AttributeEnd",
        "Shape \"bilinearmesh\" \"point3 P\" [0 0.2 0  1 0.3 0.2  0 0.8 0.3  1 0.7 -0.1] \"integer indices\" [0 1 2 3]",
        "Shape \"curve\" \"string type\" \"cylinder\" \"point3 P\" [0.1 0.4 0  0.4 0.7 0  0.6 0.3 0  0.9 0.5 0] \"float width\" 0.2",
    ];
    for shape in shapes {
        for mat in [
            format!("Material \"diffuse\" {MAT}"),
            "Material \"conductor\" \"spectrum eta\" \"metal-Cu-eta\" \"spectrum k\" \"metal-Cu-k\" \"float roughness\" 0.3".to_string(),
        ] {
            let plain = render_body(&d, &format!("{mat}\n{shape}"));
            let mapped = render_body(
                &d,
                &format!("{mat} \"string normalmap\" \"flat.exr\"\n{shape}"),
            );
            assert!(
                plain.pixels.iter().any(|p| p.x > 0.0),
                "{shape}: nothing seen"
            );
            for (i, (a, b)) in plain.pixels.iter().zip(&mapped.pixels).enumerate() {
                assert!(
                    a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits),
                    "{mat} {shape}: pixel {i}: {a} vs {b}"
                );
            }
        }
    }
}

/// A rigid transform (rotation and translation: normals map without rescaling, so the
/// world normal's finite differences are ∂n carried as pbrt-v4 carries it).
fn rigid() -> Transform {
    Transform::new(
        Mat4::from_translation(Vec3::new(0.3, -0.7, 1.1))
            * Mat4::from_axis_angle(Vec3::new(1.0, 2.0, -0.5).normalize(), 0.8),
    )
    .unwrap()
}

/// A sheared, non-uniformly scaled transform (∂p carries as a vector through any affine map).
fn sheared() -> Transform {
    let mut m = Mat4::from_scale(Vec3::new(1.3, 0.7, 1.9));
    m.y_axis.x = 0.4;
    Transform::new(Mat4::from_translation(Vec3::new(-0.2, 0.5, 0.3)) * m).unwrap()
}

#[test]
fn derivatives_are_the_finite_differences_of_each_parameterisation() {
    let tau = 2.0 * std::f64::consts::PI;
    // (kind, object-space p(u, v) per pbrt-v4's definition, written out here).
    type Param = Box<dyn Fn(f64, f64) -> DVec3>;
    let sph = |r: f64, zmin: f64, zmax: f64, phimax: f64| -> Param {
        let (t0, t1) = ((zmin / r).acos(), (zmax / r).acos());
        Box::new(move |u, v| {
            let (th, ph) = (t0 + (t1 - t0) * v, u * phimax);
            DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()) * r
        })
    };
    let bil = [
        Vec3::new(-1.0, -1.0, 0.3),
        Vec3::new(1.0, -1.2, -0.2),
        Vec3::new(-0.8, 1.0, 0.0),
        Vec3::new(1.1, 0.9, 0.7),
    ];
    let bil_p: Param = Box::new(move |u, v| {
        let c = bil.map(|p| p.as_dvec3());
        let l = |a: DVec3, b: DVec3, s: f64| a + (b - a) * s;
        l(l(c[0], c[1], u), l(c[2], c[3], u), v)
    });
    let cases: Vec<(&str, QuadricKind, Param)> = vec![
        (
            "sphere",
            QuadricKind::Sphere { radius: 1.5 },
            sph(1.5, -1.5, 1.5, tau),
        ),
        (
            "partial sphere",
            QuadricKind::SphereCut {
                radius: 1.5,
                zmin: -0.4,
                zmax: 1.1,
                phimax: 4.0,
            },
            sph(1.5, -0.4, 1.1, 4.0),
        ),
        (
            "disk",
            QuadricKind::Disk {
                height: 0.3,
                radius: 2.0,
            },
            Box::new(move |u, v| {
                let (r, ph) = (2.0 * (1.0 - v), u * tau);
                DVec3::new(r * ph.cos(), r * ph.sin(), 0.3)
            }),
        ),
        (
            "annulus",
            QuadricKind::DiskCut {
                height: -0.2,
                radius: 2.0,
                inner: 0.5,
                phimax: 3.0,
            },
            Box::new(|u, v| {
                let (r, ph) = (2.0 - 1.5 * v, u * 3.0);
                DVec3::new(r * ph.cos(), r * ph.sin(), -0.2)
            }),
        ),
        (
            "cylinder",
            QuadricKind::Cylinder {
                radius: 0.8,
                zmin: -0.5,
                zmax: 1.5,
                phimax: 5.0,
            },
            Box::new(|u, v| {
                let ph = u * 5.0;
                DVec3::new(0.8 * ph.cos(), 0.8 * ph.sin(), -0.5 + 2.0 * v)
            }),
        ),
        (
            "bilinear patch",
            QuadricKind::Bilinear {
                p: bil,
                uv: [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE],
            },
            bil_p,
        ),
    ];
    let h = 1e-4;
    for (what, kind, param) in &cases {
        for (tname, t) in [("rigid", rigid()), ("sheared", sheared())] {
            // Bilinear patches are stored in world space.
            let t = if matches!(kind, QuadricKind::Bilinear { .. }) {
                Transform::IDENTITY
            } else {
                t
            };
            for flip in [false, true] {
                let q = Quadric {
                    kind: *kind,
                    to_world: t,
                    flip,
                    alpha: None,
                };
                let world = |u: f64, v: f64| t.point(param(u, v).as_vec3()).as_dvec3();
                // The hit's world normal at (u, v): aim a ray at the point.
                let hit_at = |u: f64, v: f64| {
                    let p = world(u, v).as_vec3();
                    let n0 = t
                        .normal(
                            (param(u + 1e-3, v) - param(u - 1e-3, v))
                                .cross(param(u, v + 1e-3) - param(u, v - 1e-3))
                                .as_vec3(),
                        )
                        .normalize();
                    let o = p + n0 * 0.5;
                    let tt = q.intersect_t(o, -n0, 10.0).expect("aimed ray hits");
                    q.hit(o, -n0, tt)
                };
                for (u, v) in [(0.3, 0.6), (0.7, 0.2), (0.55, 0.45)] {
                    let hit = hit_at(u, v);
                    assert!(
                        (hit.uv.as_dvec2() - glam::DVec2::new(u, v)).length() < 1e-4,
                        "{what} {tname}: hit uv {} at ({u}, {v})",
                        hit.uv
                    );
                    let [dpdu, dpdv, dndu, dndv] = q
                        .derivatives(hit.p, hit.uv, hit.n)
                        .unwrap_or_else(|| panic!("{what}: derivatives"));
                    let fd_u = (world(u + h, v) - world(u - h, v)) / (2.0 * h);
                    let fd_v = (world(u, v + h) - world(u, v - h)) / (2.0 * h);
                    let close = |a: Vec3, b: DVec3, tol: f64| {
                        (a.as_dvec3() - b).length() <= tol * b.length().max(1.0)
                    };
                    assert!(
                        close(dpdu, fd_u, 1e-3),
                        "{what} {tname}: ∂p/∂u {dpdu} vs {fd_u}"
                    );
                    assert!(
                        close(dpdv, fd_v, 1e-3),
                        "{what} {tname}: ∂p/∂v {dpdv} vs {fd_v}"
                    );
                    // pbrt-v4's normal is ∂p/∂u × ∂p/∂v, negated with the flip.
                    let sign = if flip { -1.0 } else { 1.0 };
                    let nn = dpdu.cross(dpdv).normalize() * sign;
                    assert!(
                        nn.dot(hit.n) > 0.9999,
                        "{what} {tname}: n {} vs {nn}",
                        hit.n
                    );
                    if tname == "rigid" {
                        let n_at = |u: f64, v: f64| hit_at(u, v).n.as_dvec3();
                        let fd_nu = (n_at(u + h, v) - n_at(u - h, v)) / (2.0 * h);
                        let fd_nv = (n_at(u, v + h) - n_at(u, v - h)) / (2.0 * h);
                        assert!(
                            close(dndu, fd_nu, 2e-3),
                            "{what} flip {flip}: ∂n/∂u {dndu} vs {fd_nu}"
                        );
                        assert!(
                            close(dndv, fd_nv, 2e-3),
                            "{what} flip {flip}: ∂n/∂v {dndv} vs {fd_nv}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn bilinear_derivatives_follow_the_corners_texture_coordinates() {
    // pbrt-v4: with corner uvs, ∂p/∂s, ∂p/∂t of the texture coordinates (s, t); uvs that swap
    // u and v give ∂p/∂s = ∂p/∂v, and ∂p/∂t = ∂p/∂u negated to keep the patch's normal.
    let c = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(2.0, 1.0, 0.0),
    ];
    let swapped = [Vec2::ZERO, Vec2::Y, Vec2::X, Vec2::ONE];
    let q = Quadric {
        kind: QuadricKind::Bilinear { p: c, uv: swapped },
        to_world: Transform::IDENTITY,
        flip: false,
        alpha: None,
    };
    let o = Vec3::new(0.5, 0.25, 1.0);
    let t = q.intersect_t(o, -Vec3::Z, 5.0).unwrap();
    let hit = q.hit(o, -Vec3::Z, t);
    assert!(
        (hit.uv - Vec2::new(0.25, 0.25)).length() < 1e-6,
        "{}",
        hit.uv
    );
    let [dpds, dpdt, _, _] = q.derivatives(hit.p, hit.uv, hit.n).unwrap();
    assert!((dpds - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-5, "{dpds}");
    assert!((dpdt - Vec3::new(-2.0, 0.0, 0.0)).length() < 1e-5, "{dpdt}");
    assert!(dpds.cross(dpdt).normalize().dot(hit.n) > 0.9999);
}

#[test]
fn curve_derivatives_run_along_and_across_it() {
    let seg = CurveSegment {
        cp: [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.3, 0.4, 0.0),
            Vec3::new(0.7, -0.2, 0.1),
            Vec3::new(1.0, 0.1, 0.0),
        ],
        width: [0.2, 0.1],
        n: [Vec3::Z; 2],
        kind: CurveType::Cylinder,
    };
    let bez = |u: f64| {
        let c = seg.cp.map(|p| p.as_dvec3());
        let s = 1.0 - u;
        c[0] * s * s * s + c[1] * 3.0 * s * s * u + c[2] * 3.0 * s * u * u + c[3] * u * u * u
    };
    for flip in [false, true] {
        let q = Quadric {
            kind: QuadricKind::Curve(seg),
            to_world: rigid(),
            flip,
            alpha: None,
        };
        for u in [0.2f64, 0.5, 0.8] {
            let p = q.to_world.point(bez(u).as_vec3());
            let o = p + Vec3::new(0.01, 0.02, 1.0);
            let d = p - o;
            let t = q.intersect_t(o, d, 2.0).expect("aimed ray hits the curve");
            let hit = q.hit(o, d, t);
            let [dpdu, dpdv, dndu, dndv] = q.derivatives(hit.p, hit.uv, hit.n).unwrap();
            let uh = hit.uv.x as f64;
            let fd = q
                .to_world
                .vector(((bez(uh + 1e-5) - bez(uh - 1e-5)) / 2e-5).as_vec3());
            assert!((dpdu - fd).length() < 1e-3 * fd.length(), "{dpdu} vs {fd}");
            let w = 0.2 - 0.1 * uh as f32;
            assert!(
                (dpdv.length() - w).abs() < 1e-4 * w,
                "|∂p/∂v| {}",
                dpdv.length()
            );
            assert!(dpdu.normalize().dot(dpdv.normalize()).abs() < 1e-4);
            let sign = if flip { -1.0 } else { 1.0 };
            let nn = dpdu.cross(dpdv).normalize() * sign;
            assert!(nn.dot(hit.n) > 0.9999, "{nn} vs {}", hit.n);
            assert!(dndu == Vec3::ZERO && dndv == Vec3::ZERO);
        }
    }
}
