//! Runs the lab: loads the scenes, renders (or reuses) a reference per scene, renders every panel
//! of every figure, measures wall time and relMSE, writes images and montages, and sweeps the
//! convergence of the four estimators. The report files are written by [`super::report`].

use super::figures::{Figure, FigureScene, LobeChoice, Panel, lecture_figures};
use super::mask::{edge_mask, smooth_rel_mse};
use super::report::{
    ConvergencePoint, ConvergenceSeries, FigureResult, LabResults, PanelResult, ReferenceInfo,
};
use crate::image::{Image, compare, error_image, read_image, save_png_atomic, write_image};
use crate::integrator::{MisHeuristic, RenderOptions, Strategy, render};
use crate::light_selection::SelectorKind;
use crate::sampling::PatternKind;
use crate::scene::Scene;
use crate::scene::builtin::BUILTINS;
use crate::scene::load::{LoadOptions, load};
use anyhow::Context;
use glam::UVec2;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::HashMap;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Default lab resolution: the whole default lab stays under two minutes on two cores.
pub const DEFAULT_RES: UVec2 = UVec2::new(256, 256);
/// Default eye rays per pixel of the automatic reference (MIS, one sample of each technique).
pub const DEFAULT_REFERENCE_SPP: u32 = 512;
/// Default largest spp of the convergence sweep (doubling from 1).
pub const DEFAULT_CONVERGENCE_SPP: u32 = 64;

/// Seed offset of the reference, so its samples are independent of every panel's.
const REFERENCE_SEED_OFFSET: u64 = 0x5eed_f2ef;

/// What to run and where to write it.
#[derive(Clone, Debug)]
pub struct LabOptions {
    /// Scene of figures 1–4 and of the convergence plot: built-in name or file.
    pub scene: String,
    /// Output directory (created if missing).
    pub out: PathBuf,
    /// Resolution of every panel; `None`: the reference file's size, else [`DEFAULT_RES`].
    pub res: Option<UVec2>,
    /// Reference image of the main scene; `None` renders one (cached in `out`).
    pub reference: Option<PathBuf>,
    /// Eye rays per pixel of rendered references.
    pub reference_spp: u32,
    /// Largest spp of the convergence sweep; 0 skips the sweep.
    pub convergence_spp: u32,
    /// Seed of every panel.
    pub seed: u64,
    /// Show a progress bar (only on a terminal).
    pub progress: bool,
    /// Which figures to run, by id (`fig1` ...); empty runs all.
    pub figures: Vec<String>,
    /// Options handed to the scene loader.
    pub load: LoadOptions,
}

impl Default for LabOptions {
    fn default() -> Self {
        Self {
            scene: "cornell".into(),
            out: PathBuf::from("lab"),
            res: None,
            reference: None,
            reference_spp: DEFAULT_REFERENCE_SPP,
            convergence_spp: DEFAULT_CONVERGENCE_SPP,
            seed: 0,
            progress: true,
            figures: Vec::new(),
            load: LoadOptions::default(),
        }
    }
}

/// A loaded scene and its reference image.
struct Prepared {
    scene: Scene,
    reference: Image,
    /// Edge pixels of the reference (excluded from the smooth relMSE).
    mask: Vec<bool>,
}

/// The built-in or main scene name a figure renders, or why it cannot run.
fn figure_scene_name(fig: &Figure, main: &str) -> Result<String, String> {
    match &fig.scene {
        FigureScene::Main => Ok(main.to_string()),
        FigureScene::Builtin(name) => BUILTINS
            .iter()
            .find(|b| b.name == *name)
            .map(|b| b.name.to_string())
            .ok_or_else(|| format!("built-in scene '{name}' is not available in this build")),
        FigureScene::BuiltinPrefix(prefix) => BUILTINS
            .iter()
            .find(|b| b.name.starts_with(prefix))
            .map(|b| b.name.to_string())
            .ok_or_else(|| format!("no built-in '{prefix}*' scene is available in this build")),
    }
}

/// Scenes with more lights than this get references at fewer spp.
const MANY_LIGHTS: usize = 4;
/// Many-light references use this fraction of `--reference-spp`: their per-sample cost is
/// several times Cornell's, and a good selector converges fast enough that the reference
/// noise stays well below the panels' error.
const MANY_LIGHTS_REFERENCE_DIVISOR: u32 = 4;

/// Eye rays per pixel of the reference rendered for `scene`.
fn reference_spp(scene: &Scene, opts: &LabOptions) -> u32 {
    if scene.lights.len() > MANY_LIGHTS {
        (opts.reference_spp / MANY_LIGHTS_REFERENCE_DIVISOR).max(1)
    } else {
        opts.reference_spp
    }
}

