//! [`SceneBuilder`]: what every loader and built-in scene calls to assemble a [`Scene`].

use super::mesh_repair::{MeshRepair, repair_mesh};
use super::{AreaEmission, FilmSpec, Scene, TriangleMesh};
use crate::camera::Camera;
use crate::geometry::{
    Alpha, Geometry, MeshShading, PrimKind, Primitive, Quadric, QuadricKind, Transform,
    interaction::NO_LIGHT, quadric::CutOut,
};
use crate::lights::{DiskLight, Light, MaskedTriangleLight, QuadLight, SphereLight, TriangleLight};
use crate::material::Material;
use anyhow::{Context, bail, ensure};
use glam::{Vec2, Vec3};

/// Segments around an emissive cylinder's tessellation ([`SceneBuilder::add_cylinder`]).
pub const CYLINDER_LIGHT_SEGMENTS: u32 = 64;

/// Grid (along φ, along the other parameter) of an emissive partial sphere's or disk's
/// tessellation ([`SceneBuilder::add_partial_sphere`], [`SceneBuilder::add_partial_disk`]).
pub const PARTIAL_LIGHT_GRID: (u32, u32) = (64, 16);

/// Accumulates shapes, materials and lights, then builds the BVH once.
#[derive(Default)]
pub struct SceneBuilder {
    /// Materials added so far.
    pub materials: Vec<Material>,
    /// Lights added so far (area lights are appended as emissive shapes are added).
    pub lights: Vec<Light>,
    prims: Vec<Primitive>,
    meshes: Vec<MeshShading>,
    quadrics: Vec<Quadric>,
    /// Meshes given to [`SceneBuilder::add_mesh`] so far (names them in warnings).
    meshes_seen: usize,
    /// What was repaired in meshes added with [`SceneBuilder::add_mesh`], one line per mesh.
    pub warnings: Vec<String>,
    /// Texture lookups at points only (no pixel footprints): MIP-mapped images read their
    /// finest level, checkerboards are not antialiased.
    point_textures: bool,
}

impl SceneBuilder {
    /// An empty builder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Add a material; returns its index.
    pub fn add_material(&mut self, m: Material) -> u32 {
        self.materials.push(m);
        (self.materials.len() - 1) as u32
    }

    /// Whether textures filter over each hit's pixel footprint (pbrt-v4's MIP-mapping and
    /// checkerboard antialiasing; the default) or are read at points.
    pub fn set_texture_filtering(&mut self, on: bool) {
        self.point_textures = !on;
    }

    /// Number of primitives added so far.
    pub fn primitive_count(&self) -> usize {
        self.prims.len()
    }

    fn check_material(&self, material: u32) -> anyhow::Result<()> {
        ensure!(
            (material as usize) < self.materials.len(),
            "material index {material} out of range ({} materials)",
            self.materials.len()
        );
        Ok(())
    }

    /// Add a world-space triangle mesh. With `emission`, each triangle becomes its own
    /// [`TriangleLight`]. What can be repaired is ([`repair_mesh`]: bad normals, zero-area or
    /// non-finite triangles; a mesh left empty is dropped) and noted in
    /// [`SceneBuilder::warnings`]; loaders that know file and line call
    /// [`SceneBuilder::add_mesh_repaired`] and word the warning themselves. Errors on
    /// out-of-range indices and attribute arrays of the wrong length.
    pub fn add_mesh(
        &mut self,
        mesh: TriangleMesh,
        material: u32,
        emission: Option<AreaEmission>,
    ) -> anyhow::Result<()> {
        let n = self.meshes_seen;
        let r = self.add_mesh_repaired(mesh, material, emission)?;
        if !r.is_clean() {
            self.warnings.push(format!("mesh #{n}: {}", r.describe()));
        }
        Ok(())
    }

    /// [`SceneBuilder::add_mesh`] that leaves the warning to the caller: returns what was
    /// repaired (nothing was added if `kept() == 0`).
    pub fn add_mesh_repaired(
        &mut self,
        mesh: TriangleMesh,
        material: u32,
        emission: Option<AreaEmission>,
    ) -> anyhow::Result<MeshRepair> {
        self.add_mesh_cut_out(mesh, material, emission, None)
    }

