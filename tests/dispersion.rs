//! Dispersion (issue 18): a dielectric whose index varies with wavelength (`glass-*`, sampled
//! or `.spd` eta) gets one index per RGB channel and terminates to one channel at a refraction
//! (src/bsdf/dispersive.rs). Checked against Snell's law per channel, a tilted slab's lateral
//! shift in closed form, energy (single interface and a white furnace), the rough lobe's pdf
//! (f and pdf per channel, pdf the mean, ∫pdf = the kept fraction) and a prism that spreads a
//! white source into red and blue images at the pixels Snell's law puts them.

mod furnace_support;
mod render_support;

use furnace_support::Rng;
use glam::{UVec2, Vec2, Vec3};
use penumbra::Rgb;
use penumbra::bsdf::{Bsdf, Bxdf, Dielectric, DispersiveDielectric};
use penumbra::integrator::{IntegratorKind, RenderOptions, render};
use penumbra::material::Material;
use render_support::{mean_se_channel, pbrt_scene_in};
use std::path::Path;

/// Roughly glass-F11's spread, exaggerated a little so that channels differ clearly.
const ETA: Rgb = Rgb::new(1.77, 1.79, 1.83);

fn wo_at(deg: f32) -> Vec3 {
    let (t, p) = (deg.to_radians(), 30f32.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

fn smooth(entering: bool) -> DispersiveDielectric {
    DispersiveDielectric {
        eta: ETA,
        alpha: Vec2::ZERO,
        entering,
    }
}

/// The lobe number that picks channel `c` and then `u` ∈ [0, 1) within it.
fn uc_for(c: usize, u: f32) -> f32 {
    (c as f32 + u) / 3.0
}

fn weight(s: &penumbra::bsdf::BsdfSample) -> Rgb {
    s.f * (s.wi.z.abs() / s.pdf)
}

#[test]
fn each_channel_refracts_by_snells_law_with_its_own_index() {
    for entering in [true, false] {
        let b = smooth(entering);
        for deg in [0.0f32, 20.0, 33.0, 50.0, 80.0] {
            let wo = wo_at(deg);
            let r = b.reflectance(wo);
            for c in 0..3 {
                let eta = if entering { ETA[c] } else { 1.0 / ETA[c] };
                // Reflection (u = 0 < R_c): mirror direction, every channel kept, R_k / R̄.
                let s = b.sample(wo, uc_for(c, 0.0), Vec2::ZERO).unwrap();
                assert!(s.delta && s.wi.z > 0.0);
                assert!((s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
                let mean = (r.x + r.y + r.z) / 3.0;
                assert!((weight(&s) - r / mean).abs().max_element() < 1e-5);
                // Refraction (u close to 1 > R_c) unless channel c is totally reflected.
                let s = b.sample(wo, uc_for(c, 0.9999), Vec2::ZERO).unwrap();
                if r[c] == 1.0 {
                    assert!(s.wi.z > 0.0, "TIR in channel {c} must reflect");
                    continue;
                }
                assert!(s.delta && s.wi.z < 0.0);
                let (so, st) = (wo.truncate().length(), s.wi.truncate().length());
                assert!(
                    (so - eta * st).abs() < 1e-5,
                    "channel {c} entering={entering} {deg}°: sin θo {so} vs η sin θt {}",
                    eta * st
                );
                assert!(wo.truncate().dot(s.wi.truncate()) <= 1e-7, "same plane");
                assert!((s.wi.length() - 1.0).abs() < 1e-6);
                // 3× channel c's radiance weight 1/η², nothing in the other channels.
                let w = weight(&s);
                for k in 0..3 {
                    let want = if k == c { 3.0 / (eta * eta) } else { 0.0 };
                    assert!(
                        (w[k] - want).abs() < 1e-5 * want.max(1.0),
                        "{w} channel {c}"
                    );
                }
            }
            // The channels refract apart (blue bends most) unless one is totally reflected.
            if deg > 0.0 && r.max_element() < 1.0 {
                let t = |c| b.sample(wo, uc_for(c, 0.9999), Vec2::ZERO).unwrap().wi;
                let (red, blue) = (t(0), t(2));
                let bent = |w: Vec3| w.truncate().length();
                if entering {
                    assert!(bent(blue) < bent(red) - 1e-4, "{red} {blue}");
                } else {
                    assert!(bent(blue) > bent(red) + 1e-4, "{red} {blue}");
                }
            }
        }
    }
}

#[test]
fn smooth_dispersive_interface_conserves_energy_per_channel() {
    // Flux: reflection carries R_k, refraction T_k (radiance weight × η_k²); the estimate of
    // R_k + T_k = 1 must be 1 per channel, and the reflected fraction the channels' mean R.
    for entering in [true, false] {
        let b = smooth(entering);
        for deg in [0.0f32, 30.0, 60.0, 85.0] {
            let wo = wo_at(deg);
            let n = 300_000;
            let mut rng = Rng(7 + deg as u64);
            let (mut e, mut e2, mut nr) = ([0.0f64; 3], [0.0f64; 3], 0usize);
            for _ in 0..n {
                let s = b.sample(wo, rng.f(), Vec2::ZERO).unwrap();
                let w = weight(&s);
                nr += (s.wi.z > 0.0) as usize;
                for k in 0..3 {
                    let eta = if entering { ETA[k] } else { 1.0 / ETA[k] };
                    let v = (w[k] * if s.wi.z < 0.0 { eta * eta } else { 1.0 }) as f64;
                    e[k] += v;
                    e2[k] += v * v;
                }
            }
            for k in 0..3 {
                let m = e[k] / n as f64;
                let sd = ((e2[k] / n as f64 - m * m).max(0.0) / n as f64).sqrt();
                eprintln!("entering={entering} {deg}° channel {k}: {m:.5} ± {sd:.1e}");
                assert!(
                    (m - 1.0).abs() <= 5.0 * sd + 1e-6,
                    "channel {k}: {m} ± {sd}"
                );
            }
            let r = b.reflectance(wo);
            let mean = ((r.x + r.y + r.z) / 3.0) as f64;
            let fr = nr as f64 / n as f64;
            let sd = (mean * (1.0 - mean) / n as f64).sqrt();
            assert!(
                (fr - mean).abs() <= 5.0 * sd + 1e-9,
                "reflected {fr} vs R̄ {mean}"
            );
        }
    }
}

/// Snell at a plane with unit normal `n` (either orientation), relative index `r` = η_from /
/// η_to, for the travelling direction `d`: the test's own refraction, independent of the BSDF.
fn refract(d: Vec3, n: Vec3, r: f32) -> Option<Vec3> {
    let n = if n.dot(d) > 0.0 { -n } else { n };
    let ci = -n.dot(d);
    let s2 = r * r * (1.0 - ci * ci);
    (s2 < 1.0).then(|| (r * d + (r * ci - (1.0 - s2).sqrt()) * n).normalize())
}

#[test]
fn a_tilted_slab_shifts_each_channel_by_its_own_amount() {
    // Slab between z = 0 and z = −d, the ray arrives from above at θ: the exit ray is parallel
    // to the incoming one, shifted sideways by d sin θ (1 − cos θ / √(η² − sin² θ)).
    let d = 1.0f32;
    for deg in [30.0f32, 60.0] {
        let dir = -wo_at(deg);
        let theta = deg.to_radians();
        let mut shifts = [0.0f32; 3];
        for c in 0..3 {
            // The top face: local frame = world (normal +z), wo points back up the ray.
            let top = smooth(true);
            let s = top.sample(-dir, uc_for(c, 0.9999), Vec2::ZERO).unwrap();
            let w1 = weight(&s);
            let inside = s.wi;
            assert_eq!(
                inside,
                refract(dir, Vec3::Z, 1.0 / ETA[c]).map_or(inside, |_| inside)
            );
            assert!((inside - refract(dir, Vec3::Z, 1.0 / ETA[c]).unwrap()).length() < 1e-5);
            let p = inside * (d / -inside.z);
            // The bottom face seen from inside (the frame flips toward wo: normal +z again).
            // The path now carries channel c only: the integrator hands it channel c's glass,
            // whatever the lobe number picks.
            let mut bottom = Bsdf::DispersiveDielectric(smooth(false));
            bottom.for_throughput(w1);
            assert!(matches!(bottom, Bsdf::Dielectric(g) if g.eta == ETA[c]));
            let s = bottom.sample(-inside, 0.9999, Vec2::ZERO).unwrap();
            let out = s.wi;
            assert!((out - dir).length() < 1e-5, "channel {c}: {out} vs {dir}");
            // Throughput through the slab: 3 (the channel pick) in channel c only.
            let w = w1 * weight(&s);
            assert!((w[c] - 3.0).abs() < 1e-4 && w.element_sum() == w[c], "{w}");
            let shift = (p - p.dot(dir) * dir).length();
            let (st, ct) = theta.sin_cos();
            let want = d * st * (1.0 - ct / (ETA[c] * ETA[c] - st * st).sqrt());
            assert!(
                (shift - want).abs() < 1e-5,
                "channel {c} {deg}°: shift {shift} vs {want}"
            );
            shifts[c] = shift;
        }
        eprintln!("slab {deg}°: shifts R G B {shifts:?}");
        assert!(shifts[2] > shifts[1] && shifts[1] > shifts[0]);
        assert!(shifts[2] - shifts[0] > 5e-3, "{shifts:?}");
    }
    // A single-channel throughput is needed to collapse; white or two-channel ones are not.
    for beta in [Rgb::ONE, Rgb::new(1.0, 0.5, 0.0), Rgb::ZERO] {
        let mut b = Bsdf::DispersiveDielectric(smooth(true));
        b.for_throughput(beta);
        assert!(matches!(b, Bsdf::DispersiveDielectric(_)), "{beta}");
    }
}

fn rough(alpha: Vec2, entering: bool) -> DispersiveDielectric {
    DispersiveDielectric {
        eta: ETA,
        alpha,
        entering,
    }
}

#[test]
fn rough_f_is_per_channel_and_pdf_is_the_channel_mean() {
    let mut rng = Rng(3);
    for entering in [true, false] {
        let b = rough(Vec2::new(0.2, 0.35), entering);
        for deg in [10.0f32, 45.0, 75.0] {
            let wo = wo_at(deg);
            let mut n_samples = 0;
            for _ in 0..2000 {
                let Some(s) = b.sample(wo, rng.f(), Vec2::new(rng.f(), rng.f())) else {
                    continue;
                };
                n_samples += 1;
                assert!(!s.delta);
                let ch: Vec<Dielectric> = (0..3).map(|c| b.channel(c)).collect();
                let f = b.f(wo, s.wi);
                let pdf = b.pdf(wo, s.wi);
                for c in 0..3 {
                    assert_eq!(f[c], ch[c].f(wo, s.wi).x, "channel {c}");
                }
                let mean = (ch[0].pdf(wo, s.wi) + ch[1].pdf(wo, s.wi) + ch[2].pdf(wo, s.wi)) / 3.0;
                assert!((pdf - mean).abs() <= 1e-6 * mean, "{pdf} vs {mean}");
                assert_eq!(
                    (s.f, s.pdf),
                    (f, pdf),
                    "the sample reports f and pdf at its wi"
                );
                assert_eq!(b.f_pdf(wo, s.wi), (f, pdf));
            }
            assert!(n_samples > 1500, "{n_samples}");
        }
    }
}

/// ∫ pdf over the whole sphere by the midpoint rule in (cos θ, φ).
fn sphere_integral(g: impl Fn(Vec3) -> f64) -> f64 {
    let (nz, nphi) = (1200, 1200);
    let mut s = 0.0;
    for i in 0..nz {
        let z = -1.0 + (i as f64 + 0.5) * 2.0 / nz as f64;
        let r = (1.0 - z * z).max(0.0).sqrt();
        for j in 0..nphi {
            let phi = (j as f64 + 0.5) * std::f64::consts::TAU / nphi as f64;
            let w = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
            s += g(w);
        }
    }
    s * (2.0 / nz as f64) * (std::f64::consts::TAU / nphi as f64)
}

#[test]
fn rough_pdf_integrates_to_the_kept_fraction_and_energy_is_at_most_one() {
    for (alpha, entering, deg) in [
        (0.3f32, true, 40.0f32),
        (0.5, false, 20.0),
        (0.5, false, 60.0),
    ] {
        let b = rough(Vec2::splat(alpha), entering);
        let wo = wo_at(deg);
        let q = sphere_integral(|wi| b.pdf(wo, wi) as f64);
        let n = 200_000;
        let mut rng = Rng(11);
        let (mut kept, mut e) = (0usize, [0.0f64; 3]);
        for _ in 0..n {
            if let Some(s) = b.sample(wo, rng.f(), Vec2::new(rng.f(), rng.f())) {
                kept += 1;
                let w = weight(&s);
                for k in 0..3 {
                    let eta = if entering { ETA[k] } else { 1.0 / ETA[k] };
                    e[k] += (w[k] * if s.wi.z < 0.0 { eta * eta } else { 1.0 }) as f64;
                }
            }
        }
        let kept = kept as f64 / n as f64;
        let sd = (kept * (1.0 - kept) / n as f64).sqrt();
        eprintln!(
            "rough α={alpha} entering={entering} {deg}°: ∫pdf {q:.5}, kept {kept:.5}, energy {:?}",
            e.map(|v| v / n as f64)
        );
        assert!(q <= 1.0 + 2e-3, "∫pdf = {q}");
        assert!(
            (q - kept).abs() <= 5.0 * sd + 3e-3,
            "∫pdf {q} vs kept {kept}"
        );
        for (k, v) in e.iter().enumerate() {
            let m = v / n as f64;
            assert!(m <= 1.0 + 0.01 && m > 0.5, "channel {k}: energy {m}");
        }
    }
}

fn render_opts(spp: u32, depth: u32) -> RenderOptions {
    RenderOptions {
        spp,
        seed: 5,
        integrator: IntegratorKind::Path,
        max_depth: depth,
        roulette: false,
        ..RenderOptions::default()
    }
}

#[test]
fn a_dispersive_sphere_in_a_white_furnace_is_white() {
    // Smooth glass is lossless: under a uniform sky of radiance 1 every pixel is 1 in every
    // channel, up to the paths cut at the maximum depth (internal reflections: R ≈ 0.1 each
    // beyond the first, so 40 bounces leave nothing measurable).
    let src = r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 30 ]
Film "rgb" "integer xresolution" [ 24 ] "integer yresolution" [ 24 ]
WorldBegin
LightSource "infinite" "rgb L" [ 1 1 1 ]
Material "dielectric" "spectrum eta" "glass-F11"
Shape "sphere" "float radius" [ 1.2 ]
"#;
    let (scene, warnings) = pbrt_scene_in(src, Path::new("."));
    assert!(
        !warnings.iter().any(|w| w.contains("dispersion")),
        "{warnings:?}"
    );
    assert!(matches!(
        scene.materials[0],
        Material::DispersiveDielectric { .. }
    ));
    let (img, stats) = render(&scene, UVec2::new(24, 24), &render_opts(64, 40)).unwrap();
    assert_eq!(stats.non_finite, 0);
    for c in 0..3 {
        let (mean, se) = mean_se_channel(&img, c);
        eprintln!("furnace channel {c}: {mean:.5} ± {se:.1e}");
        assert!(se > 0.0 && se < 0.02, "σ {se}");
        assert!(
            (mean - 1.0).abs() <= 5.0 * se + 1e-4,
            "channel {c}: {mean} ± {se}"
        );
    }
}

/// Per channel, the intensity-weighted mean column of the pixels brighter than a tenth of the
/// channel's brightest (the source's image; internal-reflection ghosts are far dimmer).
fn centroids(img: &penumbra::image::Image) -> [f64; 3] {
    [0, 1, 2].map(|c| {
        let top = img.pixels.iter().map(|p| p[c]).fold(0.0f32, f32::max);
        let (mut s, mut w) = (0.0f64, 0.0f64);
        for (i, p) in img.pixels.iter().enumerate() {
            if p[c] > 0.1 * top {
                s += p[c] as f64 * ((i % img.width as usize) as f64 + 0.5);
                w += p[c] as f64;
            }
        }
        s / w
    })
}

#[test]
fn a_prism_spreads_a_white_source_into_colours_where_snell_puts_them() {
    // A 30° prism (apex edge along y) seen at normal incidence on its first face: the camera
    // looks through it at a small white emitter far away in the green channel's exit direction.
    // The red and blue images of the emitter land where each channel's index bends the view:
    // traced back from the emitter with the test's own Snell, projected by the camera.
    let half = 15f32.to_radians();
    // Outward normals of the entry and exit faces.
    let (n1, n2) = (
        Vec3::new(half.sin(), 0.0, -half.cos()),
        Vec3::new(half.sin(), 0.0, half.cos()),
    );
    // Apex at x = 1, base at x = −1: faces from the apex at ±(90° − 15°) from +z.
    let len = 2.0 / half.cos();
    let apex = Vec3::new(1.0, 0.0, 0.0);
    let (b1, b2) = (
        apex + len * Vec3::new(-half.cos(), 0.0, -half.sin()),
        apex + len * Vec3::new(-half.cos(), 0.0, half.sin()),
    );
    let p1 = (apex + b1) * 0.5;
    let eye = p1 + 8.0 * n1;
    let view = -n1;
    // Green's exit direction and point for the central ray, then the emitter there.
    let mesh = |y: f32| [apex, b1, b2].map(|p| Vec3::new(p.x, y, p.z));
    let (lo, hi) = (mesh(-2.0), mesh(2.0));
    let verts: Vec<Vec3> = lo.iter().chain(hi.iter()).copied().collect();
    let plane_hit = |o: Vec3, d: Vec3, p: Vec3, n: Vec3| o + d * ((p - o).dot(n) / d.dot(n));
    let through = |d: Vec3, eta: f32| -> (Vec3, Vec3) {
        let x1 = plane_hit(eye, d, p1, n1);
        let t = refract(d, n1, 1.0 / eta).unwrap();
        let x2 = plane_hit(x1, t, apex, n2);
        (x2, refract(t, n2, eta).unwrap())
    };
    let render_prism = |eta_param: &str| {
        let (x2, e) = through(view, 1.7912);
        let dist = 1.0e4f32;
        let c = x2 + dist * e;
        let radius = dist * 0.1f32.to_radians().tan();
        let pts: String = verts
            .iter()
            .map(|v| format!("{} {} {} ", v.x, v.y, v.z))
            .collect();
        // Caps, the two faces, the base; each wound so that its normal points out (glass
        // knows inside from outside by the geometric normal).
        let centre = verts.iter().sum::<Vec3>() / 6.0;
        let tris = [
            [0, 1, 2],
            [3, 4, 5],
            [0, 1, 4],
            [0, 4, 3],
            [0, 2, 5],
            [0, 5, 3],
            [1, 2, 5],
            [1, 5, 4],
        ];
        let indices: String = tris
            .iter()
            .map(|&[a, b, c]| {
                let (p, q, r) = (verts[a], verts[b], verts[c]);
                let out = (q - p).cross(r - p).dot((p + q + r) / 3.0 - centre) > 0.0;
                let [b, c] = if out { [b, c] } else { [c, b] };
                format!("{a} {b} {c}  ")
            })
            .collect();
        let src = format!(
            r#"LookAt {} {} {}  {} {} {}  0 1 0
Camera "perspective" "float fov" [ 2 ]
Film "rgb" "integer xresolution" [ 400 ] "integer yresolution" [ 60 ]
PixelFilter "box"
WorldBegin
AttributeBegin
Material "dielectric" {eta_param}
Shape "trianglemesh" "point3 P" [ {pts} ]
    "integer indices" [ {indices}]
AttributeEnd
AttributeBegin
AreaLightSource "diffuse" "rgb L" [ 1 1 1 ]
Translate {} {} {}
Shape "sphere" "float radius" [ {radius} ]
AttributeEnd
"#,
            eye.x, eye.y, eye.z, p1.x, p1.y, p1.z, c.x, c.y, c.z
        );
        let (scene, _) = pbrt_scene_in(&src, Path::new("."));
        let (img, stats) = render(&scene, UVec2::new(400, 60), &render_opts(24, 8)).unwrap();
        assert_eq!(stats.non_finite, 0);
        (scene, img, c)
    };
    let (scene, img, emitter) = render_prism(r#""spectrum eta" "glass-F11""#);
    let Material::DispersiveDielectric { eta, .. } = scene.materials[0] else {
        panic!("glass-F11 is dispersive: {:?}", scene.materials[0]);
    };
    let res = UVec2::new(400, 60);
    let got = centroids(&img);
    // The column of the view direction whose exit direction meets the emitter for index
    // `eta` (fixed-point steps: the exit point moves a little with the direction).
    let column = |eta: f32| {
        let mut d = view;
        for _ in 0..3 {
            let (x2, _) = through(d, eta);
            let back = refract(-(emitter - x2).normalize(), n2, 1.0 / eta).unwrap();
            d = -refract(back, n1, eta).unwrap();
        }
        scene.camera.project(eye + d, res).unwrap().x as f64
    };
    let want = [0, 1, 2].map(|c| column(eta[c]));
    eprintln!("prism F11 η {eta}: columns R G B {got:?}, Snell {want:?}");
    for c in 0..3 {
        assert!(
            (got[c] - want[c]).abs() < 1.0,
            "channel {c}: column {} vs {}",
            got[c],
            want[c]
        );
    }
    assert!((got[0] - got[2]).abs() > 20.0, "{got:?}");
    // Control: the same prism with a constant index puts every channel at one column.
    let (_, img, _) = render_prism(r#""float eta" [ 1.7912 ]"#);
    let plain = centroids(&img);
    eprintln!("prism constant η: columns {plain:?}");
    let want_plain = column(1.7912);
    assert!(
        (plain[0] - plain[2]).abs() < 0.2 && (plain[1] - want_plain).abs() < 1.0,
        "{plain:?} vs {want_plain}"
    );
}

#[test]
fn only_what_is_still_approximated_warns() {
    // A dielectric disperses (no warning); a coat keeps the index at 550 nm and says so, once.
    let scene = |material: &str| {
        let src = format!(
            r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [ 30 ]
Film "rgb" "integer xresolution" [ 4 ] "integer yresolution" [ 4 ]
WorldBegin
{material}
Shape "sphere" "float radius" [ 1 ]
{material}
Shape "sphere" "float radius" [ 0.5 ]
"#
        );
        pbrt_scene_in(&src, Path::new("."))
    };
    let (s, w) = scene(r#"Material "dielectric" "spectrum eta" [ 400 1.6 500 1.55 700 1.5 ]"#);
    assert!(!w.iter().any(|w| w.contains("dispersion")), "{w:?}");
    let Material::DispersiveDielectric { eta, .. } = s.materials[0] else {
        panic!("{:?}", s.materials[0]);
    };
    assert!(eta.z > eta.y && eta.y > eta.x && eta.x > 1.5, "{eta}");
    // A constant spectrum is no dispersion: the plain dielectric, as before.
    let (s, _) = scene(r#"Material "dielectric" "spectrum eta" [ 300 1.5 900 1.5 ]"#);
    assert!(matches!(s.materials[0], Material::Dielectric { eta, .. } if eta == 1.5));
    let (_, w) = scene(r#"Material "coateddiffuse" "spectrum eta" "glass-BK7""#);
    let n = w
        .iter()
        .filter(|w| w.contains("dispersion approximated"))
        .count();
    assert_eq!(n, 1, "{w:?}");
    assert!(
        w.iter().all(|w| w.matches("warning:").count() <= 1),
        "{w:?}"
    );
}
