//! The vector kernels of the commonest work items: a Lambertian receiver's shading geometry,
//! its light samples of triangle lights (by area or by solid angle, with MIS) and its
//! cosine-sampled BSDF rays.
//!
//! Lane by lane these run the very functions of the per-lane path (`ShadingGeometry::new`, the
//! triangle's `sample_li`, [`light_estimate`], the Lambertian `sample`, [`bsdf_ray_of`]), so
//! each lane's bits are the per-lane path's; they hold no maths of their own. What changes is
//! the layout: each input and output is an array over the packet's lanes, so the loop over
//! lanes compiles to 16-wide (AVX-512), 8-wide (AVX2) or 4-wide (SSE2) vector code instead of
//! one lane at a time, whose chains of square roots and divisions left the CPU waiting. The
//! solid-angle light samples' f64 half (Arvo's projection and inversion, which the compiler
//! leaves scalar on AVX2) is drawn first there, four lanes per register, by the sampler's own
//! generic code ([`SolidAngleDraw::lanes4`]); each lane then finishes in
//! [`TriangleLight::sample_li_drawn`], the second half of the triangle's `sample_li`.
//!
//! Which work item goes to a kernel is decided by the light ([`Light::lane_kind`]) and the BSDF
//! ([`Bsdf::lane_kind`]); the kernels' input queues ([`TriangleLightLanes`],
//! [`DiffuseBsdfLanes`]) live here, their outputs are the stages' queues.
//!
//! [`Light::lane_kind`]: crate::lights::Light::lane_kind
//! [`Bsdf::lane_kind`]: crate::bsdf::Bsdf::lane_kind

use super::MisHeuristic;
use super::estimator::{BsdfRay, bsdf_ray_of, light_estimate};
use super::queues::{BsdfRays, Lanes, Receivers, ShadowRays, V3, col};
use crate::Rgb;
use crate::bsdf::{Bxdf, Lambert};
use crate::geometry::{PACKET, Ray, RayPacket, ShadingGeometry, SurfaceHit};
use crate::isa::{Cpu, Kernel, Token};
use crate::lights::{LightSampleContext, LightSource, SamplingMode, TriangleLight};
use crate::sampling::{Frame, SolidAngleDraw};
use glam::{Vec2, Vec3};

impl Receivers {
    /// Every lane's [`ShadingGeometry`] seen along `rays` (lanes without a hit too: theirs
    /// are ignored), on `isa`.
    pub(super) fn shade(&mut self, rays: &RayPacket, cpu: Cpu) {
        struct Shade<'a>(&'a mut Receivers, &'a RayPacket);
        impl Kernel for Shade<'_> {
            type Output = ();
            #[inline(always)]
            fn run<T: Token>(self, _: T) {
                self.0.shade_body(self.1)
            }
        }
        cpu.dispatch(Shade(self, rays))
    }

    #[inline(always)]
    fn shade_body(&mut self, rays: &RayPacket) {
        for k in 0..PACKET {
            let g = ShadingGeometry::new(
                col(&rays.d, k),
                col(&self.cols.ng, k),
                col(&self.cols.ns, k),
            );
            self.wo.set(k, g.wo);
            self.front[k] = g.front;
            self.n.set(k, g.n);
            self.s.set(k, g.frame.s);
            self.t.set(k, g.frame.t);
            self.sn.set(k, g.frame.n);
            self.wo_local.set(k, g.wo_local);
        }
    }

    /// Lane k's shading geometry (valid after [`Self::shade`]).
    #[inline(always)]
    pub(super) fn geometry(&self, k: usize) -> ShadingGeometry {
        ShadingGeometry {
            wo: self.wo.get(k),
            front: self.front[k],
            n: self.n.get(k),
            frame: Frame {
                s: self.s.get(k),
                t: self.t.get(k),
                n: self.sn.get(k),
            },
            wo_local: self.wo_local.get(k),
        }
    }

    /// Lane k's hit, context, frame, local wo and BSDF as the per-lane path has them (fields
    /// the estimators do not read are left zero).
    #[inline(always)]
    fn lane(&self, k: usize) -> (SurfaceHit, LightSampleContext, Frame, Vec3, Lambert) {
        let hit = SurfaceHit {
            t: 0.0,
            p: col(&self.cols.p, k),
            ng: col(&self.cols.ng, k),
            ns: Vec3::ZERO,
            uv: Vec2::ZERO,
            p_error: self.cols.p_error[k],
            prim: 0,
            material: 0,
            light: 0,
        };
        let ctx = LightSampleContext {
            p: hit.p,
            n: self.n.get(k),
        };
        let frame = Frame {
            s: self.s.get(k),
            t: self.t.get(k),
            n: self.sn.get(k),
        };
        (hit, ctx, frame, self.wo_local.get(k), self.lambert(k))
    }
}

