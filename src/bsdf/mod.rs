//! BSDFs in the local shading frame (z = shading normal).
//!
//! Contract: `f` excludes the cosine factor; `pdf(wo, wi)` is exactly the solid-angle density
//! `sample` draws from (the chi² tests check this); samples that a lobe would put below the
//! surface are returned as `None` (their weight is zero), so `pdf` integrates to ≤ 1.
//! Delta lobes report `delta = true` with `pdf = 1` by convention and `f` chosen so that
//! `f·|cos θi| / pdf` is the sample's throughput weight (e.g. `R / |cos θi|`); `f()`/`pdf()`
//! never see them (they return 0 for delta directions).
//! One exception: the layered BSDFs (`layered`, pbrt-v4's coated diffuse and coated conductor)
//! are stochastic, like pbrt-v4's; their `pdf` is a positive density for MIS weights, not the
//! random walk's (intractable) density, and their samples carry the walk's weight.
//! The integrator builds the frame with the shading normal flipped toward `wo`, so `wo.z ≥ 0`
//! for every call; transmissive BSDFs are told which side they are entered from at construction.
//! Only BSDFs whose [`Bxdf::transmits`] is true may return `f ≠ 0` or draw samples with
//! `wi.z < 0`; which incident directions count at a surface whose geometric and shading normals
//! differ is decided by one rule for every technique, [`gathers_from`].

pub mod coated;
pub mod coated_conductor;
pub mod conductor;
pub mod dielectric;
pub mod diffuse_transmission;
pub mod dispersive;
pub mod fresnel;
pub mod ggx;
pub mod lambert;
pub mod layered;
pub mod mirror;
pub mod phong;

pub use coated::CoatedDiffuse;
pub use conductor::{Conductor, named_metal};
pub use dielectric::Dielectric;
pub use diffuse_transmission::DiffuseTransmission;
pub use dispersive::DispersiveDielectric;
pub use ggx::{TrowbridgeReitz, roughness_to_alpha};
pub use lambert::Lambert;
pub use layered::{LayerParams, Layered};
pub use mirror::Mirror;
pub use phong::Phong;

use crate::Rgb;
use crate::sampling::{
    cosine_hemisphere, cosine_hemisphere_pdf, uniform_hemisphere, uniform_hemisphere_pdf,
};
use glam::{Vec2, Vec3};

/// One sampled direction.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// Sampled incident direction (local frame, unit).
    pub wi: Vec3,
    /// BSDF value f(wo, wi) (no cosine).
    pub f: Rgb,
    /// Solid-angle pdf of `wi` (1 for delta lobes).
    pub pdf: f32,
    /// True if drawn from a delta (specular) lobe.
    pub delta: bool,
}

/// The interface every BSDF implements.
pub trait Bxdf {
    /// f(wo, wi) without the cosine.
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb;
    /// Draw wi given wo: `uc` picks a lobe, `u` warps within it.
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample>;
    /// Density of `sample` at wi.
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;
    /// `(f(wo, wi), pdf(wo, wi))` together: MIS light sampling needs both for the same pair.
    #[inline]
    fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        (self.f(wo, wi), self.pdf(wo, wi))
    }
    /// True if every lobe is a delta (mirror, smooth glass): light sampling cannot help.
    fn is_delta(&self) -> bool {
        false
    }
    /// True if light arriving from below the surface (`wi.z < 0`) can scatter toward `wo`
    /// (glass, diffuse transmission): the integrator then gathers light from both sides.
    fn transmits(&self) -> bool {
        false
    }
}

/// Whether an incident direction counts in the direct-lighting integral at a surface, given
/// its cosines with the geometric normal (`cos_geometric`, normal flipped toward the viewer)
/// and with the shading normal (`cos_shading`, the local `wi.z`). One rule for light sampling
/// and BSDF sampling, so MIS combines two estimates of the same integrand:
/// - a reflecting BSDF gathers only from above the geometric surface (its `f` is 0 below the
///   shading surface anyway);
/// - a transmitting BSDF gathers from both sides, but only where the two normals agree on
///   the side: a direction above the shading surface but below the geometric one would
///   "reflect" light that comes through the object, and the reverse would "transmit" light
///   that never crossed the surface (both are light leaks), so they contribute 0.
#[inline(always)]
pub fn gathers_from(transmits: bool, cos_geometric: f32, cos_shading: f32) -> bool {
    if transmits {
        (cos_geometric > 0.0 && cos_shading > 0.0) || (cos_geometric < 0.0 && cos_shading < 0.0)
    } else {
        cos_geometric > 0.0
    }
}

