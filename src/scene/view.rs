//! Cameras from the command line and automatic framing.
//!
//! Scenes without a camera (OBJ, camera-less glTF) are framed automatically: of the six axis
//! views of the bounding box, the one whose camera sees the most lit surface (a 24×24 probe of
//! camera rays, each hit counted when it is emissive toward the camera or directly lit by some
//! light sample) — so an open box is looked into through its open side. Ties keep the +z view.
//! `--look-from/--look-at/--up/--fov` refine any camera, the file's own included: given fields
//! replace those of the camera the scene would otherwise use. The camera in effect is reported
//! as the flags that reproduce it, for the user to paste and refine.
//!
//! OBJ and glTF data are right-handed (+x right, +y up, the viewer on the +z side), while our
//! camera follows pbrt's left-handed `LookAt`, which would show such data mirrored. Every
//! camera built here for them therefore mirrors camera-space x, so the image matches what an
//! OpenGL-style viewer shows for the same eye, target and up; a file's camera keeps its own
//! handedness when flags move it.

use crate::camera::{Camera, Projection};
use crate::geometry::interaction::NO_LIGHT;
use crate::geometry::{PrimKind, Primitive, RayQuery, Transform};
use crate::lights::{Emitter, LightSampleContext, LightSource, SamplingMode};
use crate::scene::{FilmSpec, Filter, Scene};
use anyhow::{bail, ensure};
use glam::{Mat4, UVec2, Vec2, Vec3};

/// Field of view (degrees, shorter image axis) of automatic and flag-built cameras.
pub const DEFAULT_FOV_DEG: f32 = 40.0;

/// Camera rays per side of the framing probe.
const PROBE: u32 = 24;

/// Lights tried per probe hit (spread evenly over the scene's list) and samples per light.
const PROBE_LIGHTS: usize = 8;
const PROBE_SAMPLES: [Vec2; 4] = [
    Vec2::new(0.25, 0.25),
    Vec2::new(0.75, 0.25),
    Vec2::new(0.25, 0.75),
    Vec2::new(0.75, 0.75),
];

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
    /// True if the user placed the camera (eye or target).
    pub fn places_camera(&self) -> bool {
        self.look_from.is_some() || self.look_at.is_some()
    }

    /// True if any camera flag is given.
    pub fn any(&self) -> bool {
        self.places_camera() || self.up.is_some() || self.fov.is_some()
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
    look_at_with(eye, target, up, fov_deg, true)
}

/// pbrt's `LookAt` camera, mirrored in camera-space x when `mirror` (right-handed data).
fn look_at_with(
    eye: Vec3,
    target: Vec3,
    up: Vec3,
    fov_deg: f32,
    mirror: bool,
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
    if !mirror {
        return Ok(lh);
    }
    // pbrt's LookAt puts up × dir at camera +x (image right); mirroring x puts dir × up there.
    let m = Transform::new(Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)))
        .ok_or_else(|| anyhow::anyhow!("mirror transform is singular"))?;
    Ok(Camera {
        camera_to_world: lh.camera_to_world.then_apply_to(&m),
        ..lh
    })
}

/// The six axis views of automatic framing, in the order ties are broken (+z, today's and the
/// OpenGL default view, first).
pub const SIDES: [Vec3; 6] = [
    Vec3::Z,
    Vec3::NEG_Z,
    Vec3::X,
    Vec3::NEG_X,
    Vec3::Y,
    Vec3::NEG_Y,
];

/// The up vector of the view from `side`: +y, except looking along y, where the far −z side
/// is up when looking down (and +z when looking up).
fn side_up(side: Vec3) -> Vec3 {
    if side.y != 0.0 {
        Vec3::new(0.0, 0.0, -side.y)
    } else {
        Vec3::Y
    }
}

/// Where the eye of the view from `side` goes: on that side of the box `[lo, hi]`, far enough
/// that its bounding sphere fits in `fov_deg` (the shorter image axis, so on both axes).
fn side_eye(lo: Vec3, hi: Vec3, fov_deg: f32, side: Vec3) -> Vec3 {
    let centre = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-3);
    // The sphere is tangent to the view cone at distance r / sin(half).
    centre + side * (radius / (0.5 * fov_deg.to_radians()).sin())
}

fn check_box(lo: Vec3, hi: Vec3) -> anyhow::Result<()> {
    ensure!(
        lo.is_finite() && hi.is_finite() && lo.cmple(hi).all(),
        "cannot frame an empty or non-finite bounding box ({lo} .. {hi})"
    );
    Ok(())
}