    /// [`SceneBuilder::add_mesh_repaired`] with an alpha cut-out (pbrt-v4's shape `alpha`):
    /// every ray query ignores the hits its mask does not keep (see [`Alpha`]).
    pub fn add_mesh_cut_out(
        &mut self,
        mut mesh: TriangleMesh,
        material: u32,
        emission: Option<AreaEmission>,
        alpha: Option<Alpha>,
    ) -> anyhow::Result<MeshRepair> {
        self.meshes_seen += 1;
        self.check_material(material)?;
        ensure!(
            mesh.indices.len().is_multiple_of(3),
            "mesh index count {} is not a multiple of 3",
            mesh.indices.len()
        );
        let nv = mesh.positions.len();
        if let Some(n) = &mesh.normals {
            ensure!(
                n.len() == nv,
                "mesh has {} normals for {nv} vertices",
                n.len()
            );
        }
        if let Some(uv) = &mesh.uvs {
            ensure!(
                uv.len() == nv,
                "mesh has {} uvs for {nv} vertices",
                uv.len()
            );
        }
        if let Some(&bad) = mesh.indices.iter().find(|&&i| i as usize >= nv) {
            bail!("mesh index {bad} out of range ({nv} vertices)");
        }
        if let Some(e) = &emission {
            check_emission(e)?;
        }
        let repair = repair_mesh(&mut mesh);
        if repair.kept() == 0 {
            return Ok(repair);
        }
        let TriangleMesh {
            positions,
            normals,
            uvs,
            indices,
            flip_normals,
        } = mesh;
        // Normalised here, once, so every loader and built-in scene agrees bit for bit.
        let normals = normals.map(|n| {
            n.into_iter()
                .map(|v| v.normalize_or_zero())
                .collect::<Vec<_>>()
        });
        let mesh_id = self.meshes.len() as u32;
        for tri in indices.chunks_exact(3) {
            let v = [tri[0], tri[1], tri[2]];
            let p = [
                positions[v[0] as usize],
                positions[v[1] as usize],
                positions[v[2] as usize],
            ];
            let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
            let cross = e1.cross(e2);
            let light = match &emission {
                Some(e) => {
                    // The emitting side is the hit record's geometric normal (pbrt-v4): the
                    // winding normal, flipped toward the vertex normals or by the orientation flag.
                    let mut n = cross.normalize();
                    match &normals {
                        Some(ns) => {
                            let avg = ns[v[0] as usize] + ns[v[1] as usize] + ns[v[2] as usize];
                            if n.dot(avg) < 0.0 {
                                n = -n;
                            }
                        }
                        None => {
                            if flip_normals {
                                n = -n;
                            }
                        }
                    }
                    let light =
                        TriangleLight::new(p, n, e.l, e.two_sided).and_then(|l| match &alpha {
                            None => Some(Light::Triangle(l)),
                            Some(a) => {
                                // pbrt-v4's default parameterisation without uvs, as the hit
                                // test's (0,0), (1,0), (1,1).
                                let uv = match &uvs {
                                    Some(uv) => v.map(|i| uv[i as usize]),
                                    None => [Vec2::ZERO, Vec2::X, Vec2::ONE],
                                };
                                MaskedTriangleLight::new(l, uv, a.clone())
                                    .map(|m| Light::MaskedTriangle(Box::new(m)))
                            }
                        });
                    match light {
                        Some(l) => {
                            self.lights.push(l);
                            (self.lights.len() - 1) as u32
                        }
                        None => NO_LIGHT,
                    }
                }
                None => NO_LIGHT,
            };
            self.prims.push(Primitive {
                p,
                kind: PrimKind::Triangle { mesh: mesh_id, v },
                material,
                light,
            });
        }
        self.meshes.push(MeshShading {
            normals,
            uvs,
            flip: flip_normals,
            alpha,
        });
        Ok(repair)
    }

