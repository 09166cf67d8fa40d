//! [`Geometry`]: every primitive of a scene behind one BVH — penumbra's 4-wide BVH with
//! 4-triangle packets ([`super::wide`], the default; its one-ray queries run on 8-wide nodes
//! over the same packets where the CPU has AVX2), its own binned-SAH BVH2 ([`super::bvh`]) or
//! obvhs's compressed-wide BVH (CWBVH), see [`Backend`]. The one-ray queries and hit records
//! are here, the 16-ray packet queries in [`packet`].

mod packet;

use super::bvh::Bvh;
use super::primitive::{MeshShading, PrimKind, Primitive, prim_bounds, triangle_normal};
use super::quadric::Quadric;
use super::tree2::Tree2;
use super::triangle::{RayShear, barycentric_error};
use super::wide::{Bary, WideBvh};
use super::{Ray, RayQuery, SurfaceHit};
use crate::isa::{Cpu, Isa, Kernel, Token};
use glam::{Vec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::RayHit;
use std::time::{Duration, Instant};

/// Which acceleration structure [`Geometry`] builds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Backend {
    /// penumbra's binned-SAH BVH2.
    Own,
    /// obvhs's CWBVH.
    Obvhs,
    /// obvhs's PLOC BVH2 collapsed to a 4-wide BVH with 4-triangle SoA leaf packets (the
    /// default: fastest closest- and any-hit queries on cornell and dense, see `penumbra bench`).
    #[default]
    Wide,
}

/// The built acceleration structure.
enum Accel {
    None,
    Own(Bvh),
    Obvhs(CwBvh),
    Wide(WideBvh),
}

/// All scene geometry and its BVH.
pub struct Geometry {
    prims: Vec<Primitive>,
    /// Unit geometric normal of each triangle (by `prims` index; zero for quadrics), computed
    /// once here instead of per hit with the same expression, hence the same bits.
    tri_ng: Vec<Vec3>,
    /// Per-mesh shading data.
    pub meshes: Vec<MeshShading>,
    /// Spheres and disks.
    pub quadrics: Vec<Quadric>,
    accel: Accel,
    bounds: (Vec3, Vec3),
    /// Wall time of the BVH build.
    pub build_time: Duration,
    /// Vector instruction set of the packet queries, detected once here rather than per query.
    cpu: Cpu,
    /// Some mesh has an alpha cut-out (its triangles are tested through [`Self::other_t`]).
    has_alpha: bool,
}

impl Geometry {
    /// The vector instruction set detected when this geometry was built (what its packet
    /// queries, and the integrator's lane kernels, run on).
    pub fn isa(&self) -> Isa {
        self.cpu.isa()
    }

    /// [`Self::isa`] as the proof that this CPU runs it (what vector kernels dispatch on).
    pub fn cpu(&self) -> Cpu {
        self.cpu
    }

    /// Build the default BVH over `prims` (reordered internally so the BVH's leaf order is the
    /// storage order: one indirection less per intersection test).
    pub fn new(prims: Vec<Primitive>, meshes: Vec<MeshShading>, quadrics: Vec<Quadric>) -> Self {
        Self::with_backend(prims, meshes, quadrics, Backend::default())
    }

