//! Every sampling routine at the boundary of its input square [0, 1)²: at u = 0, u = 1 − 2⁻²⁴
//! (the largest value the samplers are given), the corners and along the edges, a sample must
//! be finite, have a finite pdf > 0 and agree with the routine's own pdf — or be rejected
//! (`None`) where the routine's contract says so (a BSDF lobe below the horizon, a light facing
//! away). A sample with pdf 0 breaks every estimator that divides by it and the chi-square test
//! of the warp (issue 16: the cosine-power lobe put u = 0 exactly on the horizon).
//!
//! Covered: every routine of `penumbra warp --list` with its defaults and extreme parameters,
//! the warps of `penumbra::sampling` that are not listed (cone by sin², triangle barycentrics,
//! tent, 1D/2D distributions with empty bins at the ends, alias tables), every BSDF sampler
//! (each lobe-sampling mode, normal to grazing incidence) and every light's `sample_li` (both
//! sampling modes, receivers far, near and grazing).

use glam::{Mat4, Vec2, Vec3};
use penumbra::Rgb;
use penumbra::bsdf::{
    Bsdf, Bxdf, CoatedDiffuse, Conductor, Dielectric, Lambert, LobeSampling, Mirror, Phong,
};
use penumbra::geometry::Transform;
use penumbra::lab::warp::{Domain, ROUTINES, build};
use penumbra::lights::{
    DiskLight, DistantLight, Emitter, EnvMapLight, Light, LightSampleContext, LightSource,
    PointLight, QuadLight, SamplingMode, SphereLight, SpotLight, TriangleLight,
    UniformInfiniteLight,
};
use penumbra::material::texture::ImageRgb;
use penumbra::sampling::*;
use std::sync::Arc;

/// The largest input the samplers see: 1 − 2⁻²⁴ (the top of the 24-bit grid of the patterns).
const TOP: f32 = ONE_MINUS_EPSILON;

/// Values along an edge of [0, 1): both ends, their neighbours on the 24-bit grid, and inside.
const EDGE: [f32; 9] = [
    0.0,
    1.0 / 16_777_216.0,
    0.125,
    0.25,
    0.5,
    0.75,
    0.875,
    1.0 - 2.0 / 16_777_216.0,
    TOP,
];

/// The points of the boundary of [0, 1)² tested: the corners and every edge value on each edge.
fn boundary() -> Vec<Vec2> {
    let mut v = Vec::new();
    for &t in &EDGE {
        v.extend([
            Vec2::new(0.0, t),
            Vec2::new(TOP, t),
            Vec2::new(t, 0.0),
            Vec2::new(t, TOP),
        ]);
    }
    v.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    v.dedup();
    v
}

/// Lobe-selection numbers tested with each 2D point.
const UC: [f32; 4] = [0.0, 0.3, 0.7, TOP];

/// Collects failures so one run reports every broken routine, not just the first.
#[derive(Default)]
struct Failures(Vec<String>);

impl Failures {
    fn check(&mut self, ok: bool, msg: impl FnOnce() -> String) {
        if !ok && self.0.len() < 400 {
            let m = msg();
            if !self.0.contains(&m) {
                self.0.push(m);
            }
        }
    }

    #[track_caller]
    fn assert_none(self, what: &str) {
        assert!(
            self.0.is_empty(),
            "{what}: {} boundary failures:\n{}",
            self.0.len(),
            self.0.join("\n")
        );
    }
}

/// `a` and `b` agree to a relative `tol`.
fn close(a: f32, b: f32, tol: f32) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs())
}

// ---------------------------------------------------------------- `penumbra warp --list`

