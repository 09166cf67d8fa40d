//! Chi-square goodness-of-fit tests of every warp, solid-angle sampler and distribution in
//! `penumbra::sampling` against its pdf (≥ 1M samples each). The pdfs used as the reference are
//! written out independently here wherever the module's own pdf could share a bug with the
//! sampler (inside tests, normalisations).
//!
//! The whole family runs at an overall significance of 1% (Šidák-corrected per test).

use glam::{DVec2, DVec3, Vec2, Vec3};
use penumbra::sampling::chi2::{
    Chi2Config, Chi2Result, chi2_directions, chi2_discrete, chi2_points,
};
use penumbra::sampling::*;
use std::f64::consts::PI;

/// Number of chi-square tests in this file (for the Šidák correction); keep in sync.
const NUM_TESTS: usize = 46;

fn cfg() -> Chi2Config {
    Chi2Config {
        num_tests: NUM_TESTS,
        ..Default::default()
    }
}

fn v2(u: [f32; 3]) -> Vec2 {
    Vec2::new(u[1], u[2])
}

#[track_caller]
fn check(name: &str, r: &Chi2Result) {
    eprintln!("{name}: {}", r.summary());
    assert!(r.passed, "{name}: {}", r.summary());
}

/// Test directions at high resolution around `frame.n`: project them gnomonically onto the
/// tangent plane z = 1 of `frame` and test the points against the area pdf
/// `pdf_ω · cos³θ` (dω = cos³θ dA on that plane). `pdf_plane` gives the solid-angle pdf as a
/// function of the plane point. Samples outside `domain` go to the harness's "nowhere" category,
/// whose expected mass is what the pdf puts outside, so the test stays exact.
fn chi2_zoomed(
    cfg: &Chi2Config,
    frame: Frame,
    domain: [f32; 4],
    mut sample: impl FnMut([f32; 3]) -> Option<Vec3>,
    pdf_plane: impl Fn(DVec2) -> f64,
) -> Chi2Result {
    chi2_points(
        cfg,
        domain,
        |u| {
            let l = frame.to_local(sample(u)?);
            (l.z > 0.0).then(|| Vec2::new(l.x / l.z, l.y / l.z))
        },
        |q| {
            let q = q.as_dvec2();
            pdf_plane(q) * (1.0 + q.length_squared()).powf(-1.5)
        },
    )
}

/// Square domain of half-width `w` around the origin.
fn square(w: f32) -> [f32; 4] {
    [-w, w, -w, w]
}

// ---------------------------------------------------------------- hemispheres and spheres

#[test]
fn chi2_uniform_hemisphere() {
    let r = chi2_directions(
        &cfg(),
        |u| Some(uniform_hemisphere(v2(u))),
        |d| if d.z >= 0.0 { 0.5 / PI } else { 0.0 },
    );
    check("uniform hemisphere", &r);
}

#[test]
fn chi2_cosine_hemisphere() {
    let r = chi2_directions(
        &cfg(),
        |u| Some(cosine_hemisphere(v2(u))),
        |d| d.z.max(0.0) as f64 / PI,
    );
    check("cosine hemisphere", &r);
}

#[test]
fn chi2_uniform_sphere() {
    let r = chi2_directions(&cfg(), |u| Some(uniform_sphere(v2(u))), |_| 0.25 / PI);
    check("uniform sphere", &r);
}

fn cosine_power_pdf(d: Vec3, n: f64) -> f64 {
    if d.z <= 0.0 {
        0.0
    } else {
        (n + 1.0) / (2.0 * PI) * (d.z as f64).powf(n)
    }
}

fn chi2_cosine_power(n: f32) {
    let r = chi2_directions(
        &cfg(),
        |u| Some(cosine_power_hemisphere(v2(u), n)),
        |d| cosine_power_pdf(d, n as f64),
    );
    check(&format!("cosine power n = {n}, sphere"), &r);
    // The lobe only fills the top rows of the sphere grid when n is large: zoom in on it,
    // to about 4 standard deviations of tan θ ≈ sqrt(2/n).
    let w = (4.0 * (2.0 / n).sqrt()).min(2.5);
    let r = chi2_zoomed(
        &cfg(),
        Frame::from_normal(Vec3::Z),
        square(w),
        |u| Some(cosine_power_hemisphere(v2(u), n)),
        |q| {
            let cos = 1.0 / (1.0 + q.length_squared()).sqrt();
            (n as f64 + 1.0) / (2.0 * PI) * cos.powf(n as f64)
        },
    );
    check(&format!("cosine power n = {n}, zoomed"), &r);
}

