//! pbrt-v4's `cylinder` and `bilinearmesh` (true bilinear patches) through the loader, and
//! the displacement·∂n/∂u term of pbrt-v4's `BumpMap`.
//!
//! Independent answers: rays aimed at random points of the visible side of a (transformed,
//! partial) cylinder hit exactly those points, with the analytic normal and pbrt's uv; rays
//! aimed at the far side of a cut-away sweep pass through the gap; rays along the analytic
//! normal of random points of a curved bilinear patch hit them with their (u, v) and
//! normal ∂p/∂u × ∂p/∂v (the two-triangle stand-in misses them by a measurable distance);
//! a bump map on a cylinder matches the normal of the displaced surface p + h·n computed by
//! central finite differences.

mod render_support;

use glam::{Vec2, Vec3};
use penumbra::geometry::{Ray, RayQuery};
use penumbra::material::texture::ImageRgb;
use penumbra::material::{FloatTexture, NormalPerturbation, ShadingDerivatives, TexCoord};
use penumbra::sampling::{PatternKind, make_pattern};
use render_support::pbrt_world;
use std::f32::consts::PI;
use std::sync::Arc;

fn uniforms(n: u32, seed: u64) -> Vec<[f32; 4]> {
    let pat = make_pattern(PatternKind::Random, seed);
    (0..n)
        .map(|i| {
            let a = pat.sample_2d(glam::UVec2::new(i, 0), 0, 0, 1);
            let b = pat.sample_2d(glam::UVec2::new(i, 1), 0, 0, 1);
            [a.x, a.y, b.x, b.y]
        })
        .collect()
}

#[test]
fn cylinder_rays_hit_their_analytic_points() {
    // Radius 0.5, z in [-1, 2], a sweep of 270°, moved and rotated: world point of object
    // point q is R·q + T (R: 30° about x), the normal R·(x, y, 0).
    let (r, zmin, zmax, phimax) = (0.5f32, -1.0f32, 2.0f32, 270f32.to_radians());
    let (scene, warnings) = pbrt_world(
        "AttributeBegin\nTranslate 0.3 -0.2 0.1\nRotate 30 1 0 0\n\
         Shape \"cylinder\" \"float radius\" 0.5 \"float zmin\" -1 \"float zmax\" 2 \"float phimax\" 270\n\
         AttributeEnd",
    );
    assert!(
        !warnings.iter().any(|w| w.contains("cylinder")),
        "{warnings:?}"
    );
    let rot = glam::Mat3::from_rotation_x(30f32.to_radians());
    let t = Vec3::new(0.3, -0.2, 0.1);
    let world = |q: Vec3| rot * q + t;
    let mut hits = 0;
    for [a, b, c, d] in uniforms(2000, 7) {
        let phi = a * phimax;
        let z = zmin + b * (zmax - zmin);
        let n_obj = Vec3::new(phi.cos(), phi.sin(), 0.0);
        let q = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        // An origin on the point's outward side (visible: the cylinder is convex from
        // there along this ray), then the ray toward the point.
        let dir_out =
            (n_obj + Vec3::new(0.0, 0.0, 2.0 * c - 1.0) * 0.8 + n_obj.cross(Vec3::Z) * (d - 0.5))
                .normalize();
        if dir_out.dot(n_obj) < 0.2 {
            continue;
        }
        let o = world(q + dir_out * 3.0);
        let p = world(q);
        let dir = (p - o).normalize();
        let hit = scene.geometry.intersect(&Ray::new(o, dir));
        // The origin sees the point unless another part of the surface is in between: only
        // the convex outside is visible from outside, so the first hit is the point itself
        // whenever the origin is outside the infinite cylinder.
        let oo = rot.transpose() * (o - t);
        assert!(oo.truncate().length() > r);
        let h = hit.unwrap_or_else(|| panic!("ray toward {p} missed"));
        hits += 1;
        assert!((h.p - p).length() < 1e-4, "hit {} vs {p}", h.p);
        assert!((h.t - (p - o).length()).abs() < 1e-4);
        let n = rot * n_obj;
        assert!((h.ng - n).length() < 1e-4, "normal {} vs {n}", h.ng);
        let uv = Vec2::new(phi / phimax, (z - zmin) / (zmax - zmin));
        assert!((h.uv - uv).length() < 1e-4, "uv {} vs {uv}", h.uv);
    }
    assert!(hits > 500, "{hits}");
    // The gap of the sweep (φ in (270°, 360°)): a ray through the axis aimed at φ = 315°
    // from outside passes the gap first and hits the inside of the far wall (φ = 135°).
    let phi = 315f32.to_radians();
    let o = world(Vec3::new(3.0 * phi.cos(), 3.0 * phi.sin(), 0.5));
    let target = world(Vec3::new(0.0, 0.0, 0.5));
    let h = scene
        .geometry
        .intersect(&Ray::new(o, (target - o).normalize()))
        .expect("far wall");
    let far = world(Vec3::new(
        r * (135f32.to_radians()).cos(),
        r * (135f32.to_radians()).sin(),
        0.5,
    ));
    assert!((h.p - far).length() < 1e-4, "{} vs {far}", h.p);
    // Past zmax the ray misses.
    let o = world(Vec3::new(3.0, 0.0, 2.5));
    assert!(
        scene
            .geometry
            .intersect(&Ray::new(
                o,
                (world(Vec3::new(0.0, 0.0, 2.5)) - o).normalize()
            ))
            .is_none()
    );
}