    /// Add a parallelogram corner + s·e1 + t·e2 (s, t ∈ [0,1]) as two triangles, normal
    /// e1 × e2.
    pub fn add_quad(
        &mut self,
        corner: Vec3,
        e1: Vec3,
        e2: Vec3,
        material: u32,
        emission: Option<AreaEmission>,
    ) -> anyhow::Result<()> {
        let mesh = TriangleMesh {
            positions: vec![corner, corner + e1, corner + e1 + e2, corner + e2],
            normals: None,
            uvs: None,
            indices: vec![0, 1, 2, 0, 2, 3],
            flip_normals: false,
        };
        let before = self.prims.len();
        self.add_mesh(mesh, material, None)
            .context("adding a quad")?;
        if let Some(e) = emission {
            check_emission(&e)?;
            let n = e1.cross(e2).normalize_or_zero();
            // One light for the whole parallelogram, so it can be sampled by solid angle
            // (spherical rectangle) instead of as two triangles.
            if let Some(l) = QuadLight::new(corner, e1, e2, n, e.l, e.two_sided) {
                self.lights.push(Light::Quad(l));
                let id = (self.lights.len() - 1) as u32;
                for p in &mut self.prims[before..] {
                    p.light = id;
                }
            }
        }
        Ok(())
    }

    /// Add quadric `q` with the cut-out `alpha`, keyed by its index (every quadric's hash
    /// differs, in this geometry and in the emitters' copy alike).
    fn add_quadric(
        &mut self,
        mut q: Quadric,
        material: u32,
        emission: Option<AreaEmission>,
        alpha: Option<Alpha>,
    ) -> anyhow::Result<()> {
        if emission.is_some() && alpha.is_some() {
            // A mask over an emitter must mask its light samples too, which triangle lights
            // do (`MaskedTriangleLight`): a full sphere or disk becomes the partial one of
            // full range, tessellated with the same uv (the loader warns).
            let reverse = q.flip ^ q.to_world.swaps_handedness();
            let tau = std::f32::consts::TAU;
            match q.kind {
                QuadricKind::Sphere { radius } => {
                    let z = [-radius, radius, tau];
                    return self.add_partial_sphere(
                        q.to_world, radius, z, material, emission, reverse, alpha,
                    );
                }
                QuadricKind::Disk { height, radius } => {
                    let r = [radius, 0.0, tau];
                    return self.add_partial_disk(
                        q.to_world, height, r, material, emission, reverse, alpha,
                    );
                }
                _ => {}
            }
        }
        self.check_material(material)?;
        q.alpha = alpha.map(|alpha| CutOut {
            alpha,
            key: 1 << 63 | self.quadrics.len() as u64,
        });
        let light = match emission {
            Some(e) => {
                check_emission(&e)?;
                let light = quadric_light(&q, &e)?;
                self.lights.push(light);
                (self.lights.len() - 1) as u32
            }
            None => NO_LIGHT,
        };
        self.quadrics.push(q);
        self.prims.push(Primitive {
            p: [Vec3::ZERO; 3],
            kind: PrimKind::Quadric((self.quadrics.len() - 1) as u32),
            material,
            light,
        });
        Ok(())
    }

    /// Add a sphere of `radius` centred at the origin of `to_world`'s object space.
    /// `reverse_orientation` flips its normals (inward-facing emission).
    pub fn add_sphere(
        &mut self,
        to_world: Transform,
        radius: f32,
        material: u32,
        emission: Option<AreaEmission>,
        reverse_orientation: bool,
    ) -> anyhow::Result<()> {
        self.add_sphere_cut_out(
            to_world,
            radius,
            material,
            emission,
            reverse_orientation,
            None,
        )
    }

    /// [`SceneBuilder::add_sphere`] with an alpha cut-out over its uv (pbrt-v4's shape
    /// `alpha`). An emissive one becomes masked triangle lights (see `add_quadric`).
    pub fn add_sphere_cut_out(
        &mut self,
        to_world: Transform,
        radius: f32,
        material: u32,
        emission: Option<AreaEmission>,
        reverse_orientation: bool,
        alpha: Option<Alpha>,
    ) -> anyhow::Result<()> {
        ensure!(
            radius.is_finite() && radius > 0.0,
            "sphere radius must be positive and finite, got {radius}"
        );
        let q = Quadric {
            kind: QuadricKind::Sphere { radius },
            to_world,
            flip: reverse_orientation ^ to_world.swaps_handedness(),
            alpha: None,
        };
        self.add_quadric(q, material, emission, alpha)
    }

