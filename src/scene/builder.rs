//! [`SceneBuilder`]: what every loader and built-in scene calls to assemble a [`Scene`].
//! TODO(issue 3): implement (meshes → BVH primitives; emissive triangles → one light each).

use super::{AreaEmission, FilmSpec, Scene, TriangleMesh};
use crate::camera::Camera;
use crate::geometry::Transform;
use crate::lights::Light;
use crate::material::Material;

/// Accumulates shapes, materials and lights, then builds the BVH once.
#[derive(Default)]
pub struct SceneBuilder {
    /// Materials added so far.
    pub materials: Vec<Material>,
    /// Lights added so far (area lights are appended as emissive shapes are added).
    pub lights: Vec<Light>,
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

    /// Add a world-space triangle mesh. With `emission`, each triangle becomes its own
    /// [`crate::lights::TriangleLight`]. Errors on out-of-range indices or non-finite data;
    /// zero-area triangles are skipped.
    pub fn add_mesh(
        &mut self,
        mesh: TriangleMesh,
        material: u32,
        emission: Option<AreaEmission>,
    ) -> anyhow::Result<()> {
        let _ = (mesh, material, emission);
        todo!("issue 3")
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
        let _ = (to_world, radius, material, emission, reverse_orientation);
        todo!("issue 3")
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
        let _ = (
            to_world,
            height,
            radius,
            material,
            emission,
            reverse_orientation,
        );
        todo!("issue 3")
    }

    /// Add a light that is not attached to geometry (point, spot, distant, infinite).
    pub fn add_light(&mut self, light: Light) {
        self.lights.push(light);
    }

    /// Build the BVH and light tables.
    pub fn build(self, camera: Camera, film: FilmSpec) -> anyhow::Result<Scene> {
        let _ = (camera, film);
        todo!("issue 3")
    }
}
