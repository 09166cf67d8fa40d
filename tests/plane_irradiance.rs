//! Rays spawned at a surface must not hit that surface: Lambertian planes (two-triangle quads,
//! a subdivided grid, a trianglemesh read from pbrt text, disks) and spheres of every size
//! (1e-3 to 1e4 units), near the origin and far from it, axis-aligned and at random
//! orientations, lit by distant, point, spot, quad, triangle, sphere and uniform-sky lights
//! from grazing (2°) to normal incidence, must reflect L = ρ/π · E with E analytic, for every
//! estimator, through the 16-lane packet queries, the 4-wide one-ray test (packets of few
//! rays) and the one-ray triangle test (the BVH2 backend).
//!
//! A self-hit darkens a sample to zero, so the check is strict where the estimator is
//! deterministic (delta lights under light sampling: every sample must equal ρ/π·E up to f32
//! rounding) and 5 standard errors of the measured per-sample variance elsewhere. Every case
//! draws its own geometry and sample seeds; failures are collected and printed together.

use glam::{DVec3, Mat4, UVec2, Vec3};
use penumbra::Rgb;
use penumbra::bsdf::LobeSampling;
use penumbra::camera::Camera;
use penumbra::geometry::interaction::NO_LIGHT;
use penumbra::geometry::{Backend, PACKET, PrimKind, Ray, RayQuery, SurfaceHit, Transform};
use penumbra::integrator::queues::CameraPacket;
use penumbra::integrator::stages::{Integrator, Queues};
use penumbra::integrator::{MisHeuristic, Strategy};
use penumbra::light_selection::{SelectorKind, make_selector};
use penumbra::lights::{
    DistantLight, Light, PointLight, SamplingMode, SpotLight, UniformInfiniteLight,
};
use penumbra::material::{Material, Texture};
use penumbra::sampling::hash::{next_f32, pcg_from_keys};
use penumbra::sampling::{PatternKind, PixelSamples, make_pattern};
use penumbra::scene::pbrt::parse_pbrt_str;
use penumbra::scene::{AreaEmission, FilmSpec, Filter, Scene, SceneBuilder, TriangleMesh};
use rand_pcg::Pcg32;
use std::f64::consts::PI;
use std::path::Path;

const RHO: f32 = 0.5;

/// What is lit.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Receiver {
    /// `SceneBuilder::add_quad`: two triangles.
    Quad,
    /// A 6×6 grid of cells, 72 coplanar triangles (several BVH leaves).
    Grid,
    /// The quad as a pbrt `Shape "trianglemesh"`, through the pbrt loader.
    PbrtMesh,
    /// A disk quadric.
    Disk,
    /// A sphere quadric.
    Sphere,
}

/// What lights it.
#[derive(Clone, Copy, Debug, PartialEq)]
enum LightKind {
    Distant,
    Point,
    Spot,
    QuadArea,
    TriangleArea,
    SphereArea,
    Sky,
}

impl LightKind {
    fn is_delta(self) -> bool {
        matches!(
            self,
            LightKind::Distant | LightKind::Point | LightKind::Spot
        )
    }
}

/// The analytic irradiance model of a case's light.
enum Exact {
    Distant {
        w: DVec3,
        l: f64,
    },
    Point {
        p: DVec3,
        i: f64,
        spot: Option<(DVec3, f64, f64)>,
    },
    Polygon {
        v: Vec<DVec3>,
        l: f64,
    },
    Sphere {
        c: DVec3,
        r: f64,
        l: f64,
    },
    Sky {
        l: f64,
    },
}