    /// Add a disk of `radius` in the z = `height` plane of `to_world`'s object space, normal +z.
    pub fn add_disk(
        &mut self,
        to_world: Transform,
        height: f32,
        radius: f32,
        material: u32,
        emission: Option<AreaEmission>,
        reverse_orientation: bool,
    ) -> anyhow::Result<()> {
        self.add_disk_cut_out(
            to_world,
            height,
            radius,
            material,
            emission,
            reverse_orientation,
            None,
        )
    }

    /// [`SceneBuilder::add_disk`] with an alpha cut-out over its uv (see
    /// [`SceneBuilder::add_sphere_cut_out`]).
    #[allow(clippy::too_many_arguments)]
    pub fn add_disk_cut_out(
        &mut self,
        to_world: Transform,
        height: f32,
        radius: f32,
        material: u32,
        emission: Option<AreaEmission>,
        reverse_orientation: bool,
        alpha: Option<Alpha>,
    ) -> anyhow::Result<()> {
        ensure!(
            radius.is_finite() && radius > 0.0 && height.is_finite(),
            "disk radius must be positive and finite (radius {radius}, height {height})"
        );
        let q = Quadric {
            kind: QuadricKind::Disk { height, radius },
            to_world,
            flip: reverse_orientation ^ to_world.swaps_handedness(),
            alpha: None,
        };
        self.add_quadric(q, material, emission, alpha)
    }

