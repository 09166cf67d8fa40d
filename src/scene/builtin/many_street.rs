//! `many-street`: a city at night. G×G blocks (default 6×6, 32,652 emissive triangles;
//! `--light-count` scales G) of buildings along a street grid, lit by thousands of windows
//! (dim, warm, each building its own brightness), shop windows and neon signs, street lamps
//! (a hundred times a window's power, under opaque shades) and the head and tail lights of
//! cars. Every emitter is a triangle mesh (each triangle one light), as in production scenes.
//! The camera stands in a middle street looking along it: the buildings hide almost every
//! light, the road and the cars are glossy (they mirror the lamps) and the facades diffuse.

use super::many_open::film;
use super::many_util::{
    add_box, add_mesh_light, diffuse, log_uniform, radiance_for_power, random_colour, scene_rng,
    uniform,
};
use super::{BuiltinOptions, Scene};
use crate::Rgb;
use crate::camera::Camera;
use crate::material::{Material, Texture};
use crate::scene::SceneBuilder;
use anyhow::ensure;
use glam::{Vec2, Vec3};
use rand_pcg::Pcg32;
use std::f32::consts::TAU;

/// Street pitch: one block plus one street (m).
const PITCH: f32 = 48.0;
/// Street width, kerb to kerb plus both sidewalks (m).
const STREET: f32 = 12.0;
/// Sidewalk width (m).
const SIDEWALK: f32 = 2.0;
/// Storey height (m).
const STOREY: f32 = 3.2;
/// Lots per block side (the middle one is a courtyard).
const LOTS: u32 = 3;
/// Emissive triangles of the default 6×6 city, for scaling `--light-count`.
const TRIS_AT_6: f32 = 32_650.0;

/// Materials of the city.
struct Palette {
    facade: [u32; 4],
    concrete: u32,
    glass: u32,
    metal: u32,
    emitter: u32,
    paint: [u32; 4],
}

/// Build `many-street`.
pub fn many_street(opts: &BuiltinOptions) -> anyhow::Result<Scene> {
    let g = match opts.light_count {
        Some(n) => ((6.0 * (n as f32 / TRIS_AT_6).sqrt()).round() as u32).clamp(1, 32),
        None => 6,
    };
    ensure!(g >= 1, "many-street needs at least one block");
    let mut rng = scene_rng(4);
    let mut b = SceneBuilder::new();
    let pal = palette(&mut b, &mut rng)?;
    let road = b.add_material(Material::CoatedDiffuse {
        reflectance: Texture::Constant(Rgb::splat(0.06)),
        alpha: Vec2::splat(0.12),
        eta: 1.5,
        layer: None,
    });
    // Asphalt under everything (wet: a glossy coat over a dark base).
    let lo = -STREET * 0.5;
    let side = g as f32 * PITCH + STREET;
    b.add_quad(
        Vec3::new(lo, 0.0, lo),
        Vec3::Z * side,
        Vec3::X * side,
        road,
        None,
    )?;
    for i in 0..g {
        for j in 0..g {
            block(&mut b, &mut rng, &pal, i, j)?;
        }
    }
    // Streets along z (x = i·PITCH) and along x (z = i·PITCH), one segment per block.
    for axis in 0..2 {
        for i in 0..=g {
            for j in 0..g {
                street_segment(&mut b, &mut rng, &pal, axis, i, j)?;
            }
        }
    }
    // In the middle street along z, on the right lane, looking down the street.
    let m = (g / 2) as f32 * PITCH;
    let eye = Vec3::new(m + 2.2, 1.6, m + 1.0);
    let target = Vec3::new(m - 1.0, 4.0, m + 60.0);
    let camera = Camera::look_at(eye, target, Vec3::Y, 60.0)?;
    b.build(camera, film())
}

fn palette(b: &mut SceneBuilder, rng: &mut Pcg32) -> anyhow::Result<Palette> {
    let mut facade = [0; 4];
    for f in &mut facade {
        let c = Rgb::new(
            uniform(rng, 0.3, 0.7),
            uniform(rng, 0.3, 0.6),
            uniform(rng, 0.25, 0.5),
        );
        *f = b.add_material(Material::Diffuse {
            reflectance: Texture::Constant(c),
        });
    }
    let mut paint = [0; 4];
    for p in &mut paint {
        let c = random_colour(rng) * 0.3;
        *p = b.add_material(Material::CoatedDiffuse {
            reflectance: Texture::Constant(c.min(Rgb::splat(0.9))),
            alpha: Vec2::splat(0.04),
            eta: 1.5,
            layer: None,
        });
    }
    let (eta, k) = crate::bsdf::named_metal("Al")
        .ok_or_else(|| anyhow::anyhow!("missing metal table for Al"))?;
    Ok(Palette {
        facade,
        concrete: diffuse(b, 0.45),
        // Unlit windows: dark glass that mirrors the street.
        glass: b.add_material(Material::CoatedDiffuse {
            reflectance: Texture::Constant(Rgb::splat(0.02)),
            alpha: Vec2::splat(0.02),
            eta: 1.5,
            layer: None,
        }),
        metal: b.add_material(Material::Conductor {
            eta,
            k,
            alpha: Vec2::splat(0.3),
            reflectance: None,
        }),
        emitter: diffuse(b, 0.02),
        paint,
    })
}