/// Look from the `side` (a unit axis) at the centre of the box `[lo, hi]`, the whole box in
/// view.
pub fn axis_frame(lo: Vec3, hi: Vec3, fov_deg: f32, side: Vec3) -> anyhow::Result<Camera> {
    check_box(lo, hi)?;
    let eye = side_eye(lo, hi, fov_deg, side);
    right_handed_look_at(eye, 0.5 * (lo + hi), side_up(side), fov_deg)
}

/// Look from the +z side at the centre of the box `[lo, hi]`, the whole box in view.
pub fn auto_frame(lo: Vec3, hi: Vec3, fov_deg: f32) -> anyhow::Result<Camera> {
    axis_frame(lo, hi, fov_deg, Vec3::Z)
}

/// How many of the probe's camera rays through `cam` find lit surface: a hit that emits
/// toward the camera, or that some light sample reaches unoccluded on the side the camera
/// sees. Deterministic (fixed rays and light samples).
pub fn lit_rays(scene: &Scene, cam: &Camera) -> usize {
    let res = UVec2::splat(PROBE);
    let rays = cam.rays(res);
    let lights = &scene.lights;
    let stride = lights.len().div_ceil(PROBE_LIGHTS).max(1);
    let mut lit = 0;
    for y in 0..PROBE {
        for x in 0..PROBE {
            let ray = rays.generate(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let Some(hit) = scene.geometry.intersect(&ray) else {
                continue;
            };
            let wo = -ray.d;
            let facing = if wo.dot(hit.ng) >= 0.0 { 1.0 } else { -1.0 };
            if hit.light != NO_LIGHT
                && let Some(l) = lights.get(hit.light as usize)
                && l.radiance(hit.p, hit.ng, hit.uv, wo).max_element() > 0.0
            {
                lit += 1;
                continue;
            }
            let ctx = LightSampleContext {
                p: hit.p,
                n: hit.ng * facing,
            };
            let reached = lights.iter().step_by(stride).any(|l| {
                PROBE_SAMPLES.iter().any(|&u| {
                    let Some(s) = l.sample_li(&ctx, u, SamplingMode::Area) else {
                        return false;
                    };
                    if !(s.pdf > 0.0 && s.li.max_element() > 0.0) || s.wi.dot(ctx.n) <= 0.0 {
                        return false;
                    }
                    !scene.geometry.occluded(&hit.spawn_ray_to(s.p_light))
                })
            });
            lit += usize::from(reached);
        }
    }
    lit
}

/// The automatic camera of `scene`: the axis view that sees the most lit surface (ties, and
/// a scene where nothing is lit, keep +z), with its probe count.
pub fn best_axis_frame(scene: &Scene, fov_deg: f32) -> anyhow::Result<(Camera, Vec3, usize)> {
    let (lo, hi) = vertex_bounds(scene);
    check_box(lo, hi)?;
    let mut best: Option<(Camera, Vec3, usize)> = None;
    for side in SIDES {
        let cam = axis_frame(lo, hi, fov_deg, side)?;
        let n = lit_rays(scene, &cam);
        if best.as_ref().is_none_or(|b| n > b.2) {
            best = Some((cam, side, n));
        }
    }
    best.ok_or_else(|| anyhow::anyhow!("no candidate view"))
}

fn side_name(side: Vec3) -> &'static str {
    match (side.x, side.y, side.z) {
        (x, _, _) if x > 0.0 => "+x",
        (x, _, _) if x < 0.0 => "-x",
        (_, y, _) if y > 0.0 => "+y",
        (_, y, _) if y < 0.0 => "-y",
        (_, _, z) if z < 0.0 => "-z",
        _ => "+z",
    }
}

fn fmt_vec(v: Vec3) -> String {
    let f = |x: f32| {
        // Short but exact enough to paste back: 4 significant decimals, no "-0".
        let r = (x * 1e4).round() / 1e4;
        let r = if r == 0.0 { 0.0 } else { r };
        format!("{r}")
    };
    format!("{},{},{}", f(v.x), f(v.y), f(v.z))
}

/// The camera flags that reproduce `cam` looking at `target`.
pub fn camera_flags(cam: &Camera, target: Vec3) -> String {
    let eye = cam.camera_to_world.point(Vec3::ZERO);
    let up = cam.camera_to_world.vector(Vec3::Y).normalize_or_zero();
    let pose = format!(
        "--look-from {} --look-at {} --up {}",
        fmt_vec(eye),
        fmt_vec(target),
        fmt_vec(up)
    );
    // Only a perspective camera has a field of view to paste back.
    if cam.projection == Projection::Perspective {
        format!("{pose} --fov {}", (cam.fov_deg * 1e3).round() / 1e3)
    } else {
        pose
    }
}

