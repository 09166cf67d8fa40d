//! Texture coordinates of pbrt-v4's sphere and disk, from the book's definitions
//! (`Sphere::InteractionFromIntersection`, `Disk::InteractionFromIntersection`): for a full
//! sphere u = φ/2π and v = (θ − θ_zmin)/(θ_zmax − θ_zmin) with θ_zmin = acos(−1) = π and
//! θ_zmax = 0, so v = 1 − θ/π (0 at the bottom pole z = −r, 1 at the top); for a disk
//! u = φ/2π and v = (r_max − r)/(r_max − r_inner).
//!
//! Independent answer: rays from outside aimed at random object-space points (θ, φ) of a
//! moved and rotated sphere or disk report those formulas' uv at the hit.

use glam::{Mat3, Vec3};
use penumbra::geometry::{Ray, RayQuery};
use penumbra::scene::pbrt::parse_pbrt_str;
use std::f32::consts::PI;

fn hits(world: &str, to_world: impl Fn(Vec3) -> Vec3, points: &[(Vec3, Vec3, [f32; 2])]) {
    let src = format!(
        "LookAt 0 0 10  0 0 0  0 1 0\nCamera \"perspective\"\n\
         Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\nWorldBegin\n{world}\n"
    );
    let parsed = parse_pbrt_str("s.pbrt", &src, std::path::Path::new(".")).unwrap();
    let (b, cam, film, _) = parsed.into_builder().unwrap();
    let scene = b.build(cam, film).unwrap();
    for &(q, n, want) in points {
        let target = to_world(q);
        let eye = to_world(q + 3.0 * n);
        let h = scene
            .geometry
            .intersect(&Ray::new(eye, (target - eye).normalize()))
            .expect("hit");
        assert!((h.p - target).length() < 1e-4, "{} vs {target}", h.p);
        let du = (h.uv.x - want[0]).abs();
        assert!(
            du.min(1.0 - du) < 1e-4 && (h.uv.y - want[1]).abs() < 1e-4,
            "object point {q}: uv {} want {want:?}",
            h.uv
        );
    }
}

#[test]
fn sphere_and_disk_uv_follow_pbrt_v4() {
    let rot = Mat3::from_rotation_x(30f32.to_radians());
    let t = Vec3::new(0.3, -0.2, 0.1);
    let to_world = |q: Vec3| rot * q + t;
    let mut sphere = Vec::new();
    let mut disk = Vec::new();
    for i in 0..40 {
        let theta = 0.05 + (PI - 0.1) * ((i * 7 % 40) as f32 + 0.5) / 40.0;
        let phi = 2.0 * PI * (i as f32 + 0.5) / 40.0;
        let q = 0.8
            * Vec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
        sphere.push((q, q.normalize(), [phi / (2.0 * PI), 1.0 - theta / PI]));
        let r = 0.8 * ((i * 13 % 40) as f32 + 0.5) / 40.0;
        let q = Vec3::new(r * phi.cos(), r * phi.sin(), 0.25);
        disk.push((q, Vec3::Z, [phi / (2.0 * PI), 1.0 - r / 0.8]));
    }
    let xf = "Translate 0.3 -0.2 0.1\nRotate 30 1 0 0\n";
    hits(
        &format!("AttributeBegin\n{xf}Shape \"sphere\" \"float radius\" 0.8\nAttributeEnd"),
        to_world,
        &sphere,
    );
    hits(
        &format!(
            "AttributeBegin\n{xf}Shape \"disk\" \"float radius\" 0.8 \"float height\" 0.25\nAttributeEnd"
        ),
        to_world,
        &disk,
    );
}

fn scene_of(world: &str) -> penumbra::scene::Scene {
    let src = format!(
        "LookAt 0 0 10  0 0 0  0 1 0\nCamera \"perspective\"\n\
         Film \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\nWorldBegin\n{world}\n"
    );
    let parsed = parse_pbrt_str("s.pbrt", &src, std::path::Path::new(".")).unwrap();
    let (b, cam, film, _) = parsed.into_builder().unwrap();
    b.build(cam, film).unwrap()
}

