//! The packet queries' rays and results: [`PACKET`] rays traced together (coherent camera
//! rays of one pixel, shadow rays from nearby points toward one light), passed as
//! `[Ray; PACKET]` or as a structure-of-arrays [`RayPacket`] ([`PacketRayForm`]), and the
//! [`HitColumns`] a query can fill beside its hit records. The queries themselves are
//! [`Geometry`](super::Geometry)'s (`accel/packet.rs`), their traversal the wide BVH's
//! (`wide/packet.rs`).

use super::simd16::Simd;
use super::{Ray, SurfaceHit};
use glam::Vec3;

/// Rays per packet query.
pub const PACKET: usize = 16;

/// [`PACKET`] rays in structure-of-arrays form (lane i = ray i), for callers whose rays are
/// already in vector lanes: the packet queries read them without the transpose that
/// `[Ray; PACKET]` needs (both are a [`PacketRayForm`]).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct RayPacket {
    /// Origins: `o[axis][lane]`.
    pub o: [[f32; PACKET]; 3],
    /// Directions: `d[axis][lane]` (need not be normalised, as in [`Ray`]).
    pub d: [[f32; PACKET]; 3],
    /// Upper bounds of the valid parameter ranges.
    pub t_max: [f32; PACKET],
}

impl RayPacket {
    /// The lanes of `rays`.
    pub fn from_rays(rays: &[Ray; PACKET]) -> Self {
        let mut p = RayPacket {
            o: [[0.0; PACKET]; 3],
            d: [[0.0; PACKET]; 3],
            t_max: [0.0; PACKET],
        };
        for (i, r) in rays.iter().enumerate() {
            p.set(i, r);
        }
        p
    }

    /// Ray `i` (`i` < [`PACKET`]).
    #[inline(always)]
    pub fn ray(&self, i: usize) -> Ray {
        let i = i & (PACKET - 1);
        Ray {
            o: Vec3::new(self.o[0][i], self.o[1][i], self.o[2][i]),
            d: Vec3::new(self.d[0][i], self.d[1][i], self.d[2][i]),
            t_max: self.t_max[i],
        }
    }

    /// Make lane `i` (`i` < [`PACKET`]) the ray `r`.
    #[inline(always)]
    pub fn set(&mut self, i: usize, r: &Ray) {
        let i = i & (PACKET - 1);
        for a in 0..3 {
            self.o[a][i] = r.o[a];
            self.d[a][i] = r.d[a];
        }
        self.t_max[i] = r.t_max;
    }
}

/// The camera-hit fields the integrator's lane kernels read, in structure-of-arrays form
/// (lane i = ray i), filled by the `*_cols` packet queries next to the hit records: for every
/// lane with a hit they are that record's fields bit for bit (other lanes: unspecified).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct HitColumns {
    /// Hit points: `p[axis][lane]`.
    pub p: [[f32; PACKET]; 3],
    /// Geometric normals: `ng[axis][lane]`.
    pub ng: [[f32; PACKET]; 3],
    /// Shading normals: `ns[axis][lane]`.
    pub ns: [[f32; PACKET]; 3],
    /// Error bounds of the hit points.
    pub p_error: [f32; PACKET],
}

impl HitColumns {
    /// All zero (the lanes of a query's misses stay as they are).
    pub const fn new() -> Self {
        HitColumns {
            p: [[0.0; PACKET]; 3],
            ng: [[0.0; PACKET]; 3],
            ns: [[0.0; PACKET]; 3],
            p_error: [0.0; PACKET],
        }
    }
}

impl Default for HitColumns {
    fn default() -> Self {
        Self::new()
    }
}

/// Where the packet queries put the columns of their hits: nowhere (`()`, the plain queries,
/// whose code then has no trace of it) or a [`HitColumns`].
pub(crate) trait ColumnSink {
    /// Lanes `group` (of the vectors `p`, `ng`, `ns`, `p_error`) are hits.
    fn set_group<S: Simd>(
        &mut self,
        s: S,
        group: u32,
        p: &[S::F; 3],
        ng: &[S::F; 3],
        ns: &[S::F; 3],
        p_error: S::F,
    );
    /// Lane `i` is the hit `h`.
    fn set_lane(&mut self, i: usize, h: &SurfaceHit);
}