/// Parameter sets tested per routine: the defaults plus the extremes of each parameter.
fn param_sets(name: &str) -> Vec<Vec<&'static str>> {
    let mut sets = vec![vec![]];
    let extra: &[&[&'static str]] = match name {
        "cosine-power" => &[&["n=0"], &["n=1"], &["n=100"], &["n=10000"], &["n=1e6"]],
        "cone" => &[
            &["angle=180"],
            &["angle=90"],
            &["angle=0.5"],
            &["angle=0.1"],
        ],
        "lambert" => &[&["sampling=uniform"], &["theta=0"], &["theta=89.9"]],
        "phong" => &[
            &["n=0"],
            &["n=10000"],
            &["sampling=cosine"],
            &["sampling=uniform"],
            &["theta=89.9"],
            &["kd=0", "ks=1"],
        ],
        "ggx" => &[
            &["alpha=1"],
            &["alpha=0.01"],
            &["alpha-x=0.05", "alpha-y=0.8"],
            &["theta=0"],
            &["theta=89.9"],
            &["sampling=cosine"],
            &["sampling=uniform"],
        ],
        "coated-diffuse" => &[
            &["alpha=0"],
            &["alpha=1"],
            &["theta=89.9"],
            &["sampling=uniform"],
        ],
        _ => &[],
    };
    sets.extend(extra.iter().map(|s| s.to_vec()));
    sets
}

#[test]
fn every_listed_routine_is_finite_with_positive_pdf_on_the_boundary() {
    let mut f = Failures::default();
    let pts = boundary();
    let mut tested = 0;
    for r in ROUTINES {
        for set in param_sets(r.name) {
            let args: Vec<String> = set.iter().map(|s| s.to_string()).collect();
            let w = build(r.name, &args).unwrap_or_else(|e| panic!("{} {args:?}: {e}", r.name));
            // Only BSDFs read the lobe-selection number.
            let ucs: &[f32] = if r.params.iter().any(|p| p.key == "theta") {
                &UC
            } else {
                &[0.0]
            };
            for &u in &pts {
                for &uc in ucs {
                    let Some(x) = w.sample(uc, u) else {
                        continue;
                    };
                    tested += 1;
                    let pdf = w.pdf(x);
                    let on_domain = match w.domain {
                        Domain::Sphere => (x.length() - 1.0).abs() < 1e-4,
                        Domain::Plane { .. } => x.z == 0.0,
                    };
                    f.check(x.is_finite() && on_domain, || {
                        format!("{} uc={uc} u={u}: sample {x} not on the domain", w.label)
                    });
                    f.check(pdf.is_finite() && pdf > 0.0, || {
                        format!("{} uc={uc} u={u}: sample {x} has pdf {pdf}", w.label)
                    });
                }
            }
        }
    }
    eprintln!("{tested} boundary samples of the listed routines");
    f.assert_none("penumbra warp routines");
}

// ---------------------------------------------------------------- unlisted warps

#[test]
fn unlisted_warps_and_distributions_are_finite_with_positive_pdf_on_the_boundary() {
    let mut f = Failures::default();
    for &u in &boundary() {
        for sin2 in [1e-12f32, 1e-6, 0.01, 0.5, 1.0] {
            let d = uniform_cone_sin2(u, sin2);
            let pdf = uniform_cone_sin2_pdf(d, sin2);
            f.check(d.is_finite() && pdf.is_finite() && pdf > 0.0, || {
                format!("cone sin²={sin2} u={u}: {d} pdf {pdf}")
            });
        }
        let b = uniform_triangle(u);
        f.check(
            b.is_finite() && b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0,
            || format!("triangle barycentrics u={u}: {b}"),
        );
        for r in [0.5f32, 1.0, 2.0] {
            let x = tent(u.x, r);
            let pdf = tent_pdf(x, r);
            f.check(x.is_finite() && pdf.is_finite() && pdf > 0.0, || {
                format!("tent r={r} u={}: x={x} pdf {pdf}", u.x)
            });
        }
    }
    // Distributions with empty bins at both ends and in the middle (so u = 0 and u → 1 sit on
    // the edges of zero-width cdf intervals), and a single bin.
    let weights: [&[f32]; 4] = [
        &[0.0, 0.0, 1.0, 3.0, 0.0, 2.0, 0.0, 0.0],
        &[5.0],
        &[1e-30, 1.0, 1e-30],
        &[0.0, 1.0],
    ];
    for w in weights {
        let d1 = Distribution1D::new(w);
        let alias = AliasTable::new(w).unwrap();
        for &v in &EDGE {
            let (x, pdf, i) = d1.sample_continuous(v);
            f.check(
                x.is_finite() && pdf.is_finite() && pdf > 0.0 && close(d1.pdf(x), pdf, 1e-6),
                || {
                    format!(
                        "distribution1d {w:?} u={v}: x={x} bin {i} pdf {pdf} vs {}",
                        d1.pdf(x)
                    )
                },
            );
            let (i, pmf, _) = d1.sample_discrete(v);
            f.check(
                pmf > 0.0 && w[i] > 0.0 && close(d1.pmf(i), pmf, 1e-6),
                || format!("distribution1d {w:?} discrete u={v}: bin {i} pmf {pmf}"),
            );
            let (i, pmf) = alias.sample(v);
            f.check(
                pmf > 0.0 && w[i] > 0.0 && close(alias.pmf(i), pmf, 1e-6),
                || format!("alias {w:?} u={v}: outcome {i} pmf {pmf}"),
            );
        }
    }
    let (nu, nv) = (6, 5);
    let mut img = vec![1.0f32; nu * nv];
    for j in 0..nv {
        // Empty first and last columns and an empty first row.
        img[j * nu] = 0.0;
        img[j * nu + nu - 1] = 0.0;
    }
    for v in img.iter_mut().take(nu) {
        *v = 0.0;
    }
    let d2 = Distribution2D::new(&img, nu, nv);
    for &u in &boundary() {
        let (p, pdf) = d2.sample(u);
        f.check(
            p.is_finite() && pdf.is_finite() && pdf > 0.0 && close(d2.pdf(p), pdf, 1e-5),
            || format!("distribution2d u={u}: {p} pdf {pdf} vs {}", d2.pdf(p)),
        );
    }
    f.assert_none("unlisted warps");
}