#[test]
fn chi2_cosine_power_n1() {
    chi2_cosine_power(1.0);
}

#[test]
fn chi2_cosine_power_n10() {
    chi2_cosine_power(10.0);
}

#[test]
fn chi2_cosine_power_n100() {
    chi2_cosine_power(100.0);
}

#[test]
fn chi2_cosine_power_n1000() {
    chi2_cosine_power(1000.0);
}

// ---------------------------------------------------------------- negative controls

#[test]
fn chi2_negative_control_cosine_vs_uniform() {
    let r = chi2_directions(
        &cfg(),
        |u| Some(cosine_hemisphere(v2(u))),
        |d| if d.z >= 0.0 { 0.5 / PI } else { 0.0 },
    );
    eprintln!("negative control cosine vs uniform: {}", r.summary());
    assert!(!r.passed, "harness has no power: {}", r.summary());
}

#[test]
fn chi2_negative_control_cosine_power_10_vs_11() {
    let r = chi2_directions(
        &cfg(),
        |u| Some(cosine_power_hemisphere(v2(u), 10.0)),
        |d| cosine_power_pdf(d, 11.0),
    );
    eprintln!("negative control n = 10 vs 11: {}", r.summary());
    assert!(!r.passed, "harness has no power: {}", r.summary());
}

#[test]
fn chi2_negative_control_cosine_power_1000_vs_1050_zoomed() {
    // A 5% error in a sharp exponent is invisible on the sphere grid but not when zoomed.
    let n = 1000.0;
    let r = chi2_zoomed(
        &cfg(),
        Frame::from_normal(Vec3::Z),
        square(0.18),
        |u| Some(cosine_power_hemisphere(v2(u), n)),
        |q| {
            let cos = 1.0 / (1.0 + q.length_squared()).sqrt();
            1051.0 / (2.0 * PI) * cos.powf(1050.0)
        },
    );
    eprintln!("negative control n = 1000 vs 1050 zoomed: {}", r.summary());
    assert!(!r.passed, "zoomed harness has no power: {}", r.summary());
}

#[test]
fn chi2_negative_control_area_sampling_vs_solid_angle_pdf() {
    // Uniform-by-area points on a triangle are not uniform in solid angle: the harness must
    // tell Arvo's sampler from area sampling judged against 1/Ω.
    let (p, v) = (Vec3::ZERO, [Vec3::X, Vec3::Y, Vec3::Z]);
    let omega = triangle_solid_angle(p, v[0], v[1], v[2]);
    let r = chi2_directions(
        &cfg(),
        |u| (uniform_triangle_point(v2(u), v[0], v[1], v[2]) - p).try_normalize(),
        |d| {
            if ray_hits_triangle(p.as_dvec3(), d.as_dvec3(), v[0], v[1], v[2]) {
                1.0 / omega
            } else {
                0.0
            }
        },
    );
    eprintln!("negative control area vs solid angle: {}", r.summary());
    assert!(!r.passed, "harness has no power: {}", r.summary());
}

// ---------------------------------------------------------------- disk, triangle, tent

#[test]
fn chi2_concentric_disk() {
    let r = chi2_points(
        &Chi2Config {
            res: (64, 64),
            ..cfg()
        },
        square(1.0),
        |u| Some(concentric_disk(v2(u))),
        |p| {
            if p.length_squared() <= 1.0 {
                1.0 / PI
            } else {
                0.0
            }
        },
    );
    check("concentric disk", &r);
}

#[test]
fn chi2_uniform_triangle_barycentrics() {
    let r = chi2_points(
        &Chi2Config {
            res: (64, 64),
            ..cfg()
        },
        [0.0, 1.0, 0.0, 1.0],
        |u| Some(uniform_triangle(v2(u))),
        |b| if b.x + b.y <= 1.0 { 2.0 } else { 0.0 },
    );
    check("uniform triangle (barycentrics)", &r);
}

