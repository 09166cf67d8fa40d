//! Pinhole perspective camera with pbrt-v4 conventions: camera space is left-handed, looking
//! down +z with +y up and +x to the right of the image; the field of view spans the shorter
//! image axis; raster y grows downward.

use crate::geometry::{Ray, Transform};
use glam::{UVec2, Vec2, Vec3};

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
    /// A camera at `eye` looking at `target` (pbrt `LookAt` semantics).
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, fov_deg: f32) -> anyhow::Result<Self> {
        let cam_from_world = Transform::look_at(eye, target, up)?;
        Ok(Self {
            camera_to_world: cam_from_world.inverse(),
            fov_deg,
            screen_window: None,
        })
    }

    /// The screen window in effect for resolution `res`.
    pub fn window(&self, res: UVec2) -> [f32; 4] {
        if let Some(w) = self.screen_window {
            return w;
        }
        let aspect = res.x as f32 / res.y as f32;
        if aspect > 1.0 {
            [-aspect, aspect, -1.0, 1.0]
        } else {
            [-1.0, 1.0, -1.0 / aspect, 1.0 / aspect]
        }
    }

    /// Everything `generate_ray` needs for resolution `res`, computed once per render rather
    /// than once per ray.
    pub fn rays(&self, res: UVec2) -> CameraRays {
        let m = self.camera_to_world.m;
        CameraRays {
            origin: self.camera_to_world.point(Vec3::ZERO),
            axes: [
                m.x_axis.truncate(),
                m.y_axis.truncate(),
                m.z_axis.truncate(),
            ],
            win: self.window(res),
            tan_half: (self.fov_deg.to_radians() * 0.5).tan(),
            res: res.as_vec2(),
        }
    }

    /// The ray through continuous raster position `p_raster` (pixels, origin top-left) of a
    /// `res.x × res.y` image. The direction is unit length.
    pub fn generate_ray(&self, p_raster: Vec2, res: UVec2) -> Ray {
        self.rays(res).generate(p_raster)
    }

    /// Continuous raster position of world point `p`, or `None` if it is behind the camera.
    pub fn project(&self, p: Vec3, res: UVec2) -> Option<Vec2> {
        let pc = self.camera_to_world.m_inv.transform_point3(p);
        if pc.z <= 0.0 {
            return None;
        }
        let win = self.window(res);
        let tan_half = (self.fov_deg.to_radians() * 0.5).tan();
        let sx = pc.x / pc.z / tan_half;
        let sy = pc.y / pc.z / tan_half;
        Some(Vec2::new(
            (sx - win[0]) / (win[1] - win[0]) * res.x as f32,
            (win[3] - sy) / (win[3] - win[2]) * res.y as f32,
        ))
    }
}

/// A camera set up for one resolution: the per-render constants of [`Camera::generate_ray`].
#[derive(Clone, Copy, Debug)]
pub struct CameraRays {
    origin: Vec3,
    /// The first three columns of `camera_to_world.m` (its action on vectors).
    axes: [Vec3; 3],
    win: [f32; 4],
    tan_half: f32,
    res: Vec2,
}

impl CameraRays {
    /// The unit-direction ray through continuous raster position `p`.
    #[inline]
    pub fn generate(&self, p: Vec2) -> Ray {
        Ray::new(self.origin, self.direction(p))
    }

    /// The origin of every ray (the eye).
    #[inline]
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// The unit direction of [`CameraRays::generate`]: the one definition of the camera math.
    /// Plain f32 arithmetic (no 4-lane matrix code), so that a loop over many positions
    /// vectorises lane by lane; the transform multiplies and adds in the order of glam's
    /// `Mat4::transform_vector3` (x, then + y, then + z), so the bits are those of
    /// `camera_to_world.vector(d).normalize()`.
    #[inline(always)]
    pub fn direction(&self, p: Vec2) -> Vec3 {
        let w = &self.win;
        let sx = w[0] + (p.x / self.res.x) * (w[1] - w[0]);
        let sy = w[3] - (p.y / self.res.y) * (w[3] - w[2]);
        let d = Vec3::new(sx * self.tan_half, sy * self.tan_half, 1.0);
        let [ax, ay, az] = self.axes;
        let v = az * d.z + (ay * d.y + ax * d.x);
        v * (1.0 / (v.dot(v)).sqrt())
    }
}