#[test]
fn spherical_polygons_are_finite_with_positive_pdf_on_the_boundary() {
    let mut f = Failures::default();
    // Large, small, thin and nearly-grazing triangles.
    let tris = [
        [Vec3::X, Vec3::Y, Vec3::Z],
        [
            Vec3::new(0.8, -0.3, 0.5),
            Vec3::new(-0.2, 0.9, 0.4),
            Vec3::new(-0.5, -0.6, 0.7),
        ],
        [
            Vec3::new(10.0, 0.0, 30.0),
            Vec3::new(10.2, 0.0, 30.0),
            Vec3::new(10.0, 0.1, 30.0),
        ],
        [
            Vec3::new(-1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 0.001, 1.0),
        ],
        [
            Vec3::new(-1.0, 1.0, 0.01),
            Vec3::new(1.0, 1.0, 0.01),
            Vec3::new(0.0, 3.0, 0.2),
        ],
    ];
    for v in tris {
        let t = SphericalTriangle::new(Vec3::ZERO, v[0], v[1], v[2]).unwrap();
        for &u in &boundary() {
            let d = t.sample(u);
            let pdf = t.pdf(d);
            f.check(d.is_finite() && pdf.is_finite() && pdf > 0.0, || {
                format!("spherical triangle {v:?} u={u}: {d} pdf {pdf}")
            });
        }
    }
    let rects = [
        (Vec3::new(0.5, 0.5, 0.5), Vec3::ZERO, Vec3::X, Vec3::Y),
        (
            Vec3::new(0.3, 0.2, 0.0),
            Vec3::new(-0.5, -0.3, 1.0),
            Vec3::new(1.2, 0.0, 0.2),
            Vec3::new(0.0, 0.8, 0.0),
        ),
        (
            Vec3::new(5.0, 0.0, 0.01),
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y * 0.5,
        ),
        (
            Vec3::new(0.0, 0.0, 50.0),
            Vec3::ZERO,
            Vec3::X * 0.1,
            Vec3::Y * 0.1,
        ),
    ];
    for (p, c, ex, ey) in rects {
        let r = SphericalRectangle::new(p, c, ex, ey).unwrap();
        for &u in &boundary() {
            let q = r.sample(u);
            let pdf = r.pdf(q - p);
            f.check(q.is_finite() && pdf.is_finite() && pdf > 0.0, || {
                format!("spherical rectangle from {p} u={u}: {q} pdf {pdf}")
            });
        }
    }
    f.assert_none("spherical polygons");
}

// ---------------------------------------------------------------- BSDFs

