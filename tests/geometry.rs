//! Ray–shape intersection (incl. edges and grazing rays), transforms, self-intersection
//! avoidance (no acne, no leaks at contacts), camera framing and render determinism.

use glam::{Mat4, UVec2, Vec2, Vec3};
use penumbra::Rgb;
use penumbra::camera::Camera;
use penumbra::geometry::triangle::intersect_triangle;
use penumbra::geometry::{Ray, RayQuery, Transform};
use penumbra::integrator::estimator::shadow_ray;
use penumbra::integrator::{RenderOptions, Strategy, render};
use penumbra::material::{Material, Texture};
use penumbra::sampling::hash::{next_f32, pcg_from_keys};
use penumbra::sampling::uniform_sphere;
use penumbra::scene::builtin::BuiltinOptions;
use penumbra::scene::{FilmSpec, Filter, Scene, SceneBuilder, TriangleMesh};

fn film() -> FilmSpec {
    FilmSpec {
        resolution: UVec2::new(16, 16),
        filter: Filter::Box {
            radius: Vec2::splat(0.5),
        },
        filename: None,
        spp: None,
        sensor: Default::default(),
    }
}

fn cam() -> Camera {
    Camera::look_at(Vec3::new(0.0, 0.0, -10.0), Vec3::ZERO, Vec3::Y, 40.0).unwrap()
}

fn grey(b: &mut SceneBuilder) -> u32 {
    b.add_material(Material::Diffuse {
        reflectance: Texture::Constant(Rgb::splat(0.5)),
    })
}

#[test]
fn triangle_hit_miss_edges_and_grazing() {
    let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let down = -Vec3::Z;
    let hit = intersect_triangle(Vec3::new(0.25, 0.25, 1.0), down, f32::INFINITY, p).unwrap();
    assert!((hit.0 - 1.0).abs() < 1e-6);
    assert!(
        (hit.1 - 0.5).abs() < 1e-6 && (hit.2 - 0.25).abs() < 1e-6 && (hit.3 - 0.25).abs() < 1e-6
    );
    // Outside, behind the origin, beyond t_max.
    assert!(intersect_triangle(Vec3::new(0.8, 0.8, 1.0), down, f32::INFINITY, p).is_none());
    assert!(intersect_triangle(Vec3::new(0.25, 0.25, -1.0), down, f32::INFINITY, p).is_none());
    assert!(intersect_triangle(Vec3::new(0.25, 0.25, 1.0), down, 0.5, p).is_none());
    // Grazing: a ray in the triangle's plane never reports a hit.
    assert!(intersect_triangle(Vec3::new(-1.0, 0.25, 0.0), Vec3::X, f32::INFINITY, p).is_none());
    // Watertight: rays through the shared diagonal of a quad hit one of its two triangles.
    let q0 = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0)];
    let q1 = [Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
    let mut rng = pcg_from_keys(&[42]);
    for _ in 0..20_000 {
        let s = next_f32(&mut rng);
        let o = Vec3::new(s, s, 1.0)
            + Vec3::new(next_f32(&mut rng), next_f32(&mut rng), 0.0) * 1e-3
            - Vec3::splat(5e-4).with_z(0.0);
        let d = Vec3::new(next_f32(&mut rng) - 0.5, next_f32(&mut rng) - 0.5, -1.0).normalize()
            * 1e-3
            + down;
        let target = o + d * (1.0 / -d.z);
        if !(0.001..0.999).contains(&target.x) || !(0.001..0.999).contains(&target.y) {
            continue;
        }
        let a = intersect_triangle(o, d, f32::INFINITY, q0).is_some();
        let b = intersect_triangle(o, d, f32::INFINITY, q1).is_some();
        assert!(a || b, "crack at {target}");
    }
}

fn one_sphere(t: Transform, r: f32) -> Scene {
    let mut b = SceneBuilder::new();
    let m = grey(&mut b);
    b.add_sphere(t, r, m, None, false, None).unwrap();
    b.build(cam(), film()).unwrap()
}

