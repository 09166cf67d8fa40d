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
        let q = 0.8 * Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
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