/// Outgoing direction at polar angle `deg`, azimuth 30°.
fn wo_at(deg: f32) -> Vec3 {
    let (t, p) = (deg.to_radians(), 30f32.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

fn bsdfs() -> Vec<(String, Bsdf)> {
    let mut v = Vec::new();
    for s in [
        LobeSampling::Importance,
        LobeSampling::Cosine,
        LobeSampling::Uniform,
    ] {
        let mut push = |name: &str, mut b: Bsdf| {
            b.set_sampling(s);
            v.push((format!("{name} {s:?}"), b));
        };
        push("lambert", Bsdf::Lambert(Lambert::new(Rgb::splat(0.8))));
        for n in [0.0, 1.0, 20.0, 1000.0, 1e5] {
            push(
                &format!("phong n={n}"),
                Bsdf::Phong(Phong::new(Rgb::splat(0.3), Rgb::splat(0.6), n).unwrap()),
            );
        }
        push(
            "phong specular only",
            Bsdf::Phong(Phong::new(Rgb::ZERO, Rgb::ONE, 50.0).unwrap()),
        );
        for a in [
            Vec2::splat(1.0),
            Vec2::splat(0.3),
            Vec2::splat(0.01),
            Vec2::new(0.05, 0.8),
        ] {
            push(
                &format!("conductor α={a}"),
                Bsdf::Conductor(Conductor::new(
                    Rgb::new(0.2, 0.9, 1.1),
                    Rgb::new(3.9, 2.4, 2.1),
                    a,
                )),
            );
            push(
                &format!("coated α={a}"),
                Bsdf::CoatedDiffuse(CoatedDiffuse::new(Rgb::splat(0.5), a, 1.5)),
            );
        }
        push(
            "coated smooth",
            Bsdf::CoatedDiffuse(CoatedDiffuse::new(Rgb::splat(0.5), Vec2::ZERO, 1.5)),
        );
    }
    for entering in [true, false] {
        for a in [Vec2::ZERO, Vec2::splat(0.3), Vec2::new(0.05, 0.6)] {
            v.push((
                format!("dielectric α={a} entering={entering}"),
                Bsdf::Dielectric(Dielectric {
                    eta: 1.5,
                    alpha: a,
                    entering,
                }),
            ));
        }
    }
    v.push(("mirror".into(), Bsdf::Mirror(Mirror { r: Rgb::ONE })));
    v
}

#[test]
fn every_bsdf_sample_on_the_boundary_is_finite_and_matches_its_pdf() {
    let mut f = Failures::default();
    let pts = boundary();
    let mut tested = 0;
    for (name, b) in bsdfs() {
        for deg in [0.0, 30.0, 60.0, 85.0, 89.9] {
            let wo = wo_at(deg);
            for &u in &pts {
                for &uc in &UC {
                    let Some(s) = b.sample(wo, uc, u) else {
                        continue;
                    };
                    tested += 1;
                    let what = || format!("{name} wo {deg}° uc={uc} u={u}");
                    f.check(
                        s.wi.is_finite() && (s.wi.length() - 1.0).abs() < 1e-4 && s.f.is_finite(),
                        || format!("{}: wi {} f {}", what(), s.wi, s.f),
                    );
                    f.check(s.pdf.is_finite() && s.pdf > 0.0, || {
                        format!("{}: wi {} pdf {}", what(), s.wi, s.pdf)
                    });
                    if !s.delta {
                        let p = b.pdf(wo, s.wi);
                        f.check(close(p, s.pdf, 1e-3), || {
                            format!(
                                "{}: wi {} sampled pdf {} but pdf() {p}",
                                what(),
                                s.wi,
                                s.pdf
                            )
                        });
                    }
                }
            }
        }
    }
    eprintln!("{tested} boundary BSDF samples");
    f.assert_none("BSDF samplers");
}

// ---------------------------------------------------------------- lights

/// A 16×8 map with black columns at both edges and a bright spot.
fn env_image() -> ImageRgb {
    let (w, h) = (16u32, 8u32);
    let mut pixels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let mut c = Vec3::new(0.2 + 0.05 * x as f32, 0.3, 0.1 + 0.1 * y as f32);
            if x == 0 || x == w - 1 || y == 0 {
                c = Vec3::ZERO;
            }
            if (5..7).contains(&x) && y == 2 {
                c *= 40.0;
            }
            pixels.push(c);
        }
    }
    ImageRgb {
        width: w,
        height: h,
        pixels,
    }
}