#[test]
fn spheres_and_disks_under_transforms() {
    let s = one_sphere(Transform::translate(Vec3::new(1.0, 2.0, 3.0)), 0.5);
    let h = s
        .geometry
        .intersect(&Ray::new(Vec3::new(1.0, 2.0, -10.0), Vec3::Z))
        .unwrap();
    assert!((h.t - 12.5).abs() < 1e-4, "t = {}", h.t);
    assert!((h.ng - Vec3::NEG_Z).length() < 1e-5);
    // From inside: the far wall.
    let h = s
        .geometry
        .intersect(&Ray::new(Vec3::new(1.0, 2.0, 3.0), Vec3::Z))
        .unwrap();
    assert!((h.t - 0.5).abs() < 1e-5);
    // Tangent and just-missing rays.
    assert!(
        s.geometry
            .intersect(&Ray::new(Vec3::new(1.0, 2.51, -10.0), Vec3::Z))
            .is_none()
    );
    // Non-uniform scale: an ellipsoid with semi-axes (2, 1, 1)·r.
    let t = Transform::new(Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0))).unwrap();
    let s = one_sphere(t, 1.0);
    let h = s
        .geometry
        .intersect(&Ray::new(Vec3::new(-10.0, 0.0, 0.0), Vec3::X))
        .unwrap();
    assert!((h.t - 8.0).abs() < 1e-4);
    // Normal of the ellipsoid at (√2, √0.5, 0) is ∝ (x/4, y, 0), not the position.
    let p = Vec3::new(2f32.sqrt(), 0.5f32.sqrt(), 0.0);
    let h = s
        .geometry
        .intersect(&Ray::new(p + Vec3::new(0.0, 0.0, -5.0), Vec3::Z))
        .map(|h| h.ng);
    assert!(h.is_none() || h.unwrap().is_finite());
    let h = s
        .geometry
        .intersect(&Ray::new(p * 3.0, -p.normalize()))
        .unwrap();
    let expect = Vec3::new(p.x / 4.0, p.y, 0.0).normalize();
    assert!((h.ng - expect).length() < 1e-3, "{} vs {expect}", h.ng);
    // Disk: radius 1 at height 2 of a rotated frame.
    let mut b = SceneBuilder::new();
    let m = grey(&mut b);
    let rot = Transform::new(Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2)).unwrap();
    b.add_disk(rot, 2.0, 1.0, m, None, false, None).unwrap();
    let s = b.build(cam(), film()).unwrap();
    // Rotating +z by 90° about x gives −y: the disk lies in y = −2 with normal −y.
    let h = s
        .geometry
        .intersect(&Ray::new(Vec3::new(0.3, 5.0, 0.2), Vec3::NEG_Y))
        .unwrap();
    assert!((h.t - 7.0).abs() < 1e-4 && (h.ng - Vec3::NEG_Y).length() < 1e-5);
    assert!(
        s.geometry
            .intersect(&Ray::new(Vec3::new(0.9, 5.0, 0.9), Vec3::NEG_Y))
            .is_none()
    );
    assert!(
        s.geometry
            .intersect(&Ray::new(Vec3::new(0.0, -2.001, -5.0), Vec3::Z))
            .is_none(),
        "a ray parallel to the disk, just below it, misses"
    );
}

#[test]
fn transforms_points_vectors_normals_inverse() {
    let m = Mat4::from_scale_rotation_translation(
        Vec3::new(2.0, 0.5, 3.0),
        glam::Quat::from_rotation_y(0.7),
        Vec3::new(1.0, -2.0, 0.5),
    );
    let t = Transform::new(m).unwrap();
    let p = Vec3::new(0.3, -1.2, 2.0);
    assert!((t.inverse().point(t.point(p)) - p).length() < 1e-5);
    // A normal stays perpendicular to a transformed tangent.
    let (tan, n) = (Vec3::new(1.0, 2.0, 0.0), Vec3::new(-2.0, 1.0, 0.0));
    assert!(tan.dot(n).abs() < 1e-6);
    assert!(t.vector(tan).dot(t.normal(n)).abs() < 1e-4);
    assert!(!t.swaps_handedness());
    assert!(
        Transform::new(Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)))
            .unwrap()
            .swaps_handedness()
    );
    assert!(Transform::new(Mat4::from_scale(Vec3::new(0.0, 1.0, 1.0))).is_none());
    let c = t.then_apply_to(&t.inverse());
    assert!((c.point(p) - p).length() < 1e-5);
}