    /// Build the BVH of `backend` over `prims` (see [`Geometry::new`]).
    pub fn with_backend(
        prims: Vec<Primitive>,
        meshes: Vec<MeshShading>,
        quadrics: Vec<Quadric>,
        backend: Backend,
    ) -> Self {
        let start = Instant::now();
        let boxes: Vec<(Vec3, Vec3)> = prims.iter().map(|p| prim_bounds(p, &quadrics)).collect();
        let mut bounds = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for (lo, hi) in &boxes {
            bounds.0 = bounds.0.min(*lo);
            bounds.1 = bounds.1.max(*hi);
        }
        // Triangles of cut-out meshes are tested by `other_t` (with their alpha test), not by
        // the wide BVH's packet triangle tests.
        let mut called_back: Vec<bool> = prims
            .iter()
            .map(|p| match p.kind {
                PrimKind::Triangle { mesh, .. } => {
                    meshes.get(mesh as usize).is_some_and(|m| m.alpha.is_some())
                }
                PrimKind::Quadric(_) => false,
            })
            .collect();
        let has_alpha = called_back.contains(&true);
        if !has_alpha {
            called_back.clear();
        }
        let (order, accel): (Vec<u32>, Accel) = if prims.is_empty() {
            (Vec::new(), Accel::None)
        } else {
            match backend {
                Backend::Wide => {
                    // PLOC + reinsertion gives the better tree; the binned-SAH one is
                    // depth-limited, so it is the fallback for degenerate inputs.
                    let mut tree = Tree2::ploc(&boxes);
                    let wide = match WideBvh::build(&tree, &prims, &called_back) {
                        Some(w) => w,
                        None => {
                            tree = Tree2::from_bvh(Bvh::build(&boxes));
                            // Never empty: the binned-SAH tree is at most 64 levels deep.
                            WideBvh::build(&tree, &prims, &called_back).unwrap_or_default()
                        }
                    };
                    (tree.order, Accel::Wide(wide))
                }
                Backend::Own => {
                    let mut bvh = Bvh::build(&boxes);
                    (std::mem::take(&mut bvh.indices), Accel::Own(bvh))
                }
                Backend::Obvhs => {
                    let aabbs: Vec<Aabb> = boxes
                        .iter()
                        .map(|(lo, hi)| Aabb::new((*lo).into(), (*hi).into()))
                        .collect();
                    let mut t = Duration::ZERO;
                    let bvh = obvhs::cwbvh::builder::build_cwbvh(
                        &aabbs,
                        obvhs::BvhBuildParams::medium_build(),
                        &mut t,
                    );
                    (bvh.primitive_indices.clone(), Accel::Obvhs(bvh))
                }
            }
        };
        let prims: Vec<Primitive> = order.iter().map(|&i| prims[i as usize]).collect();
        let tri_ng = prims
            .iter()
            .map(|p| match p.kind {
                PrimKind::Triangle { .. } => triangle_normal(p.p),
                PrimKind::Quadric(_) => Vec3::ZERO,
            })
            .collect();
        Self {
            prims,
            tri_ng,
            meshes,
            quadrics,
            accel,
            bounds,
            build_time: start.elapsed(),
            cpu: Cpu::detect(),
            has_alpha,
        }
    }

    /// The same geometry behind a freshly built BVH of `backend` (benchmarks, backend tests).
    pub fn rebuild(&self, backend: Backend) -> Self {
        Self::with_backend(
            self.prims.clone(),
            self.meshes.clone(),
            self.quadrics.clone(),
            backend,
        )
    }

    /// Primitive `id` (the `prim` of a [`SurfaceHit`]); ids depend on the backend's leaf order.
    pub fn primitive(&self, id: u32) -> Option<&Primitive> {
        self.prims.get(id as usize)
    }

    /// Which backend was built (`None` for an empty scene).
    pub fn backend(&self) -> Option<Backend> {
        match self.accel {
            Accel::None => None,
            Accel::Own(_) => Some(Backend::Own),
            Accel::Obvhs(_) => Some(Backend::Obvhs),
            Accel::Wide(_) => Some(Backend::Wide),
        }
    }

    /// The default backend's BVH, if that is the one built (packet queries).
    pub(super) fn wide(&self) -> Option<&WideBvh> {
        match &self.accel {
            Accel::Wide(w) => Some(w),
            _ => None,
        }
    }

    /// Number of primitives.
    pub fn len(&self) -> usize {
        self.prims.len()
    }

    /// True if there is no primitive.
    pub fn is_empty(&self) -> bool {
        self.prims.is_empty()
    }