#[test]
fn chi2_uniform_triangle_point() {
    // An obtuse triangle in the plane z = 0.
    let (p0, p1, p2) = (
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::new(2.0, 0.3, 0.0),
        Vec3::new(0.5, 1.2, 0.0),
    );
    let area = 0.5 * (p1 - p0).cross(p2 - p0).length() as f64;
    let inside = |p: DVec2| {
        let e = |a: Vec3, b: Vec3| {
            let (a, b) = (a.truncate().as_dvec2(), b.truncate().as_dvec2());
            (b - a).perp_dot(p - a)
        };
        e(p0, p1) >= 0.0 && e(p1, p2) >= 0.0 && e(p2, p0) >= 0.0
    };
    let r = chi2_points(
        &Chi2Config {
            res: (64, 64),
            ..cfg()
        },
        [-1.0, 2.0, 0.0, 1.2],
        |u| Some(uniform_triangle_point(v2(u), p0, p1, p2).truncate()),
        |p| {
            if inside(p.as_dvec2()) {
                1.0 / area
            } else {
                0.0
            }
        },
    );
    check("uniform triangle point", &r);
}

#[test]
fn chi2_tent_filter() {
    for radius in [0.5f32, 1.5] {
        let r = chi2_points(
            &Chi2Config {
                res: (128, 1),
                ..cfg()
            },
            [-radius, radius, 0.0, 1.0],
            |u| Some(Vec2::new(tent(u[1], radius), 0.5)),
            |p| {
                let (x, r) = (p.x.abs() as f64, radius as f64);
                if x < r { (r - x) / (r * r) } else { 0.0 }
            },
        );
        check(&format!("tent r = {radius}"), &r);
    }
}

// ---------------------------------------------------------------- cones

fn cone_pdf(d: Vec3, one_minus_cos_max: f64) -> f64 {
    let d = d.as_dvec3().normalize();
    if 1.0 - d.z <= one_minus_cos_max {
        1.0 / (2.0 * PI * one_minus_cos_max)
    } else {
        0.0
    }
}

#[test]
fn chi2_uniform_cone_angles() {
    // Half-angles from 5° to 120° (a cone wider than a hemisphere).
    for deg in [5.0f64, 30.0, 60.0, 90.0, 120.0] {
        let cos_max = deg.to_radians().cos() as f32;
        let r = chi2_directions(
            &cfg(),
            |u| Some(uniform_cone(v2(u), cos_max)),
            |d| cone_pdf(d, 1.0 - cos_max as f64),
        );
        check(&format!("cone {deg}°"), &r);
    }
}

#[test]
fn chi2_uniform_cone_tiny_zoomed() {
    // A sphere light of radius 1 mm seen from 10 m: θmax ≈ 1e-4 rad.
    for sin2 in [1e-8f32, 1e-4] {
        let om = cone_one_minus_cos(sin2) as f64;
        let tan_max = (sin2 as f64 / (1.0 - sin2 as f64)).sqrt();
        let r = chi2_zoomed(
            &cfg(),
            Frame::from_normal(Vec3::Z),
            square((1.05 * tan_max) as f32),
            |u| Some(uniform_cone_sin2(v2(u), sin2)),
            |q| {
                if q.length() <= tan_max {
                    1.0 / (2.0 * PI * om)
                } else {
                    0.0
                }
            },
        );
        check(&format!("tiny cone sin² = {sin2}"), &r);
    }
}

#[test]
fn chi2_uniform_cone_sin2() {
    let sin2 = 0.3f32;
    let r = chi2_directions(
        &cfg(),
        |u| Some(uniform_cone_sin2(v2(u), sin2)),
        |d| cone_pdf(d, 1.0 - (1.0 - sin2 as f64).sqrt()),
    );
    check("cone from sin²", &r);
}

// ---------------------------------------------------------------- spherical triangles

/// Solid angle of triangle (a, b, c) from p (Van Oosterom–Strackee, f64).
fn triangle_solid_angle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f64 {
    let [a, b, c] = [a, b, c].map(|v| (v - p).as_dvec3().normalize());
    2.0 * a
        .dot(b.cross(c))
        .abs()
        .atan2(1.0 + a.dot(b) + b.dot(c) + c.dot(a))
}

/// Whether the ray from p along d hits triangle (a, b, c) (f64 Möller–Trumbore).
fn ray_hits_triangle(p: DVec3, d: DVec3, a: Vec3, b: Vec3, c: Vec3) -> bool {
    let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
    let (e1, e2) = (b - a, c - a);
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 {
        return false;
    }
    let t = p - a;
    let u = t.dot(pv) / det;
    let q = t.cross(e1);
    let v = d.dot(q) / det;
    let dist = e2.dot(q) / det;
    u >= 0.0 && v >= 0.0 && u + v <= 1.0 && dist > 0.0
}