/// pbrt-v4's partial sphere (zmin −0.3, zmax 0.6, phimax 270° of radius 0.8): points inside
/// the cuts are hit with u = φ/φmax, v = (θ − θ_zmin)/(θ_zmax − θ_zmin); a ray aimed at the
/// cut-away cap misses (its exit point is cut away too); a ray aimed at the cut-away wedge
/// sees the inside of the far side, at the antipode.
#[test]
fn partial_sphere_is_cut_as_pbrt_v4() {
    let (r, zmin, zmax, phimax) = (0.8f32, -0.3f32, 0.6f32, 270f32.to_radians());
    let rot = Mat3::from_rotation_x(30f32.to_radians());
    let t = Vec3::new(0.3, -0.2, 0.1);
    let to_world = |q: Vec3| rot * q + t;
    let scene = scene_of(
        "AttributeBegin\nTranslate 0.3 -0.2 0.1\nRotate 30 1 0 0\n\
         Shape \"sphere\" \"float radius\" 0.8 \"float zmin\" -0.3 \"float zmax\" 0.6 \"float phimax\" 270\n\
         AttributeEnd",
    );
    let (t0, t1) = ((zmin / r).acos(), (zmax / r).acos());
    let uv_of = |q: Vec3| {
        let phi = q.y.atan2(q.x).rem_euclid(2.0 * PI);
        [phi / phimax, ((q.z / r).acos() - t0) / (t1 - t0)]
    };
    let shoot = |q: Vec3| {
        let (target, eye) = (to_world(q), to_world(q * 4.0));
        scene
            .geometry
            .intersect(&Ray::new(eye, (target - eye).normalize()))
    };
    let (mut hit, mut missed, mut inside) = (0, 0, 0);
    for i in 0..60 {
        let phi = 2.0 * PI * (i as f32 + 0.5) / 60.0;
        let z = -0.75 + 1.5 * ((i * 17 % 60) as f32 + 0.5) / 60.0;
        let s = (r * r - z * z).sqrt();
        let q = Vec3::new(s * phi.cos(), s * phi.sin(), z);
        // The ray runs through the centre: it meets the sphere only at q and at −q.
        let in_cut = |q: Vec3| {
            let phi = q.y.atan2(q.x).rem_euclid(2.0 * PI);
            q.z >= zmin && q.z <= zmax && phi <= phimax
        };
        let h = shoot(q);
        if in_cut(q) {
            let h = h.expect("hit inside the cuts");
            assert!((h.p - to_world(q)).length() < 1e-4, "{q}");
            let want = uv_of(q);
            assert!(
                (h.uv - glam::Vec2::from(want)).abs().max_element() < 1e-4,
                "{q}: uv {} want {want:?}",
                h.uv
            );
            hit += 1;
        } else if in_cut(-q) {
            // The near side is cut away: the ray goes on to the far side's inside.
            let h = h.expect("far side");
            assert!((h.p - to_world(-q)).length() < 1e-4, "{q}: {}", h.p);
            assert!((h.uv - glam::Vec2::from(uv_of(-q))).abs().max_element() < 1e-4);
            inside += 1;
        } else {
            assert!(
                h.is_none(),
                "{q}: both sides cut away, hit {:?}",
                h.map(|h| h.p)
            );
            missed += 1;
        }
    }
    assert!(
        hit > 15 && missed > 3 && inside > 2,
        "{hit} {missed} {inside}"
    );
}

/// pbrt-v4's annulus (inner 0.3, radius 0.8, phimax 200°): rays through the hole or the
/// cut-away sweep miss, the rest hit with u = φ/φmax, v = (0.8 − r)/(0.8 − 0.3); emissive,
/// it is a tessellation whose triangles lie on the annulus and emit 1 toward +z.
#[test]
fn annulus_is_cut_as_pbrt_v4() {
    let (ro, ri, phimax) = (0.8f32, 0.3f32, 200f32.to_radians());
    let shape = "Shape \"disk\" \"float radius\" 0.8 \"float innerradius\" 0.3 \"float phimax\" 200 \"float height\" 0.25";
    for emissive in [false, true] {
        let light = if emissive {
            "AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
        } else {
            ""
        };
        let scene = scene_of(&format!("AttributeBegin\n{light}{shape}\nAttributeEnd"));
        for i in 0..80 {
            let phi = 2.0 * PI * (i as f32 + 0.5) / 80.0;
            let r = 0.95 * ((i * 29 % 80) as f32 + 0.5) / 80.0;
            let q = Vec3::new(r * phi.cos(), r * phi.sin(), 0.25);
            let eye = q + Vec3::new(0.01, 0.02, 3.0);
            let h = scene
                .geometry
                .intersect(&Ray::new(eye, (q - eye).normalize()));
            // Keep clear of the edges, where the tessellation's chords differ.
            let margin = if emissive { 0.02 } else { 0.0 };
            let inside = r >= ri + margin && r <= ro - margin && phi <= phimax - margin;
            let outside = r < ri - margin || r > ro + margin || phi > phimax + margin;
            if inside {
                let h = h.expect("hit");
                assert!((h.p - q).length() < 1e-3, "{q}: {}", h.p);
                if emissive {
                    let l = &scene.lights[h.light as usize];
                    use penumbra::lights::Emitter;
                    assert_eq!(l.radiance(h.p, h.ng, h.uv, Vec3::Z).max_element(), 1.0);
                } else {
                    let want = glam::Vec2::new(phi / phimax, (ro - r) / (ro - ri));
                    assert!((h.uv - want).abs().max_element() < 1e-4, "{q}: {}", h.uv);
                }
            } else if outside {
                assert!(h.is_none(), "{q} (emissive {emissive})");
            }
        }
    }
}
