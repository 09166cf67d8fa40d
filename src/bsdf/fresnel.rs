//! Fresnel reflectance: real (dielectric) and complex (conductor) indices of refraction, and the
//! hemispherical (diffuse) average used by the coated-diffuse layer.

use crate::Rgb;

/// Unpolarised Fresnel reflectance of a dielectric interface for light arriving with
/// `cos_i ≥ 0` on the side where the relative index is `eta = η_transmitted / η_incident`.
/// Returns 1 under total internal reflection.
#[inline]
pub fn fr_dielectric(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// Minimal complex number for the conductor Fresnel equations (f32 is plenty for reflectances).
#[derive(Clone, Copy, Debug)]
struct C {
    re: f32,
    im: f32,
}

impl C {
    fn add(self, o: C) -> C {
        C {
            re: self.re + o.re,
            im: self.im + o.im,
        }
    }
    fn sub(self, o: C) -> C {
        C {
            re: self.re - o.re,
            im: self.im - o.im,
        }
    }
    fn mul(self, o: C) -> C {
        C {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
    fn norm(self) -> f32 {
        self.re * self.re + self.im * self.im
    }
    fn div(self, o: C) -> C {
        let d = o.norm();
        C {
            re: (self.re * o.re + self.im * o.im) / d,
            im: (self.im * o.re - self.re * o.im) / d,
        }
    }
    /// Principal square root, computed without cancellation.
    fn sqrt(self) -> C {
        let n = self.norm().sqrt();
        if n == 0.0 {
            return C { re: 0.0, im: 0.0 };
        }
        let t1 = (0.5 * (n + self.re.abs())).sqrt();
        let t2 = 0.5 * self.im / t1;
        if self.re >= 0.0 {
            C { re: t1, im: t2 }
        } else {
            C {
                re: t2.abs(),
                im: t1.copysign(self.im),
            }
        }
    }
}

/// Fresnel reflectance of a conductor with complex index `eta + i·k` (one wavelength), for
/// `cos_i ∈ [0, 1]` on the outside.
pub fn fr_complex(cos_i: f32, eta: f32, k: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let ci = C { re: cos_i, im: 0.0 };
    let e = C { re: eta, im: k };
    let sin2_i = C {
        re: 1.0 - cos_i * cos_i,
        im: 0.0,
    };
    let sin2_t = sin2_i.div(e.mul(e));
    let cos_t = C { re: 1.0, im: 0.0 }.sub(sin2_t).sqrt();
    let r_parl = e.mul(ci).sub(cos_t).div(e.mul(ci).add(cos_t));
    let r_perp = ci.sub(e.mul(cos_t)).div(ci.add(e.mul(cos_t)));
    let r = 0.5 * (r_parl.norm() + r_perp.norm());
    // A zero denominator (eta = k = 0 at grazing) is not a physical metal; call it a mirror.
    if r.is_finite() {
        r.clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// [`fr_complex`] per RGB channel.
pub fn fr_complex_rgb(cos_i: f32, eta: Rgb, k: Rgb) -> Rgb {
    Rgb::new(
        fr_complex(cos_i, eta.x, k.x),
        fr_complex(cos_i, eta.y, k.y),
        fr_complex(cos_i, eta.z, k.z),
    )
}

/// Conductor extinction `k` (with `eta = 1`) whose normal-incidence reflectance is `r0`: pbrt-v4's
/// "reflectance" conductor mode, an artist control that keeps the complex-Fresnel angular shape
/// (Schlick-like) while hitting `r0` exactly at normal incidence. `r0` is clamped below 1.
pub fn k_from_reflectance(r0: Rgb) -> Rgb {
    let r = r0.clamp(Rgb::ZERO, Rgb::splat(0.9999));
    Rgb::new(
        2.0 * r.x.sqrt() / (1.0 - r.x).sqrt(),
        2.0 * r.y.sqrt() / (1.0 - r.y).sqrt(),
        2.0 * r.z.sqrt() / (1.0 - r.z).sqrt(),
    )
}

/// 8-point Gauss–Legendre nodes on [−1, 1] (positive half; the rule is symmetric).
const GL8_X: [f32; 4] = [0.183_434_64, 0.525_532_4, 0.796_666_5, 0.960_289_86];
/// Weights matching [`GL8_X`].
const GL8_W: [f32; 4] = [0.362_683_78, 0.313_706_65, 0.222_381_03, 0.101_228_54];

/// Hemispherical average of the Fresnel reflectance seen from outside a dielectric of relative
/// index `eta ≥ 1`: F_dr = ∫₀¹ F(μ) 2μ dμ. For eta ≥ 1 the integrand is smooth (no total
/// internal reflection), so an 8-point Gauss–Legendre rule is accurate to ~1e-5.
pub fn diffuse_fresnel_external(eta: f32) -> f32 {
    let mut s = 0.0;
    for (x, w) in GL8_X.iter().zip(GL8_W) {
        for mu in [0.5 * (1.0 + x), 0.5 * (1.0 - x)] {
            s += w * fr_dielectric(mu, eta) * 2.0 * mu;
        }
    }
    0.5 * s
}

/// Hemispherical average of the Fresnel reflectance seen from *inside* a dielectric of index
/// `eta ≥ 1` (includes total internal reflection). By reciprocity the transmitted fractions obey
/// 1 − F_dr,int = (1 − F_dr,ext) / η², which avoids integrating across the TIR kink.
pub fn diffuse_fresnel_internal(eta: f32) -> f32 {
    let eta = eta.max(1.0);
    1.0 - (1.0 - diffuse_fresnel_external(eta)) / (eta * eta)
}
