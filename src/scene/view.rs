//! Cameras for formats that may not carry one (OBJ, camera-less glTF): explicit
//! `--look-from/--look-at/--up/--fov`, or an automatic framing of the scene's bounding box.
//!
//! OBJ and glTF data are right-handed (+x right, +y up, the viewer on the +z side), while our
//! camera follows pbrt's left-handed `LookAt`, which would show such data mirrored. Every
//! camera built here therefore mirrors camera-space x, so the image matches what an OpenGL-style
//! viewer shows for the same eye, target and up.

use crate::camera::Camera;
use crate::geometry::Transform;
use crate::scene::{FilmSpec, Filter};
use anyhow::ensure;
use glam::{Mat4, UVec2, Vec2, Vec3};

/// Field of view (degrees, shorter image axis) of automatic and flag-built cameras.
pub const DEFAULT_FOV_DEG: f32 = 40.0;

/// Camera placement requested on the command line; every field is optional.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ViewOptions {
    /// Eye position (`--look-from`).
    pub look_from: Option<Vec3>,
    /// Point looked at (`--look-at`).
    pub look_at: Option<Vec3>,
    /// Up vector (`--up`, default +y).
    pub up: Option<Vec3>,
    /// Field of view in degrees along the shorter image axis (`--fov`).
    pub fov: Option<f32>,
}

impl ViewOptions {
    /// True if the user placed the camera (so a file's own camera is overridden).
    pub fn places_camera(&self) -> bool {
        self.look_from.is_some() || self.look_at.is_some()
    }
}

/// The film of OBJ and glTF scenes: 512×512, triangle (tent) filter of radius 1 pixel
/// (as the built-in Cornell box), spp left to the command line.
pub fn default_film() -> FilmSpec {
    FilmSpec {
        resolution: UVec2::new(512, 512),
        filter: Filter::Triangle { radius: Vec2::ONE },
        filename: None,
        spp: None,
        sensor: Default::default(),
    }
}

/// A right-handed look-at camera: `target` at the image centre, `up` up, and the viewer's
/// right equal to `(target − eye) × up` (OpenGL convention).
pub fn right_handed_look_at(
    eye: Vec3,
    target: Vec3,
    up: Vec3,
    fov_deg: f32,
) -> anyhow::Result<Camera> {
    ensure!(
        eye.is_finite() && target.is_finite() && up.is_finite(),
        "camera eye {eye}, target {target} and up {up} must be finite"
    );
    ensure!(
        fov_deg.is_finite() && fov_deg > 0.0 && fov_deg < 180.0,
        "field of view must be in (0, 180) degrees, got {fov_deg}"
    );
    let lh = Camera::look_at(eye, target, up, fov_deg)?;
    // pbrt's LookAt puts up × dir at camera +x (image right); mirroring x puts dir × up there.
    let mirror = Transform::new(Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)))
        .ok_or_else(|| anyhow::anyhow!("mirror transform is singular"))?;
    Ok(Camera {
        camera_to_world: lh.camera_to_world.then_apply_to(&mirror),
        ..lh
    })
}

/// Look from the +z side at the centre of the box `[lo, hi]`, far enough that its bounding
/// sphere fits in `fov_deg` (the shorter image axis, so it fits on both axes).
pub fn auto_frame(lo: Vec3, hi: Vec3, fov_deg: f32) -> anyhow::Result<Camera> {
    ensure!(
        lo.is_finite() && hi.is_finite() && lo.cmple(hi).all(),
        "cannot frame an empty or non-finite bounding box ({lo} .. {hi})"
    );
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-3);
    let half = 0.5 * fov_deg.to_radians();
    // The sphere is tangent to the view cone at distance r / sin(half).
    let dist = radius / half.sin();
    right_handed_look_at(centre + Vec3::new(0.0, 0.0, dist), centre, Vec3::Y, fov_deg)
}

/// The camera the flags ask for, or an automatic framing of `[lo, hi]` when they place none.
/// A partial placement is completed from the automatic one (e.g. only `--look-at` moves the
/// target but keeps the automatic eye).
pub fn flag_or_auto_camera(view: &ViewOptions, lo: Vec3, hi: Vec3) -> anyhow::Result<Camera> {
    let fov = view.fov.unwrap_or(DEFAULT_FOV_DEG);
    if !view.places_camera() {
        return auto_frame(lo, hi, fov);
    }
    let auto = auto_frame(lo, hi, fov)?;
    let eye = view
        .look_from
        .unwrap_or_else(|| auto.camera_to_world.point(Vec3::ZERO));
    let target = view.look_at.unwrap_or(0.5 * (lo + hi));
    right_handed_look_at(eye, target, view.up.unwrap_or(Vec3::Y), fov)
}

/// Axis-aligned bounds of `points` (`None` when there are none).
pub fn bounds_of<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> Option<(Vec3, Vec3)> {
    points.into_iter().fold(None, |acc, &p| match acc {
        None => Some((p, p)),
        Some((lo, hi)) => Some((lo.min(p), hi.max(p))),
    })
}