/// A one-sided emissive parallelogram corner + s·e1 + t·e2 facing `n`, cut into `cols` strips
/// of two triangles (each one light) of radiance `l`.
#[allow(clippy::too_many_arguments)]
fn emissive_rect(
    b: &mut SceneBuilder,
    corner: Vec3,
    e1: Vec3,
    e2: Vec3,
    n: Vec3,
    cols: u32,
    l: Rgb,
    material: u32,
) -> anyhow::Result<()> {
    // Triangles emit on the side of e1 × e2: swap the edges if that is away from `n`.
    let (e1, e2) = if e1.cross(e2).dot(n) >= 0.0 {
        (e1, e2)
    } else {
        (e2, e1)
    };
    let mut positions = Vec::new();
    for c in 0..=cols {
        let p = corner + e1 * (c as f32 / cols as f32);
        positions.extend([p, p + e2]);
    }
    let mut indices = Vec::new();
    for c in 0..cols {
        let a = 2 * c;
        indices.extend([a, a + 2, a + 3, a, a + 3, a + 1]);
    }
    add_mesh_light(b, positions, indices, l, material)
}

/// A one-sided emissive disk (a fan of `segments` triangles) facing `n`, of total power `phi`.
#[allow(clippy::too_many_arguments)]
fn emissive_disk(
    b: &mut SceneBuilder,
    centre: Vec3,
    n: Vec3,
    radius: f32,
    segments: u32,
    phi: f32,
    colour: Rgb,
    material: u32,
) -> anyhow::Result<()> {
    let helper = if n.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
    let u = helper.cross(n).normalize();
    // u × v = n, so every fan triangle (c, p_k, p_k+1) with increasing angle faces `n`.
    let v = n.cross(u);
    let mut positions = vec![centre];
    for k in 0..segments {
        let (s, c) = (k as f32 / segments as f32 * TAU).sin_cos();
        positions.push(centre + (u * c + v * s) * radius);
    }
    let mut indices = Vec::new();
    for k in 0..segments {
        indices.extend([0, 1 + k, 1 + (k + 1) % segments]);
    }
    let area = 0.5 * radius * radius * (TAU / segments as f32).sin() * segments as f32;
    add_mesh_light(
        b,
        positions,
        indices,
        radiance_for_power(phi, area, colour),
        material,
    )
}

/// A warm interior colour (incandescent to fluorescent), luminance 1.
fn interior_colour(rng: &mut Pcg32) -> Rgb {
    let t = uniform(rng, 0.0, 1.0);
    let c = Rgb::new(1.0, 0.75 + 0.2 * t, 0.45 + 0.5 * t);
    c / crate::luminance(c)
}

/// Block (i, j): a ring of 3×3 − 1 buildings of random height around a courtyard on a raised
/// sidewalk, with windows on the street facades.
fn block(
    b: &mut SceneBuilder,
    rng: &mut Pcg32,
    pal: &Palette,
    i: u32,
    j: u32,
) -> anyhow::Result<()> {
    let x0 = i as f32 * PITCH + STREET * 0.5;
    let z0 = j as f32 * PITCH + STREET * 0.5;
    let w = PITCH - STREET;
    let kerb = SIDEWALK;
    add_box(
        b,
        Vec3::new(x0 - kerb, 0.0, z0 - kerb),
        Vec3::new(x0 + w + kerb, 0.12, z0 + w + kerb),
        pal.concrete,
    )?;
    let lot = w / LOTS as f32;
    for a in 0..LOTS {
        for c in 0..LOTS {
            if a == 1 && c == 1 {
                continue;
            }
            let floors = (uniform(rng, 2.0, 11.0)) as u32;
            let lo = Vec3::new(x0 + a as f32 * lot, 0.12, z0 + c as f32 * lot);
            let hi = lo + Vec3::new(lot, floors as f32 * STOREY, lot);
            let facade = pal.facade[(rng_index(rng, 4)) as usize];
            add_box(b, lo, hi, facade)?;
            // Each building its own life: how many windows are lit and how bright.
            let lit = uniform(rng, 0.15, 0.9);
            let bright = log_uniform(rng, 2.0, 40.0);
            let mut faces = Vec::new();
            if a == 0 {
                faces.push((lo, Vec3::Z, -Vec3::X));
            }
            if a == LOTS - 1 {
                faces.push((Vec3::new(hi.x, lo.y, lo.z), Vec3::Z, Vec3::X));
            }
            if c == 0 {
                faces.push((lo, Vec3::X, -Vec3::Z));
            }
            if c == LOTS - 1 {
                faces.push((Vec3::new(lo.x, lo.y, hi.z), Vec3::X, Vec3::Z));
            }
            for (o, t, n) in faces {
                facade_lights(b, rng, pal, o, t, n, lot, floors, lit, bright)?;
            }
        }
    }
    Ok(())
}