    /// World bounding box (min, max); inverted (∞, −∞) when empty.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    /// Hit distance of primitive `id` below `t_max` (else +∞) and, for triangles, the
    /// barycentrics of that hit, so the accepted closest hit needs no second triangle test.
    #[inline(always)]
    fn prim_hit(&self, id: usize, shear: &RayShear, o: Vec3, d: Vec3, t_max: f32) -> (f32, Bary) {
        let p = &self.prims[id];
        match p.kind {
            PrimKind::Triangle { .. } if self.has_alpha => self
                .alpha_triangle(id, o, d, t_max)
                .unwrap_or((f32::INFINITY, NO_BARY)),
            PrimKind::Triangle { .. } => match shear.intersect(p.p[0], p.p[1], p.p[2], t_max) {
                Some((t, b0, b1, b2)) => (t, [b0, b1, b2]),
                None => (f32::INFINITY, NO_BARY),
            },
            PrimKind::Quadric(_) => (self.other_t(id, o, d, t_max), NO_BARY),
        }
    }

    /// Hit distance below `t_max` (else +∞) of primitive `id` that the wide BVH does not test
    /// itself: a quadric, or a triangle of a cut-out mesh (alpha-tested).
    #[inline(always)]
    fn other_t(&self, id: usize, o: Vec3, d: Vec3, t_max: f32) -> f32 {
        match self.prims[id].kind {
            PrimKind::Quadric(q) => self.quadrics[q as usize]
                .intersect_t(o, d, t_max)
                .unwrap_or(f32::INFINITY),
            PrimKind::Triangle { .. } => self
                .alpha_triangle(id, o, d, t_max)
                .map_or(f32::INFINITY, |(t, _)| t),
        }
    }

    /// Triangle `id`'s hit below `t_max` (t, barycentrics) if its mesh's alpha mask keeps it
    /// (any hit of a triangle without one).
    #[inline(never)]
    fn alpha_triangle(&self, id: usize, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, Bary)> {
        let p = &self.prims[id];
        let PrimKind::Triangle { mesh, v } = p.kind else {
            return None;
        };
        let (t, b0, b1, b2) = RayShear::new(o, d).intersect(p.p[0], p.p[1], p.p[2], t_max)?;
        let b = [b0, b1, b2];
        let m = &self.meshes[mesh as usize];
        match &m.alpha {
            None => Some((t, b)),
            Some(a) => {
                let key = ((mesh as u64) << 32 | v[0] as u64)
                    ^ ((v[1] as u64) << 21 | (v[2] as u64) << 42);
                a.keeps(mesh_uv(m, v, b), o, d, key).then_some((t, b))
            }
        }
    }

    /// Barycentrics of the accepted hit at `t` of primitive `id`, whose traversal reported
    /// placeholders when it is a cut-out triangle (tested through [`Self::other_t`]): the same
    /// triangle test again, hence the same values.
    #[inline(always)]
    fn final_bary(&self, id: usize, ray: &Ray, b: Bary) -> Bary {
        if !self.has_alpha {
            return b;
        }
        let p = &self.prims[id];
        match p.kind {
            PrimKind::Triangle { mesh, .. } if self.meshes[mesh as usize].alpha.is_some() => {
                RayShear::new(ray.o, ray.d)
                    .intersect(p.p[0], p.p[1], p.p[2], f32::INFINITY)
                    .map_or(b, |(_, b0, b1, b2)| [b0, b1, b2])
            }
            _ => b,
        }
    }

    /// True if a hit on primitive `id` needs [`Self::final_bary`] (packet queries redo those).
    #[inline(always)]
    pub(super) fn is_cut_out(&self, id: usize) -> bool {
        self.has_alpha
            && match self.prims[id].kind {
                PrimKind::Triangle { mesh, .. } => self.meshes[mesh as usize].alpha.is_some(),
                PrimKind::Quadric(_) => false,
            }
    }

    /// [`Self::other_t`] kept out of line for the wide traversal, so that the rays of
    /// triangle-only scenes, which never run it, do not pay for its per-ray setup.
    #[inline(never)]
    pub(super) fn other_t_outlined(&self, id: usize, o: Vec3, d: Vec3, t_max: f32) -> f32 {
        self.other_t(id, o, d, t_max)
    }

    /// Hit distance of primitive `id` below `t_max`, or +∞ (any-hit queries).
    #[inline(always)]
    fn prim_t(&self, id: usize, shear: &RayShear, o: Vec3, d: Vec3, t_max: f32) -> f32 {
        self.prim_hit(id, shear, o, d, t_max).0
    }

