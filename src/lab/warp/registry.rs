//! The registry of every routine `penumbra warp` can show: its name, parameters with defaults,
//! and how to build it from [`Params`] into a [`Warp`] (a sampler plus the density it claims).
//!
//! Each entry calls the sampling library or a BSDF; nothing here re-derives a warp.

use anyhow::{Context, bail};
use glam::{DVec2, Vec2, Vec3};
use std::path::Path;

use super::params::{ParamSpec, Params};
use crate::Rgb;
use crate::bsdf::{Bsdf, Bxdf, CoatedDiffuse, Conductor, Lambert, LobeSampling, Phong};
use crate::image::read_image;
use crate::sampling::{
    Distribution2D, SphericalRectangle, SphericalTriangle, concentric_disk, concentric_disk_pdf,
    cosine_hemisphere, cosine_hemisphere_pdf, cosine_power_hemisphere, cosine_power_hemisphere_pdf,
    uniform_cone, uniform_cone_pdf, uniform_hemisphere, uniform_hemisphere_pdf, uniform_sphere,
    uniform_sphere_pdf, uniform_triangle_point,
};

/// Where a routine's samples live.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Domain {
    /// Unit directions; the density is per unit solid angle.
    Sphere,
    /// Points in `rect = [x0, x1, y0, y1]`, density per unit area; `y_down` plots y growing
    /// downwards (image coordinates).
    Plane {
        /// The bounding rectangle of the support.
        rect: [f32; 4],
        /// Draw y downwards (for image-space distributions).
        y_down: bool,
    },
}

/// Draws a sample from (uc, u); `None` when the routine rejects it (e.g. below the horizon).
type SampleFn = Box<dyn Fn(f32, Vec2) -> Option<Vec3> + Send + Sync>;
/// Density at a sample (planar points are passed as (x, y, 0)).
type PdfFn = Box<dyn Fn(Vec3) -> f64 + Send + Sync>;

/// A built routine: its sampler and the density it claims to sample.
pub struct Warp {
    /// Registry name.
    pub name: &'static str,
    /// Sample domain.
    pub domain: Domain,
    /// Name with the parameter values in effect, for plot titles.
    pub label: String,
    sample: SampleFn,
    pdf: PdfFn,
}

impl std::fmt::Debug for Warp {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Warp")
            .field("label", &self.label)
            .field("domain", &self.domain)
            .finish()
    }
}

impl Warp {
    /// Draw one sample: `uc` is the 1D lobe-selection number (BSDFs), `u` the 2D point warped.
    /// Directions are unit vectors; planar points come back as (x, y, 0).
    pub fn sample(&self, uc: f32, u: Vec2) -> Option<Vec3> {
        (self.sample)(uc, u)
    }

    /// The density the routine claims at `x` (unit direction, or (x, y, 0) for points).
    pub fn pdf(&self, x: Vec3) -> f64 {
        (self.pdf)(x)
    }

    /// Coordinates per sample: 3 for directions, 2 for points.
    pub fn dim(&self) -> usize {
        match self.domain {
            Domain::Sphere => 3,
            Domain::Plane { .. } => 2,
        }
    }
}

/// One registry entry.
pub struct Routine {
    /// CLI name.
    pub name: &'static str,
    /// One-line description.
    pub summary: &'static str,
    /// Declared parameters with their defaults.
    pub params: &'static [ParamSpec],
    build: fn(&Params) -> anyhow::Result<(Domain, SampleFn, PdfFn)>,
}

impl Routine {
    /// Build the routine with the defaults overridden by `overrides` (`KEY=VALUE` each).
    pub fn build(&self, overrides: &[String]) -> anyhow::Result<Warp> {
        let p = Params::new(self.name, self.params, overrides)?;
        let (domain, sample, pdf) = (self.build)(&p)?;
        let mut label = self.name.to_string();
        for s in self.params {
            if p.is_set(s.key) {
                label.push_str(&format!(" {}={}", s.key, p.raw(s.key)));
            }
        }
        Ok(Warp {
            name: self.name,
            domain,
            label,
            sample,
            pdf,
        })
    }
}

/// Look up a routine by name; the error lists every name.
pub fn find(name: &str) -> anyhow::Result<&'static Routine> {
    ROUTINES
        .iter()
        .find(|r| r.name == name.trim())
        .ok_or_else(|| {
            let names: Vec<&str> = ROUTINES.iter().map(|r| r.name).collect();
            anyhow::anyhow!(
                "unknown routine {name:?}; expected one of: {}",
                names.join(", ")
            )
        })
}