fn chi2_spherical_triangle_full(name: &str, p: Vec3, v: [Vec3; 3]) {
    let tri = SphericalTriangle::new(p, v[0], v[1], v[2]).expect(name);
    let omega = triangle_solid_angle(p, v[0], v[1], v[2]);
    assert!(
        (tri.area as f64 - omega).abs() <= 1e-5 * omega,
        "{name}: area {} vs {omega}",
        tri.area
    );
    let r = chi2_directions(
        &cfg(),
        |u| Some(tri.sample(v2(u))),
        |d| {
            if ray_hits_triangle(p.as_dvec3(), d.as_dvec3(), v[0], v[1], v[2]) {
                1.0 / omega
            } else {
                0.0
            }
        },
    );
    check(name, &r);
}

/// A frame around the direction from `p` to `centre` whose first axis follows `along`.
fn view_frame(p: Vec3, centre: Vec3, along: Vec3) -> Frame {
    let n = (centre - p).normalize();
    let s = (along - n * along.dot(n)).normalize();
    Frame {
        s,
        t: n.cross(s),
        n,
    }
}

/// Bounding square (in the gnomonic plane of `frame`) of the given points, slightly enlarged.
fn plane_bounds(p: Vec3, frame: Frame, pts: &[Vec3]) -> [f32; 4] {
    let mut b = [f32::MAX, f32::MIN, f32::MAX, f32::MIN];
    for &v in pts {
        let l = frame.to_local(v - p);
        let q = Vec2::new(l.x / l.z, l.y / l.z);
        b = [b[0].min(q.x), b[1].max(q.x), b[2].min(q.y), b[3].max(q.y)];
    }
    let (mx, my) = (0.02 * (b[1] - b[0]), 0.02 * (b[3] - b[2]));
    [b[0] - mx, b[1] + mx, b[2] - my, b[3] + my]
}

fn chi2_spherical_triangle_zoomed(name: &str, p: Vec3, v: [Vec3; 3]) {
    let tri = SphericalTriangle::new(p, v[0], v[1], v[2]).expect(name);
    let omega = triangle_solid_angle(p, v[0], v[1], v[2]);
    assert!(
        (tri.area as f64 - omega).abs() <= 1e-4 * omega,
        "{name}: area {} vs {omega}",
        tri.area
    );
    let centre = (v[0] + v[1] + v[2]) / 3.0;
    let frame = view_frame(p, centre, v[1] - v[0]);
    let domain = plane_bounds(p, frame, &v);
    let (fs, ft, fnn) = (frame.s.as_dvec3(), frame.t.as_dvec3(), frame.n.as_dvec3());
    let r = chi2_zoomed(
        &Chi2Config {
            res: (64, 64),
            ..cfg()
        },
        frame,
        domain,
        |u| Some(tri.sample(v2(u))),
        |q| {
            let d = fs * q.x + ft * q.y + fnn;
            if ray_hits_triangle(p.as_dvec3(), d, v[0], v[1], v[2]) {
                1.0 / omega
            } else {
                0.0
            }
        },
    );
    check(name, &r);
}

#[test]
fn chi2_spherical_triangle_octant() {
    chi2_spherical_triangle_full(
        "spherical triangle octant",
        Vec3::ZERO,
        [Vec3::X, Vec3::Y, Vec3::Z],
    );
}

#[test]
fn chi2_spherical_triangle_large() {
    // Close above a big triangle: nearly a hemisphere (Ω ≈ 5.6 sr).
    chi2_spherical_triangle_full(
        "spherical triangle large",
        Vec3::new(0.1, -0.2, 0.5),
        [
            Vec3::new(-10.0, -10.0, 0.0),
            Vec3::new(10.0, -10.0, 0.0),
            Vec3::new(0.0, 12.0, 0.0),
        ],
    );
}

#[test]
fn chi2_spherical_triangle_grazing() {
    // Viewpoint just above the plane and outside the triangle: a long thin sliver.
    chi2_spherical_triangle_full(
        "spherical triangle grazing",
        Vec3::new(-0.5, -0.3, 0.03),
        [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(4.0, 0.5, 0.0),
            Vec3::new(0.5, 3.0, 0.0),
        ],
    );
}