/// A saddle-shaped patch (p11 lifted) with uvs.
const PATCH: &str = "Shape \"bilinearmesh\" \"point3 P\" [0 0 0  2 0 0  0 2 0  2 2 1.5] \
                     \"integer indices\" [0 1 2 3] \"point2 uv\" [0 0  1 0  0 1  0.5 3]";

fn patch_point(u: f32, v: f32) -> (Vec3, Vec3, Vec2) {
    let p = [
        Vec3::ZERO,
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(2.0, 2.0, 1.5),
    ];
    let uv = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::new(0.5, 3.0)];
    let lerp3 = |a: Vec3, b: Vec3, t: f32| a + (b - a) * t;
    let pt = lerp3(lerp3(p[0], p[1], u), lerp3(p[2], p[3], u), v);
    let dpdu = lerp3(p[1] - p[0], p[3] - p[2], v);
    let dpdv = lerp3(p[2] - p[0], p[3] - p[1], u);
    let t = (uv[0] * (1.0 - u) + uv[1] * u) * (1.0 - v) + (uv[2] * (1.0 - u) + uv[3] * u) * v;
    (pt, dpdu.cross(dpdv).normalize(), t)
}

#[test]
fn bilinear_patch_rays_hit_the_true_patch() {
    let (scene, warnings) = pbrt_world(PATCH);
    assert!(
        !warnings.iter().any(|w| w.contains("bilinear")),
        "{warnings:?}"
    );
    let mut worst_triangle_miss = 0.0f32;
    for [a, b, c, d] in uniforms(1000, 3) {
        let (u, v) = (0.02 + 0.96 * a, 0.02 + 0.96 * b);
        let (p, n, uv) = patch_point(u, v);
        // From above the patch along a direction near its normal.
        let tilt = Vec3::new(c - 0.5, d - 0.5, 0.0) * 0.3;
        let dir = -(n + tilt).normalize();
        let o = p - dir * 0.05;
        let h = scene
            .geometry
            .intersect(&Ray::new(o, dir))
            .unwrap_or_else(|| panic!("ray toward {p} missed"));
        assert!(
            (h.p - p).length() < 2e-5,
            "hit {} vs {p} (u {u} v {v})",
            h.p
        );
        assert!((h.ng - n).length() < 1e-4, "normal {} vs {n}", h.ng);
        assert!((h.uv - uv).length() < 1e-4, "uv {} vs {uv}", h.uv);
        // Where the two triangles would have been hit.
        let tri = |a: Vec3, b: Vec3, c: Vec3| -> Option<f32> {
            let (e1, e2) = (b - a, c - a);
            let pv = dir.cross(e2);
            let det = e1.dot(pv);
            let tv = o - a;
            let uu = tv.dot(pv) / det;
            let qv = tv.cross(e1);
            let vv = dir.dot(qv) / det;
            let t = e2.dot(qv) / det;
            (uu >= 0.0 && vv >= 0.0 && uu + vv <= 1.0).then_some(t)
        };
        let c4 = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(2.0, 2.0, 1.5),
        ];
        if let Some(t) = tri(c4[0], c4[1], c4[3]).or(tri(c4[0], c4[3], c4[2])) {
            worst_triangle_miss = worst_triangle_miss.max((o + dir * t - p).length());
        }
    }
    // The old two-triangle stand-in is off by up to ~0.2 on this saddle.
    assert!(worst_triangle_miss > 0.05, "{worst_triangle_miss}");
    // Outside the patch (u > 1) nothing is hit.
    let o = Vec3::new(2.5, 1.0, 5.0);
    assert!(scene.geometry.intersect(&Ray::new(o, -Vec3::Z)).is_none());
}

