//! Pinhole perspective camera with pbrt-v4 conventions (fov on the shorter image axis, LookAt,
//! left-handed camera space looking down +z, +y up, raster y downward).
//! TODO(issue 3): implement; `generate_ray` is the contract.

use crate::geometry::{Ray, Transform};
use glam::Vec2;

/// A pinhole camera.
#[derive(Clone, Debug)]
pub struct Camera {
    /// Camera-to-world transform (pbrt's inverse of the CTM at `Camera`).
    pub camera_to_world: Transform,
    /// Full field of view in degrees, along the shorter image axis.
    pub fov_deg: f32,
    /// Screen window [xmin, xmax, ymin, ymax]; `None` = pbrt's default from the aspect ratio.
    pub screen_window: Option<[f32; 4]>,
}

impl Camera {
    /// The ray through continuous raster position `p_raster` (pixels, origin top-left) of a
    /// `res.x × res.y` image.
    pub fn generate_ray(&self, p_raster: Vec2, res: glam::UVec2) -> Ray {
        let _ = (p_raster, res);
        todo!("issue 3")
    }
}
