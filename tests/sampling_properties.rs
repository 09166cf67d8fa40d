//! Deterministic properties of `penumbra::sampling`: every pdf integrates to 1 over its domain
//! (quadrature), inverses round-trip, frames are orthonormal, and the sample patterns stratify,
//! decorrelate dimensions and (for Sobol) beat random points on star discrepancy.

use glam::{UVec2, Vec2, Vec3};
use penumbra::sampling::*;
use std::f64::consts::PI;

// ---------------------------------------------------------------- quadrature helpers

/// ∫ pdf dω over the sphere by the midpoint rule on (z, φ) (dω = dz dφ).
fn integrate_sphere(nz: usize, nphi: usize, pdf: impl Fn(Vec3) -> f32) -> f64 {
    let mut s = 0.0f64;
    for i in 0..nz {
        let z = -1.0 + (i as f64 + 0.5) * 2.0 / nz as f64;
        let r = (1.0 - z * z).sqrt();
        let mut row = 0.0f64;
        for j in 0..nphi {
            let phi = (j as f64 + 0.5) * 2.0 * PI / nphi as f64;
            let d = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
            row += pdf(d) as f64;
        }
        s += row;
    }
    s * (2.0 / nz as f64) * (2.0 * PI / nphi as f64)
}

/// ∫ pdf dω for a pdf that depends on θ only, as 2π ∫ pdf(z) dz with a graded z grid that
/// resolves lobes as sharp as cos^1000.
fn integrate_zonal(pdf: impl Fn(Vec3) -> f32) -> f64 {
    let m = 200_000;
    let mut s = 0.0f64;
    for i in 0..m {
        // t = 1 − z ∈ [0, 2], graded quadratically towards the pole.
        let (a, b) = (i as f64 / m as f64, (i + 1) as f64 / m as f64);
        let (t0, t1) = (2.0 * a * a, 2.0 * b * b);
        let t = 0.5 * (t0 + t1);
        let d = direction_from_one_minus_cos(t as f32, 0.3);
        s += pdf(d) as f64 * (t1 - t0);
    }
    2.0 * PI * s
}

/// A direction pdf under test.
type PdfFn = Box<dyn Fn(Vec3) -> f32>;

#[test]
fn hemisphere_and_sphere_pdfs_integrate_to_one() {
    let cases: Vec<(&str, PdfFn)> = vec![
        ("uniform hemisphere", Box::new(uniform_hemisphere_pdf)),
        ("cosine hemisphere", Box::new(cosine_hemisphere_pdf)),
        ("uniform sphere", Box::new(|_| uniform_sphere_pdf())),
        (
            "cone 30°",
            Box::new(|d| uniform_cone_pdf(d, 30f32.to_radians().cos())),
        ),
        (
            "cone 120°",
            Box::new(|d| uniform_cone_pdf(d, 120f32.to_radians().cos())),
        ),
        ("cone sin² 0.2", Box::new(|d| uniform_cone_sin2_pdf(d, 0.2))),
    ];
    for (name, pdf) in cases {
        let i = integrate_zonal(pdf);
        assert!((i - 1.0).abs() < 1e-4, "{name}: ∫pdf = {i}");
    }
    for n in [0.0f32, 1.0, 10.0, 100.0, 1000.0] {
        let i = integrate_zonal(|d| cosine_power_hemisphere_pdf(d, n));
        assert!((i - 1.0).abs() < 1e-4, "cosine power {n}: ∫pdf = {i}");
    }
    // And one non-zonal check of the same pdfs on an ordinary (z, φ) grid.
    let i = integrate_sphere(400, 200, |d| cosine_power_hemisphere_pdf(d, 10.0));
    assert!((i - 1.0).abs() < 1e-3, "cosine power 10 on grid: {i}");
}