/// Light samples of triangle lights for diffuse receivers: bit k of `active` marks lane k as
/// loaded.
pub(super) struct TriangleLightLanes {
    /// Loaded lanes.
    pub(super) active: u32,
    pmf: Lanes,
    /// The selection pmf inside the MIS weights (`SelectedLight::mis_pmf`).
    mis_pmf: Lanes,
    v: [V3; 3],
    n: V3,
    area: Lanes,
    l: V3,
    two_sided: [bool; PACKET],
    ok: [bool; PACKET],
}

impl TriangleLightLanes {
    /// No lanes loaded.
    pub(super) fn new() -> Self {
        Self {
            active: 0,
            pmf: [0.0; PACKET],
            mis_pmf: [0.0; PACKET],
            v: [V3::ZERO; 3],
            n: V3::ZERO,
            area: [0.0; PACKET],
            l: V3::ZERO,
            two_sided: [false; PACKET],
            ok: [false; PACKET],
        }
    }

    /// Load lane k: light `tri` picked with probability `pmf` (`mis_pmf` for the MIS weight).
    #[inline]
    pub(super) fn load(&mut self, k: usize, tri: &TriangleLight, pmf: f32, mis_pmf: f32) {
        self.active |= 1 << k;
        self.pmf[k] = pmf;
        self.mis_pmf[k] = mis_pmf;
        for (v, p) in self.v.iter_mut().zip(tri.p) {
            v.set(k, p);
        }
        self.n.set(k, tri.n);
        self.area[k] = tri.area;
        self.l.set(k, tri.l);
        self.two_sided[k] = tri.two_sided;
    }