    /// The hit record of primitive `id` hit at `t` with triangle barycentrics `b`.
    pub(super) fn surface_hit(&self, id: usize, ray: &Ray, t: f32, b: Bary) -> SurfaceHit {
        self.surface_hit_body(id, ray, t, b)
    }

    /// [`Self::surface_hit`], inlined into [`Self::intersect_full`]'s instruction-set versions.
    #[inline(always)]
    fn surface_hit_body(&self, id: usize, ray: &Ray, t: f32, b: Bary) -> SurfaceHit {
        // SAFETY: `id` comes from a traversal, which reports only ids it has tested: leaf-order
        // ids < prims.len() stored by the wide BVH's build, or ids the callback backends passed
        // to `prim_hit`, which indexes `prims` with a bounds check. `tri_ng` has one entry per
        // primitive.
        let (p, tri_ng) = unsafe { (self.prims.get_unchecked(id), *self.tri_ng.get_unchecked(id)) };
        match p.kind {
            PrimKind::Triangle { mesh, v } => {
                let [b0, b1, b2] = b;
                let verts = p.p;
                let pos = verts[0] * b0 + verts[1] * b1 + verts[2] * b2;
                let m = &self.meshes[mesh as usize];
                let mut ng = tri_ng;
                let ns = match &m.normals {
                    Some(n) => {
                        let ns = unit_or_zero(
                            n[v[0] as usize] * b0 + n[v[1] as usize] * b1 + n[v[2] as usize] * b2,
                        );
                        if ns == Vec3::ZERO {
                            ng
                        } else {
                            if ng.dot(ns) < 0.0 {
                                ng = -ng;
                            }
                            ns
                        }
                    }
                    None => {
                        if m.flip {
                            ng = -ng;
                        }
                        ng
                    }
                };
                let uv = mesh_uv(m, v, [b0, b1, b2]);
                let err = barycentric_error([b0, b1, b2], verts);
                SurfaceHit {
                    t,
                    p: pos,
                    ng,
                    ns,
                    uv,
                    p_error: err.dot(ng.abs()),
                    prim: id as u32,
                    material: p.material,
                    light: p.light,
                }
            }
            PrimKind::Quadric(q) => {
                let h = self.quadrics[q as usize].hit(ray.o, ray.d, t);
                SurfaceHit {
                    t,
                    p: h.p,
                    ng: h.n,
                    ns: h.n,
                    uv: h.uv,
                    p_error: h.p_error,
                    prim: id as u32,
                    material: p.material,
                    light: p.light,
                }
            }
        }
    }
}

/// `v.normalize_or_zero()`, bit for bit (same length, reciprocal and product), but with the
/// validity test 0 < 1/|v| < ∞ as one integer compare: the positive finite non-zero floats
/// are exactly the bit patterns 1..=0x7f7f_ffff (zero wraps below, +∞, NaN and negative
/// values lie above). Over the float compares: mis-area 2731 → 2721 Ir/sample (2fe2695).
#[inline(always)]
fn unit_or_zero(v: Vec3) -> Vec3 {
    let rcp = 1.0 / v.dot(v).sqrt();
    if rcp.to_bits().wrapping_sub(1) < f32::MAX.to_bits() {
        v * rcp
    } else {
        Vec3::ZERO
    }
}

/// Texture coordinates of mesh `m`'s triangle `v` at barycentrics `b`.
#[inline(always)]
fn mesh_uv(m: &MeshShading, v: [u32; 3], b: Bary) -> Vec2 {
    let [b0, b1, b2] = b;
    match &m.uvs {
        Some(uv) => uv[v[0] as usize] * b0 + uv[v[1] as usize] * b1 + uv[v[2] as usize] * b2,
        // pbrt-v4's default parameterisation (0,0), (1,0), (1,1).
        None => Vec2::new(b1 + b2, b2),
    }
}

/// Placeholder barycentrics for quadric hits (which do not use them).
const NO_BARY: Bary = [1.0 / 3.0; 3];