impl Exact {
    /// Irradiance at `x` with unit normal `n` (the light entirely above the horizon).
    fn irradiance(&self, x: DVec3, n: DVec3) -> f64 {
        match self {
            Exact::Distant { w, l } => l * n.dot(*w).max(0.0),
            Exact::Point { p, i, spot } => {
                let d = *p - x;
                let r = d.length();
                let mut i = *i;
                if let Some((axis, cos_total, cos_start)) = spot {
                    // pbrt-v4's smoothstep falloff in cos θ.
                    let c = axis.dot(-d / r);
                    let t = ((c - cos_total) / (cos_start - cos_total)).clamp(0.0, 1.0);
                    i *= t * t * (3.0 - 2.0 * t);
                }
                i * n.dot(d).max(0.0) / (r * r * r)
            }
            Exact::Polygon { v, l } => lambert_polygon(x, n, v, *l),
            Exact::Sphere { c, r, l } => {
                // π L sin²α cos θ: exact for a sphere wholly above the horizon.
                let d = *c - x;
                let d2 = d.length_squared();
                PI * l * (r * r / d2) * n.dot(d / d2.sqrt())
            }
            Exact::Sky { l } => PI * l,
        }
    }
}

/// Lambert's formula for a uniformly emitting polygon wholly above the receiver's horizon:
/// E = L/2 · |Σ Θᵢ n · unit(vᵢ × vᵢ₊₁)| with vᵢ the directions to the vertices.
fn lambert_polygon(p: DVec3, n: DVec3, verts: &[DVec3], l: f64) -> f64 {
    let v: Vec<DVec3> = verts.iter().map(|&x| (x - p).normalize()).collect();
    let mut s = 0.0;
    for i in 0..v.len() {
        let (a, b) = (v[i], v[(i + 1) % v.len()]);
        let c = a.cross(b);
        s += c.length().atan2(a.dot(b)) * n.dot(c.normalize());
    }
    0.5 * l * s.abs()
}

/// A small deterministic random stream for the case geometry.
struct Rng(Pcg32);

impl Rng {
    fn new(keys: &[u64]) -> Self {
        Rng(pcg_from_keys(keys))
    }
    fn f(&mut self) -> f32 {
        next_f32(&mut self.0)
    }
    fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.f()
    }
    fn unit(&mut self) -> Vec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, std::f32::consts::TAU);
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// One randomly drawn configuration.
#[derive(Debug)]
struct Case {
    id: u64,
    receiver: Receiver,
    light: LightKind,
    /// Edge length of the plane (or diameter of the disk / sphere).
    size: f32,
    center: Vec3,
    /// Right-handed frame of the receiver: u × v = n.
    u: Vec3,
    v: Vec3,
    n: Vec3,
    /// Elevation of the light above the plane (degrees).
    elevation: f32,
    /// Azimuth of the light in the (u, v) plane (radians).
    azimuth: f32,
    /// Distance of the light (units of `size`).
    distance: f32,
    backend: Backend,
    axis_aligned: bool,
}

impl Case {
    fn draw(id: u64, receiver: Receiver, light: LightKind) -> Case {
        let mut r = Rng::new(&[0x9e37, id]);
        let size = 10f32.powf(r.range(-3.0, 4.0));
        let axis_aligned = id.is_multiple_of(3);
        let (u, v, n) = if axis_aligned {
            let axes = [Vec3::X, Vec3::Y, Vec3::Z];
            let k = (r.f() * 3.0) as usize % 3;
            let sign = if r.f() < 0.5 { -1.0 } else { 1.0 };
            let n = axes[k] * sign;
            let u = axes[(k + 1) % 3];
            (u, n.cross(u), n)
        } else {
            let n = r.unit();
            let a = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
            let t = n.cross(a).normalize();
            let b = n.cross(t);
            let phi = r.range(0.0, std::f32::consts::TAU);
            let u = t * phi.cos() + b * phi.sin();
            (u, n.cross(u), n)
        };
        let far = id % 2 == 1;
        let mut center = if far {
            // Up to 1e3 sizes away (and at most 2e4 units): the plane then spans ~1e4 ulps.
            let d = (size * 10f32.powf(r.range(1.0, 3.0))).min(2e4).max(size);
            r.unit() * d
        } else {
            r.unit() * (0.5 * size * r.f())
        };
        if axis_aligned && !far {
            // The plane through the origin (the y = 0 floor), whose hit points' error
            // bound along the normal is exactly zero, or close to it (its y = 0.37 floor of
            // size 19): offsets along the normal far below the size.
            let keep = if id.is_multiple_of(4) {
                0.0
            } else {
                10f32.powf(r.range(-3.0, 0.0))
            };
            center -= n * (n.dot(center) * (1.0 - keep));
        }
        let elevation = if id % 4 == 1 {
            r.range(2.0, 6.0)
        } else {
            r.range(2.0, 90.0)
        };
        let azimuth = r.range(0.0, std::f32::consts::TAU);
        let distance = r.range(1.5, 3.0);
        let backend = if id % 5 == 2 {
            Backend::Own
        } else {
            Backend::Wide
        };
        Case {
            id,
            receiver,
            light,
            size,
            center,
            u,
            v,
            n,
            elevation,
            azimuth,
            distance,
            backend,
            axis_aligned,
        }
    }

