//! [`Geometry`]'s 16-ray packet queries: one traversal of the wide BVH for the packet
//! ([`WideBvh::closest_packet`], [`WideBvh::any_packet`]), then the hit records of rays that
//! hit the same triangle formed on the vector lanes at once. Each lane's result equals the
//! one-ray query's ([`RayQuery::intersect`] / [`RayQuery::occluded`]) bit for bit.

use super::Geometry;
use crate::geometry::packet::{
    ColumnSink, HitColumns, PACKET, PACKET_MASK, PacketRayForm, PacketRays, bits,
};
use crate::geometry::primitive::{PrimKind, Primitive};
use crate::geometry::simd16::{OnSimd, Simd, SimdKernel};
use crate::geometry::triangle::POINT_ERROR_GAMMA;
use crate::geometry::wide::PacketHits;
use crate::geometry::{RayQuery, SurfaceHit};
#[cfg(doc)]
use crate::geometry::{packet::RayPacket, wide::WideBvh};
use crate::isa::{Cpu, Isa};

impl Geometry {
    /// Closest hit of each active ray (bit i of `active` ⇒ ray i is traced); out[i] = None for
    /// inactive lanes and misses. Equal, lane by lane, to `self.intersect(&ray_i)`. `rays` is
    /// either form of [`PacketRayForm`]: `[Ray; PACKET]` or [`RayPacket`].
    pub fn intersect_packet<R: PacketRayForm>(
        &self,
        rays: &R,
        active: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
    ) {
        self.intersect_packet_with(self.cpu, rays, active, out, &mut ());
    }

    /// [`Self::intersect_packet`] on a chosen vector backend (for tests and benchmarks; one
    /// this CPU does not run falls back to the widest it does).
    pub fn intersect_packet_on<R: PacketRayForm>(
        &self,
        isa: Isa,
        rays: &R,
        active: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
    ) {
        self.intersect_packet_with(isa.cpu(), rays, active, out, &mut ());
    }

    /// [`Self::intersect_packet`] that also writes the hits' points, normals and error bounds
    /// to `cols` (see [`HitColumns`]): for each lane i with `out[i] = Some(h)`, the columns'
    /// lane i holds `h.p`, `h.ng`, `h.ns`, `h.p_error` bit for bit.
    pub fn intersect_packet_cols<R: PacketRayForm>(
        &self,
        rays: &R,
        active: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
        cols: &mut HitColumns,
    ) {
        self.intersect_packet_with(self.cpu, rays, active, out, cols);
    }

    /// [`Self::intersect_packet_cols`] on a chosen vector backend (see
    /// [`Self::intersect_packet_on`]).
    pub fn intersect_packet_cols_on<R: PacketRayForm>(
        &self,
        isa: Isa,
        rays: &R,
        active: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
        cols: &mut HitColumns,
    ) {
        self.intersect_packet_with(isa.cpu(), rays, active, out, cols);
    }

    /// [`Self::intersect_packet`] on `cpu`, with the hits' columns to `cols`.
    fn intersect_packet_with<R: PacketRays + ?Sized, C: ColumnSink>(
        &self,
        cpu: Cpu,
        rays: &R,
        active: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
        cols: &mut C,
    ) {
        let active = active & PACKET_MASK;
        *out = [None; PACKET];
        // Only hits are stored below: whole `None`s cost 2657 vs 2643 Ir/sample (f592b8a).
        let Some(bvh) = self.wide() else {
            for i in bits(active) {
                if let Some(h) = self.intersect(&rays.ray(i)) {
                    cols.set_lane(i, &h);
                    out[i] = Some(h);
                }
            }
            return;
        };
        if bvh.is_single_leaf() {
            // Most scenes' emitter-only geometry, which most rays miss: its box test on the
            // vectors (`RayQuery::intersect`'s pre-test, lane by lane), then the scalar query
            // for the rays that enter the box.
            for i in bits(bvh.root_box_packet(cpu, rays, active)) {
                if let Some(h) = self.intersect_full(&rays.ray(i)) {
                    cols.set_lane(i, &h);
                    out[i] = Some(h);
                }
            }
            return;
        }
        let mut hits = PacketHits::new();
        bvh.closest_packet(cpu, rays, active, &mut hits, |id, ray, t_max| {
            self.other_t_outlined(id, ray.o, ray.d, t_max)
        });
        let mut ties = hits.ties;
        if self.has_alpha {
            // Cut-out hits carry placeholder barycentrics: the one-ray query forms those.
            for i in bits(hits.found & !ties) {
                if self.is_cut_out(hits.hit(i).0) {
                    ties |= 1 << i;
                }
            }
        }
        self.hit_records(cpu, rays, &hits, hits.found & !ties, out, cols);
        for i in bits(ties) {
            out[i] = self.intersect(&rays.ray(i));
            if let Some(h) = &out[i] {
                cols.set_lane(i, h);
            }
        }
    }

