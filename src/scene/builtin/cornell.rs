//! The default scene: Bitterli's Cornell box exactly as in its pbrt-v4 file.

use super::cornell_data::{LIGHT, LIGHT_L, MATERIALS, MESHES, MeshData};
use super::{BuiltinOptions, Scene};
use crate::Rgb;
use crate::camera::Camera;
use crate::geometry::Transform;
use crate::material::{Material, Texture};
use crate::scene::{AreaEmission, FilmSpec, Filter, SceneBuilder, TriangleMesh};
use glam::{Mat4, UVec2, Vec2, Vec3};

/// The pbrt file's `Transform` (column-major, camera-from-world).
const CAMERA_FROM_WORLD: [f32; 16] = [
    1.0, -0.0, -0.0, -0.0, -0.0, 1.0, -0.0, -0.0, -0.0, -0.0, -1.0, -0.0, -0.0, -1.0, 6.8, 1.0,
];

/// The camera of the pbrt file.
pub fn cornell_camera() -> Camera {
    let m = Mat4::from_cols_array(&CAMERA_FROM_WORLD);
    let cam_from_world = Transform::new(m).expect("the Cornell camera matrix is invertible");
    Camera {
        camera_to_world: cam_from_world.inverse(),
        fov_deg: 19.5,
        screen_window: None,
        projection: crate::camera::Projection::Perspective,
        lens: crate::camera::Lens::PINHOLE,
    }
}

/// Film of the built-in scene: 512² (the file says 1024²), triangle filter of radius 1, 64 spp.
pub fn cornell_film() -> FilmSpec {
    FilmSpec {
        resolution: UVec2::new(512, 512),
        filter: Filter::Triangle { radius: Vec2::ONE },
        filename: None,
        spp: Some(64),
        sensor: Default::default(),
    }
}

fn mesh(d: &MeshData) -> TriangleMesh {
    let v3 = |a: &[f32]| {
        a.chunks_exact(3)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect()
    };
    TriangleMesh {
        positions: v3(d.p),
        normals: Some(v3(d.n)),
        uvs: Some(
            d.uv.chunks_exact(2)
                .map(|c| Vec2::new(c[0], c[1]))
                .collect(),
        ),
        indices: d.indices.to_vec(),
        flip_normals: false,
    }
}

/// Add the box (walls, blocks unless `blocks` is false, light) to a builder; returns the
/// material indices by name.
pub fn add_cornell_box(
    b: &mut SceneBuilder,
    blocks: bool,
) -> anyhow::Result<Vec<(&'static str, u32)>> {
    let ids: Vec<(&'static str, u32)> = MATERIALS
        .iter()
        .map(|(name, r)| {
            let m = Material::Diffuse {
                reflectance: Texture::Constant(Rgb::from_array(*r)),
            };
            (*name, b.add_material(m))
        })
        .collect();
    let id = |name: &str| ids.iter().find(|(n, _)| *n == name).map(|(_, i)| *i);
    for d in MESHES {
        if !blocks && d.material.ends_with("Box") {
            continue;
        }
        b.add_mesh(mesh(d), id(d.material).unwrap_or(0), None)?;
    }
    let emission = AreaEmission {
        l: Rgb::from_array(LIGHT_L),
        two_sided: false,
    };
    b.add_mesh(
        mesh(&LIGHT),
        id(LIGHT.material).unwrap_or(0),
        Some(emission),
    )?;
    Ok(ids)
}

/// Build the default Cornell box.
pub fn cornell(_opts: &BuiltinOptions) -> anyhow::Result<Scene> {
    let mut b = SceneBuilder::new();
    add_cornell_box(&mut b, true)?;
    let mut scene = b.build(cornell_camera(), cornell_film())?;
    // The file's `Integrator "path" "integer maxdepth" [ 65 ]`.
    scene.integrator = Some(crate::scene::IntegratorSpec {
        kind: crate::integrator::IntegratorKind::Path,
        max_depth: 65,
        light_selection: None,
    });
    Ok(scene)
}

/// The Cornell box with glossy spheres instead of blocks: modified Phong (front row, exponents
/// 10, 100, 1000) and GGX conductors (back row, floating: gold α = 0.05, copper α = 0.2, aluminium
/// α = 0.5), to show how the estimators handle glossy lobes.
pub fn cornell_phong(_opts: &BuiltinOptions) -> anyhow::Result<Scene> {
    let mut b = SceneBuilder::new();
    add_cornell_box(&mut b, false)?;
    let r = 0.28;
    for (i, n) in [10.0f32, 100.0, 1000.0].into_iter().enumerate() {
        let m = b.add_material(Material::Phong {
            kd: Texture::Constant(Rgb::new(0.25, 0.25, 0.35)),
            ks: Rgb::splat(0.6),
            n,
        });
        let c = Vec3::new(-0.62 + 0.62 * i as f32, r, 0.3);
        b.add_sphere(Transform::translate(c), r, m, None, false, None)?;
    }
    for (i, (metal, alpha)) in [("Au", 0.05f32), ("Cu", 0.2), ("Al", 0.5)]
        .into_iter()
        .enumerate()
    {
        let (eta, k) = crate::bsdf::named_metal(metal)
            .ok_or_else(|| anyhow::anyhow!("missing metal table for {metal}"))?;
        let m = b.add_material(Material::Conductor {
            eta,
            k,
            alpha: Vec2::splat(alpha),
            reflectance: None,
        });
        // Floating above the front row so the camera sees both rows.
        let c = Vec3::new(-0.62 + 0.62 * i as f32, 1.0, -0.35);
        b.add_sphere(Transform::translate(c), r, m, None, false, None)?;
    }
    b.build(cornell_camera(), cornell_film())
}