#[inline]
fn to_obvhs(ray: &Ray) -> obvhs::ray::Ray {
    // `+ 0.0` turns −0.0 into +0.0: obvhs derives the child order from the direction's sign
    // while its slab test inverts −0.0 to −∞, and the two disagree for axis-parallel rays.
    let d = ray.d + Vec3::ZERO;
    obvhs::ray::Ray::new(Vec3A::from(ray.o), Vec3A::from(d), 0.0, ray.t_max)
}

impl Geometry {
    /// Closest hit through a backend that calls back per primitive (own BVH2, obvhs):
    /// (leaf-order id, t, barycentrics).
    fn closest_by_callback(&self, ray: &Ray) -> Option<(usize, f32, Bary)> {
        let shear = RayShear::new(ray.o, ray.d);
        // Barycentrics of the best hit so far: a test result is accepted exactly when its t is
        // below the current best (the contract of both traversals), so record them then.
        let mut bary = NO_BARY;
        let mut leaf = |id: usize, t_max: f32| {
            let (t, b) = self.prim_hit(id, &shear, ray.o, ray.d, t_max);
            if t < t_max {
                bary = b;
            }
            t
        };
        let (id, t) = match &self.accel {
            Accel::None | Accel::Wide(_) => return None,
            Accel::Own(bvh) => bvh.closest(ray.o, ray.d, ray.t_max, &mut leaf)?,
            Accel::Obvhs(bvh) => {
                let mut hit = RayHit::none();
                let found = bvh.ray_traverse(to_obvhs(ray), &mut hit, |r, id| leaf(id, r.tmax));
                if !found {
                    return None;
                }
                (hit.primitive_id as usize, hit.t)
            }
        };
        Some((id, t, bary))
    }
}

impl Geometry {
    /// [`RayQuery::occluded`] for the backends other than the default one.
    #[inline(never)]
    fn occluded_other(&self, ray: &Ray) -> bool {
        let shear = || RayShear::new(ray.o, ray.d);
        match &self.accel {
            Accel::None => false,
            Accel::Wide(bvh) => bvh.any(ray.o, ray.d, ray.t_max, |id| {
                self.other_t(id, ray.o, ray.d, ray.t_max) < ray.t_max
            }),
            Accel::Own(bvh) => {
                let shear = shear();
                bvh.any(ray.o, ray.d, ray.t_max, |id| {
                    self.prim_t(id, &shear, ray.o, ray.d, ray.t_max) < ray.t_max
                })
            }
            Accel::Obvhs(bvh) => {
                let shear = shear();
                !bvh.ray_traverse_miss(to_obvhs(ray), |r, id| {
                    self.prim_t(id, &shear, ray.o, ray.d, r.tmax)
                })
            }
        }
    }