/// A random index in 0..n.
fn rng_index(rng: &mut Pcg32, n: u32) -> u32 {
    ((uniform(rng, 0.0, 1.0) * n as f32) as u32).min(n - 1)
}

/// The windows of one facade (origin `o` at its lower corner, running along `t` for `width`,
/// facing `n`): shop windows and neon signs on the ground floor, office and flat windows above
/// (lit with probability `lit`, of power around `bright` W), dark glass where unlit.
#[allow(clippy::too_many_arguments)]
fn facade_lights(
    b: &mut SceneBuilder,
    rng: &mut Pcg32,
    pal: &Palette,
    o: Vec3,
    t: Vec3,
    n: Vec3,
    width: f32,
    floors: u32,
    lit: f32,
    bright: f32,
) -> anyhow::Result<()> {
    let out = o + n * 0.02;
    // Ground floor: two shops, each a large window, some with a neon sign above.
    for s in 0..2 {
        let along = s as f32 * width * 0.5 + 0.6;
        let (ww, wh) = (width * 0.5 - 1.2, 2.2);
        let corner = out + t * along + Vec3::Y * 0.3;
        if uniform(rng, 0.0, 1.0) < 0.5 {
            let phi = log_uniform(rng, 20.0, 200.0);
            let l = radiance_for_power(phi, ww * wh, interior_colour(rng));
            emissive_rect(b, corner, t * ww, Vec3::Y * wh, n, 2, l, pal.emitter)?;
        } else {
            b.add_quad(corner, t * ww, Vec3::Y * wh, pal.glass, None)?;
        }
        if uniform(rng, 0.0, 1.0) < 0.35 {
            let (sw, sh) = (ww * uniform(rng, 0.5, 0.9), 0.12);
            let phi = log_uniform(rng, 5.0, 60.0);
            let l = radiance_for_power(phi, sw * sh, random_colour(rng));
            let corner = out + n * 0.03 + t * (along + 0.5 * (ww - sw)) + Vec3::Y * 2.75;
            emissive_rect(b, corner, t * sw, Vec3::Y * sh, n, 24, l, pal.emitter)?;
        }
    }
    // Upper floors: windows 1.2 m × 1.6 m every ~2.4 m.
    let k = (width / 2.4).floor().max(1.0) as u32;
    let pitch = width / k as f32;
    for f in 1..floors {
        for w in 0..k {
            let corner = out
                + t * (w as f32 * pitch + 0.5 * (pitch - 1.2))
                + Vec3::Y * (f as f32 * STOREY + 0.9);
            let (e1, e2) = (t * 1.2, Vec3::Y * 1.6);
            if uniform(rng, 0.0, 1.0) < lit {
                let phi = bright * log_uniform(rng, 0.3, 3.0);
                let l = radiance_for_power(phi, 1.92, interior_colour(rng));
                emissive_rect(b, corner, e1, e2, n, 1, l, pal.emitter)?;
            } else {
                b.add_quad(corner, e1, e2, pal.glass, None)?;
            }
        }
    }
    Ok(())
}

