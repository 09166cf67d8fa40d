//! Alpha cut-outs on quadrics, curves and bilinear patches (pbrt-v4's shape `"float alpha"` /
//! `"texture alpha"`, as tests/alpha_cutout.rs checks them on meshes): a disk, annulus,
//! partial sphere, bilinear patch or curve of coverage c passes a fraction 1 − c of a distant
//! light's rays (5σ binomial bound), a sphere or an open cylinder, whose two walls each decide,
//! (1 − c)²; a mask cut away over the near wall shows the far wall (pbrt-v4 traces on past a
//! rejected hit); every query (closest, any-hit, 16-ray packets, all three BVH backends)
//! agrees ray by ray; kept hits are the unmasked shape's hit records bit for bit; and through
//! the pbrt loader a cut-out disk or sphere over a ground passes 1 − c of the sun, unwarned.

mod geometry_support;
mod render_support;

use geometry_support::agreed_hits;
use glam::{Mat4, UVec2, Vec2, Vec3};
use penumbra::geometry::curve::{CurveSegment, CurveType};
use penumbra::geometry::interaction::NO_LIGHT;
use penumbra::geometry::quadric::CutOut;
use penumbra::geometry::{
    Alpha, AlphaTexture, Backend, Geometry, PrimKind, Primitive, Quadric, QuadricKind, Ray,
    SurfaceHit, Transform,
};
use penumbra::sampling::{PatternKind, make_pattern};
use render_support::{assert_fraction, check_fraction, roof_mean};
use std::f32::consts::PI;
use std::sync::Arc;

/// Geometry of the quadrics `qs` (material 0, no lights) behind `backend`'s BVH.
fn geometry(qs: &[Quadric], backend: Backend) -> Geometry {
    let prims = (0..qs.len())
        .map(|i| Primitive {
            p: [Vec3::ZERO; 3],
            kind: PrimKind::Quadric(i as u32),
            material: 0,
            light: NO_LIGHT,
        })
        .collect();
    Geometry::with_backend(prims, Vec::new(), qs.to_vec(), backend)
}

/// A quadric of `kind` under `to_world` with the mask `alpha` (key `key`).
fn quadric(kind: QuadricKind, to_world: Transform, alpha: Option<Alpha>, key: u64) -> Quadric {
    Quadric {
        kind,
        to_world,
        flip: false,
        alpha: alpha.map(|alpha| CutOut { alpha, key }),
    }
}

/// Per ray: the closest hit (quadric index and record), checked equal across every query and
/// backend ([`agreed_hits`]).
fn answers(qs: &[Quadric], rays: &[Ray]) -> Vec<Option<(u32, SurfaceHit)>> {
    let name = |g: &Geometry, id: u32| match g.primitive(id).expect("hit prim").kind {
        PrimKind::Quadric(q) => q,
        PrimKind::Triangle { .. } => u32::MAX,
    };
    agreed_hits(|backend| geometry(qs, backend), name, rays)
}

/// `n` parallel rays along `d` (slightly tilted from +z) from z = −5, uniform over the square
/// [−h, h]² of the plane z = 0 (every one meets each test shape, which spans it).
fn rays_up(n: u32, h: f32, seed: u64) -> Vec<Ray> {
    let pat = make_pattern(PatternKind::Random, seed);
    let d = Vec3::new(0.03, -0.02, 1.0).normalize();
    (0..n)
        .map(|i| {
            let u = pat.sample_2d(UVec2::new(i, 0), 0, 0, 1);
            let at = Vec3::new(h * (2.0 * u.x - 1.0), h * (2.0 * u.y - 1.0), 0.0);
            Ray::new(at - d * (5.0 / d.z), d)
        })
        .collect()
}

/// A rotated, translated, non-uniformly scaled object space (cut-outs are tested in it).
fn skewed() -> Transform {
    Transform::new(
        Mat4::from_translation(Vec3::new(0.1, -0.2, 0.05))
            * Mat4::from_rotation_z(0.4)
            * Mat4::from_scale(Vec3::new(1.2, 0.9, 1.0)),
    )
    .unwrap()
}

