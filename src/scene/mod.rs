//! Scenes: the [`Scene`] every integrator renders, the [`SceneBuilder`] every loader and built-in
//! scene fills, and the loaders themselves. Nothing below this module knows about file formats.
//! TODO(issue 3): builder (meshes → BVH, emissive triangles → lights), built-in `cornell`.
//! TODO(issue 5): pbrt-v4 loader (OBJ/MTL and glTF: `obj`, `gltf`, cameras in `view`).

pub mod builder;
pub mod builtin;
pub mod film;
pub mod gltf;
mod gltf_alpha;
pub mod gltf_check;
pub mod guard;
pub mod load;
pub mod loop_subdiv;
pub mod mesh_repair;
pub mod obj;
pub mod obj_text;
pub mod pbrt;
pub mod polygon;
pub mod shading_normals;
pub mod view;

pub use builder::SceneBuilder;

use crate::Rgb;
use crate::camera::Camera;
use crate::lights::Light;
use crate::material::Material;
use glam::{UVec2, Vec2, Vec3};

/// Pixel reconstruction filter, applied by filter importance sampling (every sample weight 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    /// Box of the given radius in pixels (0.5 = one pixel).
    Box {
        /// Radius (x, y).
        radius: Vec2,
    },
    /// Tent (triangle) of the given radius.
    Triangle {
        /// Radius (x, y).
        radius: Vec2,
    },
    /// pbrt-v4's gaussian (its default filter): the Gaussian of standard deviation `sigma`
    /// minus its value at the radius, per axis.
    Gaussian {
        /// Radius (x, y).
        radius: Vec2,
        /// Standard deviation in pixels.
        sigma: f32,
    },
    /// Mitchell–Netravali cubic with parameters B and C, stretched to the radius.
    Mitchell {
        /// Radius (x, y).
        radius: Vec2,
        /// B.
        b: f32,
        /// C.
        c: f32,
    },
    /// pbrt's "sinc": the Lanczos-windowed sinc, sinc(x)·sinc(x/τ) within the radius.
    Sinc {
        /// Radius (x, y).
        radius: Vec2,
        /// Window width τ.
        tau: f32,
    },
}

/// Output settings a scene file may carry (CLI flags override them).
#[derive(Clone, Debug)]
pub struct FilmSpec {
    /// Resolution in pixels.
    pub resolution: UVec2,
    /// Reconstruction filter.
    pub filter: Filter,
    /// Default output file name, if the scene names one.
    pub filename: Option<String>,
    /// Default eye rays per pixel, if the scene names one.
    pub spp: Option<u32>,
    /// Sensor response applied to the finished image (pbrt-v4 `iso`, exposure, white balance).
    pub sensor: film::SensorResponse,
}

/// Emission attached to a shape (pbrt `AreaLightSource "diffuse"`).
#[derive(Clone, Copy, Debug)]
pub struct AreaEmission {
    /// Radiance (already multiplied by any scale).
    pub l: Rgb,
    /// Emits on both sides.
    pub two_sided: bool,
}

/// An indexed triangle mesh in world space.
#[derive(Clone, Debug, Default)]
pub struct TriangleMesh {
    /// Vertex positions (world space).
    pub positions: Vec<Vec3>,
    /// Optional per-vertex shading normals (world space).
    pub normals: Option<Vec<Vec3>>,
    /// Optional per-vertex texture coordinates.
    pub uvs: Option<Vec<Vec2>>,
    /// Three indices per triangle.
    pub indices: Vec<u32>,
    /// pbrt's `ReverseOrientation` xor "transform swaps handedness": flips the geometric
    /// normal when the mesh has no per-vertex normals.
    pub flip_normals: bool,
}

/// A renderable scene.
pub struct Scene {
    /// Geometry and its BVH.
    pub geometry: crate::geometry::Geometry,
    /// The emissive primitives alone, with their own BVH (for BSDF rays seeking emitters).
    pub emitters: crate::geometry::Geometry,
    /// Materials, indexed by `SurfaceHit::material`.
    pub materials: Vec<Material>,
    /// Whether some material has a normal or bump map, decided when the scene is built (keep
    /// it true when adding such a material): without one, closest hits skip the perturbation
    /// pass (`shading_normals::perturb_hits`).
    pub perturbs_normals: bool,
    /// All lights; area lights are referenced by `SurfaceHit::light`.
    pub lights: Vec<Light>,
    /// Indices of infinite lights (added to rays that escape).
    pub infinite_lights: Vec<u32>,
    /// The camera.
    pub camera: Camera,
    /// Film settings.
    pub film: FilmSpec,
    /// What the scene file asks of the integrator (pbrt-v4's `Integrator`), if it says.
    pub integrator: Option<IntegratorSpec>,
}

/// The integrator settings of a render: each explicit choice (a CLI flag, a viewer or Python
/// argument), else the scene file's `Integrator`, else direct lighting, depth 5 and the default
/// light selection.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IntegratorChoice {
    /// Direct lighting or path tracing.
    pub kind: crate::integrator::IntegratorKind,
    /// Bounces (pbrt-v4's `maxdepth`).
    pub max_depth: u32,
    /// Light selection at every vertex.
    pub light_selection: crate::light_selection::SelectorKind,
}

impl Scene {
    /// What a render of this scene uses, given the caller's explicit choices (`None`: not
    /// chosen); the one place where flags, the file's `Integrator` and the defaults meet.
    pub fn integrator_choice(
        &self,
        kind: Option<crate::integrator::IntegratorKind>,
        max_depth: Option<u32>,
        light_selection: Option<crate::light_selection::SelectorKind>,
    ) -> IntegratorChoice {
        let file = self.integrator.as_ref();
        IntegratorChoice {
            kind: kind
                .or(file.map(|i| i.kind))
                .unwrap_or(crate::integrator::IntegratorKind::Direct),
            max_depth: max_depth.or(file.map(|i| i.max_depth)).unwrap_or(5),
            light_selection: light_selection
                .or_else(|| file.and_then(|i| i.light_selection))
                .unwrap_or(crate::light_selection::SelectorKind::DEFAULT),
        }
    }
}

/// A scene file's `Integrator` directive as penumbra renders it: the CLI's `--integrator`,
/// `--max-depth` and `--light-selection` override it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IntegratorSpec {
    /// Direct lighting or path tracing (`path`, and the integrators penumbra renders as path).
    pub kind: crate::integrator::IntegratorKind,
    /// `maxdepth` (pbrt-v4's default 5).
    pub max_depth: u32,
    /// `lightsampler` mapped to a selector name, when the file gives one.
    pub light_selection: Option<crate::light_selection::SelectorKind>,
}