    /// Add pbrt-v4's partial sphere `[zmin, zmax, phimax (radians)]` of `radius` in
    /// `to_world`'s object space, with an optional alpha cut-out over its uv. An emissive one
    /// becomes a [`PARTIAL_LIGHT_GRID`] mesh of triangle lights with the sphere's normals and
    /// uvs (the loader warns).
    #[allow(clippy::too_many_arguments)]
    pub fn add_partial_sphere(
        &mut self,
        to_world: Transform,
        radius: f32,
        [zmin, zmax, phimax]: [f32; 3],
        material: u32,
        emission: Option<AreaEmission>,
        reverse_orientation: bool,
        alpha: Option<Alpha>,
    ) -> anyhow::Result<()> {
        ensure!(
            radius.is_finite() && radius > 0.0,
            "sphere radius must be positive and finite, got {radius}"
        );
        let (zmin, zmax) = (
            zmin.min(zmax).clamp(-radius, radius),
            zmin.max(zmax).clamp(-radius, radius),
        );
        ensure!(
            zmin < zmax && phimax > 0.0 && phimax.is_finite(),
            "partial sphere needs zmin < zmax within the radius and phimax > 0 (z {zmin}..{zmax}, phimax {phimax})"
        );
        let flip = reverse_orientation ^ to_world.swaps_handedness();
        if let Some(e) = emission {
            let (t0, t1) = ((zmin / radius).acos(), (zmax / radius).acos());
            let mesh = tessellate(&to_world, flip, PARTIAL_LIGHT_GRID, |u, v| {
                let (theta, phi) = (t0 + (t1 - t0) * v, u * phimax);
                let n = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                );
                (n * radius, n)
            });
            return self
                .add_mesh_cut_out(mesh, material, Some(e), alpha)
                .map(|_| ());
        }
        let q = Quadric {
            kind: QuadricKind::SphereCut {
                radius,
                zmin,
                zmax,
                phimax,
            },
            to_world,
            flip,
            alpha: None,
        };
        self.add_quadric(q, material, None, alpha)
    }

    /// Add pbrt-v4's annulus / partial disk (`inner` ≤ r ≤ `radius`, φ in [0, `phimax`]) in the
    /// z = `height` plane of `to_world`'s object space, with an optional alpha cut-out. An
    /// emissive one becomes a [`PARTIAL_LIGHT_GRID`] mesh of triangle lights (the loader warns).
    #[allow(clippy::too_many_arguments)]
    pub fn add_partial_disk(
        &mut self,
        to_world: Transform,
        height: f32,
        [radius, inner, phimax]: [f32; 3],
        material: u32,
        emission: Option<AreaEmission>,
        reverse_orientation: bool,
        alpha: Option<Alpha>,
    ) -> anyhow::Result<()> {
        ensure!(
            radius.is_finite() && radius > 0.0 && height.is_finite(),
            "disk radius must be positive and finite (radius {radius}, height {height})"
        );
        ensure!(
            (0.0..radius).contains(&inner) && phimax > 0.0 && phimax.is_finite(),
            "partial disk needs 0 ≤ innerradius < radius and phimax > 0 (inner {inner}, phimax {phimax})"
        );
        let flip = reverse_orientation ^ to_world.swaps_handedness();
        if let Some(e) = emission {
            let mesh = tessellate(&to_world, flip, PARTIAL_LIGHT_GRID, |u, v| {
                let (r, phi) = (radius - (radius - inner) * v, u * phimax);
                (Vec3::new(r * phi.cos(), r * phi.sin(), height), Vec3::Z)
            });
            return self
                .add_mesh_cut_out(mesh, material, Some(e), alpha)
                .map(|_| ());
        }
        let q = Quadric {
            kind: QuadricKind::DiskCut {
                height,
                radius,
                inner,
                phimax,
            },
            to_world,
            flip,
            alpha: None,
        };
        self.add_quadric(q, material, None, alpha)
    }

    /// Add pbrt-v4's cylinder `[radius, zmin, zmax, phimax (radians)]` of `to_world`'s object
    /// space (axis z). An emissive one becomes a mesh of
    /// [`CYLINDER_LIGHT_SEGMENTS`] × 2 triangle lights with the cylinder's normals (the
    /// lights sample triangles; the loader warns). `alpha`: an optional cut-out over its uv.
    pub fn add_cylinder(
        &mut self,
        to_world: Transform,
        [radius, zmin, zmax, phimax]: [f32; 4],
        material: u32,
        emission: Option<AreaEmission>,
        reverse_orientation: bool,
        alpha: Option<Alpha>,
    ) -> anyhow::Result<()> {
        ensure!(
            radius.is_finite() && radius > 0.0 && zmin.is_finite() && zmax.is_finite(),
            "cylinder radius must be positive and finite (radius {radius}, z {zmin}..{zmax})"
        );
        ensure!(
            zmin < zmax && phimax > 0.0 && phimax.is_finite(),
            "cylinder needs zmin < zmax and phimax > 0 (z {zmin}..{zmax}, phimax {phimax})"
        );
        // pbrt-v4's quadric rule, as for spheres and disks: the object-space ∂p/∂u × ∂p/∂v
        // is negated for ReverseOrientation XOR a handedness swap, then carried to world
        // space as a normal, so a mirrored cylinder faces inward.
        let flip = reverse_orientation ^ to_world.swaps_handedness();
        if let Some(e) = emission {
            // One band of quads around the sweep, wound (p1 − p0) × (p2 − p0) outward: along
            // +φ, then +z.
            let mesh = tessellate(&to_world, flip, (CYLINDER_LIGHT_SEGMENTS, 1), |u, v| {
                let (s, c) = (u * phimax).sin_cos();
                let z = if v == 0.0 { zmin } else { zmax };
                (Vec3::new(radius * c, radius * s, z), Vec3::new(c, s, 0.0))
            });
            return self
                .add_mesh_cut_out(mesh, material, Some(e), alpha)
                .map(|_| ());
        }
        let q = Quadric {
            kind: QuadricKind::Cylinder {
                radius,
                zmin,
                zmax,
                phimax,
            },
            to_world,
            flip,
            alpha: None,
        };
        self.add_quadric(q, material, None, alpha)
    }

    /// Add a world-space bilinear patch (corners p00, p10, p01, p11, their uvs), normal
    /// ∂p/∂u × ∂p/∂v (negated with `flip`), with an optional alpha cut-out over its uv; not
    /// emissive.
    pub fn add_bilinear_patch(
        &mut self,
        p: [Vec3; 4],
        uv: [glam::Vec2; 4],
        material: u32,
        flip: bool,
        alpha: Option<Alpha>,
    ) -> anyhow::Result<()> {
        ensure!(
            p.iter().all(|v| v.is_finite()) && uv.iter().all(|v| v.is_finite()),
            "bilinear patch corners and uvs must be finite"
        );
        let q = Quadric {
            kind: QuadricKind::Bilinear { p, uv },
            to_world: Transform::IDENTITY,
            flip,
            alpha: None,
        };
        self.add_quadric(q, material, None, alpha)
    }

    /// Add one cubic Bézier segment of a pbrt-v4 `curve` in `to_world`'s object space, with an
    /// optional alpha cut-out over its (u along, v across) (not emissive).
    pub fn add_curve(
        &mut self,
        to_world: Transform,
        segment: crate::geometry::curve::CurveSegment,
        material: u32,
        reverse_orientation: bool,
        alpha: Option<Alpha>,
    ) -> anyhow::Result<()> {
        ensure!(
            segment.cp.iter().all(|p| p.is_finite())
                && segment.width.iter().all(|w| w.is_finite() && *w >= 0.0),
            "curve control points and widths must be finite (widths ≥ 0)"
        );
        let q = Quadric {
            kind: QuadricKind::Curve(segment),
            to_world,
            // pbrt-v4's curves flip as its quadrics do.
            flip: reverse_orientation ^ to_world.swaps_handedness(),
            alpha: None,
        };
        self.add_quadric(q, material, None, alpha)
    }

    /// Add a light that is not attached to geometry (point, spot, distant, infinite).
    pub fn add_light(&mut self, light: Light) {
        self.lights.push(light);
    }

    /// Build the BVH and light tables.
    pub fn build(self, camera: Camera, film: FilmSpec) -> anyhow::Result<Scene> {
        ensure!(
            film.resolution.x > 0 && film.resolution.y > 0,
            "film resolution must be positive, got {}x{}",
            film.resolution.x,
            film.resolution.y
        );
        let emitters = emitter_geometry(&self.prims, &self.meshes, &self.quadrics);
        let geometry = Geometry::new(self.prims, self.meshes, self.quadrics);
        let mut lights = self.lights;
        let (lo, hi) = geometry.bounds();
        let (center, radius) = if lo.x <= hi.x {
            ((lo + hi) * 0.5, ((hi - lo) * 0.5).length().max(1e-3))
        } else {
            (Vec3::ZERO, 1.0)
        };
        for l in &mut lights {
            l.preprocess(center, radius);
        }
        let infinite_lights = lights
            .iter()
            .enumerate()
            .filter(|(_, l)| l.is_infinite())
            .map(|(i, _)| i as u32)
            .collect();
        let mut materials = self.materials;
        let filtering: Vec<bool> = materials.iter().map(Material::filters_textures).collect();
        if !self.point_textures && filtering.contains(&true) {
            let fp = std::sync::Arc::new(crate::material::Footprint::new(
                &camera,
                film.resolution,
                film.spp.unwrap_or(64),
                &geometry,
                |m| filtering.get(m as usize).copied().unwrap_or(false),
            ));
            for (m, f) in materials.iter_mut().zip(&filtering) {
                if *f {
                    let base = std::mem::replace(m, Material::Mirror);
                    *m = Material::Filtered {
                        base: Box::new(base),
                        footprint: fp.clone(),
                    };
                }
            }
        }
        Ok(Scene {
            geometry,
            emitters,
            materials,
            lights,
            infinite_lights,
            camera,
            film,
            integrator: None,
        })
    }
}