#[test]
fn chi2_spherical_triangle_obtuse_tilted() {
    chi2_spherical_triangle_full(
        "spherical triangle obtuse tilted",
        Vec3::new(0.3, 0.1, -0.2),
        [
            Vec3::new(-1.0, 0.2, 1.0),
            Vec3::new(1.5, -0.4, 0.3),
            Vec3::new(0.1, 0.1, 2.0),
        ],
    );
}

#[test]
fn chi2_spherical_triangle_tiny() {
    // Edges of ~2 mm at 1 m: Ω ≈ 2e-6 sr.
    let c = Vec3::new(0.3, 0.4, 0.866);
    chi2_spherical_triangle_zoomed(
        "spherical triangle tiny",
        Vec3::ZERO,
        [
            c + Vec3::new(0.002, 0.0, 0.0),
            c + Vec3::new(-0.001, 0.0015, 0.0),
            c + Vec3::new(0.0, -0.001, 0.001),
        ],
    );
}

#[test]
fn chi2_spherical_triangle_tiny_grazing() {
    // A 1 cm triangle 2 m away, seen 88° off its normal.
    let grazing = 88f32.to_radians();
    let p = Vec3::new(2.0 * grazing.sin(), 0.0, 2.0 * grazing.cos());
    chi2_spherical_triangle_zoomed(
        "spherical triangle tiny grazing",
        p,
        [
            Vec3::new(-0.005, -0.004, 0.0),
            Vec3::new(0.006, 0.0, 0.0),
            Vec3::new(0.0, 0.005, 0.0),
        ],
    );
}

#[test]
fn chi2_spherical_triangle_medium_grazing_zoomed() {
    let p = Vec3::new(-1.0, 0.2, 0.05);
    chi2_spherical_triangle_zoomed(
        "spherical triangle medium grazing (zoomed)",
        p,
        [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.5, 0.4, 0.0),
            Vec3::new(0.2, -0.3, 0.0),
        ],
    );
}

// ---------------------------------------------------------------- spherical rectangles

/// Whether the ray from p along d hits the rectangle corner + s·ex + t·ey, s, t ∈ [0, 1].
fn ray_hits_rectangle(p: DVec3, d: DVec3, corner: Vec3, ex: Vec3, ey: Vec3) -> bool {
    let (c, ex, ey) = (corner.as_dvec3(), ex.as_dvec3(), ey.as_dvec3());
    let n = ex.cross(ey);
    let den = d.dot(n);
    if den == 0.0 {
        return false;
    }
    let t = (c - p).dot(n) / den;
    if t <= 0.0 {
        return false;
    }
    let h = p + d * t - c;
    let (s, u) = (
        h.dot(ex) / ex.length_squared(),
        h.dot(ey) / ey.length_squared(),
    );
    (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&u)
}

fn rectangle_solid_angle(p: Vec3, corner: Vec3, ex: Vec3, ey: Vec3) -> f64 {
    triangle_solid_angle(p, corner, corner + ex, corner + ex + ey)
        + triangle_solid_angle(p, corner, corner + ex + ey, corner + ey)
}

fn chi2_spherical_rectangle(name: &str, p: Vec3, corner: Vec3, ex: Vec3, ey: Vec3, zoom: bool) {
    let rect = SphericalRectangle::new(p, corner, ex, ey).expect(name);
    let omega = rectangle_solid_angle(p, corner, ex, ey);
    assert!(
        (rect.solid_angle as f64 - omega).abs() <= 1e-4 * omega,
        "{name}: solid angle {} vs {omega}",
        rect.solid_angle
    );
    let hit = |d: DVec3| ray_hits_rectangle(p.as_dvec3(), d, corner, ex, ey);
    let sample = |u: [f32; 3]| (rect.sample(v2(u)) - p).try_normalize();
    let r = if zoom {
        let frame = view_frame(p, corner + 0.5 * (ex + ey), ex);
        let pts = [corner, corner + ex, corner + ey, corner + ex + ey];
        let (fs, ft, fnn) = (frame.s.as_dvec3(), frame.t.as_dvec3(), frame.n.as_dvec3());
        chi2_zoomed(
            &Chi2Config {
                res: (64, 64),
                ..cfg()
            },
            frame,
            plane_bounds(p, frame, &pts),
            sample,
            |q| {
                if hit(fs * q.x + ft * q.y + fnn) {
                    1.0 / omega
                } else {
                    0.0
                }
            },
        )
    } else {
        chi2_directions(&cfg(), sample, |d| {
            if hit(d.as_dvec3()) { 1.0 / omega } else { 0.0 }
        })
    };
    check(name, &r);
}