/// The box of the scene's triangle vertices (exact, unlike the BVH's padded bounds, so
/// framing does not move when the BVH changes); the BVH's box if there are quadrics.
fn vertex_bounds(scene: &Scene) -> (Vec3, Vec3) {
    let g = &scene.geometry;
    let mut b = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for i in 0..g.len() as u32 {
        match g.primitive(i) {
            Some(Primitive {
                kind: PrimKind::Triangle { .. },
                p,
                ..
            }) => {
                for v in p {
                    b = (b.0.min(*v), b.1.max(*v));
                }
            }
            _ => return g.bounds(),
        }
    }
    b
}

/// Place the camera of a scene whose file has none: the flags where given, the rest from the
/// automatic framing. Returns the note that tells the user which camera was used.
pub fn place_auto_camera(scene: &mut Scene, view: &ViewOptions) -> anyhow::Result<String> {
    let fov = view.fov.unwrap_or(DEFAULT_FOV_DEG);
    let (lo, hi) = vertex_bounds(scene);
    check_box(lo, hi)?;
    let centre = 0.5 * (lo + hi);
    let (eye, up, why) = match view.look_from {
        Some(eye) => (eye, view.up.unwrap_or(Vec3::Y), String::new()),
        None => {
            let (_, side, n) = best_axis_frame(scene, fov)?;
            let why = format!(
                " (the view from {} sees the most lit surface, {n} of {} probe rays)",
                side_name(side),
                PROBE * PROBE
            );
            let up = view.up.unwrap_or(side_up(side));
            (side_eye(lo, hi, fov, side), up, why)
        }
    };
    let target = view.look_at.unwrap_or(centre);
    scene.camera = right_handed_look_at(eye, target, up, fov)?;
    let origin = if view.any() {
        "camera from the flags, completed by automatic framing"
    } else {
        "no camera in the file; automatic framing"
    };
    Ok(format!(
        "{origin}{why}: {}",
        camera_flags(&scene.camera, target)
    ))
}

/// Apply the flags to a camera the file (or built-in scene) defines: given fields replace the
/// camera's own; an eye without a target looks at the centre of the scene, a changed up or
/// fov alone keeps the eye and direction. The camera keeps its handedness. `None` when no
/// flag is given (the camera is untouched).
pub fn apply_view_flags(scene: &mut Scene, view: &ViewOptions) -> anyhow::Result<Option<String>> {
    if !view.any() {
        return Ok(None);
    }
    let cam = &scene.camera;
    let c2w = cam.camera_to_world;
    let eye0 = c2w.point(Vec3::ZERO);
    let dir0 = c2w.vector(Vec3::Z).normalize_or_zero();
    let up0 = c2w.vector(Vec3::Y).normalize_or_zero();
    let (lo, hi) = scene.geometry.bounds();
    let centre = if lo.cmple(hi).all() && lo.is_finite() && hi.is_finite() {
        0.5 * (lo + hi)
    } else {
        eye0 + dir0
    };
    // Distance to the scene along the view, so the printed target is a point worth looking at.
    let reach = (centre - eye0).dot(dir0);
    let reach = if reach.is_finite() && reach > 0.0 {
        reach
    } else {
        1.0
    };
    // Only a perspective camera has a field of view: an orthographic one's view is its
    // screen window, a spherical one sees every direction.
    if view.fov.is_some() && cam.projection != Projection::Perspective {
        bail!(
            "--fov applies to a perspective camera only; the scene's camera is {}",
            match cam.projection {
                Projection::Orthographic => "orthographic (its screenwindow sets the view)",
                _ => "spherical (it sees every direction)",
            }
        );
    }
    let fov = view.fov.unwrap_or(cam.fov_deg);
    let mirror = c2w.swaps_handedness();
    let (camera, target) = if view.places_camera() || view.up.is_some() {
        let eye = view.look_from.unwrap_or(eye0);
        let target = match (view.look_at, view.look_from) {
            (Some(t), _) => t,
            (None, Some(_)) => centre,
            (None, None) => eye0 + dir0 * reach,
        };
        let up = view.up.unwrap_or(up0);
        let mut c = look_at_with(eye, target, up, fov, mirror)?;
        // A new pose, the same camera: its kind of projection, window and lens stay.
        c.screen_window = cam.screen_window;
        c.projection = cam.projection;
        c.lens = cam.lens;
        (c, target)
    } else {
        ensure!(
            fov.is_finite() && fov > 0.0 && fov < 180.0,
            "field of view must be in (0, 180) degrees, got {fov}"
        );
        let mut c = cam.clone();
        c.fov_deg = fov;
        (c, eye0 + dir0 * reach)
    };
    scene.camera = camera;
    Ok(Some(format!(
        "the scene's camera with the camera flags applied: {}",
        camera_flags(&scene.camera, target)
    )))
}