#[test]
fn spawned_rays_do_not_reintersect_their_surface() {
    // Far from the origin, so absolute errors are large: acne would show here first.
    let center = Vec3::new(1000.0, -500.0, 2000.0);
    let s = one_sphere(Transform::translate(center), 3.0);
    let mut rng = pcg_from_keys(&[7]);
    for _ in 0..20_000 {
        let dir = uniform_sphere(glam::Vec2::new(next_f32(&mut rng), next_f32(&mut rng)));
        let o = center + dir * 50.0;
        let Some(h) = s.geometry.intersect(&Ray::new(o, -dir)) else {
            panic!("missed the sphere");
        };
        // Leaving outward: nothing to hit. Leaving inward: the far side, never t ≈ 0.
        let w = uniform_sphere(glam::Vec2::new(next_f32(&mut rng), next_f32(&mut rng)));
        let w = if w.dot(h.ng) < 0.0 { -w } else { w };
        assert!(
            s.geometry
                .intersect(&Ray::new(h.spawn_origin(w), w))
                .is_none(),
            "self-intersection leaving {}",
            h.p
        );
        let r = s.geometry.intersect(&Ray::new(h.spawn_origin(-w), -w));
        assert!(
            r.is_some_and(|r| r.t > 1e-3),
            "inward ray lost or hit its origin"
        );
    }
}

#[test]
fn spawned_origins_lie_on_the_side_they_leave_to() {
    // The spawn rule without the intersection test's help: for hits on random triangles of
    // every size, orientation and distance from the origin (axis-aligned ones included), the
    // spawned origin lies on the side of the triangle's exact plane that the ray leaves to,
    // or exactly on it (checked in f64).
    use penumbra::geometry::{Geometry, MeshShading};
    let mut rng = pcg_from_keys(&[41]);
    let mut f = || next_f32(&mut rng);
    let (mut checked, mut on_plane, mut least) = (0, 0, f64::INFINITY);
    for k in 0..3000 {
        let size = 10f32.powf(-3.0 + 7.0 * f());
        let far = 10f32.powf(3.0 * f()) * size;
        let centre = uniform_sphere(Vec2::new(f(), f())) * far * (k % 2) as f32;
        let mut p = [0; 3].map(|_| centre + uniform_sphere(Vec2::new(f(), f())) * size);
        if k % 3 == 0 {
            // In a plane x, y or z = c (c = 0 for every sixth).
            let axis = k / 3 % 3;
            let c = if k % 2 == 0 { 0.0 } else { centre[axis] };
            for v in &mut p {
                v[axis] = c;
            }
        }
        let g = Geometry::new(
            vec![lone_triangle(p)],
            vec![MeshShading::default()],
            Vec::new(),
        );
        let (a, b) = (f(), f());
        let (a, b) = if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        let target = p[0] + (p[1] - p[0]) * a + (p[2] - p[0]) * b;
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let eye = target + (n.normalize() + uniform_sphere(Vec2::new(f(), f()))) * size;
        let Some(h) = g.intersect(&Ray::new(eye, target - eye)) else {
            continue;
        };
        let pd = p.map(|v| v.as_dvec3());
        let nd = (pd[1] - pd[0]).cross(pd[2] - pd[0]).normalize();
        for _ in 0..8 {
            let w = uniform_sphere(Vec2::new(f(), f()));
            let side =
                if w.dot(h.ng) >= 0.0 { 1.0 } else { -1.0 } * nd.dot(h.ng.as_dvec3()).signum();
            let dist = side * nd.dot(h.spawn_origin(w).as_dvec3() - pd[0]);
            checked += 1;
            assert!(
                dist >= 0.0,
                "origin {dist} behind the plane of {p:?}, leaving along {w}"
            );
            if dist == 0.0 {
                on_plane += 1;
            } else {
                least = least.min(dist / h.p_error as f64);
            }
        }
    }
    eprintln!(
        "{checked} origins, {on_plane} exactly on their plane, the others at ≥ {least:.3} of the bound"
    );
    assert!(
        checked > 20_000 && on_plane > 1000,
        "{checked} checked, {on_plane} on the plane"
    );
}

/// Triangle `p` as a primitive (material 0, no light).
fn lone_triangle(p: [Vec3; 3]) -> penumbra::geometry::Primitive {
    penumbra::geometry::Primitive {
        p,
        kind: penumbra::geometry::PrimKind::Triangle {
            mesh: 0,
            v: [0, 1, 2],
        },
        material: 0,
        light: u32::MAX,
    }
}