/// Build routine `name` with `overrides` (`KEY=VALUE` each).
pub fn build(name: &str, overrides: &[String]) -> anyhow::Result<Warp> {
    find(name)?.build(overrides)
}

/// The `--list` text: every routine with its parameters and defaults.
pub fn list_text() -> String {
    let mut s = String::new();
    for r in ROUTINES {
        s.push_str(&format!("{:<20} {}\n", r.name, r.summary));
        for p in r.params {
            let d = if p.default.is_empty() {
                "(unset)"
            } else {
                p.default
            };
            s.push_str(&format!("    {:<12} = {:<22} {}\n", p.key, d, p.help));
        }
    }
    s
}

const INCIDENT: [ParamSpec; 3] = [
    ParamSpec {
        key: "theta",
        default: "45",
        help: "polar angle of the outgoing direction wo, degrees in [0, 90)",
    },
    ParamSpec {
        key: "phi",
        default: "30",
        help: "azimuth of wo, degrees",
    },
    ParamSpec {
        key: "wo",
        default: "",
        help: "wo as x,y,z (overrides theta/phi; z > 0)",
    },
];

const SAMPLING: ParamSpec = ParamSpec {
    key: "sampling",
    default: "importance",
    help: "lobe sampling: importance, cosine or uniform",
};

