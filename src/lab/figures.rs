//! The lecture's comparison figures as data: which scene, which panels, and for every panel the
//! estimator settings (strategy, N eye rays × M shadow rays, pattern, light selection).
//!
//! Keeping the figures declarative lets the runner, the report and the tests share one list, so
//! a figure's sample counts are written down exactly once.

use crate::bsdf::LobeSampling;
use crate::integrator::Strategy;
use crate::light_selection::SelectorKind;
use crate::sampling::PatternKind;

/// Which scene a figure renders.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FigureScene {
    /// The scene given on the command line (default `cornell`).
    Main,
    /// A specific built-in scene; the figure is skipped with a note when it does not exist.
    Builtin(&'static str),
    /// The first built-in whose name starts with this prefix (e.g. `many-`), if any.
    BuiltinPrefix(&'static str),
}

/// How a panel samples the glossy lobe of its BSDFs (the lecture's Phong slide).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LobeChoice {
    /// Uniform on the hemisphere.
    Uniform,
    /// Cosine-weighted.
    Cosine,
    /// Cosine-power around the lobe (importance sampling).
    Importance,
}

impl LobeChoice {
    /// Name used in labels and file names (matches `--bsdf-sampling`).
    pub fn name(self) -> &'static str {
        match self {
            LobeChoice::Uniform => "uniform",
            LobeChoice::Cosine => "cosine",
            LobeChoice::Importance => "cosine-power",
        }
    }

    /// The renderer's setting for this choice.
    pub fn sampling(self) -> LobeSampling {
        match self {
            LobeChoice::Uniform => LobeSampling::Uniform,
            LobeChoice::Cosine => LobeSampling::Cosine,
            LobeChoice::Importance => LobeSampling::Importance,
        }
    }
}

/// One image of a figure.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Short human-readable name shown in the montage ("light-area", "stratified", ...).
    pub label: String,
    /// Estimator.
    pub strategy: Strategy,
    /// Eye rays per pixel (N).
    pub spp: u32,
    /// Light (or BSDF) samples per eye ray (M).
    pub shadow_rays: u32,
    /// Sample pattern of every dimension.
    pub pattern: PatternKind,
    /// Light selection strategy.
    pub light_selection: SelectorKind,
    /// Lobe sampling of the BSDFs; `None` keeps each BSDF's default (importance sampling).
    pub lobe: Option<LobeChoice>,
}

impl Panel {
    /// A panel with the default light selection and lobe sampling.
    fn new(
        label: &str,
        strategy: Strategy,
        spp: u32,
        shadow_rays: u32,
        pattern: PatternKind,
    ) -> Self {
        Self {
            label: label.to_string(),
            strategy,
            spp,
            shadow_rays,
            pattern,
            light_selection: SelectorKind::DEFAULT,
            lobe: None,
        }
    }

    /// "N × M" as the lecture writes it.
    pub fn counts(&self) -> String {
        format!("{} × {}", self.spp, self.shadow_rays)
    }

    /// File-name-safe identifier, unique within its figure.
    pub fn slug(&self) -> String {
        let label: String = self
            .label
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() {
                    c.to_ascii_lowercase()
                } else {
                    '-'
                }
            })
            .collect();
        format!("{label}-{}x{}", self.spp, self.shadow_rays)
    }

    /// Shadow (or BSDF) rays per pixel: the cost measure used for equal-sample comparisons.
    pub fn samples_per_pixel(&self) -> u64 {
        self.spp as u64 * self.shadow_rays.max(1) as u64
    }
}

/// One figure: a titled row of panels rendered on the same scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// Stable identifier used for file names (`fig1-...`).
    pub id: &'static str,
    /// Title drawn above the montage.
    pub title: &'static str,
    /// The lecture's point, one sentence (shown in the HTML report).
    pub claim: &'static str,
    /// Which scene it renders.
    pub scene: FigureScene,
    /// The panels, left to right.
    pub panels: Vec<Panel>,
}

/// Light selection strategies compared by figure 6, in the lecture's order.
pub const LIGHT_SELECTIONS: [SelectorKind; 6] = [
    SelectorKind::Uniform,
    SelectorKind::Power,
    SelectorKind::Spatial,
    SelectorKind::Adaptive,
    SelectorKind::Wald,
    SelectorKind::Bvh,
];

/// The lecture's figures 1–6.
pub fn lecture_figures() -> Vec<Figure> {
    use PatternKind::{Fixed, Grid, Random, Stratified};
    use Strategy::{Bsdf, LightArea, LightSolidAngle};
    let mut phong = Vec::new();
    for lobe in [
        LobeChoice::Uniform,
        LobeChoice::Cosine,
        LobeChoice::Importance,
    ] {
        let mut p = Panel::new(lobe.name(), Bsdf, 4, 32, Stratified);
        p.lobe = Some(lobe);
        phong.push(p);
    }
    let lights = LIGHT_SELECTIONS
        .iter()
        .map(|&s| {
            let mut p = Panel::new(s.name(), LightSolidAngle, 4, 4, Stratified);
            p.light_selection = s;
            p
        })
        .collect();
    vec![
        Figure {
            id: "fig1",
            title: "BSDF (projected solid angle) vs light-area sampling",
            claim: "For a small light, sampling its area is far less noisy than sampling directions.",
            scene: FigureScene::Main,
            panels: vec![
                Panel::new("bsdf", Bsdf, 4, 100, Stratified),
                Panel::new("light-area", LightArea, 4, 100, Stratified),
            ],
        },
        Figure {
            id: "fig2",
            title: "Fixed vs random sample location on the light",
            claim: "A fixed point on the light gives hard, wrong shadows; random points give noise.",
            scene: FigureScene::Main,
            panels: vec![
                Panel::new("fixed", LightArea, 4, 1, Fixed),
                Panel::new("random", LightArea, 4, 1, Random),
            ],
        },
        Figure {
            id: "fig3",
            title: "Regular grid vs stratified random on the light",
            claim: "A regular grid bands the penumbra; jittered strata trade banding for less noise.",
            scene: FigureScene::Main,
            panels: vec![
                Panel::new("grid", LightArea, 4, 64, Grid),
                Panel::new("stratified", LightArea, 4, 64, Stratified),
            ],
        },
        Figure {
            id: "fig4",
            title: "Stratified: 4 eye × 16 shadow rays vs 64 eye × 1",
            claim: "At equal shadow rays, more eye rays also antialias edges and textures.",
            scene: FigureScene::Main,
            panels: vec![
                Panel::new("stratified", LightArea, 4, 16, Stratified),
                Panel::new("stratified", LightArea, 64, 1, Stratified),
            ],
        },
        Figure {
            id: "fig5",
            title: "Phong lobe: uniform vs cosine vs cosine-power sampling",
            claim: "Sampling proportional to the cosine-power lobe removes most of the glossy noise.",
            scene: FigureScene::Builtin("cornell-phong"),
            panels: phong,
        },
        Figure {
            id: "fig6",
            title: "Many lights: light selection at equal samples",
            claim: "Selecting lights by (estimated) contribution beats uniform selection.",
            scene: FigureScene::BuiltinPrefix("many-"),
            panels: lights,
        },
    ]
}