    /// Every lane's estimate (loaded or not) sampled in `mode` with the draws `u` (lane k:
    /// `(u[0][k], u[1][k])`), MIS-weighted by `mis` when given, on instruction set `isa`,
    /// written to all the lanes of `out` (so before any lane's own); the loaded lanes with an
    /// estimate become active there. Returns their number.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn run(
        &mut self,
        rx: &Receivers,
        u: &[Lanes; 2],
        mis: Option<MisHeuristic>,
        mode: SamplingMode,
        cpu: Cpu,
        out: &mut ShadowRays,
    ) -> u32 {
        struct Run<'a> {
            lanes: &'a mut TriangleLightLanes,
            rx: &'a Receivers,
            u: &'a [Lanes; 2],
            mis: Option<MisHeuristic>,
            mode: SamplingMode,
            out: &'a mut ShadowRays,
        }
        impl Kernel for Run<'_> {
            type Output = u32;
            #[inline(always)]
            fn run<T: Token>(self, t: T) -> u32 {
                self.lanes
                    .dispatch(t, self.rx, self.u, self.mis, self.mode, self.out);
                mask_of(&self.lanes.ok)
            }
        }
        let ok = cpu.dispatch(Run {
            lanes: self,
            rx,
            u,
            mis,
            mode,
            out: &mut *out,
        }) & self.active;
        out.active |= ok;
        ok.count_ones()
    }

    /// One copy of the lane loop per (`mis`, `mode`), each with both constant, so each loop
    /// body is straight-line code for its own case.
    #[inline(always)]
    fn dispatch<T: Token>(
        &mut self,
        t: T,
        rx: &Receivers,
        u: &[Lanes; 2],
        mis: Option<MisHeuristic>,
        mode: SamplingMode,
        out: &mut ShadowRays,
    ) {
        use SamplingMode::{Area, SolidAngle};
        match (mis, mode) {
            (None, Area) => self.body(t, rx, u, None, Area, out),
            (None, SolidAngle) => self.body(t, rx, u, None, SolidAngle, out),
            (Some(MisHeuristic::Power), Area) => {
                self.body(t, rx, u, Some(MisHeuristic::Power), Area, out)
            }
            (Some(MisHeuristic::Power), SolidAngle) => {
                self.body(t, rx, u, Some(MisHeuristic::Power), SolidAngle, out)
            }
            (Some(MisHeuristic::Balance), Area) => {
                self.body(t, rx, u, Some(MisHeuristic::Balance), Area, out)
            }
            (Some(MisHeuristic::Balance), SolidAngle) => {
                self.body(t, rx, u, Some(MisHeuristic::Balance), SolidAngle, out)
            }
        }
    }

    /// The lane loop, specialised in each caller for its `mis` and `mode`.
    #[inline(always)]
    fn body<T: Token>(
        &mut self,
        t: T,
        rx: &Receivers,
        u: &[Lanes; 2],
        mis: Option<MisHeuristic>,
        mode: SamplingMode,
        out: &mut ShadowRays,
    ) {
        // A constant of each copy of the loop (`t.avx2()` is one for each token type), so the
        // loop holds one of the two ways of sampling, not a branch between them.
        let ahead = mode == SamplingMode::SolidAngle && t.avx2().is_some();
        let draws = if ahead {
            self.solid_angle_draws(t, rx, u)
        } else {
            [SolidAngleDraw::NONE; PACKET]
        };
        for k in 0..PACKET {
            let (hit, ctx, frame, wo_local, lambert) = rx.lane(k);
            let tri = TriangleLight {
                p: [self.v[0].get(k), self.v[1].get(k), self.v[2].get(k)],
                n: self.n.get(k),
                area: self.area[k],
                l: self.l.get(k),
                two_sided: self.two_sided[k],
            };
            let u = Vec2::new(u[0][k], u[1][k]);
            // A match, not `and_then`: the closure cost mis-area 0.38 → 0.50 s (dbcda06).
            let ls = if ahead {
                tri.sample_li_drawn(&ctx, u, Some(draws[k]))
            } else {
                tri.sample_li(&ctx, u, mode)
            };
            let est = match ls {
                Some(ls) => light_estimate(
                    &ls,
                    self.pmf[k],
                    self.mis_pmf[k],
                    &lambert,
                    &frame,
                    wo_local,
                    &ctx,
                    &hit,
                    mis,
                ),
                None => None,
            };
            let (ok, ray, value, w) = match est {
                Some((ray, value, w)) => (true, ray, value, w),
                None => (false, Ray::new(Vec3::ZERO, Vec3::ZERO), Rgb::ZERO, 1.0),
            };
            self.ok[k] = ok;
            out.put_weighted(k, &ray, value, w);
        }
    }
}

impl TriangleLightLanes {
    /// Every lane's [`SolidAngleDraw`] (the f64 half of its solid-angle sample, which
    /// [`TriangleLight::sample_li_drawn`] finishes), four lanes per register on AVX2, else
    /// lane by lane (the same bits). The kernel draws ahead on AVX2 only: on the other sets
    /// its lanes draw in `sample_li` itself. There the compiler vectorizes the whole lane loop,
    /// f64 half included, by masked AVX-512 instructions (eight f64 lanes per register), or
    /// nothing needs speed (portable code); with AVX2's lack of masks it left the f64 half
    /// scalar. On AVX-512 drawing ahead made cornell path 9 % slower (docs/path-tracing.md).
    #[inline(always)]
    fn solid_angle_draws<T: Token>(
        &self,
        t: T,
        rx: &Receivers,
        u: &[Lanes; 2],
    ) -> [SolidAngleDraw; PACKET] {
        #[cfg(target_arch = "x86_64")]
        if let Some(a) = t.avx2() {
            let mut draws = [SolidAngleDraw::NONE; PACKET];
            const { assert!(PACKET.is_multiple_of(4)) };
            for g in (0..PACKET).step_by(4) {
                fn q(l: &Lanes, g: usize) -> &[f32; 4] {
                    l[g..g + 4].try_into().expect("4 lanes")
                }
                // Written out, not `array::map`: that is a call, outside the AVX2 code.
                let p = [
                    q(&rx.cols.p[0], g),
                    q(&rx.cols.p[1], g),
                    q(&rx.cols.p[2], g),
                ];
                fn v3(v: &V3, g: usize) -> [&[f32; 4]; 3] {
                    [q(&v.x, g), q(&v.y, g), q(&v.z, g)]
                }
                let v = [v3(&self.v[0], g), v3(&self.v[1], g), v3(&self.v[2], g)];
                let d = SolidAngleDraw::lanes4(a, p, v, [q(&u[0], g), q(&u[1], g)]);
                draws[g..g + 4].copy_from_slice(&d);
            }
            return draws;
        }
        let _ = t;
        std::array::from_fn(|k| {
            let v = [self.v[0].get(k), self.v[1].get(k), self.v[2].get(k)];
            SolidAngleDraw::new(col(&rx.cols.p, k), v, Vec2::new(u[0][k], u[1][k]))
        })
    }
}