    /// Bit i set ⇔ ray i is active and `self.occluded(&ray_i)`; `rays` is either form of
    /// [`PacketRayForm`].
    ///
    /// One traversal of the wide BVH for the packet; a subtree that at most [`SPARSE`] of the
    /// rays enter is finished by the scalar query of each (incoherent shadow rays, e.g. on
    /// `dense`, would otherwise make the packet visit the union of the rays' subtrees).
    pub fn occluded_packet<R: PacketRayForm>(&self, rays: &R, active: u32) -> u32 {
        self.occluded_packet_with(self.cpu, rays, active)
    }

    /// [`Self::occluded_packet`] on a chosen vector backend (for tests and benchmarks; one
    /// this CPU does not run falls back to the widest it does).
    pub fn occluded_packet_on<R: PacketRayForm>(&self, isa: Isa, rays: &R, active: u32) -> u32 {
        self.occluded_packet_with(isa.cpu(), rays, active)
    }

    /// [`Self::occluded_packet`] on `cpu`.
    fn occluded_packet_with<R: PacketRays + ?Sized>(&self, cpu: Cpu, rays: &R, active: u32) -> u32 {
        let active = active & PACKET_MASK;
        let Some(bvh) = self.wide() else {
            return bits(active).fold(0, |m, i| m | (self.occluded(&rays.ray(i)) as u32) << i);
        };
        bvh.any_packet(cpu, rays, active, SPARSE, |id, ray| {
            self.other_t_outlined(id, ray.o, ray.d, ray.t_max) < ray.t_max
        })
    }
}

/// Subtrees entered by at most this many rays of a shadow packet are left to the scalar
/// any-hit query (measured on cornell and `dense --triangles 200000`: 4 was fastest on both,
/// 2 and 8 close behind; without the fallback `dense` was slower than scalar queries).
const SPARSE: u32 = 4;