#[test]
fn planar_pdfs_integrate_to_one() {
    let m = 2000;
    let mut disk = 0.0f64;
    for i in 0..m {
        for j in 0..m {
            let p = Vec2::new(
                -1.0 + 2.0 * (i as f32 + 0.5) / m as f32,
                -1.0 + 2.0 * (j as f32 + 0.5) / m as f32,
            );
            disk += concentric_disk_pdf(p) as f64;
        }
    }
    disk *= 4.0 / (m * m) as f64;
    assert!((disk - 1.0).abs() < 1e-3, "disk: {disk}");
    for r in [0.5f32, 1.0, 2.0] {
        let m = 100_000;
        let s: f64 = (0..m)
            .map(|i| tent_pdf(-r + 2.0 * r * (i as f32 + 0.5) / m as f32, r) as f64)
            .sum::<f64>()
            * 2.0
            * r as f64
            / m as f64;
        assert!((s - 1.0).abs() < 1e-5, "tent {r}: {s}");
    }
}

/// ∫ pdf dω by quasi-Monte Carlo (a 2D Kronecker lattice mapped to the sphere): for
/// indicator-like pdfs it converges much faster than a product midpoint rule.
fn integrate_sphere_qmc(pdf: impl Fn(Vec3) -> f32) -> f64 {
    let n = 4_000_000u64;
    let (a1, a2) = (0.754_877_666_246_692_7f64, 0.569_840_290_998_053_2f64);
    let s: f64 = (0..n)
        .map(|k| {
            let u = Vec2::new(
                ((k as f64 * a1) % 1.0) as f32,
                ((k as f64 * a2) % 1.0) as f32,
            );
            pdf(uniform_sphere(u)) as f64
        })
        .sum();
    4.0 * PI * s / n as f64
}

#[test]
fn solid_angle_sampler_pdfs_integrate_to_one() {
    // ∫ (1/Ω)·[d hits the shape] dω = 1 checks Ω against an independent quadrature.
    let tri = SphericalTriangle::new(
        Vec3::new(0.2, 0.1, -0.3),
        Vec3::new(-1.0, 0.2, 1.0),
        Vec3::new(1.5, -0.4, 0.3),
        Vec3::new(0.1, 0.1, 2.0),
    )
    .unwrap();
    let i = integrate_sphere_qmc(|d| tri.pdf(d));
    assert!((i - 1.0).abs() < 5e-4, "spherical triangle: {i}");
    let rect = SphericalRectangle::new(
        Vec3::new(0.3, 0.2, 0.4),
        Vec3::ZERO,
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 0.0),
    )
    .unwrap();
    let i = integrate_sphere_qmc(|d| rect.pdf(d));
    assert!((i - 1.0).abs() < 5e-4, "spherical rectangle: {i}");
}

#[test]
fn solid_angles_match_closed_forms() {
    let octant = SphericalTriangle::new(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z).unwrap();
    assert!((octant.area as f64 - PI / 2.0).abs() < 1e-6);
    let face = SphericalRectangle::new(Vec3::splat(0.5), Vec3::ZERO, Vec3::X, Vec3::Y).unwrap();
    assert!((face.solid_angle as f64 - 2.0 * PI / 3.0).abs() < 1e-6);
    // A rectangle is two triangles, including far away and at grazing angles.
    for (p, size) in [
        (Vec3::new(0.3, 0.7, 1.0), 1.0f32),
        (Vec3::new(0.0, 0.0, 100.0), 0.01),
        (Vec3::new(-3.0, 0.5, 0.01), 1.0),
    ] {
        let (c, ex, ey) = (Vec3::ZERO, Vec3::X * size, Vec3::Y * size * 2.0);
        let r = SphericalRectangle::new(p, c, ex, ey).unwrap().solid_angle as f64;
        let t1 = SphericalTriangle::new(p, c, c + ex, c + ex + ey)
            .unwrap()
            .area as f64;
        let t2 = SphericalTriangle::new(p, c, c + ex + ey, c + ey)
            .unwrap()
            .area as f64;
        assert!((r - t1 - t2).abs() <= 1e-4 * r, "{p}: {r} vs {}", t1 + t2);
    }
}

// ---------------------------------------------------------------- inverses

