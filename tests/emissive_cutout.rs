//! Emissive alpha cut-outs (pbrt-v4's `"float alpha"` / `"texture alpha"` on an area light):
//! a light of coverage a emits a·L on average. BSDF rays see it through the stochastic hit
//! test and light samples through the coverage at the sampled point, so every strategy (and
//! MIS, which mixes them) must find the same light. Checked on a floor under a square light:
//! constant coverage 0.3 delivers 0.3 of the unmasked light's radiance (5σ), and a mask that
//! keeps exactly one half of the square delivers what a light of only that half delivers.

mod render_support;

use glam::UVec2;
use penumbra::integrator::{IntegratorKind, MisHeuristic, RenderOptions, Strategy, render};
use render_support::{STRATEGIES, assert_fraction, mean_se, pbrt_scene_in};

/// A diffuse floor at z = 0 seen from z = 0.5, under a black, downward-facing square light at z = 1
/// spanning x ∈ [`x0`, `x1`], y ∈ [−1, 1] (uv: u = (x + 1)/2, v = (y + 1)/2, as over the
/// whole square [−1, 1]²), with the shape parameters `alpha` (pbrt text, may be empty) and the
/// directives `pre`.
fn scene(x0: f32, x1: f32, pre: &str, alpha: &str) -> String {
    let (u0, u1) = ((x0 + 1.0) / 2.0, (x1 + 1.0) / 2.0);
    lit_by(
        pre,
        &format!(
            "Shape \"trianglemesh\" {alpha} \"integer indices\" [0 2 1 0 3 2] \
             \"point3 P\" [{x0} -1 1  {x1} -1 1  {x1} 1 1  {x0} 1 1] \
             \"point2 uv\" [{u0} 0  {u1} 0  {u1} 1  {u0} 1]"
        ),
    )
}

/// The floor of [`scene`] lit by the black area light `shape`.
fn lit_by(pre: &str, shape: &str) -> String {
    format!(
        "LookAt 0 0 0.5  0 0 0  0 1 0\n\
         Camera \"perspective\" \"float fov\" 40\n\
         Film \"rgb\" \"integer xresolution\" 24 \"integer yresolution\" 24 \"string filename\" \"x.exr\"\n\
         WorldBegin\n\
         {pre}\n\
         Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n\
         Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \
         \"point3 P\" [-20 -20 0  20 -20 0  20 20 0  -20 20 0]\n\
         AttributeBegin\n\
         Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n\
         AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n\
         {shape}\n\
         AttributeEnd\n"
    )
}

/// Mean and standard error of the floor's radiance under `strategy` (direct lighting, or
/// path tracing with `depth` bounces).
fn mean(src: &str, strategy: Strategy, mis: MisHeuristic, path: Option<u32>) -> (f64, f64) {
    let (scene, warnings) = pbrt_scene_in(src, std::path::Path::new("."));
    assert!(
        !warnings
            .iter()
            .any(|w| w.contains("alpha") && !w.contains("tessellated")),
        "alpha warned about: {warnings:?}"
    );
    let mut opts = RenderOptions {
        spp: 64,
        seed: 9,
        strategy,
        mis,
        progress: false,
        ..RenderOptions::default()
    };
    if let Some(depth) = path {
        opts.integrator = IntegratorKind::Path;
        opts.max_depth = depth;
    }
    let (img, _) = render(&scene, UVec2::new(24, 24), &opts).expect("renders");
    mean_se(&img)
}

#[test]
fn constant_coverage_scales_the_light_under_every_strategy() {
    let open = scene(-1.0, 1.0, "", "");
    let cut = scene(-1.0, 1.0, "", "\"float alpha\" 0.3");
    for (strategy, mis) in STRATEGIES {
        assert_fraction(
            &format!("{strategy:?}/{mis:?}, coverage 0.3"),
            mean(&cut, strategy, mis, None),
            mean(&open, strategy, mis, None),
            0.3,
        );
    }
    // Path tracing: the light is black and the floor flat, so no light bounces and the path
    // tracer must find the same fraction.
    assert_fraction(
        "path tracing, MIS, coverage 0.3",
        mean(&cut, Strategy::Mis, MisHeuristic::Power, Some(3)),
        mean(&open, Strategy::Mis, MisHeuristic::Power, Some(3)),
        0.3,
    );
}

#[test]
fn a_half_mask_emits_exactly_the_kept_half() {
    // pbrt-v4's float checkerboard with uscale 2: coverage 1 where u < ½ (x < 0), else 0.
    let tex = "Texture \"half\" \"float\" \"checkerboard\" \"float uscale\" 2 \"float vscale\" 1 \
               \"float tex1\" 1 \"float tex2\" 0";
    let masked = scene(-1.0, 1.0, tex, "\"texture alpha\" \"half\"");
    // The same light cut to the half x ∈ [−1, 0] by geometry: the independent answer.
    let half = scene(-1.0, 0.0, "", "");
    for (strategy, mis) in STRATEGIES {
        assert_fraction(
            &format!("{strategy:?}/{mis:?}, half mask vs half light"),
            mean(&masked, strategy, mis, None),
            mean(&half, strategy, mis, None),
            1.0,
        );
    }
}

#[test]
fn a_cut_out_disk_light_scales_too() {
    // A disk light is sampled analytically; with a mask it becomes triangle lights (warned),
    // whose 64-gon has 0.16 % less area than the disk: far inside the bound.
    let disk = |alpha: &str| {
        lit_by(
            "",
            &format!(
                "Translate 0 0 1\nReverseOrientation\n\
                 Shape \"disk\" \"float radius\" 1 {alpha}"
            ),
        )
    };
    let (_, warnings) = pbrt_scene_in(&disk("\"float alpha\" 0.3"), std::path::Path::new("."));
    assert!(
        warnings.iter().any(|w| w.contains("tessellated")),
        "the tessellation is not said: {warnings:?}"
    );
    for (strategy, mis) in [
        (Strategy::LightSolidAngle, MisHeuristic::Power),
        (Strategy::Mis, MisHeuristic::Power),
    ] {
        assert_fraction(
            &format!("{strategy:?}/{mis:?}, disk of coverage 0.3"),
            mean(&disk("\"float alpha\" 0.3"), strategy, mis, None),
            mean(&disk(""), strategy, mis, None),
            0.3,
        );
    }
}