/// Every routine, in `--list` order.
pub static ROUTINES: &[Routine] = &[
    Routine {
        name: "uniform-hemisphere",
        summary: "uniform directions on the upper hemisphere (pdf 1/2π)",
        params: &[],
        build: |_| {
            Ok(sphere(
                |_, u| Some(uniform_hemisphere(u)),
                |d| uniform_hemisphere_pdf(d) as f64,
            ))
        },
    },
    Routine {
        name: "cosine-hemisphere",
        summary: "cosine-weighted hemisphere (pdf cos θ / π)",
        params: &[],
        build: |_| {
            Ok(sphere(
                |_, u| Some(cosine_hemisphere(u)),
                |d| cosine_hemisphere_pdf(d) as f64,
            ))
        },
    },
    Routine {
        name: "cosine-power",
        summary: "cosine-power lobe around +z (pdf (n+1)/2π cosⁿθ)",
        params: &[ParamSpec {
            key: "n",
            default: "10",
            help: "exponent, finite and >= 0",
        }],
        build: |p| {
            let n = p.float("n")?;
            if n < 0.0 {
                return Err(p.invalid("n", "must be >= 0"));
            }
            Ok(sphere(
                move |_, u| Some(cosine_power_hemisphere(u, n)),
                move |d| cosine_power_hemisphere_pdf(d, n) as f64,
            ))
        },
    },
    Routine {
        name: "sphere",
        summary: "uniform directions on the sphere (pdf 1/4π)",
        params: &[],
        build: |_| {
            Ok(sphere(
                |_, u| Some(uniform_sphere(u)),
                |_| uniform_sphere_pdf() as f64,
            ))
        },
    },
    Routine {
        name: "disk",
        summary: "concentric (Shirley–Chiu) map to the unit disk (pdf 1/π)",
        params: &[],
        build: |_| {
            Ok(plane(
                [-1.0, 1.0, -1.0, 1.0],
                false,
                |_, u| Some(concentric_disk(u).extend(0.0)),
                |x| concentric_disk_pdf(x.truncate()) as f64,
            ))
        },
    },
    Routine {
        name: "triangle",
        summary: "uniform points on a 2D triangle by area (pdf 1/area)",
        params: &[
            ParamSpec {
                key: "a",
                default: "-1,0",
                help: "first vertex x,y",
            },
            ParamSpec {
                key: "b",
                default: "2,0.3",
                help: "second vertex x,y",
            },
            ParamSpec {
                key: "c",
                default: "0.5,1.2",
                help: "third vertex x,y",
            },
        ],
        build: build_triangle,
    },
    Routine {
        name: "cone",
        summary: "uniform directions in a cone around +z",
        params: &[ParamSpec {
            key: "angle",
            default: "30",
            help: "half-angle, degrees in (0, 180]",
        }],
        build: |p| {
            let deg = p.float("angle")?;
            if !(deg > 0.0 && deg <= 180.0) {
                return Err(p.invalid("angle", "must be in (0, 180] degrees"));
            }
            let cos_max = (deg as f64).to_radians().cos() as f32;
            if cos_max >= 1.0 {
                return Err(p.invalid("angle", "is too small to resolve in f32"));
            }
            Ok(sphere(
                move |_, u| Some(uniform_cone(u, cos_max)),
                move |d| uniform_cone_pdf(d, cos_max) as f64,
            ))
        },
    },
    Routine {
        name: "spherical-triangle",
        summary: "uniform in the solid angle of a triangle seen from the origin (Arvo)",
        params: &[
            ParamSpec {
                key: "a",
                default: "0.8,-0.3,0.5",
                help: "direction (or point) of the first vertex",
            },
            ParamSpec {
                key: "b",
                default: "-0.2,0.9,0.4",
                help: "second vertex",
            },
            ParamSpec {
                key: "c",
                default: "-0.5,-0.6,0.7",
                help: "third vertex",
            },
        ],
        build: |p| {
            let (a, b, c) = (p.vec3("a")?, p.vec3("b")?, p.vec3("c")?);
            let tri = SphericalTriangle::new(Vec3::ZERO, a, b, c).ok_or_else(|| {
                anyhow::anyhow!(
                    "spherical-triangle: vertices a={a}, b={b}, c={c} are degenerate \
                     (zero length, collinear or coplanar with the origin)"
                )
            })?;
            Ok(sphere(
                move |_, u| Some(tri.sample(u)),
                move |d| tri.pdf(d) as f64,
            ))
        },
    },
    Routine {
        name: "spherical-rectangle",
        summary: "uniform in the solid angle of a rectangle (Ureña et al.)",
        params: &[
            ParamSpec {
                key: "corner",
                default: "-0.5,-0.3,1",
                help: "corner point",
            },
            ParamSpec {
                key: "ex",
                default: "1.2,0,0.2",
                help: "first edge vector",
            },
            ParamSpec {
                key: "ey",
                default: "0,0.8,0",
                help: "second edge vector, perpendicular to ex",
            },
            ParamSpec {
                key: "p",
                default: "0.3,0.2,0",
                help: "viewpoint",
            },
        ],
        build: |p| {
            let (corner, ex, ey, o) = (
                p.vec3("corner")?,
                p.vec3("ex")?,
                p.vec3("ey")?,
                p.vec3("p")?,
            );
            let rect = SphericalRectangle::new(o, corner, ex, ey).ok_or_else(|| {
                anyhow::anyhow!(
                    "spherical-rectangle: corner={corner}, ex={ex}, ey={ey} seen from p={o} is \
                     degenerate (zero or non-perpendicular edges, or p in the rectangle's plane)"
                )
            })?;
            Ok(sphere(
                move |_, u| (rect.sample(u) - o).try_normalize(),
                move |d| rect.pdf(d) as f64,
            ))
        },
    },
    Routine {
        name: "piecewise-2d",
        summary: "piecewise-constant 2D distribution on [0,1]² (image luminance)",
        params: &[ParamSpec {
            key: "image",
            default: "",
            help: "image file (exr, pfm, hdr, png...); unset: built-in procedural 64x48",
        }],
        build: build_piecewise,
    },
    Routine {
        name: "lambert",
        summary: "Lambertian BSDF sampler",
        params: &[INCIDENT[0], INCIDENT[1], INCIDENT[2], SAMPLING],
        build: |p| {
            let mut b = Bsdf::Lambert(Lambert::new(Rgb::splat(0.8)));
            b.set_sampling(lobe_sampling(p)?);
            bsdf(b, incident(p)?)
        },
    },
    Routine {
        name: "phong",
        summary: "modified Phong BSDF sampler (diffuse + cosine-power lobe)",
        params: &[
            ParamSpec {
                key: "kd",
                default: "0.3",
                help: "diffuse reflectance (grey or r,g,b)",
            },
            ParamSpec {
                key: "ks",
                default: "0.6",
                help: "specular reflectance (kd + ks <= 1)",
            },
            ParamSpec {
                key: "n",
                default: "20",
                help: "Phong exponent, >= 0",
            },
            INCIDENT[0],
            INCIDENT[1],
            INCIDENT[2],
            SAMPLING,
        ],
        build: |p| {
            let mut ph = Phong::new(p.rgb("kd")?, p.rgb("ks")?, p.float("n")?)
                .map_err(|e| anyhow::anyhow!("{e} (--param kd/ks/n)"))?;
            ph.sampling = lobe_sampling(p)?;
            bsdf(Bsdf::Phong(ph), incident(p)?)
        },
    },
    Routine {
        name: "ggx",
        summary: "GGX (Trowbridge–Reitz) conductor, visible-normal sampling",
        params: &[
            ParamSpec {
                key: "alpha",
                default: "0.3",
                help: "roughness α (both axes)",
            },
            ParamSpec {
                key: "alpha-x",
                default: "",
                help: "α along x (anisotropic; overrides alpha)",
            },
            ParamSpec {
                key: "alpha-y",
                default: "",
                help: "α along y (anisotropic; overrides alpha)",
            },
            INCIDENT[0],
            INCIDENT[1],
            INCIDENT[2],
            SAMPLING,
        ],
        build: |p| {
            let alpha = alphas(p)?;
            let mut b = Bsdf::Conductor(Conductor::new(
                Rgb::new(0.2, 0.9, 1.1),
                Rgb::new(3.9, 2.4, 2.1),
                alpha,
            ));
            b.set_sampling(lobe_sampling(p)?);
            bsdf(b, incident(p)?)
        },
    },
    Routine {
        name: "coated-diffuse",
        summary: "GGX dielectric coat over a diffuse base",
        params: &[
            ParamSpec {
                key: "reflectance",
                default: "0.5",
                help: "base albedo (grey or r,g,b) in [0, 1]",
            },
            ParamSpec {
                key: "alpha",
                default: "0.2",
                help: "coat roughness α (both axes)",
            },
            ParamSpec {
                key: "alpha-x",
                default: "",
                help: "coat α along x (overrides alpha)",
            },
            ParamSpec {
                key: "alpha-y",
                default: "",
                help: "coat α along y (overrides alpha)",
            },
            ParamSpec {
                key: "eta",
                default: "1.5",
                help: "coat index of refraction, >= 1",
            },
            INCIDENT[0],
            INCIDENT[1],
            INCIDENT[2],
            SAMPLING,
        ],
        build: |p| {
            let r = p.rgb("reflectance")?;
            if r.min_element() < 0.0 || r.max_element() > 1.0 {
                return Err(p.invalid("reflectance", "must be in [0, 1]"));
            }
            let eta = p.float("eta")?;
            if eta < 1.0 {
                return Err(p.invalid("eta", "must be >= 1"));
            }
            let mut b = Bsdf::CoatedDiffuse(CoatedDiffuse::new(r, alphas(p)?, eta));
            b.set_sampling(lobe_sampling(p)?);
            bsdf(b, incident(p)?)
        },
    },
];