fn grid_u(m: usize) -> impl Iterator<Item = Vec2> {
    (0..m).flat_map(move |i| {
        (0..m).map(move |j| Vec2::new((i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32))
    })
}

#[track_caller]
fn assert_round_trip(name: &str, u: Vec2, back: Vec2, tol: f32) {
    // φ wraps around: compare on the circle for the second coordinate.
    let dy = (u.y - back.y).abs();
    let dy = dy.min(1.0 - dy);
    assert!(
        (u.x - back.x).abs() <= tol && dy <= tol,
        "{name}: {u} -> {back}"
    );
}

#[test]
fn warp_inverses_round_trip() {
    for u in grid_u(64) {
        assert_round_trip(
            "uniform hemisphere",
            u,
            uniform_hemisphere_inverse(uniform_hemisphere(u)),
            1e-5,
        );
        assert_round_trip(
            "cosine hemisphere",
            u,
            cosine_hemisphere_inverse(cosine_hemisphere(u)),
            1e-5,
        );
        assert_round_trip(
            "uniform sphere",
            u,
            uniform_sphere_inverse(uniform_sphere(u)),
            1e-5,
        );
        assert_round_trip(
            "concentric disk",
            u,
            concentric_disk_inverse(concentric_disk(u)),
            1e-5,
        );
        assert_round_trip(
            "uniform triangle",
            u,
            uniform_triangle_inverse(uniform_triangle(u)),
            1e-5,
        );
        for n in [1.0f32, 10.0, 100.0, 1000.0] {
            let d = cosine_power_hemisphere(u, n);
            assert_round_trip(
                &format!("cosine power {n}"),
                u,
                cosine_power_hemisphere_inverse(d, n),
                1e-4,
            );
        }
        for cos_max in [0.9f32, 0.0, -0.5] {
            let d = uniform_cone(u, cos_max);
            assert_round_trip("cone", u, uniform_cone_inverse(d, cos_max), 1e-4);
        }
        for sin2 in [1e-8f32, 1e-3, 0.5] {
            let d = uniform_cone_sin2(u, sin2);
            assert_round_trip(
                &format!("cone sin² {sin2}"),
                u,
                uniform_cone_sin2_inverse(d, sin2),
                1e-3,
            );
        }
    }
}

#[test]
fn spherical_triangle_inverse_round_trips() {
    let c = Vec3::new(0.3, 0.4, 0.866);
    let cases = [
        (Vec3::ZERO, [Vec3::X, Vec3::Y, Vec3::Z], 1e-4f32),
        (
            Vec3::new(0.1, -0.2, 0.5),
            [
                Vec3::new(-10.0, -10.0, 0.0),
                Vec3::new(10.0, -10.0, 0.0),
                Vec3::new(0.0, 12.0, 0.0),
            ],
            1e-4,
        ),
        (
            Vec3::new(-0.5, -0.3, 0.03),
            [
                Vec3::ZERO,
                Vec3::new(4.0, 0.5, 0.0),
                Vec3::new(0.5, 3.0, 0.0),
            ],
            1e-3,
        ),
        (
            Vec3::ZERO,
            [
                c + Vec3::new(0.002, 0.0, 0.0),
                c + Vec3::new(-0.001, 0.0015, 0.0),
                c + Vec3::new(0.0, -0.001, 0.001),
            ],
            5e-3,
        ),
    ];
    for (p, v, tol) in cases {
        let t = SphericalTriangle::new(p, v[0], v[1], v[2]).unwrap();
        for u in grid_u(40) {
            let d = t.sample(u);
            assert!(t.contains(d), "{p}: sample {d} outside the triangle");
            let back = t.inverse(d);
            assert!((u - back).abs().max_element() <= tol, "{p}: {u} -> {back}");
        }
    }
}

#[test]
fn solid_angle_samples_land_on_the_shape() {
    let t = SphericalTriangle::new(
        Vec3::new(0.3, 0.1, -0.2),
        Vec3::new(-1.0, 0.2, 1.0),
        Vec3::new(1.5, -0.4, 0.3),
        Vec3::new(0.1, 0.1, 2.0),
    )
    .unwrap();
    let r = SphericalRectangle::new(
        Vec3::new(-0.3, 0.5, 0.02),
        Vec3::ZERO,
        Vec3::new(3.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    )
    .unwrap();
    for u in grid_u(50) {
        let d = t.sample(u);
        assert!((d.length() - 1.0).abs() < 1e-5);
        let p = r.sample(u);
        assert!(
            p.z.abs() < 1e-5
                && (-1e-5..=3.00001).contains(&p.x)
                && (-1e-5..=1.00001).contains(&p.y),
            "{p}"
        );
    }
}

// ---------------------------------------------------------------- frames and MIS

#[test]
fn frame_is_orthonormal_for_all_normals() {
    let mut normals = vec![
        Vec3::Z,
        -Vec3::Z,
        Vec3::X,
        -Vec3::Y,
        Vec3::new(0.0, 1e-7, -1.0).normalize(),
        Vec3::new(1e-4, -1e-4, -1.0).normalize(),
    ];
    for u in grid_u(30) {
        normals.push(uniform_sphere(u));
    }
    for n in normals {
        let f = Frame::from_normal(n);
        for (a, b) in [(f.s, f.t), (f.t, f.n), (f.n, f.s)] {
            assert!(a.dot(b).abs() < 1e-5, "{n}: not orthogonal");
        }
        for v in [f.s, f.t, f.n] {
            assert!((v.length() - 1.0).abs() < 1e-5, "{n}: not unit");
        }
        assert!((f.s.cross(f.t) - f.n).length() < 1e-5, "{n}: left-handed");
        let v = Vec3::new(0.3, -0.5, 0.8);
        assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        assert!((f.to_local(n) - Vec3::Z).length() < 1e-5);
    }
}

#[test]
fn mis_weights_sum_to_one() {
    for (a, b) in [(0.3f32, 2.0f32), (5.0, 0.0), (1e-3, 1e3)] {
        let p = power_heuristic(1.0, a, 1.0, b) + power_heuristic(1.0, b, 1.0, a);
        let q = balance_heuristic(1.0, a, 1.0, b) + balance_heuristic(1.0, b, 1.0, a);
        assert!((p - 1.0).abs() < 1e-6 && (q - 1.0).abs() < 1e-6);
    }
    assert_eq!(power_heuristic(1.0, 0.0, 1.0, 0.0), 0.0);
}

// ---------------------------------------------------------------- sample patterns

const COUNTS: [u32; 13] = [1, 2, 3, 4, 5, 7, 8, 12, 16, 17, 24, 64, 100];

#[test]
fn pattern_names_round_trip() {
    for k in PatternKind::ALL {
        assert_eq!(k.to_string().parse::<PatternKind>().unwrap(), k);
        assert_eq!(make_pattern(k, 1).kind(), k);
    }
    assert_eq!("LHS".parse::<PatternKind>().unwrap(), PatternKind::Lhs);
    let err = "halton".parse::<PatternKind>().unwrap_err().to_string();
    assert!(err.contains("halton") && err.contains("sobol"), "{err}");
}

#[test]
fn grid_dims_are_near_square() {
    assert_eq!(pattern::grid_dims(0), (1, 1));
    assert_eq!(pattern::grid_dims(16), (4, 4));
    assert_eq!(pattern::grid_dims(12), (3, 4));
    assert_eq!(pattern::grid_dims(24), (4, 6));
    assert_eq!(pattern::grid_dims(17), (1, 17));
    for c in 1..2000u32 {
        let (nx, ny) = pattern::grid_dims(c);
        assert_eq!(nx * ny, c);
        assert!(nx <= ny);
    }
}

#[test]
fn fixed_pattern_is_the_centre() {
    let p = make_pattern(PatternKind::Fixed, 3);
    for i in 0..10 {
        assert_eq!(p.sample_2d(UVec2::new(i, 2), i, i, 10), Vec2::splat(0.5));
        assert_eq!(p.sample_1d(UVec2::new(i, 2), i, i, 10), 0.5);
    }
}

#[test]
fn stratified_patterns_put_one_sample_per_stratum() {
    for kind in [PatternKind::Grid, PatternKind::Stratified, PatternKind::Lhs] {
        let pat = make_pattern(kind, 42);
        for count in COUNTS {
            for (pixel, dim) in [
                (UVec2::new(0, 0), 0u32),
                (UVec2::new(17, 3), 5),
                (UVec2::new(999, 512), 1),
            ] {
                let pts: Vec<Vec2> = (0..count)
                    .map(|i| pat.sample_2d(pixel, dim, i, count))
                    .collect();
                let (nx, ny) = if kind == PatternKind::Lhs {
                    (count, count)
                } else {
                    pattern::grid_dims(count)
                };
                let mut seen = vec![false; (nx * ny) as usize];
                let (mut xs, mut ys) = (vec![0u32; count as usize], vec![0u32; count as usize]);
                for p in &pts {
                    assert!(
                        (0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y),
                        "{kind}: {p}"
                    );
                    let (sx, sy) = ((p.x * nx as f32) as u32, (p.y * ny as f32) as u32);
                    if kind == PatternKind::Lhs {
                        xs[sx as usize] += 1;
                        ys[sy as usize] += 1;
                    } else {
                        let s = (sy * nx + sx) as usize;
                        assert!(!seen[s], "{kind} count {count}: stratum {s} twice");
                        seen[s] = true;
                    }
                }
                if kind == PatternKind::Lhs {
                    assert!(
                        xs.iter().chain(&ys).all(|&c| c == 1),
                        "{kind} count {count}: not N-rooks"
                    );
                }
                if kind == PatternKind::Grid {
                    for p in &pts {
                        let c = Vec2::new(
                            ((p.x * nx as f32).floor() + 0.5) / nx as f32,
                            ((p.y * ny as f32).floor() + 0.5) / ny as f32,
                        );
                        assert!(
                            (*p - c).length() < 1e-6,
                            "grid point {p} is not a stratum centre"
                        );
                    }
                }
                // 1D: one sample per 1/count stratum.
                let mut seen1 = vec![false; count as usize];
                for i in 0..count {
                    let x = pat.sample_1d(pixel, dim, i, count);
                    let s = (x * count as f32) as usize;
                    assert!(!seen1[s], "{kind} 1D count {count}: stratum {s} twice");
                    seen1[s] = true;
                }
            }
        }
    }
}

#[test]
fn patterns_are_deterministic_and_seeded() {
    for kind in PatternKind::ALL {
        let (a, b, c) = (
            make_pattern(kind, 9),
            make_pattern(kind, 9),
            make_pattern(kind, 10),
        );
        let mut differs = false;
        for i in 0..32 {
            let px = UVec2::new(i * 7, 3);
            assert_eq!(
                a.sample_2d(px, 2, i, 32).to_array().map(f32::to_bits),
                b.sample_2d(px, 2, i, 32).to_array().map(f32::to_bits)
            );
            assert_eq!(
                a.sample_1d(px, 2, i, 32).to_bits(),
                b.sample_1d(px, 2, i, 32).to_bits()
            );
            differs |= a.sample_2d(px, 2, i, 32) != c.sample_2d(px, 2, i, 32);
        }
        assert_eq!(
            differs,
            kind != PatternKind::Fixed,
            "{kind}: seed has no effect"
        );
    }
    // Evaluation order / threads cannot matter: values are pure functions.
    use rayon::prelude::*;
    let p = make_pattern(PatternKind::Sobol, 5);
    let serial: Vec<Vec2> = (0..4096u32)
        .map(|i| p.sample_2d(UVec2::new(i % 64, i / 64), 1, i % 16, 16))
        .collect();
    let parallel: Vec<Vec2> = (0..4096u32)
        .into_par_iter()
        .map(|i| p.sample_2d(UVec2::new(i % 64, i / 64), 1, i % 16, 16))
        .collect();
    assert_eq!(serial, parallel);
    // Sobol past sobol_burley's 2^16 points and past its 256 dimensions must not panic.
    let v = p.sample_2d(UVec2::ZERO, 1000, 70_000, 100_000);
    assert!((0.0..1.0).contains(&v.x) && (0.0..1.0).contains(&v.y));
}

#[test]
fn pattern_dimensions_are_decorrelated() {
    // The same index in two dimensions must not give correlated values (Pearson r ≈ 0 over
    // many pixels), or e.g. the light sample would track the pixel position.
    for kind in [
        PatternKind::Random,
        PatternKind::Grid,
        PatternKind::Stratified,
        PatternKind::Lhs,
        PatternKind::Sobol,
    ] {
        let pat = make_pattern(kind, 1);
        let count = 16;
        let (mut sx, mut sy, mut sxx, mut syy, mut sxy, mut n) = (0.0f64, 0.0, 0.0, 0.0, 0.0, 0.0);
        for px in 0..2000u32 {
            for i in 0..count {
                let a = pat.sample_2d(UVec2::new(px, 0), 0, i, count).x as f64;
                let b = pat.sample_2d(UVec2::new(px, 0), 1, i, count).x as f64;
                sx += a;
                sy += b;
                sxx += a * a;
                syy += b * b;
                sxy += a * b;
                n += 1.0;
            }
        }
        let cov = sxy / n - sx / n * sy / n;
        let r = cov / ((sxx / n - (sx / n).powi(2)) * (syy / n - (sy / n).powi(2))).sqrt();
        // 32000 pairs: the standard error of r is ≈ 0.0056.
        assert!(r.abs() < 0.03, "{kind}: dims 0 and 1 correlated, r = {r}");
    }
}

/// Exact L∞ star discrepancy of a 2D point set (O(n³), fine for a few hundred points).
fn star_discrepancy(pts: &[Vec2]) -> f64 {
    let n = pts.len() as f64;
    let mut xs: Vec<f64> = pts.iter().map(|p| p.x as f64).chain([1.0]).collect();
    let mut ys: Vec<f64> = pts.iter().map(|p| p.y as f64).chain([1.0]).collect();
    xs.sort_by(f64::total_cmp);
    ys.sort_by(f64::total_cmp);
    let mut d = 0.0f64;
    for &a in &xs {
        for &b in &ys {
            let (mut open, mut closed) = (0usize, 0usize);
            for p in pts {
                let (x, y) = (p.x as f64, p.y as f64);
                open += (x < a && y < b) as usize;
                closed += (x <= a && y <= b) as usize;
            }
            d = d
                .max(a * b - open as f64 / n)
                .max(closed as f64 / n - a * b);
        }
    }
    d
}

#[test]
fn sobol_has_lower_star_discrepancy_than_random() {
    let (sobol, random) = (
        make_pattern(PatternKind::Sobol, 3),
        make_pattern(PatternKind::Random, 3),
    );
    let (mut ds, mut dr) = (Vec::new(), Vec::new());
    for px in 0..8u32 {
        let pixel = UVec2::new(px, 1);
        let s: Vec<Vec2> = (0..256)
            .map(|i| sobol.sample_2d(pixel, 2, i, 256))
            .collect();
        let r: Vec<Vec2> = (0..256)
            .map(|i| random.sample_2d(pixel, 2, i, 256))
            .collect();
        ds.push(star_discrepancy(&s));
        dr.push(star_discrepancy(&r));
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    eprintln!("star discrepancy, 256 points: sobol {ds:.4?}, random {dr:.4?}");
    let worst_sobol = ds.iter().cloned().fold(0.0, f64::max);
    let best_random = dr.iter().cloned().fold(1.0, f64::min);
    assert!(worst_sobol < best_random, "sobol {ds:?} vs random {dr:?}");
    assert!(mean(&ds) < 0.5 * mean(&dr));
}