/// Render options of a panel.
fn panel_options(panel: &Panel, seed: u64) -> RenderOptions {
    RenderOptions {
        spp: panel.spp,
        shadow_rays: panel.shadow_rays,
        seed,
        strategy: panel.strategy,
        mis: MisHeuristic::Power,
        pattern: panel.pattern,
        light_selection: panel.light_selection,
        bsdf_sampling: panel.lobe.map(LobeChoice::sampling).unwrap_or_default(),
        ..RenderOptions::default()
    }
}

/// Rough cost of a render in "shading samples", for the progress bar only.
fn cost(res: UVec2, spp: u32, shadow_rays: u32, strategy: Strategy) -> u64 {
    let per_eye = 1 + shadow_rays.max(1) as u64 * if strategy == Strategy::Mis { 2 } else { 1 };
    res.x as u64 * res.y as u64 * spp as u64 * per_eye
}

/// File-name-safe form of a scene spec (built-in name or path).
fn scene_slug(spec: &str) -> String {
    let stem = Path::new(spec)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| spec.to_string());
    stem.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Doubling spp values 1, 2, 4, ... up to `max`.
pub fn convergence_spps(max: u32) -> Vec<u32> {
    std::iter::successors(Some(1u32), |&s| s.checked_mul(2))
        .take_while(|&s| s <= max)
        .collect()
}

/// The whole-run progress bar.
struct Progress {
    bar: ProgressBar,
}

impl Progress {
    fn new(enabled: bool, total: u64) -> Self {
        let bar = if enabled && std::io::stderr().is_terminal() {
            let b = ProgressBar::with_draw_target(Some(total.max(1)), ProgressDrawTarget::stderr());
            if let Ok(style) =
                ProgressStyle::with_template("{bar:40} {percent:>3}% {elapsed} ETA {eta}  {msg}")
            {
                b.set_style(style);
            }
            b
        } else {
            ProgressBar::hidden()
        };
        Self { bar }
    }

    fn start(&self, what: &str) {
        self.bar.set_message(what.to_string());
    }

    fn done(&self, units: u64) {
        self.bar.inc(units);
    }
}