/// The emissive primitives alone, behind their own BVH, with only the meshes and quadrics they
/// use: BSDF rays look for the nearest emitter here first and test visibility only when one is
/// found, so the many BSDF rays that miss every light cost a few box tests instead of a
/// closest-hit query of the whole scene.
fn emitter_geometry(prims: &[Primitive], meshes: &[MeshShading], quadrics: &[Quadric]) -> Geometry {
    let mut mesh_map = vec![u32::MAX; meshes.len()];
    let mut quadric_map = vec![u32::MAX; quadrics.len()];
    let (mut own_meshes, mut own_quadrics) = (Vec::new(), Vec::new());
    let own_prims = prims
        .iter()
        .filter(|p| p.light != NO_LIGHT)
        .map(|p| {
            let mut p = *p;
            p.kind = match p.kind {
                PrimKind::Triangle { mesh, v } => {
                    let m = &mut mesh_map[mesh as usize];
                    if *m == u32::MAX {
                        *m = own_meshes.len() as u32;
                        own_meshes.push(meshes[mesh as usize].clone());
                    }
                    PrimKind::Triangle { mesh: *m, v }
                }
                PrimKind::Quadric(q) => {
                    let m = &mut quadric_map[q as usize];
                    if *m == u32::MAX {
                        *m = own_quadrics.len() as u32;
                        own_quadrics.push(quadrics[q as usize].clone());
                    }
                    PrimKind::Quadric(*m)
                }
            };
            p
        })
        .collect();
    Geometry::new(own_prims, own_meshes, own_quadrics)
}