#[test]
fn chi2_spherical_rectangle_cube_face() {
    chi2_spherical_rectangle(
        "spherical rectangle cube face",
        Vec3::new(0.5, 0.5, 0.5),
        Vec3::ZERO,
        Vec3::X,
        Vec3::Y,
        false,
    );
}

#[test]
fn chi2_spherical_rectangle_large_rotated() {
    // Edges not aligned with the axes; viewpoint close to the plane above the interior.
    let ex = Vec3::new(3.0, 2.0, 1.0);
    let ey = Vec3::new(-1.0, 1.0, 1.0) * 1.5;
    assert!(ex.dot(ey).abs() < 1e-6);
    let corner = Vec3::new(-1.0, -1.5, -0.5);
    let n = ex.cross(ey).normalize();
    let p = corner + 0.4 * ex + 0.6 * ey + 0.1 * n;
    chi2_spherical_rectangle(
        "spherical rectangle large rotated",
        p,
        corner,
        ex,
        ey,
        false,
    );
}

#[test]
fn chi2_spherical_rectangle_grazing() {
    chi2_spherical_rectangle(
        "spherical rectangle grazing",
        Vec3::new(-0.3, 0.5, 0.02),
        Vec3::ZERO,
        Vec3::new(3.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        false,
    );
}

#[test]
fn chi2_spherical_rectangle_behind() {
    // Viewpoint on the other side of the plane (flips the local frame).
    chi2_spherical_rectangle(
        "spherical rectangle from below",
        Vec3::new(0.7, -0.4, -0.6),
        Vec3::ZERO,
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 0.0),
        false,
    );
}

#[test]
fn chi2_spherical_rectangle_tiny() {
    chi2_spherical_rectangle(
        "spherical rectangle tiny",
        Vec3::ZERO,
        Vec3::new(0.2, -0.1, 1.0),
        Vec3::new(0.002, 0.0, 0.0),
        Vec3::new(0.0, 0.001, 0.0),
        true,
    );
}

#[test]
fn chi2_spherical_rectangle_tiny_grazing() {
    let grazing = 87f32.to_radians();
    chi2_spherical_rectangle(
        "spherical rectangle tiny grazing",
        Vec3::new(0.0, -1.5 * grazing.sin(), 1.5 * grazing.cos()),
        Vec3::new(-0.005, -0.005, 0.0),
        Vec3::new(0.01, 0.0, 0.0),
        Vec3::new(0.0, 0.01, 0.0),
        true,
    );
}

// ---------------------------------------------------------------- distributions

/// A non-trivial "environment map": a bright sun, a smooth sky, zero blocks and noise.
fn test_image(nu: usize, nv: usize) -> Vec<f32> {
    let mut h = 12345u32;
    (0..nv)
        .flat_map(|v| (0..nu).map(move |u| (u, v)))
        .map(|(u, v)| {
            h = h.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
            let noise = (h >> 8) as f32 / (1u32 << 24) as f32;
            let (x, y) = ((u as f32 + 0.5) / nu as f32, (v as f32 + 0.5) / nv as f32);
            let sun = 200.0 * (-((x - 0.3).powi(2) + (y - 0.2).powi(2)) * 800.0).exp();
            let sky = 1.0 + y;
            let hole = if (u / 5 + v / 3) % 3 == 0 { 0.0 } else { 1.0 };
            (sun + sky * hole * noise) * (PI as f32 * y).sin()
        })
        .collect()
}

#[test]
fn chi2_distribution2d_image() {
    let (nu, nv) = (48, 24);
    let img = test_image(nu, nv);
    let d = Distribution2D::new(&img, nu, nv);
    let mean: f64 = img.iter().map(|&x| x as f64).sum::<f64>() / (nu * nv) as f64;
    let r = chi2_points(
        &Chi2Config {
            res: (96, 48),
            ..cfg()
        },
        [0.0, 1.0, 0.0, 1.0],
        |u| {
            let (p, pdf) = d.sample(v2(u));
            // The returned pdf must be the density at the returned point.
            let (iu, iv) = ((p.x * nu as f32) as usize, (p.y * nv as f32) as usize);
            let want = img[iv * nu + iu] as f64 / mean;
            assert!((pdf as f64 - want).abs() <= 1e-4 * want, "{pdf} vs {want}");
            Some(p)
        },
        |p| {
            let (iu, iv) = (
                ((p.x as f64 * nu as f64) as usize).min(nu - 1),
                ((p.y as f64 * nv as f64) as usize).min(nv - 1),
            );
            img[iv * nu + iu] as f64 / mean
        },
    );
    check("distribution2d image", &r);
}