#[test]
fn emissive_bilinear_mesh_stays_triangles() {
    let (_, warnings) = pbrt_world(&format!("AreaLightSource \"diffuse\"\n{PATCH}"));
    assert!(
        warnings.iter().any(|w| w.contains("non-parallelogram")),
        "{warnings:?}"
    );
    let (_, warnings) = pbrt_world(
        "AreaLightSource \"diffuse\"\nShape \"bilinearmesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 0] \"integer indices\" [0 1 2 3]",
    );
    assert!(
        !warnings.iter().any(|w| w.contains("bilinear")),
        "{warnings:?}"
    );
}

/// The bump map of a linear-ramp displacement h(u) = a + b·u (a 64-texel ramp image, read
/// inside its interior where bilinear interpolation is exactly linear) on a cylinder of
/// radius R (u = φ/2π, v = z): pbrt-v4's normal ∂p′/∂u × ∂p′/∂v with
/// ∂p′/∂u = ∂p/∂u + ∂h/∂u·n + h·∂n/∂u against central differences of p + h·n.
#[test]
fn bump_map_includes_the_displacement_times_dndu_term() {
    let n_tex = 64;
    let (a, b) = (0.6f32, 0.8f32);
    // Texel i covers u in [i/64, (i+1)/64); its centre (i + ½)/64 holds h there.
    let img = ImageRgb {
        width: n_tex,
        height: 1,
        pixels: (0..n_tex)
            .map(|i| Vec3::splat(a + b * (i as f32 + 0.5) / n_tex as f32))
            .collect(),
    };
    let h = |u: f32| a + b * u;
    let bump = NormalPerturbation::Bump(FloatTexture::Image {
        image: Arc::new(img),
        scale: 1.0,
        invert: false,
    });
    let radius = 1.0f32;
    let surf = |u: f32, v: f32| {
        let phi = 2.0 * PI * u;
        let n = Vec3::new(phi.cos(), phi.sin(), 0.0);
        (n * radius + Vec3::Z * v, n)
    };
    let mut worst = 0.0f32;
    let mut worst_without = f32::INFINITY;
    for k in 0..20 {
        let u = 0.1 + 0.8 * k as f32 / 19.0;
        let v = 0.3;
        let (_, n) = surf(u, v);
        let phi = 2.0 * PI * u;
        let t = Vec3::new(-phi.sin(), phi.cos(), 0.0);
        let d = ShadingDerivatives {
            dpdu: t * 2.0 * PI * radius,
            dpdv: Vec3::Z,
            dndu: t * 2.0 * PI,
            dndv: Vec3::ZERO,
        };
        let got = bump.shading_normal(&TexCoord::point(Vec2::new(u, v)), n, n, &d);
        // The displaced surface, differentiated numerically (in f64).
        let disp = |u: f64, v: f64| {
            let phi = 2.0 * std::f64::consts::PI * u;
            let hh = h(u as f32) as f64;
            glam::DVec3::new(
                phi.cos() * (radius as f64 + hh),
                phi.sin() * (radius as f64 + hh),
                v,
            )
        };
        let e = 1e-4;
        let (u64_, v64) = (u as f64, v as f64);
        let pu = (disp(u64_ + e, v64) - disp(u64_ - e, v64)) / (2.0 * e);
        let pv = (disp(u64_, v64 + e) - disp(u64_, v64 - e)) / (2.0 * e);
        let mut want = pu.cross(pv).normalize().as_vec3();
        if want.dot(n) < 0.0 {
            want = -want;
        }
        worst = worst.max((got - want).length());
        let without = bump.shading_normal(
            &TexCoord::point(Vec2::new(u, v)),
            n,
            n,
            &ShadingDerivatives {
                dndu: Vec3::ZERO,
                ..d
            },
        );
        worst_without = worst_without.min((without - want).length());
    }
    eprintln!("bump normal error {worst:.2e}; without the h·∂n/∂u term ≥ {worst_without:.2e}");
    // f32 forward differences of h over 0.0005 in u (bilinear texels in f32): ~1e-4.
    assert!(worst < 1e-3, "{worst}");
    assert!(worst_without > 20.0 * worst, "{worst_without} vs {worst}");
}