    /// Unit direction toward the light.
    fn light_dir(&self) -> Vec3 {
        let e = self.elevation.to_radians();
        let along = self.u * self.azimuth.cos() + self.v * self.azimuth.sin();
        (self.n * e.sin() + along * e.cos()).normalize()
    }
}

fn film() -> FilmSpec {
    FilmSpec {
        resolution: UVec2::new(8, 8),
        filter: Filter::Box {
            radius: glam::Vec2::splat(0.5),
        },
        filename: None,
        spp: None,
        sensor: Default::default(),
    }
}

/// The receiver's vertices (corner, corner + e1, corner + e1 + e2, corner + e2) as
/// `SceneBuilder::add_quad` forms them.
fn quad_vertices(c: &Case) -> [Vec3; 4] {
    let s = c.size;
    let (e1, e2) = (c.u * s, c.v * s);
    let corner = c.center - e1 * 0.5 - e2 * 0.5;
    [corner, corner + e1, corner + e1 + e2, corner + e2]
}

/// A pbrt scene with the receiver quad as a trianglemesh (vertices printed so they read back
/// to the same f32s).
fn pbrt_mesh_builder(c: &Case) -> SceneBuilder {
    let p = quad_vertices(c);
    let pts: Vec<String> = p
        .iter()
        .map(|v| format!("{:?} {:?} {:?}", v.x, v.y, v.z))
        .collect();
    let src = format!(
        "WorldBegin\nMaterial \"diffuse\" \"rgb reflectance\" [ {RHO} {RHO} {RHO} ]\n\
         Shape \"trianglemesh\" \"integer indices\" [ 0 1 2 0 2 3 ]\n  \"point3 P\" [ {} ]\n",
        pts.join("  ")
    );
    let (b, _, _, warnings) = parse_pbrt_str("plane.pbrt", &src, Path::new("."))
        .and_then(|s| s.into_builder())
        .expect("the pbrt plane parses");
    assert!(warnings.is_empty(), "{warnings:?}");
    b
}

/// A case's scene with the analytic model of its light.
struct Built {
    scene: Scene,
    exact: Exact,
    /// The receiver's material index.
    receiver: u32,
    /// The chance that a cosine-distributed direction at the receiver's centre reaches the
    /// light (E / πL): what BSDF sampling's efficiency depends on.
    p_hit: f64,
}

