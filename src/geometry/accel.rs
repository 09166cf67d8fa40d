//! [`Geometry`]: every primitive of a scene behind one BVH — penumbra's 4-wide BVH with
//! 4-triangle packets ([`super::wide`], the default), its own binned-SAH BVH2 ([`super::bvh`]) or
//! obvhs's compressed-wide BVH (CWBVH), see [`Backend`].

use super::bvh::Bvh;
use super::packet::{ColumnSink, PACKET, PacketHits, PacketRays, bits};
use super::quadric::Quadric;
#[cfg(target_arch = "x86_64")]
use super::simd16::{Avx2, Avx512};
use super::simd16::{Portable, Simd};
use super::tree2::Tree2;
use super::triangle::{POINT_ERROR_GAMMA, RayShear, barycentric_error};
use super::wide::{Bary, WideBvh};
use super::{Ray, RayQuery, SurfaceHit};
use crate::isa::Isa;
use glam::{Vec2, Vec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::RayHit;
use std::time::{Duration, Instant};

/// Per-vertex data of a mesh that hit records interpolate.
#[derive(Clone, Debug, Default)]
pub struct MeshShading {
    /// Optional per-vertex shading normals.
    pub normals: Option<Vec<Vec3>>,
    /// Optional per-vertex texture coordinates.
    pub uvs: Option<Vec<Vec2>>,
    /// Flip the geometric normal (only when there are no vertex normals).
    pub flip: bool,
}

/// What a primitive is.
#[derive(Clone, Copy, Debug)]
pub enum PrimKind {
    /// Triangle `tri` (its vertex indices are `indices[3·tri..]`) of mesh `mesh`.
    Triangle {
        /// Mesh index into `Geometry::meshes`.
        mesh: u32,
        /// Vertex indices into the mesh's arrays.
        v: [u32; 3],
    },
    /// Index into `Geometry::quadrics`.
    Quadric(u32),
}

/// A primitive: triangle vertices inline for the hot intersection loop, plus its ids. Vertices
/// (not edges) are stored so that neighbours see bit-identical shared vertices (watertight).
#[derive(Clone, Copy, Debug)]
pub struct Primitive {
    /// Triangle vertices (unused for quadrics).
    pub p: [Vec3; 3],
    /// Shape.
    pub kind: PrimKind,
    /// Material index.
    pub material: u32,
    /// Area light index or `NO_LIGHT`.
    pub light: u32,
}

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
    pub(super) isa: Isa,
}