/// A `(nu, nv)` grid triangle mesh of the object-space surface `f(u, v) → (point, normal)` over
/// [0, 1]², in world space, with the surface's normals (negated with `flip`) and uv = (u, v);
/// wound so the triangles' normals agree with the vertex normals.
fn tessellate(
    to_world: &Transform,
    flip: bool,
    (nu, nv): (u32, u32),
    f: impl Fn(f32, f32) -> (Vec3, Vec3),
) -> TriangleMesh {
    let nt = to_world.m_inv.transpose();
    let (mut positions, mut normals, mut uvs, mut indices) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for i in 0..=nu {
        for j in 0..=nv {
            let (u, v) = (i as f32 / nu as f32, j as f32 / nv as f32);
            let (p, n) = f(u, v);
            positions.push(to_world.point(p));
            let n = nt.transform_vector3(n).normalize_or_zero();
            normals.push(if flip { -n } else { n });
            uvs.push(glam::Vec2::new(u, v));
        }
    }
    let at = |i: u32, j: u32| i * (nv + 1) + j;
    for i in 0..nu {
        for j in 0..nv {
            indices.extend_from_slice(&[at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            indices.extend_from_slice(&[at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    TriangleMesh {
        positions,
        normals: Some(normals),
        uvs: Some(uvs),
        indices,
        flip_normals: flip,
    }
}

fn check_emission(e: &AreaEmission) -> anyhow::Result<()> {
    ensure!(
        e.l.is_finite() && e.l.min_element() >= 0.0,
        "emitted radiance must be finite and non-negative, got {:?}",
        e.l
    );
    Ok(())
}

/// The area light of an emissive sphere or disk. Lights are analytic in world space, so the
/// transform must scale uniformly (rotations, translations and mirrors are fine).
fn quadric_light(q: &Quadric, e: &AreaEmission) -> anyhow::Result<Light> {
    let m = &q.to_world.m;
    let sx = m.x_axis.truncate().length();
    let sy = m.y_axis.truncate().length();
    let sz = m.z_axis.truncate().length();
    let uniform = (sx - sy).abs() <= 1e-4 * sx && (sx - sz).abs() <= 1e-4 * sx;
    ensure!(
        uniform,
        "emissive spheres and disks need a uniformly scaling transform (scales {sx}, {sy}, {sz})"
    );
    let light = match q.kind {
        QuadricKind::Sphere { radius } => {
            let c = q.to_world.point(Vec3::ZERO);
            SphereLight::new(c, radius * sx, e.l, q.flip)
                .map(|s| Light::Sphere(s.with_two_sided(e.two_sided)))
        }
        QuadricKind::Disk { height, radius } => {
            let c = q.to_world.point(Vec3::new(0.0, 0.0, height));
            let mut n = q.to_world.normal(Vec3::Z).normalize_or_zero();
            if q.flip {
                n = -n;
            }
            DiskLight::new(c, n, radius * sx, e.l, e.two_sided).map(Light::Disk)
        }
        QuadricKind::Cylinder { .. }
        | QuadricKind::SphereCut { .. }
        | QuadricKind::DiskCut { .. }
        | QuadricKind::Bilinear { .. }
        | QuadricKind::Curve(_) => None,
    };
    light.ok_or_else(|| anyhow::anyhow!("degenerate emissive shape"))
}