/// The scene of case `c` and the analytic model of its light.
fn build(c: &Case) -> Built {
    let mut b = if c.receiver == Receiver::PbrtMesh {
        pbrt_mesh_builder(c)
    } else {
        SceneBuilder::new()
    };
    let receiver = if c.receiver == Receiver::PbrtMesh {
        (b.materials.len() - 1) as u32
    } else {
        b.add_material(Material::Diffuse {
            reflectance: Texture::Constant(Rgb::splat(RHO)),
        })
    };
    let black = b.add_material(Material::Diffuse {
        reflectance: Texture::Constant(Rgb::ZERO),
    });
    let s = c.size;
    match c.receiver {
        Receiver::Quad => {
            let p = quad_vertices(c);
            b.add_quad(p[0], c.u * s, c.v * s, receiver, None).unwrap();
        }
        Receiver::Grid => {
            let k = 6u32;
            let p = quad_vertices(c);
            let (e1, e2) = (c.u * s, c.v * s);
            let mut positions = Vec::new();
            for j in 0..=k {
                for i in 0..=k {
                    positions.push(p[0] + e1 * (i as f32 / k as f32) + e2 * (j as f32 / k as f32));
                }
            }
            let mut indices = Vec::new();
            let at = |i: u32, j: u32| j * (k + 1) + i;
            for j in 0..k {
                for i in 0..k {
                    let (a, b2, c2, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                    indices.extend_from_slice(&[a, b2, c2, a, c2, d]);
                }
            }
            let mesh = TriangleMesh {
                positions,
                normals: None,
                uvs: None,
                indices,
                flip_normals: false,
            };
            b.add_mesh(mesh, receiver, None).unwrap();
        }
        Receiver::PbrtMesh => {}
        Receiver::Disk => {
            let m = Mat4::from_cols(
                c.u.extend(0.0),
                c.v.extend(0.0),
                c.n.extend(0.0),
                c.center.extend(1.0),
            );
            let t = Transform::new(m).unwrap();
            b.add_disk(t, 0.0, 0.5 * s, receiver, None, false, None)
                .unwrap();
        }
        Receiver::Sphere => {
            b.add_sphere(
                Transform::translate(c.center),
                0.5 * s,
                receiver,
                None,
                false,
                None,
            )
            .unwrap();
        }
    }
    let w = c.light_dir();
    let dist = c.distance * s;
    let p_light = c.center + w * dist;
    let sin_e = c.elevation.to_radians().sin();
    // An orthonormal pair spanning the plane perpendicular to w, with a1 × a2 = −w: area
    // lights built on it emit toward the receiver.
    let a = if w.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    let a1 = w.cross(a).normalize();
    let a2 = a1.cross(w);
    // Keep area lights wholly above the receiver plane (the closed forms need that).
    let half = dist * (0.2f32).min(0.4 * sin_e / (2f32.sqrt() * (1.0 - sin_e * sin_e).sqrt()));
    let emission = |l: f32| {
        Some(AreaEmission {
            l: Rgb::splat(l),
            two_sided: false,
        })
    };
    let dv = |v: Vec3| v.as_dvec3();
    // The light's radiance: ~10 units of irradiance at normal incidence.
    let exact = match c.light {
        LightKind::Distant => {
            let l = DistantLight::new(w, Rgb::splat(10.0));
            let e = Exact::Distant {
                w: dv(l.w_light),
                l: 10.0,
            };
            b.add_light(Light::Distant(l));
            e
        }
        LightKind::Point | LightKind::Spot => {
            let i = 10.0 * dist * dist;
            let spot = if c.light == LightKind::Spot {
                let l = SpotLight::new(
                    p_light,
                    c.center - p_light,
                    Rgb::splat(i),
                    70f32.to_radians().cos(),
                    80f32.to_radians().cos(),
                );
                let s = (
                    dv(l.dir),
                    l.cos_total_width as f64,
                    l.cos_falloff_start as f64,
                );
                b.add_light(Light::Spot(l));
                Some(s)
            } else {
                b.add_light(Light::Point(PointLight::new(p_light, Rgb::splat(i))));
                None
            };
            Exact::Point {
                p: dv(p_light),
                i: i as f64,
                spot,
            }
        }
        LightKind::QuadArea => {
            let le = 10.0 * (dist * dist) / (4.0 * half * half);
            let (e1, e2) = (a1 * (2.0 * half), a2 * (2.0 * half));
            let corner = p_light - a1 * half - a2 * half;
            b.add_quad(corner, e1, e2, black, emission(le)).unwrap();
            Exact::Polygon {
                v: vec![
                    dv(corner),
                    dv(corner + e1),
                    dv(corner + e1 + e2),
                    dv(corner + e2),
                ],
                l: le as f64,
            }
        }
        LightKind::TriangleArea => {
            let le = 10.0 * (dist * dist) / (1.3 * half * half);
            let v: Vec<Vec3> = (0..3)
                .map(|k| {
                    let phi = k as f32 * std::f32::consts::TAU / 3.0;
                    p_light + (a1 * phi.cos() + a2 * phi.sin()) * half
                })
                .collect();
            let mesh = TriangleMesh {
                positions: v.clone(),
                normals: None,
                uvs: None,
                indices: vec![0, 1, 2],
                flip_normals: false,
            };
            b.add_mesh(mesh, black, emission(le)).unwrap();
            Exact::Polygon {
                v: v.iter().map(|&p| dv(p)).collect(),
                l: le as f64,
            }
        }
        LightKind::SphereArea => {
            let r = dist * (0.2f32).min(0.5 * sin_e);
            let le = 10.0 * (dist * dist) / (std::f32::consts::PI * r * r);
            b.add_sphere(
                Transform::translate(p_light),
                r,
                black,
                emission(le),
                false,
                None,
            )
            .unwrap();
            Exact::Sphere {
                c: dv(p_light),
                r: r as f64,
                l: le as f64,
            }
        }
        LightKind::Sky => {
            b.add_light(Light::UniformInfinite(UniformInfiniteLight::new(
                Rgb::splat(3.0),
            )));
            Exact::Sky { l: 3.0 }
        }
    };
    let cam = Camera::look_at(c.center + c.n * (3.0 * s), c.center, c.u, 40.0).unwrap();
    let mut scene = b.build(cam, film()).unwrap();
    if c.backend != Backend::Wide {
        scene.geometry = scene.geometry.rebuild(c.backend);
        scene.emitters = scene.emitters.rebuild(c.backend);
    }
    let p_hit = match &exact {
        Exact::Polygon { l, .. } | Exact::Sphere { l, .. } | Exact::Sky { l } => {
            exact.irradiance(dv(c.center), dv(c.n)) / (PI * l)
        }
        _ => 0.0,
    };
    Built {
        scene,
        exact,
        receiver,
        p_hit,
    }
}

/// The receiver's unit normal at hit `h`, in f64 from the stored geometry: the hit
/// triangle's winding normal, the disk's axis or the sphere's radius.
fn receiver_normal(scene: &Scene, c: &Case, h: &SurfaceHit) -> DVec3 {
    match scene.geometry.primitive(h.prim).map(|p| p.kind) {
        Some(PrimKind::Triangle { .. }) => {
            let p = scene
                .geometry
                .primitive(h.prim)
                .unwrap()
                .p
                .map(|v| v.as_dvec3());
            (p[1] - p[0]).cross(p[2] - p[0]).normalize()
        }
        _ if c.receiver == Receiver::Sphere => (h.p.as_dvec3() - c.center.as_dvec3()).normalize(),
        _ => c.n.as_dvec3(),
    }
}

/// A camera ray toward a random point of the receiver that the camera sees unobstructed,
/// with the exact radiance there.
fn camera_ray(b: &Built, c: &Case, cam: Vec3, r: &mut Rng) -> (Ray, f64) {
    let (scene, s) = (&b.scene, c.size);
    for _ in 0..100 {
        let target = if c.receiver == Receiver::Sphere {
            // A point on the cap facing the camera (which looks along −n).
            let m = loop {
                let m = r.unit();
                if m.dot(c.n) > 0.4 {
                    break m;
                }
            };
            c.center + m * (0.5 * s)
        } else {
            c.center + c.u * (s * r.range(-0.3, 0.3)) + c.v * (s * r.range(-0.3, 0.3))
        };
        let ray = Ray::new(cam, (target - cam).normalize());
        let Some(h) = scene.geometry.intersect(&ray) else {
            continue;
        };
        if h.light != NO_LIGHT || h.material != b.receiver {
            continue;
        }
        let n = receiver_normal(scene, c, &h);
        let e = b.exact.irradiance(h.p.as_dvec3(), n);
        return (ray, RHO as f64 / PI * e);
    }
    panic!("case {c:?}: no unobstructed view of the receiver");
}

/// An estimator configuration under test.
struct Config {
    name: &'static str,
    strategy: Strategy,
    mis: MisHeuristic,
    mis_light: SamplingMode,
}

const CONFIGS: [Config; 5] = [
    Config {
        name: "bsdf",
        strategy: Strategy::Bsdf,
        mis: MisHeuristic::Power,
        mis_light: SamplingMode::SolidAngle,
    },
    Config {
        name: "light-area",
        strategy: Strategy::LightArea,
        mis: MisHeuristic::Power,
        mis_light: SamplingMode::SolidAngle,
    },
    Config {
        name: "light-solid-angle",
        strategy: Strategy::LightSolidAngle,
        mis: MisHeuristic::Power,
        mis_light: SamplingMode::SolidAngle,
    },
    Config {
        name: "mis-power",
        strategy: Strategy::Mis,
        mis: MisHeuristic::Power,
        mis_light: SamplingMode::SolidAngle,
    },
    Config {
        name: "mis-balance-area",
        strategy: Strategy::Mis,
        mis: MisHeuristic::Balance,
        mis_light: SamplingMode::Area,
    },
];

/// Rounds of camera packets per case and configuration.
const ROUNDS: u32 = 72;

/// Measured samples of one case and configuration: (estimate, exact) pairs.
fn measure(b: &Built, c: &Case, cfg: &Config, seed: u64) -> Vec<(f64, f64)> {
    let scene = &b.scene;
    let selector = make_selector(SelectorKind::Uniform, scene, seed);
    let pattern = make_pattern(PatternKind::Random, seed);
    let est = Integrator {
        scene,
        selector: selector.as_ref(),
        pattern: pattern.as_ref(),
        strategy: cfg.strategy,
        mis: cfg.mis,
        eye_rays: 1,
        shadow_rays: 1,
        bsdf_sampling: LobeSampling::Importance,
        mis_light: cfg.mis_light,
        max_depth: 1,
        roulette: false,
        hide_emitters: false,
    };
    let mut r = Rng::new(&[0x51ed, c.id, seed]);
    let s = c.size;
    // The camera above the receiver, tilted up to 60° off the normal away from the light's
    // azimuth, so that area lights high above do not hide the receiver.
    let tilt = if c.elevation > 30.0 {
        r.range(30.0, 60.0)
    } else {
        r.range(0.0, 60.0)
    }
    .to_radians();
    let along = c.u * c.azimuth.cos() + c.v * c.azimuth.sin();
    let side = -along + (c.u * r.range(-0.3, 0.3) + c.v * r.range(-0.3, 0.3));
    let side = side.try_normalize().unwrap_or(c.u);
    let cam = c.center + (c.n * tilt.cos() + side * tilt.sin()) * (s * r.range(2.0, 4.0));
    let mut queues = Queues::new();
    let mut out = Vec::new();
    for round in 0..ROUNDS {
        // Mostly full packets (the 16-lane kernels); every fourth round three rays, whose
        // shadow rays go through the one-ray 4-wide test.
        let lanes = if round % 4 == 3 { 3 } else { PACKET };
        let mut packet = CameraPacket::new();
        let mut pxs: Vec<PixelSamples> = Vec::with_capacity(lanes);
        let mut want = Vec::with_capacity(lanes);
        for k in 0..lanes {
            let (ray, x) = camera_ray(b, c, cam, &mut r);
            pxs.push(pattern.pixel(UVec2::new(round, k as u32)));
            packet.push(k as u8, 0, ray);
            want.push(x);
        }
        let mut radiance = [Rgb::ZERO; PACKET];
        est.li_packet(&pxs, &packet, &mut radiance, &mut queues);
        for k in 0..lanes {
            out.push((radiance[k].x as f64, want[k]));
        }
    }
    out
}

/// Relative slack for f32 rounding of the light's own quantities (r², cos θ, the sampled
/// point) and of the analytic model's inputs.
const SLACK: f64 = 2e-3;

/// Absolute slack (in units of the case's mean radiance) for the rounding of the hit point
/// and its normal: a few ulps of the receiver's distance from the origin, relative to its
/// size, which moves cos θ by as much (it matters at a sphere's terminator).
fn geometric_slack(c: &Case) -> f64 {
    16.0 * f32::EPSILON as f64 * (1.0 + (c.center.length() / c.size) as f64)
}

#[test]
fn lambertian_receivers_reflect_rho_over_pi_times_analytic_irradiance() {
    let receivers = [
        Receiver::Quad,
        Receiver::Grid,
        Receiver::PbrtMesh,
        Receiver::Disk,
        Receiver::Sphere,
    ];
    let lights = [
        LightKind::Distant,
        LightKind::Point,
        LightKind::Spot,
        LightKind::QuadArea,
        LightKind::TriangleArea,
        LightKind::SphereArea,
        LightKind::Sky,
    ];
    let mut failures = Vec::new();
    let (mut checked, mut skipped) = (0, 0);
    let mut id = 0u64;
    for rep in 0..4 {
        for &receiver in &receivers {
            for &light in &lights {
                id += 1;
                // Area lights near a sphere would dip below the horizon of some of its points.
                if receiver == Receiver::Sphere
                    && matches!(
                        light,
                        LightKind::QuadArea | LightKind::TriangleArea | LightKind::SphereArea
                    )
                {
                    continue;
                }
                let case = Case::draw(id * 4 + rep, receiver, light);
                let built = build(&case);
                for (ci, cfg) in CONFIGS.iter().enumerate() {
                    if light.is_delta() && cfg.strategy == Strategy::Bsdf {
                        // BSDF sampling never finds a delta light (it contributes 0).
                        continue;
                    }
                    let n = (ROUNDS as f64) * PACKET as f64;
                    if cfg.strategy == Strategy::Bsdf && built.p_hit * n < 150.0 {
                        // Too few BSDF samples would reach so small a light for a variance.
                        skipped += 1;
                        continue;
                    }
                    let seed = case.id * 16 + ci as u64;
                    let v = measure(&built, &case, cfg, seed);
                    checked += 1;
                    let m = v.len() as f64;
                    let scale = v.iter().map(|p| p.1).sum::<f64>() / m;
                    let diff: Vec<f64> = v.iter().map(|(l, x)| (l - x) / scale).collect();
                    let mean = diff.iter().sum::<f64>() / m;
                    let var = diff.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (m - 1.0);
                    let se = (var / m).sqrt();
                    let got = v.iter().map(|p| p.0).sum::<f64>() / m;
                    let deterministic = light.is_delta();
                    let geo = geometric_slack(&case);
                    // The largest deviation of one sample beyond its rounding slack.
                    let worst = v
                        .iter()
                        .map(|(l, x)| ((l - x).abs() - SLACK * x) / scale - geo)
                        .fold(f64::NEG_INFINITY, f64::max);
                    let zeros = v.iter().filter(|(l, x)| *l == 0.0 && *x > 0.0).count();
                    let bad = if deterministic {
                        worst > 0.0
                    } else {
                        mean.abs() > 5.0 * se + SLACK + geo
                    };
                    if bad {
                        failures.push(format!(
                            "case {} {:?} {:?} {} ({:?}{}, size {:.3e}, |centre| {:.3e}, \
                             elevation {:.1}°): mean {got:.5} vs exact {scale:.5} \
                             ({:+.2}%, {:.1}σ, worst sample {worst:+.1e}), {zeros} of {} samples black",
                            case.id,
                            receiver,
                            light,
                            cfg.name,
                            case.backend,
                            if case.axis_aligned {
                                ", axis-aligned"
                            } else {
                                ""
                            },
                            case.size,
                            case.center.length(),
                            case.elevation,
                            100.0 * mean,
                            mean / se.max(1e-300),
                            v.len()
                        ));
                    }
                }
            }
        }
    }
    eprintln!(
        "{checked} case × estimator checks ({skipped} BSDF checks skipped for small lights), {} failed",
        failures.len()
    );
    for f in &failures {
        eprintln!("  {f}");
    }
    assert!(
        failures.is_empty(),
        "{} of {checked} checks failed",
        failures.len()
    );
}