/// Run the lab; writes every image, montage, plot and report into `opts.out`.
pub fn run_lab(opts: &LabOptions) -> anyhow::Result<LabResults> {
    let started = Instant::now();
    anyhow::ensure!(
        opts.reference_spp >= 1,
        "--reference-spp must be at least 1"
    );
    std::fs::create_dir_all(&opts.out)
        .with_context(|| format!("creating output directory {}", opts.out.display()))?;
    let user_reference = match &opts.reference {
        Some(path) => Some(
            read_image(path).with_context(|| format!("reading reference {}", path.display()))?,
        ),
        None => None,
    };
    let res = opts
        .res
        .or_else(|| {
            user_reference
                .as_ref()
                .map(|r| UVec2::new(r.width, r.height))
        })
        .unwrap_or(DEFAULT_RES);
    if let Some(r) = &user_reference {
        anyhow::ensure!(
            r.width == res.x && r.height == res.y,
            "reference is {}x{} but the lab renders at {}x{}; pass a matching --res",
            r.width,
            r.height,
            res.x,
            res.y
        );
    }

    let all = lecture_figures();
    for want in &opts.figures {
        anyhow::ensure!(
            all.iter().any(|f| f.id == want),
            "unknown figure '{want}' (expected one of: {})",
            all.iter().map(|f| f.id).collect::<Vec<_>>().join(", ")
        );
    }
    let figures: Vec<Figure> = all
        .into_iter()
        .filter(|f| opts.figures.is_empty() || opts.figures.iter().any(|w| w == f.id))
        .collect();

    // Load every scene a figure needs once; a missing optional scene skips its figure.
    let mut notes = Vec::new();
    let mut scenes: HashMap<String, Scene> = HashMap::new();
    let mut fig_scene: Vec<Result<String, String>> = Vec::new();
    let spps = convergence_spps(opts.convergence_spp);
    // The main scene is needed for the convergence sweep or a figure on it.
    let mut needed = Vec::new();
    if !spps.is_empty() || figures.iter().any(|f| f.scene == FigureScene::Main) {
        needed.push(opts.scene.clone());
    }
    for fig in &figures {
        let name = figure_scene_name(fig, &opts.scene);
        if let Ok(n) = &name
            && !needed.contains(n)
        {
            needed.push(n.clone());
        }
        fig_scene.push(name);
    }
    for name in &needed {
        let loaded = load(name, &opts.load)?;
        for w in &loaded.warnings {
            notes.push(format!("{name}: {w}"));
        }
        scenes.insert(name.clone(), loaded.scene);
    }

    // Plan the run so the progress bar covers all of it.
    let mut total = 0u64;
    for (name, scene) in &scenes {
        let given = user_reference.is_some() && name == &opts.scene;
        let spp = reference_spp(scene, opts);
        if !given && !reference_path(&opts.out, name, res, spp).exists() {
            total += cost(res, spp, 1, Strategy::Mis);
        }
    }
    for fig in &figures {
        total += fig
            .panels
            .iter()
            .map(|p| cost(res, p.spp, p.shadow_rays, p.strategy))
            .sum::<u64>();
    }
    for s in Strategy::ALL {
        total += spps.iter().map(|&n| cost(res, n, 1, s)).sum::<u64>();
    }
    let progress = Progress::new(opts.progress, total);

    // References.
    let mut prepared: HashMap<String, Prepared> = HashMap::new();
    let mut references = Vec::new();
    for name in &needed {
        let Some(scene) = scenes.remove(name) else {
            continue;
        };
        let (reference, info) = if name == &opts.scene
            && let (Some(img), Some(path)) = (user_reference.clone(), &opts.reference)
        {
            let info = ReferenceInfo {
                scene: name.clone(),
                source: "file".into(),
                path: path.display().to_string(),
                spp: None,
                time_s: 0.0,
                smooth_fraction: 0.0,
                light_selection: String::new(),
            };
            (img, info)
        } else {
            progress.start(&format!("reference {name}"));
            let (img, info) = cached_reference(&scene, name, res, opts, &progress)?;
            (img, info)
        };
        let mask = edge_mask(&reference);
        let mut info = info;
        info.smooth_fraction = smooth_rel_mse(&reference, &reference, &mask).1;
        references.push(info);
        prepared.insert(
            name.clone(),
            Prepared {
                scene,
                reference,
                mask,
            },
        );
    }

    // Figures.
    let mut figure_results = Vec::new();
    for (fig, scene_name) in figures.iter().zip(fig_scene) {
        let scene_name = match scene_name {
            Ok(n) => n,
            Err(why) => {
                notes.push(format!("{}: skipped: {why}", fig.id));
                figure_results.push(FigureResult::skipped(fig, why));
                continue;
            }
        };
        let Some(prep) = prepared.get(&scene_name) else {
            continue;
        };
        let mut result = FigureResult::skipped(fig, String::new());
        result.scene = scene_name.clone();
        result.skipped.clear();
        let mut montage_panels = Vec::new();
        for panel in &fig.panels {
            let units = cost(res, panel.spp, panel.shadow_rays, panel.strategy);
            progress.start(&format!("{} {} {}", fig.id, panel.label, panel.counts()));
            let rendered = render(&prep.scene, res, &panel_options(panel, opts.seed));
            progress.done(units);
            let (img, stats) = rendered?;
            let err = compare(&img, &prep.reference)?;
            let stem = format!("{}-{}", fig.id, panel.slug());
            let files = write_outputs(&opts.out, &stem, &img, &prep.reference)?;
            let pr = PanelResult {
                figure: fig.id.to_string(),
                label: panel.label.clone(),
                strategy: panel.strategy.name().to_string(),
                pattern: panel.pattern.name().to_string(),
                light_selection: panel.light_selection.name().to_string(),
                lobe: panel.lobe.map(|l| l.name().to_string()),
                spp: panel.spp,
                shadow_rays: panel.shadow_rays,
                time_s: stats.time.as_secs_f64(),
                rays: stats.rays,
                rel_mse: err.rel_mse,
                smooth_rel_mse: smooth_rel_mse(&img, &prep.reference, &prep.mask).0,
                mse: err.mse,
                exr: files.exr,
                png: files.png,
                error_png: files.error_png,
            };
            montage_panels.push((img, pr.montage_label()));
            result.panels.push(pr);
        }
        if !montage_panels.is_empty() {
            let file = format!("{}.png", fig.id);
            let m = crate::image::montage::montage(
                &montage_panels,
                montage_panels.len(),
                0.0,
                fig.title,
            );
            save_png_atomic(&m, &opts.out.join(&file))?;
            result.montage = Some(file);
        }
        figure_results.push(result);
    }

    // Convergence of the four estimators on the main scene.
    let mut convergence = Vec::new();
    if !spps.is_empty()
        && let Some(prep) = prepared.get(&opts.scene)
    {
        for strategy in Strategy::ALL {
            let mut points = Vec::new();
            for &spp in &spps {
                progress.start(&format!("convergence {strategy} {spp} spp"));
                let o = RenderOptions {
                    spp,
                    shadow_rays: 1,
                    seed: opts.seed,
                    strategy,
                    mis: MisHeuristic::Power,
                    pattern: PatternKind::Stratified,
                    light_selection: SelectorKind::DEFAULT,
                    ..RenderOptions::default()
                };
                let (img, stats) = render(&prep.scene, res, &o)?;
                progress.done(cost(res, spp, 1, strategy));
                let err = compare(&img, &prep.reference)?;
                points.push(ConvergencePoint {
                    spp,
                    time_s: stats.time.as_secs_f64(),
                    rel_mse: err.rel_mse,
                    smooth_rel_mse: smooth_rel_mse(&img, &prep.reference, &prep.mask).0,
                });
            }
            convergence.push(ConvergenceSeries {
                strategy: strategy.name().to_string(),
                points,
            });
        }
    }
    progress.bar.finish_and_clear();

    let mut results = LabResults {
        scene: opts.scene.clone(),
        resolution: [res.x, res.y],
        seed: opts.seed,
        references,
        figures: figure_results,
        convergence,
        convergence_svg: None,
        convergence_png: None,
        notes,
        total_time_s: 0.0,
    };
    if !results.convergence.is_empty() {
        super::report::write_convergence_plot(&opts.out, &mut results)?;
    }
    results.total_time_s = started.elapsed().as_secs_f64();
    super::report::write_json(&opts.out, &results)?;
    super::report::write_html(&opts.out, &results)?;
    Ok(results)
}