/// The test shapes, each spanning the ray square [−0.5, 0.5]² (within its skewed object
/// space), with how many of its walls a ray crosses.
fn shapes() -> Vec<(&'static str, QuadricKind, Transform, i32)> {
    let id = Transform::IDENTITY;
    let z_up = Transform::new(Mat4::from_rotation_x(PI / 2.0)).unwrap();
    vec![
        (
            "disk",
            QuadricKind::Disk {
                height: 0.2,
                radius: 1.5,
            },
            skewed(),
            1,
        ),
        (
            "annulus",
            QuadricKind::DiskCut {
                height: -0.1,
                radius: 3.0,
                inner: 0.4,
                phimax: 1.2 * PI,
            },
            // Its hole and gap away from the rays: the square lies at x, y ∈ [1, 2], φ within
            // [0.4, 1.2] of the sweep's [0, 1.2π].
            Transform::translate(Vec3::new(-1.5, -1.5, 0.0)),
            1,
        ),
        ("sphere", QuadricKind::Sphere { radius: 1.5 }, skewed(), 2),
        (
            "partial sphere (dome)",
            QuadricKind::SphereCut {
                radius: 1.5,
                zmin: 0.0,
                zmax: 1.5,
                phimax: 2.0 * PI,
            },
            id,
            1,
        ),
        (
            "cylinder (sideways)",
            QuadricKind::Cylinder {
                radius: 1.5,
                zmin: -1.0,
                zmax: 1.0,
                phimax: 2.0 * PI,
            },
            // Axis along y: vertical rays cross both walls.
            z_up,
            2,
        ),
        (
            "bilinear patch",
            QuadricKind::Bilinear {
                p: [
                    Vec3::new(-1.0, -1.0, 0.3),
                    Vec3::new(1.0, -1.0, -0.2),
                    Vec3::new(-1.0, 1.0, 0.0),
                    Vec3::new(1.0, 1.0, 0.6),
                ],
                uv: [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE],
            },
            id,
            1,
        ),
        (
            "flat curve",
            QuadricKind::Curve(CurveSegment {
                cp: [
                    Vec3::new(-1.0, 0.0, 0.0),
                    Vec3::new(-0.3, 0.1, 0.1),
                    Vec3::new(0.3, -0.1, 0.0),
                    Vec3::new(1.0, 0.0, 0.1),
                ],
                width: [1.6, 1.6],
                n: [Vec3::Z; 2],
                kind: CurveType::Flat,
            }),
            id,
            1,
        ),
    ]
}

#[test]
fn constant_alpha_passes_one_minus_coverage_per_wall() {
    let n = 30_000;
    for (what, kind, t, walls) in shapes() {
        let rays = rays_up(n, 0.5, 11);
        let plain = answers(&[quadric(kind, t, None, 0)], &rays);
        assert!(
            plain.iter().all(|h| h.is_some()),
            "{what}: every ray meets the unmasked shape"
        );
        for c in [0.3f32, 0.75] {
            let a = answers(&[quadric(kind, t, Some(Alpha::Constant(c)), 7)], &rays);
            let passed = a.iter().filter(|h| h.is_none()).count();
            let want = (1.0 - c as f64).powi(walls);
            check_fraction(&format!("{what}, coverage {c}"), passed, rays.len(), want);
            // Kept hits are the unmasked shape's records, bit for bit, where the near wall
            // kept the ray; past a rejected near wall the far wall's record follows.
            let (mut near, mut far) = (0, 0);
            for (m, p) in a.iter().zip(&plain) {
                let (Some((_, m)), Some((_, p))) = (m, p) else {
                    continue;
                };
                if m.t == p.t {
                    assert!(
                        m.p == p.p && m.uv == p.uv && m.ng == p.ng && m.p_error == p.p_error,
                        "{what}: {m:?} vs {p:?}"
                    );
                    near += 1;
                } else {
                    assert!(walls == 2 && m.t > p.t, "{what}: kept {m:?}, plain {p:?}");
                    far += 1;
                }
            }
            check_fraction(&format!("{what}, near wall"), near, n as usize, c as f64);
            if walls == 2 {
                check_fraction(
                    &format!("{what}, far wall"),
                    far,
                    n as usize,
                    (1.0 - c as f64) * c as f64,
                );
            }
        }
        // Coverage 1 is opaque, 0 transparent.
        let a = answers(&[quadric(kind, t, Some(Alpha::Constant(1.0)), 7)], &rays);
        assert!(a.iter().all(|h| h.is_some()), "{what}: coverage 1");
        let a = answers(&[quadric(kind, t, Some(Alpha::Constant(0.0)), 7)], &rays);
        assert!(a.iter().all(|h| h.is_none()), "{what}: coverage 0");
    }
}

