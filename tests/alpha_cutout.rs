//! Alpha cut-outs (pbrt-v4's shape `"float alpha"` / `"texture alpha"`): a quad of coverage c
//! passes a fraction 1 − c of a distant light's rays (5σ binomial bound), stacked quads
//! (1 − c)² (each surface decides independently), a texture mask exactly where it is 0;
//! every query (closest, any-hit, 16-ray packets, all three BVH backends) agrees ray by ray;
//! kept hits carry the hit record of the same quad without a mask; and through the pbrt
//! loader a direct-lighting render under a cut-out roof is 1 − c of the unshadowed one.

mod geometry_support;
mod render_support;

use geometry_support::agreed_hits;
use glam::{UVec2, Vec2, Vec3};
use penumbra::geometry::interaction::NO_LIGHT;
use penumbra::geometry::{
    Alpha, AlphaTexture, Backend, Geometry, MeshShading, PrimKind, Primitive, Ray, RayQuery,
};
use penumbra::sampling::{PatternKind, make_pattern};
use render_support::{assert_fraction, check_fraction, roof_mean};
use std::sync::Arc;

/// The quad [-1, 1]² at height z as triangles of mesh `mesh` (uv = ((x+1)/2, (y+1)/2)).
fn quad(mesh: u32, z: f32) -> Vec<Primitive> {
    let p = [
        Vec3::new(-1.0, -1.0, z),
        Vec3::new(1.0, -1.0, z),
        Vec3::new(1.0, 1.0, z),
        Vec3::new(-1.0, 1.0, z),
    ];
    [[0u32, 1, 2], [0, 2, 3]]
        .iter()
        .map(|&v| Primitive {
            p: v.map(|i| p[i as usize]),
            kind: PrimKind::Triangle { mesh, v },
            material: 0,
            light: NO_LIGHT,
        })
        .collect()
}

fn shading(alpha: Option<Alpha>) -> MeshShading {
    MeshShading {
        normals: None,
        uvs: Some(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ]),
        flip: false,
        alpha,
    }
}

/// Quads at the heights `zs` with the masks `alphas`.
fn quads(zs: &[f32], alphas: &[Option<Alpha>], backend: Backend) -> Geometry {
    let prims = zs
        .iter()
        .enumerate()
        .flat_map(|(m, &z)| quad(m as u32, z))
        .collect();
    let meshes = alphas.iter().cloned().map(shading).collect();
    Geometry::with_backend(prims, meshes, Vec::new(), backend)
}

/// `n` parallel rays toward a distant light (direction slightly tilted), from points uniform
/// under the middle of the quads.
fn light_rays(n: u32) -> Vec<Ray> {
    let pat = make_pattern(PatternKind::Random, 11);
    let d = Vec3::new(0.05, -0.03, 1.0).normalize();
    (0..n)
        .map(|i| {
            let u = pat.sample_2d(UVec2::new(i, 0), 0, 0, 1);
            Ray::new(Vec3::new(1.6 * u.x - 0.8, 1.6 * u.y - 0.8, -1.0), d)
        })
        .collect()
}

/// Per ray: closest-hit (mesh, first vertex) and t (None for a miss), checked equal across
/// every query and backend ([`agreed_hits`]).
fn answers(zs: &[f32], alphas: &[Option<Alpha>], rays: &[Ray]) -> Vec<Option<(u32, f32)>> {
    // Prim ids depend on the backend's leaf order: compare (mesh, first vertex) instead.
    let name = |g: &Geometry, id: u32| match g.primitive(id).expect("hit prim").kind {
        PrimKind::Triangle { mesh, v } => mesh * 16 + v[1],
        PrimKind::Quadric(_) => u32::MAX,
    };
    agreed_hits(|backend| quads(zs, alphas, backend), name, rays)
        .into_iter()
        .map(|h| h.map(|(n, h)| (n, h.t)))
        .collect()
}

#[test]
fn constant_alpha_passes_one_minus_coverage() {
    let rays = light_rays(40_000);
    for c in [0.25f32, 0.6] {
        let a = answers(&[0.0], &[Some(Alpha::Constant(c))], &rays);
        let passed = a.iter().filter(|h| h.is_none()).count();
        check_fraction(&format!("coverage {c}"), passed, rays.len(), 1.0 - c as f64);
    }
    // Coverage 1 and 0: all blocked, none blocked.
    let a = answers(&[0.0], &[Some(Alpha::Constant(1.0))], &rays);
    assert!(a.iter().all(|h| h.is_some()));
    let a = answers(&[0.0], &[Some(Alpha::Constant(0.0))], &rays);
    assert!(a.iter().all(|h| h.is_none()));
}

#[test]
fn stacked_cut_outs_decide_independently() {
    let rays = light_rays(40_000);
    let c = 0.5f32;
    let a = answers(
        &[0.0, 0.5],
        &[Some(Alpha::Constant(c)), Some(Alpha::Constant(c))],
        &rays,
    );
    let passed = a.iter().filter(|h| h.is_none()).count();
    check_fraction("two quads of coverage 0.5", passed, rays.len(), 0.25);
    // Rays the lower quad lets through go on to the upper one: a quarter of all rays hit
    // the upper quad (its mesh is 1, so its names are ≥ 16).
    let upper = a.iter().flatten().filter(|(n, _)| *n >= 16).count();
    check_fraction("stopped by the upper quad", upper, rays.len(), 0.25);
}