/// Where the cached reference of `scene` at `res` and `spp` lives.
pub fn reference_path(out: &Path, scene: &str, res: UVec2, spp: u32) -> PathBuf {
    out.join(format!(
        "reference-{}-{}x{}-{}spp.exr",
        scene_slug(scene),
        res.x,
        res.y,
        spp
    ))
}

/// The reference of `scene`: read from the cache in `opts.out` when present and of the right
/// size, else rendered with MIS at [`reference_spp`] and cached (EXR + PNG).
fn cached_reference(
    scene: &Scene,
    name: &str,
    res: UVec2,
    opts: &LabOptions,
    progress: &Progress,
) -> anyhow::Result<(Image, ReferenceInfo)> {
    let spp = reference_spp(scene, opts);
    let path = reference_path(&opts.out, name, res, spp);
    let file = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    // Many lights: the light BVH (uniform would leave the reference noisy); a few: uniform,
    // the cheapest, whose error there equals the others'.
    let selection = if scene.lights.len() > MANY_LIGHTS {
        SelectorKind::Bvh
    } else {
        SelectorKind::Uniform
    };
    let mut info = ReferenceInfo {
        scene: name.to_string(),
        source: "cache".into(),
        path: file,
        spp: Some(spp),
        time_s: 0.0,
        smooth_fraction: 0.0,
        light_selection: selection.name().to_string(),
    };
    if path.exists() {
        // A damaged or mis-sized cache is re-rendered rather than trusted.
        if let Ok(img) = read_image(&path)
            && img.width == res.x
            && img.height == res.y
            && !img.has_non_finite()
        {
            return Ok((img, info));
        }
    }
    let o = RenderOptions {
        spp,
        shadow_rays: 1,
        seed: opts.seed.wrapping_add(REFERENCE_SEED_OFFSET),
        strategy: Strategy::Mis,
        mis: MisHeuristic::Power,
        pattern: PatternKind::Stratified,
        light_selection: selection,
        ..RenderOptions::default()
    };
    let (img, stats) = render(scene, res, &o)?;
    progress.done(cost(res, spp, 1, Strategy::Mis));
    write_image(&img, &path, 0.0)?;
    write_image(&img, &path.with_extension("png"), 0.0)?;
    info.source = "rendered".into();
    info.time_s = stats.time.as_secs_f64();
    Ok((img, info))
}

/// Relative file names written for one panel.
struct PanelFiles {
    exr: String,
    png: String,
    error_png: String,
}

/// Write a panel as EXR and PNG plus its false-colour relMSE map.
fn write_outputs(
    out: &Path,
    stem: &str,
    img: &Image,
    reference: &Image,
) -> anyhow::Result<PanelFiles> {
    let files = PanelFiles {
        exr: format!("{stem}.exr"),
        png: format!("{stem}.png"),
        error_png: format!("{stem}-error.png"),
    };
    write_image(img, &out.join(&files.exr), 0.0)?;
    write_image(img, &out.join(&files.png), 0.0)?;
    write_image(
        &error_image(img, reference)?,
        &out.join(&files.error_png),
        0.0,
    )?;
    Ok(files)
}