/// One street segment between two crossings: lamps on alternating sides and parked or moving
/// cars. `axis` 0: the street along z at x = i·PITCH; 1: along x at z = i·PITCH; `j` the
/// block it runs beside.
fn street_segment(
    b: &mut SceneBuilder,
    rng: &mut Pcg32,
    pal: &Palette,
    axis: u32,
    i: u32,
    j: u32,
) -> anyhow::Result<()> {
    let centre = i as f32 * PITCH;
    let start = j as f32 * PITCH + STREET * 0.5;
    let len = PITCH - STREET;
    // World point at `across` from the street's centre line, `along` from the segment start.
    let at = |across: f32, y: f32, along: f32| {
        if axis == 0 {
            Vec3::new(centre + across, y, start + along)
        } else {
            Vec3::new(start + along, y, centre + across)
        }
    };
    let (dir, right) = if axis == 0 {
        (Vec3::Z, -Vec3::X)
    } else {
        (Vec3::X, Vec3::Z)
    };
    let half_road = STREET * 0.5 - SIDEWALK;
    for (k, along) in [6.0, 18.0, 30.0].into_iter().enumerate() {
        let s = if (k as u32 + i + j).is_multiple_of(2) {
            1.0
        } else {
            -1.0
        };
        let base = at(s * (half_road + 0.6), 0.12, along);
        let lamp_power = log_uniform(rng, 800.0, 3000.0);
        // Sodium or white LED.
        let colour = if uniform(rng, 0.0, 1.0) < 0.5 {
            Rgb::new(1.0, 0.55, 0.2)
        } else {
            Rgb::new(0.9, 0.95, 1.0)
        };
        let colour = colour / crate::luminance(colour);
        let pole = Vec3::new(0.08, 0.0, 0.08);
        add_box(b, base - pole, base + pole + Vec3::Y * 7.9, pal.metal)?;
        // Arm over the road and a shade; the lamp faces the road under the shade.
        let head = at(s * (half_road - 1.0), 7.75, along);
        let lo = base.min(head) - Vec3::new(0.2, 0.0, 0.2);
        let hi = base.max(head) + Vec3::new(0.2, 0.25, 0.2);
        add_box(b, lo.with_y(7.8), hi.with_y(8.05), pal.metal)?;
        emissive_disk(b, head, -Vec3::Y, 0.18, 16, lamp_power, colour, pal.emitter)?;
    }
    // Cars: parked at the kerb (dark) or in a lane (lit, facing its driving direction).
    let mut along = uniform(rng, 0.5, 4.0);
    while along + 4.4 < len {
        if uniform(rng, 0.0, 1.0) < 0.45 {
            let lane = if uniform(rng, 0.0, 1.0) < 0.5 {
                1.0
            } else {
                -1.0
            };
            let moving = uniform(rng, 0.0, 1.0) < 0.5;
            let across = lane * if moving { 1.8 } else { half_road - 1.1 };
            let paint = pal.paint[rng_index(rng, 4) as usize];
            car(
                b,
                rng,
                pal,
                paint,
                at(across, 0.0, along),
                dir,
                right,
                lane,
                moving,
            )?;
        }
        along += uniform(rng, 5.0, 9.0);
    }
    Ok(())
}

/// A car of 1.8 m × 4.4 m starting at `rear_left` along `dir`; `lane` ±1 says which way it
/// drives (−1: against `dir`); a moving car has head and tail lights on.
#[allow(clippy::too_many_arguments)]
fn car(
    b: &mut SceneBuilder,
    rng: &mut Pcg32,
    pal: &Palette,
    paint: u32,
    start: Vec3,
    dir: Vec3,
    right: Vec3,
    lane: f32,
    moving: bool,
) -> anyhow::Result<()> {
    let side = right * 0.9;
    let body_lo = (start - side).min(start + side + dir * 4.4);
    let body_hi = (start - side).max(start + side + dir * 4.4);
    add_box(b, body_lo + Vec3::Y * 0.25, body_hi.with_y(1.0), paint)?;
    let c_lo = (start - side * 0.85 + dir * 1.1).min(start + side * 0.85 + dir * 3.3);
    let c_hi = (start - side * 0.85 + dir * 1.1).max(start + side * 0.85 + dir * 3.3);
    add_box(b, c_lo.with_y(1.0), c_hi.with_y(1.45), pal.glass)?;
    if !moving {
        return Ok(());
    }
    // Front and back along the driving direction.
    let fwd = dir * lane;
    let (front, back) = if lane > 0.0 {
        (start + dir * 4.4, start)
    } else {
        (start, start + dir * 4.4)
    };
    let head_power = log_uniform(rng, 60.0, 250.0);
    let white = Rgb::new(1.0, 0.95, 0.85) / crate::luminance(Rgb::new(1.0, 0.95, 0.85));
    let red = Rgb::new(1.0, 0.05, 0.02) / crate::luminance(Rgb::new(1.0, 0.05, 0.02));
    for s in [-0.6f32, 0.6] {
        let c = front + right * s + Vec3::Y * 0.65 + fwd * 0.02;
        emissive_disk(b, c, fwd, 0.09, 8, head_power, white, pal.emitter)?;
        let t = back + right * s - right * 0.15 + Vec3::Y * 0.7 - fwd * 0.02;
        let l = radiance_for_power(log_uniform(rng, 1.0, 5.0), 0.3 * 0.1, red);
        emissive_rect(b, t, right * 0.3, Vec3::Y * 0.1, -fwd, 2, l, pal.emitter)?;
    }
    Ok(())
}