/// Cosine-sampled BSDF rays of diffuse receivers (every lane of [`Receivers::diffuse`] that is
/// loaded here with its draw).
pub(super) struct DiffuseBsdfLanes {
    /// Loaded lanes.
    pub(super) active: u32,
    ok: [bool; PACKET],
}

impl DiffuseBsdfLanes {
    /// No lanes loaded.
    pub(super) fn new() -> Self {
        Self {
            active: 0,
            ok: [false; PACKET],
        }
    }

    /// Every lane's ray (loaded or not) with direction draws `u` (lane k: `(u[0][k],
    /// u[1][k])`) on instruction set `isa`, written to all the lanes of `out` (so before any
    /// lane's own); the lanes of `active` with a ray become active there. Returns their number.
    pub(super) fn run(
        &mut self,
        rx: &Receivers,
        u: &[Lanes; 2],
        cpu: Cpu,
        out: &mut BsdfRays,
    ) -> u32 {
        struct Run<'a>(
            &'a mut DiffuseBsdfLanes,
            &'a Receivers,
            &'a [Lanes; 2],
            &'a mut BsdfRays,
        );
        impl Kernel for Run<'_> {
            type Output = u32;
            #[inline(always)]
            fn run<T: Token>(self, _: T) -> u32 {
                self.0.body(self.1, self.2, self.3);
                mask_of(&self.0.ok)
            }
        }
        let ok = cpu.dispatch(Run(self, rx, u, &mut *out)) & self.active;
        out.active |= ok;
        ok.count_ones()
    }

    /// The lane loop.
    #[inline(always)]
    fn body(&mut self, rx: &Receivers, u: &[Lanes; 2], out: &mut BsdfRays) {
        for k in 0..PACKET {
            let (hit, ctx, frame, wo_local, lambert) = rx.lane(k);
            let u = Vec2::new(u[0][k], u[1][k]);
            // A match, not `and_then`, as in the light kernel (measured there).
            let b = match lambert.sample(wo_local, 0.0, u) {
                Some(bs) => bsdf_ray_of(&bs, &frame, ctx.n, &hit),
                None => None,
            };
            let (ok, b) = match b {
                Some(b) => (true, b),
                None => (false, BsdfRay::NONE),
            };
            self.ok[k] = ok;
            out.put(k, &b);
        }
    }
}