#[test]
fn chi2_distribution1d_continuous() {
    let w: Vec<f32> = (0..50)
        .map(|i| {
            if i % 7 == 3 {
                0.0
            } else {
                ((i as f32) * 0.37).sin().abs() + 0.01 * i as f32
            }
        })
        .collect();
    let d = Distribution1D::new(&w);
    let mean = w.iter().map(|&x| x as f64).sum::<f64>() / w.len() as f64;
    let r = chi2_points(
        &Chi2Config {
            res: (200, 1),
            ..cfg()
        },
        [0.0, 1.0, 0.0, 1.0],
        |u| Some(Vec2::new(d.sample_continuous(u[1]).0, 0.5)),
        |p| w[((p.x as f64 * 50.0) as usize).min(49)] as f64 / mean,
    );
    check("distribution1d continuous", &r);
}

/// Skewed weights: a power law over four decades with a few exact zeros.
fn skewed_weights(n: usize) -> Vec<f32> {
    (0..n)
        .map(|i| {
            if i % 11 == 5 {
                0.0
            } else {
                1.0 / ((i + 1) as f32).powf(1.5)
            }
        })
        .collect()
}

fn pmf_of(w: &[f32]) -> Vec<f64> {
    let s: f64 = w.iter().map(|&x| x as f64).sum();
    w.iter().map(|&x| x as f64 / s).collect()
}

#[test]
fn chi2_alias_table_skewed() {
    let w = skewed_weights(200);
    let t = AliasTable::new(&w).unwrap();
    let pmf = pmf_of(&w);
    let r = chi2_discrete(&cfg(), &pmf, |u| {
        let (i, p) = t.sample(u[0]);
        assert!((p as f64 - pmf[i]).abs() <= 1e-6 * pmf[i] + 1e-12);
        Some(i)
    });
    check("alias table skewed", &r);
}

#[test]
fn chi2_cdf_discrete_skewed() {
    let w = skewed_weights(200);
    let d = Distribution1D::new(&w);
    let pmf = pmf_of(&w);
    let r = chi2_discrete(&cfg(), &pmf, |u| {
        let (i, p, _) = d.sample_discrete(u[0]);
        assert!((p as f64 - pmf[i]).abs() <= 1e-5 * pmf[i] + 1e-12);
        Some(i)
    });
    check("cdf discrete skewed", &r);
}

#[test]
fn chi2_cdf_discrete_remapped_u_is_uniform() {
    // The reused u must be uniform on [0,1) and independent of the chosen bin.
    let w = [1.0f32, 5.0, 0.0, 2.0];
    let d = Distribution1D::new(&w);
    let pmf = pmf_of(&w);
    let r = chi2_points(
        &Chi2Config {
            res: (4, 32),
            ..cfg()
        },
        [0.0, 4.0, 0.0, 1.0],
        |u| {
            let (i, _, ur) = d.sample_discrete(u[0]);
            Some(Vec2::new(i as f32 + 0.5, ur))
        },
        |p| pmf[(p.x as usize).min(3)],
    );
    check("remapped u", &r);
}

// ---------------------------------------------------------------- sample patterns

#[test]
fn chi2_patterns_are_uniform_over_pixels() {
    // Across pixels, each pattern's points must be uniform on [0,1)² (no bias), for a count
    // that is neither a square nor a power of two.
    for kind in [
        PatternKind::Random,
        PatternKind::Stratified,
        PatternKind::Lhs,
        PatternKind::Sobol,
    ] {
        let pat = make_pattern(kind, 7);
        let count = 24u32;
        let mut k = 0u32;
        let r = chi2_points(
            &Chi2Config {
                res: (32, 32),
                ..cfg()
            },
            [0.0, 1.0, 0.0, 1.0],
            |_| {
                let (pixel, index) = (k / count, k % count);
                k += 1;
                Some(pat.sample_2d(
                    glam::UVec2::new(pixel % 1000, pixel / 1000),
                    3,
                    index,
                    count,
                ))
            },
            |_| 1.0,
        );
        check(&format!("pattern {kind} uniform"), &r);
    }
}