impl ColumnSink for () {
    #[inline(always)]
    fn set_group<S: Simd>(
        &mut self,
        _: S,
        _: u32,
        _: &[S::F; 3],
        _: &[S::F; 3],
        _: &[S::F; 3],
        _: S::F,
    ) {
    }
    #[inline(always)]
    fn set_lane(&mut self, _: usize, _: &SurfaceHit) {}
}

impl ColumnSink for HitColumns {
    #[inline(always)]
    fn set_group<S: Simd>(
        &mut self,
        s: S,
        group: u32,
        p: &[S::F; 3],
        ng: &[S::F; 3],
        ns: &[S::F; 3],
        p_error: S::F,
    ) {
        // A blend with the old lanes: the other lanes may hold other hits already.
        let m = s.mask(group);
        for a in 0..3 {
            S::store(S::select(m, p[a], s.load(&self.p[a])), &mut self.p[a]);
            S::store(S::select(m, ng[a], s.load(&self.ng[a])), &mut self.ng[a]);
            S::store(S::select(m, ns[a], s.load(&self.ns[a])), &mut self.ns[a]);
        }
        S::store(
            S::select(m, p_error, s.load(&self.p_error)),
            &mut self.p_error,
        );
    }
    #[inline(always)]
    fn set_lane(&mut self, i: usize, h: &SurfaceHit) {
        let i = i & (PACKET - 1);
        for a in 0..3 {
            self.p[a][i] = h.p[a];
            self.ng[a][i] = h.ng[a];
            self.ns[a][i] = h.ns[a];
        }
        self.p_error[i] = h.p_error;
    }
}

/// The forms a packet's rays can be passed in to the packet queries
/// ([`Geometry::intersect_packet`](super::Geometry::intersect_packet),
/// [`Geometry::occluded_packet`](super::Geometry::occluded_packet) and their variants):
/// `[Ray; PACKET]` (one ray per element) or [`RayPacket`] (already in lanes, read without the
/// transpose). Sealed: implemented only for these two, since the kernels read the rays through
/// the crate's private vector types:
///
/// ```compile_fail
/// struct Mine;
/// impl penumbra::geometry::PacketRayForm for Mine {}
/// ```
pub trait PacketRayForm: sealed::PacketRays {}

impl PacketRayForm for [Ray; PACKET] {}

impl PacketRayForm for RayPacket {}

pub(crate) use sealed::PacketRays;

/// The kernels' view of a [`PacketRayForm`]; nominally `pub` inside a private module so that
/// it can be the public trait's supertrait while no other crate can name or implement it.
mod sealed {
    use super::super::simd16::Simd;
    use super::{PACKET, Ray, RayPacket};

    /// The two forms of a packet's rays the kernels read: `[Ray; PACKET]` and [`RayPacket`].
    pub trait PacketRays {
        /// `[o.x, o.y, o.z, d.x, d.y, d.z, t_max]` as lanes (see [`Simd::rays`]).
        fn lanes<S: Simd>(&self, s: S) -> [S::F; 7];
        /// Ray `i` (for the scalar steps).
        fn ray(&self, i: usize) -> Ray;
    }

    impl PacketRays for [Ray; PACKET] {
        #[inline(always)]
        fn lanes<S: Simd>(&self, s: S) -> [S::F; 7] {
            s.rays(self)
        }
        #[inline(always)]
        fn ray(&self, i: usize) -> Ray {
            self[i & (PACKET - 1)]
        }
    }

    impl PacketRays for RayPacket {
        #[inline(always)]
        fn lanes<S: Simd>(&self, s: S) -> [S::F; 7] {
            let (o, d) = (&self.o, &self.d);
            [
                s.load(&o[0]),
                s.load(&o[1]),
                s.load(&o[2]),
                s.load(&d[0]),
                s.load(&d[1]),
                s.load(&d[2]),
                s.load(&self.t_max),
            ]
        }
        #[inline(always)]
        fn ray(&self, i: usize) -> Ray {
            RayPacket::ray(self, i)
        }
    }
}

/// The lanes of a packet as a mask.
pub(crate) const PACKET_MASK: u32 = ((1u64 << PACKET) - 1) as u32;

/// Indices of the set bits of `m`, lowest first: the lanes of a packet mask.
#[inline(always)]
pub fn bits(mut m: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        if m == 0 {
            return None;
        }
        let i = m.trailing_zeros() as usize;
        m &= m - 1;
        Some(i)
    })
}