impl Geometry {
    /// The vector instruction set detected when this geometry was built (what its packet
    /// queries, and the integrator's lane kernels, run on).
    pub fn isa(&self) -> Isa {
        self.isa
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
        let (order, accel): (Vec<u32>, Accel) = if prims.is_empty() {
            (Vec::new(), Accel::None)
        } else {
            match backend {
                Backend::Wide => {
                    // PLOC + reinsertion gives the better tree; the binned-SAH one is
                    // depth-limited, so it is the fallback for degenerate inputs.
                    let mut tree = Tree2::ploc(&boxes);
                    let wide = match WideBvh::build(&tree, &prims) {
                        Some(w) => w,
                        None => {
                            tree = Tree2::from_bvh(Bvh::build(&boxes));
                            // Never empty: the binned-SAH tree is at most 64 levels deep.
                            WideBvh::build(&tree, &prims).unwrap_or_default()
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
            isa: Isa::detect(),
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
            PrimKind::Triangle { .. } => match shear.intersect(p.p[0], p.p[1], p.p[2], t_max) {
                Some((t, b0, b1, b2)) => (t, [b0, b1, b2]),
                None => (f32::INFINITY, NO_BARY),
            },
            PrimKind::Quadric(_) => (self.quadric_t(id, o, d, t_max), NO_BARY),
        }
    }

    /// Hit distance of non-triangle primitive `id` below `t_max`, or +∞.
    #[inline(always)]
    fn quadric_t(&self, id: usize, o: Vec3, d: Vec3, t_max: f32) -> f32 {
        match self.prims[id].kind {
            PrimKind::Quadric(q) => self.quadrics[q as usize]
                .intersect_t(o, d, t_max)
                .unwrap_or(f32::INFINITY),
            PrimKind::Triangle { .. } => f32::INFINITY,
        }
    }

    /// [`Self::quadric_t`] kept out of line for the wide traversal: inlined, the compiler
    /// hoists its per-ray setup (splats of the ray) out of the traversal loop, which every ray
    /// pays for although triangle-only scenes never run it.
    #[inline(never)]
    pub(super) fn quadric_t_outlined(&self, id: usize, o: Vec3, d: Vec3, t_max: f32) -> f32 {
        self.quadric_t(id, o, d, t_max)
    }

    /// Hit distance of primitive `id` below `t_max`, or +∞ (any-hit queries).
    #[inline(always)]
    fn prim_t(&self, id: usize, shear: &RayShear, o: Vec3, d: Vec3, t_max: f32) -> f32 {
        self.prim_hit(id, shear, o, d, t_max).0
    }

    /// The hit record of primitive `id` hit at `t` with triangle barycentrics `b`.
    pub(super) fn surface_hit(&self, id: usize, ray: &Ray, t: f32, b: Bary) -> SurfaceHit {
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
                let uv = match &m.uvs {
                    Some(uv) => {
                        uv[v[0] as usize] * b0 + uv[v[1] as usize] * b1 + uv[v[2] as usize] * b2
                    }
                    // pbrt-v4's default parameterisation (0,0), (1,0), (1,1).
                    None => Vec2::new(b1 + b2, b2),
                };
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

impl Geometry {
    /// The hit records of the rays `lanes` of a packet query (`hits` finished), into `out`,
    /// on backend `isa` (one this CPU runs): `out[i] = Some(self.surface_hit(..))` for each,
    /// bit for bit, and its point, normals and error bound to lane i of `cols`.
    pub(super) fn hit_records<R: PacketRays + ?Sized, C: ColumnSink>(
        &self,
        isa: Isa,
        rays: &R,
        hits: &PacketHits,
        lanes: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
        cols: &mut C,
    ) {
        match isa {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: callers pass a set this CPU runs (`Geometry::isa` or `Isa::supported`).
            Isa::Avx512 => unsafe { self.hit_records_avx512(rays, hits, lanes, out, cols) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above: the CPU runs AVX2.
            Isa::Avx2 => unsafe { self.hit_records_avx2(rays, hits, lanes, out, cols) },
            _ => self.hit_records_impl::<Portable, R, C>(rays, hits, lanes, out, cols),
        }
    }

    /// [`Self::hit_records_impl`] on AVX-512.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq")]
    fn hit_records_avx512<R: PacketRays + ?Sized, C: ColumnSink>(
        &self,
        rays: &R,
        hits: &PacketHits,
        lanes: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
        cols: &mut C,
    ) {
        self.hit_records_impl::<Avx512, R, C>(rays, hits, lanes, out, cols)
    }

    /// [`Self::hit_records_impl`] on AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn hit_records_avx2<R: PacketRays + ?Sized, C: ColumnSink>(
        &self,
        rays: &R,
        hits: &PacketHits,
        lanes: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
        cols: &mut C,
    ) {
        self.hit_records_impl::<Avx2, R, C>(rays, hits, lanes, out, cols)
    }

    /// Rays that hit the same triangle (most of a coherent packet) get their records on the
    /// vector lanes at once; single rays and quadric hits go through [`Self::surface_hit`].
    #[inline(always)]
    fn hit_records_impl<S: Simd, R: PacketRays + ?Sized, C: ColumnSink>(
        &self,
        rays: &R,
        hits: &PacketHits,
        mut lanes: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
        cols: &mut C,
    ) {
        let ids = S::load(&hits.id);
        while lanes != 0 {
            let first = lanes.trailing_zeros() as usize & (PACKET - 1);
            let group = S::bits(S::eq_bits(ids, S::splat(hits.id[first]))) & lanes;
            lanes &= !group;
            let id = hits.id[first].to_bits() as usize;
            // SAFETY: as in `surface_hit`, ids reported by a traversal index `prims`.
            let p = unsafe { self.prims.get_unchecked(id) };
            match p.kind {
                PrimKind::Triangle { mesh, v } if group & (group - 1) != 0 => {
                    self.triangle_records::<S, C>(id, p, mesh, v, hits, group, out, cols);
                }
                _ => {
                    for i in bits(group) {
                        let (id, t, b) = hits.hit(i);
                        let h = self.surface_hit(id, &rays.ray(i), t, b);
                        cols.set_lane(i, &h);
                        out[i] = Some(h);
                    }
                }
            }
        }
    }

    /// [`Self::surface_hit`]'s triangle branch for the rays `group`, which all hit triangle
    /// `id` (= `p`, of mesh `mesh` with vertex indices `v`): each lane does that branch's f32
    /// operations in its order (glam's `Vec3` arithmetic is per component), so the records
    /// are the same bits.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn triangle_records<S: Simd, C: ColumnSink>(
        &self,
        id: usize,
        p: &Primitive,
        mesh: u32,
        v: [u32; 3],
        hits: &PacketHits,
        group: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
        cols: &mut C,
    ) {
        let sp = S::splat;
        let zero = sp(0.0);
        let b = [
            S::load(&hits.b[0]),
            S::load(&hits.b[1]),
            S::load(&hits.b[2]),
        ];
        let verts = [p.p[0].to_array(), p.p[1].to_array(), p.p[2].to_array()];
        // pos = v0·b0 + v1·b1 + v2·b2 and `barycentric_error`'s sum of |products|.
        let mut pos = [zero; 3];
        let mut err = [zero; 3];
        for a in 0..3 {
            let q = [
                sp(verts[0][a]) * b[0],
                sp(verts[1][a]) * b[1],
                sp(verts[2][a]) * b[2],
            ];
            pos[a] = q[0] + q[1] + q[2];
            err[a] = (S::abs(q[0]) + S::abs(q[1]) + S::abs(q[2])) * sp(POINT_ERROR_GAMMA);
        }
        // SAFETY: `tri_ng` has one entry per primitive, and `id` indexes `prims`.
        let tri_ng = unsafe { *self.tri_ng.get_unchecked(id) }.to_array();
        let m = &self.meshes[mesh as usize];
        let (ng, ns) = match &m.normals {
            Some(n) => {
                let nv = [
                    n[v[0] as usize].to_array(),
                    n[v[1] as usize].to_array(),
                    n[v[2] as usize].to_array(),
                ];
                let mut r = [zero; 3];
                for a in 0..3 {
                    r[a] = sp(nv[0][a]) * b[0] + sp(nv[1][a]) * b[1] + sp(nv[2][a]) * b[2];
                }
                // `unit_or_zero`: 0 < 1/|r| < ∞ is its integer test as float compares.
                let rcp = S::div(sp(1.0), S::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]));
                let valid = S::and(S::lt(zero, rcp), S::lt(rcp, sp(f32::INFINITY)));
                let mut u = [zero; 3];
                let mut g = [zero; 3];
                for a in 0..3 {
                    u[a] = S::select(valid, r[a] * rcp, zero);
                    g[a] = sp(tri_ng[a]);
                }
                let is_zero = S::and(
                    S::and(S::eq(u[0], zero), S::eq(u[1], zero)),
                    S::eq(u[2], zero),
                );
                let d = g[0] * u[0] + g[1] * u[1] + g[2] * u[2];
                let flip = S::andnot(S::lt(d, zero), is_zero);
                let (mut ng, mut ns) = ([zero; 3], [zero; 3]);
                for a in 0..3 {
                    ng[a] = S::select(flip, sp(-tri_ng[a]), g[a]);
                    ns[a] = S::select(is_zero, g[a], u[a]);
                }
                (ng, ns)
            }
            None => {
                let n = if m.flip {
                    [-tri_ng[0], -tri_ng[1], -tri_ng[2]]
                } else {
                    tri_ng
                };
                let g = [sp(n[0]), sp(n[1]), sp(n[2])];
                (g, g)
            }
        };
        let uv = match &m.uvs {
            Some(uv) => {
                let w = [
                    uv[v[0] as usize].to_array(),
                    uv[v[1] as usize].to_array(),
                    uv[v[2] as usize].to_array(),
                ];
                let mut c = [zero; 2];
                for a in 0..2 {
                    c[a] = sp(w[0][a]) * b[0] + sp(w[1][a]) * b[1] + sp(w[2][a]) * b[2];
                }
                c
            }
            None => [b[1] + b[2], b[2]],
        };
        let p_error = err[0] * S::abs(ng[0]) + err[1] * S::abs(ng[1]) + err[2] * S::abs(ng[2]);
        cols.set_group::<S>(group, &pos, &ng, &ns, p_error);
        // The fields in `SurfaceHit`'s order, transposed to one row per ray.
        let rows = S::transpose([
            S::load(&hits.t),
            pos[0],
            pos[1],
            pos[2],
            ng[0],
            ng[1],
            ng[2],
            ns[0],
            ns[1],
            ns[2],
            uv[0],
            uv[1],
            p_error,
            sp(f32::from_bits(id as u32)),
            sp(f32::from_bits(p.material)),
            sp(f32::from_bits(p.light)),
        ]);
        for i in 0..PACKET {
            if group >> i & 1 != 0 {
                let mut rec = [0.0f32; PACKET];
                S::store(rows[i], &mut rec);
                out[i] = Some(SurfaceHit::from_lanes(rec));
            }
        }
    }
}

/// `v.normalize_or_zero()`, bit for bit (same length, reciprocal and product), but with the
/// validity test 0 < 1/|v| < ∞ as one integer compare: the positive finite non-zero floats
/// are exactly the bit patterns 1..=0x7f7f_ffff (zero wraps below, +∞, NaN and negative
/// values lie above), while the float form compiles to a dozen-instruction class test.
#[inline(always)]
fn unit_or_zero(v: Vec3) -> Vec3 {
    let rcp = 1.0 / v.dot(v).sqrt();
    if rcp.to_bits().wrapping_sub(1) < f32::MAX.to_bits() {
        v * rcp
    } else {
        Vec3::ZERO
    }
}

/// Unit geometric normal of triangle `p` (winding order), zero if degenerate.
fn triangle_normal(p: [Vec3; 3]) -> Vec3 {
    (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero()
}

fn prim_bounds(p: &Primitive, quadrics: &[Quadric]) -> (Vec3, Vec3) {
    match p.kind {
        PrimKind::Triangle { .. } => {
            let [a, b, c] = p.p;
            let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
            // Axis-aligned triangles have flat boxes, which slab tests may reject for rays that
            // do hit them: pad by a relative epsilon.
            let pad = (hi - lo).max_element() * 1e-6 + lo.abs().max(hi.abs()).max_element() * 1e-7;
            (lo - pad, hi + pad)
        }
        PrimKind::Quadric(q) => quadrics[q as usize].bounds(),
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
                self.quadric_t(id, ray.o, ray.d, ray.t_max) < ray.t_max
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

    /// [`RayQuery::intersect`] after the cheap pre-test, out of line: its frame (traversal
    /// stack, six saved registers) is not set up for rays that the pre-test rejects.
    #[inline(never)]
    pub(super) fn intersect_full(&self, ray: &Ray) -> Option<SurfaceHit> {
        let (id, t, b) = match &self.accel {
            // The wide BVH tests triangles itself; only quadrics come back here.
            Accel::Wide(bvh) => bvh.closest(ray.o, ray.d, ray.t_max, |id, t_max| {
                self.quadric_t_outlined(id, ray.o, ray.d, t_max)
            })?,
            _ => self.closest_by_callback(ray)?,
        };
        Some(self.surface_hit(id, ray, t, b))
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
        // The default backend by a compare; the others out of line (inline, LLVM folds all
        // four into a jump table that every shadow ray pays for).
        if let Accel::Wide(bvh) = &self.accel {
            return bvh.any(ray.o, ray.d, ray.t_max, |id| {
                self.quadric_t_outlined(id, ray.o, ray.d, ray.t_max) < ray.t_max
            });
        }
        self.occluded_other(ray)
    }
}