/// How the non-delta lobes of a BSDF are sampled (the lecture's I₁/I₂ variants, for the lab).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum LobeSampling {
    /// Importance sampling matched to the BSDF (cosine for diffuse, cosⁿ / GGX VNDF for glossy).
    #[default]
    Importance,
    /// Cosine-weighted hemisphere for every lobe.
    Cosine,
    /// Uniform hemisphere for every lobe.
    Uniform,
}

impl std::str::FromStr for LobeSampling {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim() {
            "importance" | "cosine-power" => Ok(Self::Importance),
            "cosine" => Ok(Self::Cosine),
            "uniform" => Ok(Self::Uniform),
            _ => Err(format!(
                "unknown BSDF sampling '{s}' (expected importance, cosine or uniform)"
            )),
        }
    }
}

impl LobeSampling {
    /// Draw from the BSDF-independent hemisphere density of this mode (Importance → cosine).
    #[inline]
    pub fn sample_hemisphere(self, u: Vec2) -> Vec3 {
        match self {
            LobeSampling::Uniform => uniform_hemisphere(u),
            _ => cosine_hemisphere(u),
        }
    }

    /// Density of [`LobeSampling::sample_hemisphere`] (0 below the surface).
    #[inline]
    pub fn hemisphere_pdf(self, wi: Vec3) -> f32 {
        if wi.z <= 0.0 {
            return 0.0;
        }
        match self {
            LobeSampling::Uniform => uniform_hemisphere_pdf(wi),
            _ => cosine_hemisphere_pdf(wi),
        }
    }
}

/// Mirror direction of `w` about the shading normal (+z).
#[inline]
pub fn reflect_z(w: Vec3) -> Vec3 {
    Vec3::new(-w.x, -w.y, w.z)
}

/// Mirror direction of `w` about the unit vector `n` (both pointing away from the surface).
#[inline]
pub fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    2.0 * w.dot(n) * n - w
}

/// Draw `wi` from a mode-dependent hemisphere density and evaluate `bsdf` there: the shared
/// sampling path of every non-importance [`LobeSampling`] mode.
// Always inlined, like `TriangleLight::sample_li` (whose comment has the measurement).
#[inline(always)]
fn sample_by_hemisphere(
    bsdf: &impl Bxdf,
    mode: LobeSampling,
    wo: Vec3,
    u: Vec2,
) -> Option<BsdfSample> {
    if wo.z <= 0.0 {
        return None;
    }
    let wi = mode.sample_hemisphere(u);
    let pdf = mode.hemisphere_pdf(wi);
    if pdf <= 0.0 {
        return None;
    }
    Some(BsdfSample {
        wi,
        f: bsdf.f(wo, wi),
        pdf,
        delta: false,
    })
}

/// The sample at `wi` of a reflection lobe drawn by the BSDF's own importance sampler: `None`
/// below the horizon (a glossy lobe around the mirror direction pokes under it, and such
/// directions carry zero weight) or where the pdf is 0 or not finite; else f and pdf at `wi`.
/// The common tail of the samplers of phong, conductor and coated diffuse.
#[inline]
fn reflection_sample(bsdf: &impl Bxdf, wo: Vec3, wi: Vec3) -> Option<BsdfSample> {
    if wi.z <= 0.0 {
        return None;
    }
    let pdf = bsdf.pdf(wo, wi);
    if pdf <= 0.0 || !pdf.is_finite() {
        return None;
    }
    Some(BsdfSample {
        wi,
        f: bsdf.f(wo, wi),
        pdf,
        delta: false,
    })
}

/// Closed set of BSDFs (enum dispatch keeps the per-sample path free of virtual calls).
#[derive(Clone, Debug)]
pub enum Bsdf {
    /// Ideal diffuse.
    Lambert(Lambert),
    /// Modified (energy-conserving) Phong.
    Phong(Phong),
    /// GGX rough (or smooth) conductor.
    Conductor(Conductor),
    /// Smooth or GGX rough glass.
    Dielectric(Dielectric),
    /// Glass with one index per RGB channel (dispersion).
    DispersiveDielectric(DispersiveDielectric),
    /// GGX dielectric coat over a diffuse base.
    CoatedDiffuse(CoatedDiffuse),
    /// Ideal mirror.
    Mirror(Mirror),
    /// pbrt-v4's stochastic layered BSDF (coated diffuse / coated conductor); boxed so that
    /// its 80 bytes do not double the size of every other BSDF in the integrator's lanes.
    Layered(Box<Layered>),
    /// Lambertian reflection and transmission (thin sheets).
    DiffuseTransmission(DiffuseTransmission),
}