fn lights() -> Vec<(&'static str, Light)> {
    let tri = [
        Vec3::new(-0.5, -0.3, 0.0),
        Vec3::new(0.6, -0.2, 0.0),
        Vec3::new(0.1, 0.7, 0.0),
    ];
    let env = EnvMapLight::new(
        Arc::new(env_image()),
        Vec3::ONE,
        Transform::new(Mat4::from_rotation_z(0.7) * Mat4::from_rotation_x(0.5)).unwrap(),
    )
    .unwrap();
    vec![
        (
            "triangle",
            Light::Triangle(TriangleLight::new(tri, Vec3::Z, Vec3::ONE, false).unwrap()),
        ),
        (
            "triangle two-sided",
            Light::Triangle(TriangleLight::new(tri, Vec3::Z, Vec3::ONE, true).unwrap()),
        ),
        (
            "quad",
            Light::Quad(
                QuadLight::new(
                    Vec3::new(-0.5, -0.5, 0.0),
                    Vec3::X,
                    Vec3::new(0.0, 0.7, 0.0),
                    Vec3::Z,
                    Vec3::ONE,
                    false,
                )
                .unwrap(),
            ),
        ),
        (
            "parallelogram",
            Light::Quad(
                QuadLight::new(
                    Vec3::new(-0.5, -0.5, 0.0),
                    Vec3::X,
                    Vec3::new(0.4, 0.7, 0.0),
                    Vec3::Z,
                    Vec3::ONE,
                    true,
                )
                .unwrap(),
            ),
        ),
        (
            "sphere",
            Light::Sphere(
                SphereLight::new(Vec3::new(0.0, 0.0, 0.5), 0.3, Vec3::ONE, false).unwrap(),
            ),
        ),
        (
            "disk",
            Light::Disk(DiskLight::new(Vec3::ZERO, Vec3::Z, 0.6, Vec3::ONE, false).unwrap()),
        ),
        (
            "point",
            Light::Point(PointLight::new(Vec3::new(0.1, 0.2, 0.3), Vec3::ONE)),
        ),
        (
            "spot",
            Light::Spot(SpotLight::new(
                Vec3::new(0.0, 0.0, 2.0),
                -Vec3::Z,
                Vec3::ONE,
                0.9,
                0.5,
            )),
        ),
        (
            "distant",
            Light::Distant(DistantLight::new(Vec3::new(0.3, 0.2, 1.0), Vec3::ONE)),
        ),
        (
            "uniform infinite",
            Light::UniformInfinite(UniformInfiniteLight::new(Vec3::ONE)),
        ),
        ("envmap", Light::EnvMap(Box::new(env))),
    ]
}

/// The quantity a light's solid-angle pdf divides by at sample `s`: the cosine at the sampled
/// point for area sampling (planar lights here all face ±z), sin θ of the environment map's
/// chart; 1 where the pdf is constant.
fn conditioning(light: &Light, s: &penumbra::lights::LightLiSample, mode: SamplingMode) -> f32 {
    match light {
        Light::EnvMap(e) => e.direction_to_uv(s.wi).1,
        Light::Sphere(_) if mode == SamplingMode::Area => {
            let n = (s.p_light - Vec3::new(0.0, 0.0, 0.5)).normalize();
            n.dot(s.wi).abs()
        }
        Light::Triangle(_) | Light::Quad(_) | Light::Disk(_) => s.wi.z.abs(),
        _ => 1.0,
    }
}