/// A direction routine from its sampler and pdf.
fn sphere(
    sample: impl Fn(f32, Vec2) -> Option<Vec3> + Send + Sync + 'static,
    pdf: impl Fn(Vec3) -> f64 + Send + Sync + 'static,
) -> (Domain, SampleFn, PdfFn) {
    (Domain::Sphere, Box::new(sample), Box::new(pdf))
}

/// A planar routine over `rect` from its sampler and pdf.
fn plane(
    rect: [f32; 4],
    y_down: bool,
    sample: impl Fn(f32, Vec2) -> Option<Vec3> + Send + Sync + 'static,
    pdf: impl Fn(Vec3) -> f64 + Send + Sync + 'static,
) -> (Domain, SampleFn, PdfFn) {
    (
        Domain::Plane { rect, y_down },
        Box::new(sample),
        Box::new(pdf),
    )
}

/// A BSDF's sampler at outgoing direction `wo`: delta samples carry no density, so they
/// count as lost (the harness's "nowhere" category), as in tests/bsdf_chi2.rs.
fn bsdf(b: Bsdf, wo: Vec3) -> anyhow::Result<(Domain, SampleFn, PdfFn)> {
    let b2 = b.clone();
    Ok(sphere(
        move |uc, u| b.sample(wo, uc, u).filter(|s| !s.delta).map(|s| s.wi),
        move |wi| b2.pdf(wo, wi) as f64,
    ))
}

/// The outgoing direction from `wo` or `theta`/`phi`.
fn incident(p: &Params) -> anyhow::Result<Vec3> {
    if p.is_set("wo") {
        let wo = p.vec3("wo")?;
        return match wo.try_normalize() {
            Some(w) if w.z > 0.0 => Ok(w),
            _ => Err(p.invalid("wo", "must be non-zero with z > 0 (above the surface)")),
        };
    }
    let theta = p.float("theta")?;
    if !(0.0..90.0).contains(&theta) {
        return Err(p.invalid("theta", "must be in [0, 90) degrees"));
    }
    let phi = p.float("phi")?;
    let (t, f) = (theta.to_radians(), phi.to_radians());
    Ok(Vec3::new(t.sin() * f.cos(), t.sin() * f.sin(), t.cos()))
}

/// The `sampling` parameter.
fn lobe_sampling(p: &Params) -> anyhow::Result<LobeSampling> {
    p.raw("sampling")
        .parse::<LobeSampling>()
        .map_err(|e| p.invalid("sampling", e))
}