#[test]
fn quadric_error_bounds_cover_the_intersections_own_rounding() {
    // Spheres and disks far from the origin, rotated, uniformly and anisotropically scaled:
    // a spawned ray's origin is mapped back to object space (f32) to be intersected, and the
    // hit's error bound must clear that mapping's error too, with margin (measured: at most
    // 37% of the bound), so that no spawned ray re-hits its quadric and inward rays reach the
    // far side.
    use penumbra::geometry::{Geometry, MeshShading, PrimKind, Primitive, Quadric, QuadricKind};
    use penumbra::sampling::concentric_disk;
    let mut rng = pcg_from_keys(&[31]);
    let mut u2 = || Vec2::new(next_f32(&mut rng), next_f32(&mut rng));
    let configs = [
        (1e4f32, 1.0f32, Vec3::ONE),
        (3e3, 0.05, Vec3::ONE),
        (2e4, 10.0, Vec3::ONE),
        (1e3, 1.0, Vec3::splat(7.3)),
        (1e3, 1.0, Vec3::splat(0.013)),
        (1e3, 1.0, Vec3::new(1.0, 6.0, 0.15)),
    ];
    let (mut worst, mut rays) = (0.0f64, 0);
    for (dist, radius, scale) in configs {
        for sphere in [true, false] {
            for _ in 0..40 {
                let (a, b) = (u2(), u2());
                let rot = glam::Quat::from_axis_angle(uniform_sphere(a), 6.0 * b.x);
                let m = Mat4::from_scale_rotation_translation(scale, rot, uniform_sphere(b) * dist);
                let kind = if sphere {
                    QuadricKind::Sphere { radius }
                } else {
                    QuadricKind::Disk {
                        height: 0.3,
                        radius,
                    }
                };
                let q = Quadric {
                    kind,
                    to_world: Transform::new(m).unwrap(),
                    flip: false,
                    alpha: None,
                };
                let prim = Primitive {
                    p: [Vec3::ZERO; 3],
                    kind: PrimKind::Quadric(0),
                    material: 0,
                    light: u32::MAX,
                };
                let g = Geometry::new(vec![prim], vec![MeshShading::default()], vec![q.clone()]);
                let exact_inv = m.as_dmat4().inverse();
                for _ in 0..20 {
                    let u = u2();
                    let local = if sphere {
                        uniform_sphere(u) * radius
                    } else {
                        let d = concentric_disk(u) * (0.95 * radius);
                        Vec3::new(d.x, d.y, 0.3)
                    };
                    let target = q.to_world.point(local);
                    let n = q.to_world.normal(if sphere { local } else { Vec3::Z });
                    let view = (n.normalize() + uniform_sphere(u2()) * 0.5).normalize();
                    let eye = target + view * (3.0 * radius * scale.max_element());
                    let Some(h) = g.intersect(&Ray::new(eye, target - eye)) else {
                        continue;
                    };
                    for _ in 0..8 {
                        let w = uniform_sphere(u2());
                        let r = Ray::new(h.spawn_origin(w), w);
                        rays += 1;
                        // The object-space origin the intersection uses against the exact
                        // one, seen along the normal in world space, relative to the bound.
                        let mapped = q.to_world.m_inv.transform_point3(r.o).as_dvec3();
                        let exact = exact_inv.transform_point3(r.o.as_dvec3());
                        let off = m.as_dmat4().transform_vector3(mapped - exact);
                        worst = worst.max(off.dot(h.ng.as_dvec3()).abs() / h.p_error as f64);
                        let hit = g.intersect(&r);
                        let cos = w.dot(h.ng);
                        if cos >= 0.0 || !sphere {
                            assert!(hit.is_none(), "self-hit leaving {} along {w}", h.p);
                        } else if cos < -1e-3 {
                            assert!(hit.is_some(), "inward ray from {} escaped", h.p);
                        }
                    }
                }
            }
        }
    }
    eprintln!("{rays} spawned rays; the back mapping used at most {worst:.3} of the bound");
    assert!(rays > 10_000, "{rays} rays");
    assert!(
        worst < 0.75,
        "the back mapping used {worst} of the error bound"
    );
}