/// pbrt-v4's triangle ∂n/∂u from vertex normals converges to the analytic one on a finely
/// tessellated cylinder.
#[test]
fn triangle_dndu_matches_the_cylinders() {
    let m = 256;
    let (u0, u1) = (0.3f32, 0.3 + 1.0 / m as f32);
    let at = |u: f32, v: f32| {
        let phi = 2.0 * PI * u;
        Vec3::new(phi.cos(), phi.sin(), 0.0 * v)
    };
    let n = [at(u0, 0.0), at(u1, 0.0), at(u1, 1.0)];
    let uv = [Vec2::new(u0, 0.0), Vec2::new(u1, 0.0), Vec2::new(u1, 1.0)];
    let (dndu, dndv) = penumbra::scene::shading_normals::triangle_dndu(n, uv);
    let um = 0.5 * (u0 + u1);
    let phi = 2.0 * PI * um;
    let want = Vec3::new(-phi.sin(), phi.cos(), 0.0) * 2.0 * PI;
    assert!(
        (dndu - want).length() < 1e-3 * want.length(),
        "{dndu} vs {want}"
    );
    assert!(dndv.length() < 1e-6, "{dndv}");
}

/// A flat curve along a straight line is hit from above exactly within half its width of
/// the line, at the distance of the line, with u along it and the normal facing the ray; the
/// `cylinder` type turns the normal across the width as a cylinder's; a `ribbon` seen edge-on
/// vanishes.
#[test]
fn straight_curves_are_ribbons_of_their_width() {
    let p = "\"point3 P\" [0 0 0  1 0 0  2 0 0  3 0 0] \"float width\" 0.2";
    let (flat, w) = pbrt_world(&format!("Shape \"curve\" {p}"));
    assert!(!w.iter().any(|w| w.contains("curve")), "{w:?}");
    let (cyl, _) = pbrt_world(&format!("Shape \"curve\" {p} \"string type\" \"cylinder\""));
    let (edge_on, _) = pbrt_world(&format!(
        "Shape \"curve\" {p} \"string type\" \"ribbon\" \"normal N\" [0 1 0  0 1 0]"
    ));
    let (face_on, _) = pbrt_world(&format!(
        "Shape \"curve\" {p} \"string type\" \"ribbon\" \"normal N\" [0 0 1  0 0 1]"
    ));
    let mut n_hit = 0;
    for [a, b, _, _] in uniforms(2000, 5) {
        let (x, y) = (0.1 + 2.8 * a, -0.2 + 0.4 * b);
        if (y.abs() - 0.1).abs() < 1e-3 {
            continue;
        }
        let ray = Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z);
        let h = flat.geometry.intersect(&ray);
        assert_eq!(h.is_some(), y.abs() < 0.1, "x {x} y {y}");
        assert_eq!(face_on.geometry.intersect(&ray).is_some(), y.abs() < 0.1);
        assert!(edge_on.geometry.intersect(&ray).is_none());
        if let Some(h) = h {
            n_hit += 1;
            assert!((h.t - 5.0).abs() < 1e-4, "t {}", h.t);
            assert!(
                (h.uv.x - x / 3.0).abs() < 1e-4,
                "u {} vs {}",
                h.uv.x,
                x / 3.0
            );
            assert!(
                ((h.uv.y - 0.5).abs() - y.abs() / 0.2).abs() < 1e-4,
                "v {}",
                h.uv.y
            );
            assert!((h.ng.z.abs() - 1.0).abs() < 1e-5, "flat normal {}", h.ng);
            let c = cyl.geometry.intersect(&ray).expect("cylinder curve");
            let want = (std::f32::consts::PI * y / 0.2).cos();
            assert!(
                (c.ng.z.abs() - want).abs() < 1e-3,
                "cylinder normal {} vs cos {want}",
                c.ng
            );
        }
    }
    assert!(n_hit > 500, "{n_hit}");
}