impl Geometry {
    /// The hit records of the rays `lanes` of a packet query (`hits` finished), into `out`,
    /// on `cpu`: `out[i] = Some(self.surface_hit(..))` for each, bit for bit, and its point,
    /// normals and error bound to lane i of `cols`.
    fn hit_records<R: PacketRays + ?Sized, C: ColumnSink>(
        &self,
        cpu: Cpu,
        rays: &R,
        hits: &PacketHits,
        lanes: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
        cols: &mut C,
    ) {
        /// [`Geometry::hit_records_impl`]'s arguments.
        struct Records<'a, R: ?Sized, C> {
            g: &'a Geometry,
            rays: &'a R,
            hits: &'a PacketHits,
            lanes: u32,
            out: &'a mut [Option<SurfaceHit>; PACKET],
            cols: &'a mut C,
        }
        impl<R: PacketRays + ?Sized, C: ColumnSink> SimdKernel for Records<'_, R, C> {
            type Output = ();
            #[inline(always)]
            fn run<S: Simd>(self, s: S) {
                let k = self;
                k.g.hit_records_impl(s, k.rays, k.hits, k.lanes, k.out, k.cols)
            }
        }
        cpu.dispatch(OnSimd(Records {
            g: self,
            rays,
            hits,
            lanes,
            out,
            cols,
        }))
    }

    /// Rays that hit the same triangle (most of a coherent packet) get their records on the
    /// vector lanes at once; single rays and quadric hits go through [`Self::surface_hit`].
    #[inline(always)]
    fn hit_records_impl<S: Simd, R: PacketRays + ?Sized, C: ColumnSink>(
        &self,
        s: S,
        rays: &R,
        hits: &PacketHits,
        mut lanes: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
        cols: &mut C,
    ) {
        let ids = s.load(&hits.id);
        while lanes != 0 {
            let first = lanes.trailing_zeros() as usize & (PACKET - 1);
            let group = S::bits(S::eq_bits(ids, s.splat(hits.id[first]))) & lanes;
            lanes &= !group;
            let id = hits.id[first].to_bits() as usize;
            // SAFETY: as in `surface_hit`, ids reported by a traversal index `prims`.
            let p = unsafe { self.prims.get_unchecked(id) };
            match p.kind {
                PrimKind::Triangle { mesh, v } if group & (group - 1) != 0 => {
                    self.triangle_records(s, id, p, mesh, v, hits, group, out, cols);
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
        s: S,
        id: usize,
        p: &Primitive,
        mesh: u32,
        v: [u32; 3],
        hits: &PacketHits,
        group: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
        cols: &mut C,
    ) {
        let zero = s.splat(0.0);
        let b = [s.load(&hits.b[0]), s.load(&hits.b[1]), s.load(&hits.b[2])];
        let verts = [p.p[0].to_array(), p.p[1].to_array(), p.p[2].to_array()];
        // pos = v0·b0 + v1·b1 + v2·b2 and `barycentric_error`'s sum of |products|.
        let mut pos = [zero; 3];
        let mut err = [zero; 3];
        for a in 0..3 {
            let q = [
                s.splat(verts[0][a]) * b[0],
                s.splat(verts[1][a]) * b[1],
                s.splat(verts[2][a]) * b[2],
            ];
            pos[a] = q[0] + q[1] + q[2];
            err[a] = (S::abs(q[0]) + S::abs(q[1]) + S::abs(q[2])) * s.splat(POINT_ERROR_GAMMA);
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
                    r[a] = s.splat(nv[0][a]) * b[0]
                        + s.splat(nv[1][a]) * b[1]
                        + s.splat(nv[2][a]) * b[2];
                }
                // `unit_or_zero`: 0 < 1/|r| < ∞ is its integer test as float compares.
                let rcp = S::div(
                    s.splat(1.0),
                    S::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]),
                );
                let valid = S::and(S::lt(zero, rcp), S::lt(rcp, s.splat(f32::INFINITY)));
                let mut u = [zero; 3];
                let mut g = [zero; 3];
                for a in 0..3 {
                    u[a] = S::select(valid, r[a] * rcp, zero);
                    g[a] = s.splat(tri_ng[a]);
                }
                let is_zero = S::and(
                    S::and(S::eq(u[0], zero), S::eq(u[1], zero)),
                    S::eq(u[2], zero),
                );
                let d = g[0] * u[0] + g[1] * u[1] + g[2] * u[2];
                let flip = S::andnot(S::lt(d, zero), is_zero);
                let (mut ng, mut ns) = ([zero; 3], [zero; 3]);
                for a in 0..3 {
                    ng[a] = S::select(flip, s.splat(-tri_ng[a]), g[a]);
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
                let g = [s.splat(n[0]), s.splat(n[1]), s.splat(n[2])];
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
                    c[a] =
                        s.splat(w[0][a]) * b[0] + s.splat(w[1][a]) * b[1] + s.splat(w[2][a]) * b[2];
                }
                c
            }
            None => [b[1] + b[2], b[2]],
        };
        let p_error = err[0] * S::abs(ng[0]) + err[1] * S::abs(ng[1]) + err[2] * S::abs(ng[2]);
        cols.set_group(s, group, &pos, &ng, &ns, p_error);
        // The fields in `SurfaceHit`'s order, transposed to one row per ray.
        let rows = S::transpose([
            s.load(&hits.t),
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
            s.splat(f32::from_bits(id as u32)),
            s.splat(f32::from_bits(p.material)),
            s.splat(f32::from_bits(p.light)),
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