/// GGX widths from `alpha` or `alpha-x` / `alpha-y`, each in [0, 10].
fn alphas(p: &Params) -> anyhow::Result<Vec2> {
    for key in ["alpha", "alpha-x", "alpha-y"] {
        if p.is_set(key) && !(0.0..=10.0).contains(&p.float(key)?) {
            return Err(p.invalid(key, "must be in [0, 10]"));
        }
    }
    let mut a = Vec2::splat(p.float("alpha")?);
    if p.is_set("alpha-x") {
        a.x = p.float("alpha-x")?;
    }
    if p.is_set("alpha-y") {
        a.y = p.float("alpha-y")?;
    }
    Ok(a)
}

/// Uniform points on a 2D triangle, with a f64 inside test for the pdf.
fn build_triangle(p: &Params) -> anyhow::Result<(Domain, SampleFn, PdfFn)> {
    let (a, b, c) = (p.vec2("a")?, p.vec2("b")?, p.vec2("c")?);
    let (da, db, dc) = (a.as_dvec2(), b.as_dvec2(), c.as_dvec2());
    let twice_area = (db - da).perp_dot(dc - da);
    let scale = (db - da).length() * (dc - da).length();
    if !(twice_area.abs() > 1e-9 * scale && scale > 0.0) {
        bail!("triangle: vertices a={a}, b={b}, c={c} are degenerate (zero area)");
    }
    let inv_area = 2.0 / twice_area.abs();
    let sign = twice_area.signum();
    // Points on an edge (ξ on the boundary of the unit square) are rounded to f32 and may land
    // a few ulp outside: the inside test allows 4 ulp of the triangle's coordinates.
    let extent = [da, db, dc]
        .iter()
        .map(|v| v.abs().max_element())
        .fold(0.0, f64::max);
    let slack = 4.0 * f32::EPSILON as f64 * extent;
    let inside = move |q: DVec2| {
        let e = |u: DVec2, v: DVec2| sign * (v - u).perp_dot(q - u) >= -slack * (v - u).length();
        e(da, db) && e(db, dc) && e(dc, da)
    };
    let rect = [
        a.x.min(b.x).min(c.x),
        a.x.max(b.x).max(c.x),
        a.y.min(b.y).min(c.y),
        a.y.max(b.y).max(c.y),
    ];
    let (a3, b3, c3) = (a.extend(0.0), b.extend(0.0), c.extend(0.0));
    Ok(plane(
        rect,
        false,
        move |_, u| Some(uniform_triangle_point(u, a3, b3, c3)),
        move |x| {
            if inside(x.truncate().as_dvec2()) {
                inv_area
            } else {
                0.0
            }
        },
    ))
}

/// Resolution of the built-in procedural image (non-square, so that a u/v mix-up shows).
const PROCEDURAL_RES: (usize, usize) = (64, 48);

/// A non-trivial built-in density on [0,1]²: a bright Gaussian blob, a diagonal ripple and a
/// zero-density hole, so that peaks, gradients and an empty region all appear in the plots.
pub fn procedural_image() -> (Vec<f32>, usize, usize) {
    let (nu, nv) = PROCEDURAL_RES;
    let mut f = Vec::with_capacity(nu * nv);
    for j in 0..nv {
        for i in 0..nu {
            let (x, y) = ((i as f32 + 0.5) / nu as f32, (j as f32 + 0.5) / nv as f32);
            let blob = 4.0 * (-((x - 0.3).powi(2) + (y - 0.6).powi(2)) / 0.01).exp();
            let ripple = 0.5 * (1.0 + (12.0 * x + 5.0 * y).sin());
            let hole = (x - 0.75).powi(2) + (y - 0.25).powi(2) < 0.02;
            f.push(if hole { 0.0 } else { 0.05 + blob + ripple });
        }
    }
    (f, nu, nv)
}

/// Piecewise-constant 2D distribution from an image's luminance or the procedural image.
fn build_piecewise(p: &Params) -> anyhow::Result<(Domain, SampleFn, PdfFn)> {
    let (f, nu, nv) = if p.is_set("image") {
        let path = Path::new(p.raw("image"));
        let img =
            read_image(path).with_context(|| format!("piecewise-2d: image={}", path.display()))?;
        let f = img
            .pixels
            .iter()
            .map(|&c| crate::luminance(c).max(0.0))
            .collect();
        (f, img.width as usize, img.height as usize)
    } else {
        procedural_image()
    };
    let dist = Distribution2D::try_new(&f, nu, nv).map_err(|e| p.invalid("image", e))?;
    let dist2 = dist.clone();
    Ok(plane(
        [0.0, 1.0, 0.0, 1.0],
        true,
        move |_, u| Some(dist.sample(u).0.extend(0.0)),
        move |x| dist2.pdf(x.truncate()) as f64,
    ))
}