/// Bit k set where `b[k]`.
// Read inside the kernel that wrote `b` (outside it: 2 % of cornell direct, AVX-512, perf).
#[inline(always)]
fn mask_of(b: &[bool; PACKET]) -> u32 {
    b.iter()
        .enumerate()
        .fold(0, |m, (k, &on)| m | (on as u32) << k)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::LobeSampling;
    use crate::isa::Isa;
    use crate::sampling::hash::{next_f32, pcg_from_keys};
    use rand_pcg::Pcg32;

    fn unit(rng: &mut Pcg32) -> Vec3 {
        loop {
            let v = Vec3::new(next_f32(rng), next_f32(rng), next_f32(rng)) * 2.0 - Vec3::ONE;
            if v.length_squared() > 1e-3 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }

    /// A packet of random receivers (points, normals slightly off the geometric ones, rays from
    /// either side, albedos) with their shading computed on `isa`.
    fn receivers(rng: &mut Pcg32, isa: Cpu) -> (Receivers, RayPacket) {
        let mut rx = Receivers::new();
        let mut rays = RayPacket::from_rays(&[Ray::new(Vec3::ZERO, Vec3::Z); PACKET]);
        for k in 0..PACKET {
            let p = unit(rng) * next_f32(rng);
            let ng = unit(rng);
            let ns = (ng + unit(rng) * 0.2).normalize();
            for a in 0..3 {
                rx.cols.p[a][k] = p[a];
                rx.cols.ng[a][k] = ng[a];
                rx.cols.ns[a][k] = ns[a];
            }
            rx.cols.p_error[k] = 1e-6 * next_f32(rng);
            rays.set(k, &Ray::new(Vec3::new(0.0, 0.0, -5.0), p - unit(rng) * 3.0));
            let albedo = Vec3::new(next_f32(rng), next_f32(rng), next_f32(rng));
            rx.set_diffuse(k, albedo);
        }
        rx.shade(&rays, isa);
        (rx, rays)
    }

    /// Lane k's per-lane state, made the way the per-lane path makes it.
    fn scalar_lane(
        rx: &Receivers,
        rays: &RayPacket,
        k: usize,
    ) -> (SurfaceHit, LightSampleContext, ShadingGeometry, Lambert) {
        let hit = SurfaceHit {
            t: 1.0,
            p: col(&rx.cols.p, k),
            ng: col(&rx.cols.ng, k),
            ns: col(&rx.cols.ns, k),
            uv: Vec2::ZERO,
            p_error: rx.cols.p_error[k],
            prim: 0,
            material: 0,
            light: 0,
        };
        let g = ShadingGeometry::new(rays.ray(k).d, hit.ng, hit.ns);
        let ctx = LightSampleContext { p: hit.p, n: g.n };
        (hit, ctx, g, Lambert::new(rx.albedo.get(k)))
    }

    fn bits(v: Vec3) -> [u32; 3] {
        v.to_array().map(f32::to_bits)
    }

    #[test]
    fn kernels_take_exactly_the_bsdfs_and_lights_they_reproduce() {
        use crate::bsdf::{Bsdf, LaneBsdf, Mirror};
        use crate::lights::{LaneLight, Light, PointLight};
        // The BSDF kernel draws cosine-weighted directions: importance and cosine sampling of a
        // Lambertian BSDF are that density, uniform sampling is not.
        let r = Vec3::new(0.2, 0.5, 0.7);
        for (s, kernel) in [
            (LobeSampling::Importance, true),
            (LobeSampling::Cosine, true),
            (LobeSampling::Uniform, false),
        ] {
            let b = Bsdf::Lambert(Lambert { r, sampling: s });
            match b.lane_kind() {
                Some(LaneBsdf::Lambert(a)) => assert!(kernel && a == r, "{s:?}"),
                None => assert!(!kernel, "{s:?}"),
            }
        }
        assert!(Bsdf::Mirror(Mirror { r: Vec3::ONE }).lane_kind().is_none());
        let v = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let tri = TriangleLight::new(v, Vec3::Z, Vec3::ONE, false).expect("has an area");
        assert!(matches!(
            Light::Triangle(tri).lane_kind(),
            Some(LaneLight::Triangle(_))
        ));
        let point = Light::Point(PointLight::new(Vec3::ZERO, Vec3::ONE));
        assert!(point.lane_kind().is_none());
    }

    #[test]
    fn light_kernel_lanes_equal_the_per_lane_functions_on_every_isa() {
        // The kernel's lanes must be bit for bit the per-lane functions on every instruction
        // set (no fused multiply-adds, no reordered sums, nothing dropped).
        let mut checked = 0;
        for isa in Isa::available() {
            for round in 0..24u64 {
                let mut rng = pcg_from_keys(&[7, round]);
                let (rx, rays) = receivers(&mut rng, isa.cpu());
                let mut lanes = TriangleLightLanes::new();
                let mut tris = Vec::new();
                for k in 0..PACKET {
                    let c = Vec3::new(0.0, 2.0, 0.0) + unit(&mut rng) * 0.5;
                    let v = [c + unit(&mut rng), c + unit(&mut rng), c + unit(&mut rng)];
                    let tri = TriangleLight::new(v, unit(&mut rng), Vec3::splat(4.0), k % 3 == 0)
                        .expect("a random triangle has an area");
                    let (pmf, u) = (0.5, Vec2::new(next_f32(&mut rng), next_f32(&mut rng)));
                    lanes.load(k, &tri, pmf, pmf);
                    tris.push((tri, pmf, u));
                }
                let draws = [0, 1].map(|a| std::array::from_fn(|k| tris[k].2[a]));
                let mode = [SamplingMode::Area, SamplingMode::SolidAngle][round as usize % 2];
                let mis = [None, Some(MisHeuristic::Power), Some(MisHeuristic::Balance)]
                    [round as usize % 3];
                let mut out = ShadowRays::new();
                let n = lanes.run(&rx, &draws, mis, mode, isa.cpu(), &mut out);
                assert_eq!(n, out.active.count_ones());
                for (k, (tri, pmf, u)) in tris.iter().enumerate() {
                    let (hit, ctx, g, lambert) = scalar_lane(&rx, &rays, k);
                    let want = tri.sample_li(&ctx, *u, mode).and_then(|ls| {
                        light_estimate(
                            &ls, *pmf, *pmf, &lambert, &g.frame, g.wo_local, &ctx, &hit, mis,
                        )
                    });
                    let what = format!("{isa:?} round {round} lane {k}");
                    assert_eq!(out.active >> k & 1 != 0, want.is_some(), "{what}");
                    if let Some((ray, value, w)) = want {
                        let got = out.rays.ray(k);
                        assert_eq!(bits(got.o), bits(ray.o), "{what}");
                        assert_eq!(bits(got.d), bits(ray.d), "{what}");
                        assert_eq!(got.t_max.to_bits(), ray.t_max.to_bits(), "{what}");
                        assert_eq!(bits(out.value(k)), bits(value), "{what}");
                        assert_eq!(out.weight(k).to_bits(), w.to_bits(), "{what}");
                        checked += 1;
                    }
                }
            }
        }
        // Enough lanes face their light for the comparison to mean something.
        assert!(checked > 100, "only {checked} lanes had an estimate");
    }

    #[test]
    fn bsdf_kernel_lanes_equal_the_per_lane_functions_on_every_isa() {
        let mut checked = 0;
        for isa in Isa::available() {
            for round in 0..16u64 {
                let mut rng = pcg_from_keys(&[8, round]);
                let (rx, rays) = receivers(&mut rng, isa.cpu());
                let mut lanes = DiffuseBsdfLanes::new();
                let u: Vec<Vec2> = (0..PACKET)
                    .map(|_| Vec2::new(next_f32(&mut rng), next_f32(&mut rng)))
                    .collect();
                lanes.active = u32::MAX >> (32 - PACKET);
                let draws = [0, 1].map(|a| std::array::from_fn(|k| u[k][a]));
                let mut out = BsdfRays::new();
                lanes.run(&rx, &draws, isa.cpu(), &mut out);
                for (k, &u) in u.iter().enumerate() {
                    let (hit, ctx, g, lambert) = scalar_lane(&rx, &rays, k);
                    let want = lambert
                        .sample(g.wo_local, 0.0, u)
                        .and_then(|bs| bsdf_ray_of(&bs, &g.frame, ctx.n, &hit));
                    let what = format!("{isa:?} round {round} lane {k}");
                    assert_eq!(out.active >> k & 1 != 0, want.is_some(), "{what}");
                    if let Some(b) = want {
                        let got = out.get(k);
                        assert_eq!(bits(got.ray.o), bits(b.ray.o), "{what}");
                        assert_eq!(bits(got.ray.d), bits(b.ray.d), "{what}");
                        assert_eq!(bits(got.weight), bits(b.weight), "{what}");
                        assert_eq!(got.pdf.to_bits(), b.pdf.to_bits(), "{what}");
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 100, "only {checked} lanes had a ray");
    }
}