macro_rules! dispatch {
    ($self:ident, $b:ident => $e:expr) => {
        match $self {
            Bsdf::Lambert($b) => $e,
            Bsdf::Phong($b) => $e,
            Bsdf::Conductor($b) => $e,
            Bsdf::Dielectric($b) => $e,
            Bsdf::DispersiveDielectric($b) => $e,
            Bsdf::CoatedDiffuse($b) => $e,
            Bsdf::Mirror($b) => $e,
            Bsdf::Layered($b) => $e,
            Bsdf::DiffuseTransmission($b) => $e,
        }
    };
}

/// A BSDF as the integrator's vector kernels (`integrator/lanes.rs`) take it: which kernel
/// evaluates and samples it exactly as its own [`Bxdf`] methods do, with the data it reads.
#[derive(Clone, Copy, Debug)]
pub enum LaneBsdf {
    /// Lambertian with cosine-weighted sampling (importance and cosine coincide): its albedo.
    Lambert(Rgb),
}

impl Bsdf {
    /// The vector kernel for this BSDF, if one exists (`None`: one sample at a time).
    #[inline(always)]
    pub fn lane_kind(&self) -> Option<LaneBsdf> {
        match self {
            Bsdf::Lambert(b) if b.sampling != LobeSampling::Uniform => Some(LaneBsdf::Lambert(b.r)),
            _ => None,
        }
    }

    /// `(f(wo, wi), pdf(wo, wi))` in one dispatch: MIS light sampling needs both for the same
    /// pair, and one call instead of two saves a call and a match per light sample. It is the
    /// BxDF's own `f_pdf`, so the rough dielectrics evaluate their microfacet lobe once.
    #[inline]
    pub fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        dispatch!(self, b => b.f_pdf(wo, wi))
    }

    /// The BSDF for a path whose throughput is `beta`: a dispersive dielectric reached by a
    /// path that carries one channel only (it refracted through dispersive glass before)
    /// becomes that channel's plain dielectric, so the channel is not picked again (a pick of
    /// another would end the path: 2/3 of the samples lost per further refraction). The other
    /// channels' zero throughput keeps them zero, as pbrt-v4's terminated wavelengths stay.
    #[inline]
    pub fn for_throughput(&mut self, beta: Rgb) {
        if let Bsdf::DispersiveDielectric(d) = self {
            let nonzero = beta.to_array().map(|v| v != 0.0);
            if let [true, false, false] | [false, true, false] | [false, false, true] = nonzero {
                let c = nonzero.iter().position(|&b| b).unwrap_or(0);
                *self = Bsdf::Dielectric(d.channel(c));
            }
        }
    }

    /// Choose how every non-delta lobe is sampled (the lab's I₁/I₂ comparison); delta BSDFs
    /// ignore it because a delta lobe can only be sampled one way.
    pub fn set_sampling(&mut self, s: LobeSampling) {
        match self {
            Bsdf::Lambert(b) => b.sampling = s,
            Bsdf::Phong(b) => b.sampling = s,
            Bsdf::Conductor(b) => b.sampling = s,
            Bsdf::CoatedDiffuse(b) => b.sampling = s,
            Bsdf::Layered(b) => b.sampling = s,
            Bsdf::DiffuseTransmission(b) => b.sampling = s,
            Bsdf::Dielectric(_) | Bsdf::DispersiveDielectric(_) | Bsdf::Mirror(_) => {}
        }
    }
}

impl Bxdf for Bsdf {
    #[inline]
    fn f(&self, wo: Vec3, wi: Vec3) -> Rgb {
        dispatch!(self, b => b.f(wo, wi))
    }
    #[inline]
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BsdfSample> {
        dispatch!(self, b => b.sample(wo, uc, u))
    }
    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        dispatch!(self, b => b.pdf(wo, wi))
    }
    /// [`Bsdf::f_pdf`]: one dispatch for both.
    #[inline]
    fn f_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        Bsdf::f_pdf(self, wo, wi)
    }
    #[inline]
    fn is_delta(&self) -> bool {
        dispatch!(self, b => b.is_delta())
    }
    #[inline]
    fn transmits(&self) -> bool {
        dispatch!(self, b => b.transmits())
    }
}