/// A curved flat curve (a Bézier arc in the xy plane, width 0.1 → 0.3) seen from above: a
/// ray hits exactly when its distance to the arc (brute force over 20000 points) is below
/// half the width there, outside a band of 5 % of the width around the edge (pbrt-v4
/// refines the arc into pieces flat to 5 % of the width).
#[test]
fn curved_curves_match_the_brute_force_distance() {
    let (scene, _) = pbrt_world(
        "Shape \"curve\" \"point3 P\" [0 0 0  1 1.2 0  2 1.2 0  3 0 0] \"float width0\" 0.1 \"float width1\" 0.3",
    );
    let cp = [
        Vec3::ZERO,
        Vec3::new(1.0, 1.2, 0.0),
        Vec3::new(2.0, 1.2, 0.0),
        Vec3::new(3.0, 0.0, 0.0),
    ];
    let bez = |u: f32| {
        let s = 1.0 - u;
        cp[0] * s * s * s + cp[1] * 3.0 * s * s * u + cp[2] * 3.0 * s * u * u + cp[3] * u * u * u
    };
    let pts: Vec<(f32, Vec3)> = (0..=20000)
        .map(|i| {
            let u = i as f32 / 20000.0;
            (u, bez(u))
        })
        .collect();
    let (mut agree, mut total) = (0, 0);
    for [a, b, _, _] in uniforms(3000, 9) {
        let q = Vec2::new(0.2 + 2.6 * a, -0.2 + 1.4 * b);
        let (u, d) = pts
            .iter()
            .map(|&(u, p)| (u, (p.truncate() - q).length()))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .unwrap();
        let half = 0.5 * (0.1 + 0.2 * u);
        if (d - half).abs() < 0.05 * 2.0 * half {
            continue;
        }
        total += 1;
        let hit = scene.geometry.intersect(&Ray::new(q.extend(5.0), -Vec3::Z));
        if hit.is_some() == (d < half) {
            agree += 1;
        } else {
            eprintln!("disagree at {q}: distance {d}, half width {half}, hit {hit:?}");
        }
        if let Some(h) = hit {
            assert!((h.t - 5.0).abs() < 1e-3, "t {}", h.t);
            assert!((h.uv.x - u).abs() < 0.02, "u {} vs {u}", h.uv.x);
        }
    }
    assert!(total > 2000);
    assert_eq!(agree, total, "{agree} of {total} agree");
}

/// Under a mirroring transform a cylinder's normal points inward, as pbrt-v4's: its
/// `Cylinder::InteractionFromIntersection` negates the object-space ∂p/∂u × ∂p/∂v for
/// ReverseOrientation XOR a handedness swap before carrying it to render space as a normal
/// (which keeps its side); ReverseOrientation turns it back out.
#[test]
fn mirrored_cylinder_faces_inward_as_in_pbrt_v4() {
    for (extra, outward) in [("", false), ("ReverseOrientation\n", true)] {
        let (scene, _) = pbrt_world(&format!(
            "AttributeBegin\nScale -1 1 1\n{extra}Shape \"cylinder\" \"float radius\" 0.5\nAttributeEnd"
        ));
        let h = scene
            .geometry
            .intersect(&Ray::new(Vec3::new(3.0, 0.0, 0.0), -Vec3::X))
            .expect("hit");
        assert!((h.p - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-5, "{}", h.p);
        assert_eq!(h.ng.x > 0.9, outward, "normal {} ({extra:?})", h.ng);
    }
}