#[test]
fn every_light_sample_on_the_boundary_is_finite_and_matches_its_pdf() {
    let mut f = Failures::default();
    let pts = boundary();
    // Far above, near above, grazing, below (back side), inside the sphere light, far away.
    let receivers = [
        Vec3::new(0.2, 0.1, 3.0),
        Vec3::new(0.1, 0.0, 0.05),
        Vec3::new(2.0, 0.5, 0.05),
        Vec3::new(0.3, -0.2, -0.4),
        Vec3::new(0.05, 0.0, 0.45),
        Vec3::new(3.0, 2.0, 60.0),
    ];
    let mut tested = 0;
    for (name, light) in lights() {
        for p in receivers {
            for n in [Vec3::ZERO, Vec3::Z] {
                let ctx = LightSampleContext { p, n };
                for mode in [SamplingMode::Area, SamplingMode::SolidAngle] {
                    for &u in &pts {
                        let Some(s) = light.sample_li(&ctx, u, mode) else {
                            continue;
                        };
                        tested += 1;
                        let what = || format!("{name} from {p} {mode:?} u={u}");
                        f.check(
                            s.wi.is_finite()
                                && (s.wi.length() - 1.0).abs() < 1e-4
                                && s.li.is_finite()
                                && s.p_light.is_finite(),
                            || format!("{}: wi {} li {} p {}", what(), s.wi, s.li, s.p_light),
                        );
                        f.check(s.pdf.is_finite() && s.pdf > 0.0, || {
                            format!("{}: wi {} pdf {}", what(), s.wi, s.pdf)
                        });
                        if !s.delta {
                            let q = light.pdf_li(&ctx, s.wi, s.p_light, Vec3::ZERO, mode);
                            // pdfs ∝ 1/c (c = |cos θ| at an area-sampled point, sin θ of the
                            // map) turn the ~1e-7 rounding of an f32 direction into a relative
                            // error ~1e-7/c: allowed, as long as the pdf stays finite and > 0.
                            let tol = 1e-2 + 1e-5 / conditioning(&light, &s, mode);
                            f.check(close(q, s.pdf, tol), || {
                                format!(
                                    "{}: wi {} sampled pdf {} but pdf_li {q}",
                                    what(),
                                    s.wi,
                                    s.pdf
                                )
                            });
                        }
                    }
                }
            }
        }
    }
    eprintln!("{tested} boundary light samples");
    f.assert_none("light samplers");
}

/// The endpoint fix is a clamp and nothing more: ξ₁ = 0 samples what ξ₁ = 2⁻²⁴ samples (the
/// next point of the 24-bit grid, inside the same stratum), and every other input maps exactly
/// as the plain formula (cos θ = ξ₁, √ξ₁, ξ₁^(1/(n+1)); the tent's inverse cdf), so images
/// drawn from ξ ≥ 2⁻²⁴ stay bit-identical to the unclamped maps.
#[test]
fn the_warps_only_clamp_their_zero_endpoint() {
    let grid = 1.0 / 16_777_216.0;
    assert_eq!(open_unit(0.0), grid);
    assert_eq!(open_unit(grid * 0.25), grid);
    for &x in &[grid, 2.0 * grid, 0.125, 0.5, TOP] {
        assert_eq!(open_unit(x), x);
    }
    for &v in &EDGE {
        let (zero, first) = (Vec2::new(0.0, v), Vec2::new(grid, v));
        assert_eq!(uniform_hemisphere(zero), uniform_hemisphere(first), "v {v}");
        assert_eq!(cosine_hemisphere(zero), cosine_hemisphere(first), "v {v}");
        for n in [0.0, 1.0, 100.0, 1e4] {
            let (a, b) = (
                cosine_power_hemisphere(zero, n),
                cosine_power_hemisphere(first, n),
            );
            assert_eq!(a, b, "n {n}, v {v}");
        }
        // The plain maps' cos θ for every other input.
        for &x in &EDGE[1..] {
            let u = Vec2::new(x, v);
            assert_eq!(uniform_hemisphere(u).z, x, "u {u}");
            assert_eq!(cosine_hemisphere(u).z, x.sqrt(), "u {u}");
        }
    }
    for r in [0.5, 1.0, 2.0] {
        assert_eq!(tent(0.0, r), tent(grid / 2.0, r), "r {r}");
        assert!(
            tent(0.0, r) > -r && tent_pdf(tent(0.0, r), r) > 0.0,
            "r {r}"
        );
        for &u in &EDGE[1..] {
            // The plain inverse cdf of each half.
            let plain = if u < 0.5 {
                -(r * (1.0 - (2.0 * u).sqrt()))
            } else {
                r * (1.0 - (1.0 - (2.0 * u - 1.0)).sqrt())
            };
            assert_eq!(tent(u, r), plain, "u {u}, r {r}");
        }
    }
}