#[test]
fn shadow_rays_no_acne_and_no_leaks_at_contacts() {
    // A floor with a closed box standing on it, touching the floor.
    let mut b = SceneBuilder::new();
    let m = grey(&mut b);
    b.add_quad(
        Vec3::new(-10.0, 0.0, -10.0),
        Vec3::new(0.0, 0.0, 20.0),
        Vec3::new(20.0, 0.0, 0.0),
        m,
        None,
    )
    .unwrap();
    let (lo, hi) = (Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 2.0, 1.0));
    let c = |x: bool, y: bool, z: bool| {
        Vec3::new(
            if x { hi.x } else { lo.x },
            if y { hi.y } else { lo.y },
            if z { hi.z } else { lo.z },
        )
    };
    let positions: Vec<Vec3> = (0..8)
        .map(|i| c(i & 1 != 0, i & 2 != 0, i & 4 != 0))
        .collect();
    let indices = vec![
        0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4,
        1, 5, 7, 1, 7, 3,
    ];
    b.add_mesh(
        TriangleMesh {
            positions,
            normals: None,
            uvs: None,
            indices,
            flip_normals: false,
        },
        m,
        None,
    )
    .unwrap();
    let s = b.build(cam(), film()).unwrap();
    let mut rng = pcg_from_keys(&[9]);
    for _ in 0..5_000 {
        // A floor point just outside the box's base (within 1e-3 of the contact line, x < −1).
        let z = next_f32(&mut rng) * 1.8 - 0.9;
        let x = -1.0 - next_f32(&mut rng) * 1e-3 - 1e-6;
        let o = Vec3::new(x, 3.0, z);
        let h = s
            .geometry
            .intersect(&Ray::new(o, Vec3::NEG_Y))
            .expect("floor");
        assert!(h.p.y.abs() < 1e-5);
        // A light point on the far side of the box, low: the box must block it (no leak under
        // the contact) ...
        let target = Vec3::new(3.0, 0.05 + next_f32(&mut rng) * 0.5, z);
        assert!(
            s.geometry.occluded(&shadow_ray(&h, target)),
            "leak at {}",
            h.p
        );
        // ... and a point straight above is visible (no acne on the floor).
        let up = h.p + Vec3::new(-0.5, 5.0, 0.0);
        assert!(!s.geometry.occluded(&shadow_ray(&h, up)), "acne at {}", h.p);
    }
}

#[test]
fn camera_framing_follows_pbrt() {
    let scene = penumbra::scene::builtin::find("cornell").unwrap();
    let scene = (scene.build)(&BuiltinOptions::default()).unwrap();
    let res = UVec2::new(512, 512);
    // Worked by hand from the pbrt file: camera-from-world maps (x, y, z) to
    // (x, y − 1, 6.8 − z); tan(19.5°/2) = 0.171835; raster = ((s + 1)/2·512, (1 − s_y)/2·512).
    let light_center = Vec3::new(-0.005, 1.98, -0.03);
    let p = scene.camera.project(light_center, res).unwrap();
    let t = (19.5f32.to_radians() / 2.0).tan();
    let sx = -0.005 / 6.83 / t;
    let sy = 0.98 / 6.83 / t;
    let expect = Vec2::new((sx + 1.0) / 2.0 * 512.0, (1.0 - sy) / 2.0 * 512.0);
    assert!((p - expect).length() < 1e-3, "{p} vs {expect}");
    assert!(
        (p.x - 254.91).abs() < 0.05 && (p.y - 42.22).abs() < 0.05,
        "{p}"
    );
    // The red wall (x = −1) is on the left, the green one (x = +1) on the right.
    assert!(
        scene
            .camera
            .project(Vec3::new(-1.0, 1.0, 0.0), res)
            .unwrap()
            .x
            < 100.0
    );
    assert!(
        scene
            .camera
            .project(Vec3::new(1.0, 1.0, 0.0), res)
            .unwrap()
            .x
            > 412.0
    );
    // generate_ray through the projected position passes through the point.
    let r = scene.camera.generate_ray(p, res);
    let to = (light_center - r.o).normalize();
    assert!(r.d.dot(to) > 1.0 - 1e-6);
    // Non-square images: fov spans the shorter axis.
    let wide = UVec2::new(800, 400);
    let edge_y = scene.camera.generate_ray(Vec2::new(400.0, 0.0), wide);
    let half = edge_y.d.y.atan2(-edge_y.d.z).to_degrees();
    assert!((half - 19.5 / 2.0).abs() < 1e-3, "vertical half-fov {half}");
}

#[test]
fn renders_are_bit_identical_across_thread_counts() {
    let scene =
        (penumbra::scene::builtin::find("cornell").unwrap().build)(&BuiltinOptions::default())
            .unwrap();
    let res = UVec2::new(48, 40);
    for strategy in [Strategy::Mis, Strategy::Bsdf] {
        let opts = RenderOptions {
            spp: 4,
            seed: 3,
            strategy,
            ..RenderOptions::default()
        };
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| render(&scene, res, &opts).unwrap().0)
        };
        let a = run(1);
        assert_eq!(a, run(2));
        assert_eq!(a, run(3));
        let other = RenderOptions {
            seed: 4,
            ..opts.clone()
        };
        assert_ne!(
            a,
            render(&scene, res, &other).unwrap().0,
            "the seed must matter"
        );
    }
}