#[test]
fn stacked_cut_out_quadrics_decide_independently() {
    // Two disks of coverage ½ with different keys: a quarter of the rays pass, a quarter
    // stop at the upper one.
    let rays = rays_up(30_000, 0.5, 5);
    let disk = |z: f32, key: u64| {
        quadric(
            QuadricKind::Disk {
                height: z,
                radius: 2.0,
            },
            Transform::IDENTITY,
            Some(Alpha::Constant(0.5)),
            key,
        )
    };
    let a = answers(&[disk(0.0, 1 << 63), disk(0.5, 1 << 63 | 1)], &rays);
    let passed = a.iter().filter(|h| h.is_none()).count();
    check_fraction("two disks of coverage 0.5", passed, rays.len(), 0.25);
    let upper = a.iter().flatten().filter(|(q, _)| *q == 1).count();
    check_fraction("stopped by the upper disk", upper, rays.len(), 0.25);
}

/// Coverage 1 where u < 0.3, else 0.
#[derive(Debug)]
struct StripeU;

impl AlphaTexture for StripeU {
    fn alpha(&self, uv: Vec2) -> f32 {
        if uv.x < 0.3 { 1.0 } else { 0.0 }
    }
}

/// Coverage 1 where v > ½ (a sphere's upper hemisphere), else 0.
#[derive(Debug)]
struct UpperHalf;

impl AlphaTexture for UpperHalf {
    fn alpha(&self, uv: Vec2) -> f32 {
        if uv.y > 0.5 { 1.0 } else { 0.0 }
    }
}

#[test]
fn texture_alpha_cuts_exactly_where_it_is_zero() {
    // A disk keeps the hits whose φ/2π < 0.3.
    let rays = rays_up(20_000, 0.9, 3);
    let disk = quadric(
        QuadricKind::Disk {
            height: 0.0,
            radius: 2.0,
        },
        Transform::IDENTITY,
        Some(Alpha::Texture(Arc::new(StripeU))),
        1,
    );
    let a = answers(&[disk], &rays);
    let mut checked = 0;
    for (r, h) in rays.iter().zip(&a) {
        let p = r.at(-r.o.z / r.d.z);
        let u = p.y.atan2(p.x).rem_euclid(2.0 * PI) / (2.0 * PI);
        if (u - 0.3).abs() > 1e-4 && u > 1e-4 {
            assert_eq!(h.is_some(), u < 0.3, "ray at u = {u}: hit {h:?}");
            checked += 1;
        }
    }
    assert!(checked > 19_900, "{checked}");
    // A sphere whose lower half is cut away: rays from below go through the near wall and
    // hit the far one from inside, whose record is the outward normal's side.
    let sphere = quadric(
        QuadricKind::Sphere { radius: 1.5 },
        Transform::IDENTITY,
        Some(Alpha::Texture(Arc::new(UpperHalf))),
        2,
    );
    let a = answers(&[sphere], &rays);
    for (r, h) in rays.iter().zip(&a) {
        let (_, h) = h.expect("the far wall is kept");
        assert!(h.p.z > 0.0 && h.uv.y > 0.5, "{r:?}: {h:?}");
        assert!(h.ng.dot(r.d) > 0.0, "seen from inside: {h:?}");
        assert!((h.p.length() - 1.5).abs() < 1e-5, "{h:?}");
    }
}

#[test]
fn pbrt_cut_out_quadric_roofs_pass_one_minus_coverage_of_the_sun() {
    let open = roof_mean("");
    let c = 0.35;
    // A disk over the ground, and a sphere around the whole view (the shadow rays cross its
    // wall once, from inside).
    for (what, shape) in [
        (
            "disk",
            format!(
                "AttributeBegin Translate 0 0 1 Shape \"disk\" \"float radius\" 40 \"float alpha\" {c} AttributeEnd"
            ),
        ),
        (
            "sphere",
            format!("Shape \"sphere\" \"float radius\" 30 \"float alpha\" {c}"),
        ),
    ] {
        let under = roof_mean(&shape);
        assert_fraction(
            &format!("{what} roof of coverage {c}"),
            under,
            open,
            1.0 - c,
        );
        let (shut, _) = roof_mean(&shape.replace(&format!("{c}"), "1"));
        assert!(
            shut < 1e-6 * open.0,
            "{what}: opaque roof lets {shut} through"
        );
    }
}