/// Coverage 1 where u < 0.3, else 0.
#[derive(Debug)]
struct Stripe;

impl AlphaTexture for Stripe {
    fn alpha(&self, uv: Vec2) -> f32 {
        if uv.x < 0.3 { 1.0 } else { 0.0 }
    }
}

#[test]
fn texture_alpha_cuts_exactly_where_it_is_zero() {
    let rays = light_rays(20_000);
    let a = answers(&[0.0], &[Some(Alpha::Texture(Arc::new(Stripe)))], &rays);
    let mut checked = 0;
    for (r, h) in rays.iter().zip(&a) {
        let x = r.at(-r.o.z / r.d.z).x;
        let u = (x + 1.0) / 2.0;
        if (u - 0.3).abs() > 1e-4 {
            assert_eq!(h.is_some(), u < 0.3, "ray at u = {u}: hit {h:?}");
            checked += 1;
        }
    }
    assert!(checked > 19_900);
}

#[test]
fn kept_hits_are_the_unmasked_quads_hits() {
    // Cut-out triangles are tested outside the packet triangle kernels: their hit records
    // must still be the ones the same quad gives without a mask, bit for bit.
    let rays = light_rays(4_000);
    let masked = quads(&[0.0], &[Some(Alpha::Constant(0.5))], Backend::Wide);
    let plain = quads(&[0.0], &[None], Backend::Wide);
    let mut kept = 0;
    for r in &rays {
        let Some(h) = masked.intersect(r) else {
            continue;
        };
        let q = plain.intersect(r).expect("the plain quad is hit");
        assert!(
            h.t == q.t && h.p == q.p && h.uv == q.uv && h.ng == q.ng && h.p_error == q.p_error,
            "{h:?} vs {q:?}"
        );
        kept += 1;
    }
    assert!(kept > 1_500 && kept < 2_500, "kept {kept} of 4000");
}

/// A roof at z = 1 over the ground of `render_support::roof_scene`: a quad of the given alpha, or none.
fn quad_roof(alpha: Option<f32>) -> String {
    match alpha {
        Some(a) => format!(
            "Shape \"trianglemesh\" \"float alpha\" {a} \"integer indices\" [0 1 2 0 2 3] \
             \"point3 P\" [-20 -20 1  20 -20 1  20 20 1  -20 20 1]"
        ),
        None => String::new(),
    }
}

fn render_mean(alpha: Option<f32>) -> (f64, f64) {
    roof_mean(&quad_roof(alpha))
}

#[test]
fn pbrt_cut_out_roof_passes_one_minus_coverage_of_the_sun() {
    let open = render_mean(None);
    let c = 0.35;
    let under = render_mean(Some(c));
    assert_fraction(
        &format!("roof of coverage {c}"),
        under,
        open,
        1.0 - c as f64,
    );
    // An opaque roof (alpha 1 is no cut-out) blocks the sun entirely.
    let (shut, _) = render_mean(Some(1.0));
    assert!(shut < 1e-6 * open.0, "opaque roof lets {shut} through");
}

/// A leaf over the quad's uv square: inside |v − ½| < ½·sin(πu) (area 2/π), outside nothing.
/// Inside it the coverage is 1 (`soft: false`) or u (`soft: true`, total ∫ u·sin(πu) du = 1/π),
/// so the blocked fraction of rays spread uniformly over the quad is 2/π or 1/π.
#[derive(Debug)]
struct Leaf {
    soft: bool,
}

impl AlphaTexture for Leaf {
    fn alpha(&self, uv: Vec2) -> f32 {
        let inside = (uv.y - 0.5).abs() < 0.5 * (std::f32::consts::PI * uv.x).sin();
        match (inside, self.soft) {
            (false, _) => 0.0,
            (true, false) => 1.0,
            (true, true) => uv.x,
        }
    }
}

/// `n` parallel tilted rays whose hit points on the plane z = 0 are uniform over the quad
/// [-1, 1]² (so over its uv square).
fn covering_rays(n: u32) -> Vec<Ray> {
    let pat = make_pattern(PatternKind::Random, 23);
    let d = Vec3::new(-0.04, 0.07, 1.0).normalize();
    (0..n)
        .map(|i| {
            let u = pat.sample_2d(UVec2::new(i, 0), 0, 0, 1);
            let hit = Vec3::new(2.0 * u.x - 1.0, 2.0 * u.y - 1.0, 0.0);
            Ray::new(hit - d / d.z, d)
        })
        .collect()
}

#[test]
fn leaf_texture_blocks_its_analytic_coverage() {
    let rays = covering_rays(40_000);
    let pi = std::f64::consts::PI;
    for (soft, blocked) in [(false, 2.0 / pi), (true, 1.0 / pi)] {
        let a = answers(
            &[0.0],
            &[Some(Alpha::Texture(Arc::new(Leaf { soft })))],
            &rays,
        );
        let passed = a.iter().filter(|h| h.is_none()).count();
        check_fraction(
            &format!("leaf (soft: {soft})"),
            passed,
            rays.len(),
            1.0 - blocked,
        );
    }
}