    /// [`RayQuery::intersect`] after the cheap pre-test, out of line, so that rays the
    /// pre-test rejects skip its setup (mis-area 2771 → 2731 Ir/sample, c225f85). Compiled
    /// for the detected instruction set ([`Cpu::dispatch`]): the same operations, VEX-encoded
    /// on AVX2 (three-operand forms, fewer register copies), hence the same bits.
    #[inline(never)]
    pub(super) fn intersect_full(&self, ray: &Ray) -> Option<SurfaceHit> {
        /// [`Geometry::intersect_body`] as a [`Kernel`].
        struct Closest1<'a>(&'a Geometry, &'a Ray);
        impl Kernel for Closest1<'_> {
            type Output = Option<SurfaceHit>;
            #[inline(always)]
            fn run<T: Token>(self, t: T) -> Self::Output {
                self.0.intersect_body(t, self.1)
            }
        }
        self.cpu.dispatch(Closest1(self, ray))
    }

    /// [`RayQuery::occluded`] on the default backend, compiled for the detected instruction
    /// set: through the 8-wide nodes where they exist (AVX2).
    #[inline(never)]
    fn occluded_wide(&self, bvh: &WideBvh, ray: &Ray) -> bool {
        /// The any-hit query as a [`Kernel`].
        struct Any1<'a>(&'a Geometry, &'a WideBvh, &'a Ray);
        impl Kernel for Any1<'_> {
            type Output = bool;
            #[inline(always)]
            fn run<T: Token>(self, t: T) -> bool {
                let Any1(g, bvh, ray) = self;
                let other = |id| g.other_t_outlined(id, ray.o, ray.d, ray.t_max) < ray.t_max;
                #[cfg(target_arch = "x86_64")]
                if let Some(avx2) = t.with_avx2() {
                    return bvh.any8(avx2, ray.o, ray.d, ray.t_max, other);
                }
                let _ = t;
                bvh.any(ray.o, ray.d, ray.t_max, other)
            }
        }
        self.cpu.dispatch(Any1(self, bvh, ray))
    }

    /// Start loading what [`Self::surface_hit`] reads of primitive `id` (its record and
    /// geometric normal), called at each new best hit of the traversal: on large scenes these
    /// are cache misses, which then overlap the rest of the traversal.
    #[inline(always)]
    fn prefetch_hit(&self, id: usize) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
            let p = self.prims.as_ptr().wrapping_add(id) as *const i8;
            let n = self.tri_ng.as_ptr().wrapping_add(id) as *const i8;
            // SAFETY: a prefetch is a hint that never faults, whatever the address.
            unsafe {
                _mm_prefetch(p, _MM_HINT_T0);
                _mm_prefetch(p.wrapping_add(size_of::<Primitive>() - 1), _MM_HINT_T0);
                _mm_prefetch(n, _MM_HINT_T0);
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = id;
    }

    /// The body of [`Self::intersect_full`], inlined into each instruction set's version.
    #[inline(always)]
    fn intersect_body<T: Token>(&self, isa: T, ray: &Ray) -> Option<SurfaceHit> {
        let (id, t, b) = match &self.accel {
            // The wide BVH tests triangles itself; only quadrics come back here.
            Accel::Wide(bvh) => {
                let other = |id, t_max| self.other_t_outlined(id, ray.o, ray.d, t_max);
                let found = |id| {
                    if bvh.is_large() {
                        self.prefetch_hit(id)
                    }
                };
                // The 8-wide nodes where the CPU runs AVX2 (the same hits).
                #[cfg(target_arch = "x86_64")]
                if let Some(avx2) = isa.with_avx2() {
                    let hit = bvh.closest8(avx2, ray.o, ray.d, ray.t_max, other, found)?;
                    return Some(self.wide_hit(ray, hit));
                }
                let _ = isa;
                bvh.closest_hinted(ray.o, ray.d, ray.t_max, other, found)?
            }
            _ => self.closest_by_callback(ray)?,
        };
        Some(self.surface_hit_body(id, ray, t, self.final_bary(id, ray, b)))
    }

    /// The hit record of a traversal's (leaf-order id, t, barycentrics).
    #[inline(always)]
    fn wide_hit(&self, ray: &Ray, (id, t, b): (usize, f32, Bary)) -> SurfaceHit {
        self.surface_hit_body(id, ray, t, self.final_bary(id, ray, b))
    }
}

impl RayQuery for Geometry {
    fn intersect(&self, ray: &Ray) -> Option<SurfaceHit> {
        // Most rays against the emitter-only geometry (one leaf on most scenes) miss it.
        if let Accel::Wide(bvh) = &self.accel
            && bvh.single_leaf_missed(ray.o, ray.d, ray.t_max)
        {
            return None;
        }
        self.intersect_full(ray)
    }

    fn occluded(&self, ray: &Ray) -> bool {
        // The default backend by a compare, the others out of line: mis-area 2721 → 2717 Ir/sample.
        if let Accel::Wide(bvh) = &self.accel {
            if bvh.has_nodes8() {
                return self.occluded_wide(bvh, ray);
            }
            return bvh.any(ray.o, ray.d, ray.t_max, |id| {
                self.other_t_outlined(id, ray.o, ray.d, ray.t_max) < ray.t_max
            });
        }
        self.occluded_other(ray)
    }
}
