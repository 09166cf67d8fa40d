//! `penumbra render`: load a scene, render it with the chosen estimator, write the image.

use anyhow::Context;
use glam::UVec2;
use penumbra::integrator::{MisHeuristic, RenderOptions, Strategy, render};
use penumbra::light_selection::SelectorKind;
use penumbra::sampling::PatternKind;
use penumbra::scene::builtin::BuiltinOptions;
use penumbra::scene::load::{LoadOptions, load};
use penumbra::scene::view::ViewOptions;
use std::path::PathBuf;

/// Arguments of `penumbra render`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Built-in scene name (see `penumbra scenes`) or scene file path.
    #[arg(default_value = "cornell")]
    pub scene: String,
    /// Output image (.png, .exr or .pfm); default: the scene's file name or penumbra.png.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Eye rays per pixel (N); default: the scene's, else 64.
    #[arg(long)]
    pub spp: Option<u32>,
    /// Light (or BSDF) samples per eye ray (M).
    #[arg(long, default_value_t = 1)]
    pub shadow_rays: u32,
    /// Resolution WxH; default: the scene's.
    #[arg(long, value_parser = parse_res)]
    pub res: Option<UVec2>,
    /// Seed of every random number.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Worker threads (default: all cores). The image does not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
    /// Estimator: bsdf, light-area, light-solid-angle or mis.
    #[arg(long, default_value = "mis")]
    pub strategy: Strategy,
    /// MIS heuristic: power (β = 2) or balance.
    #[arg(long, default_value = "power")]
    pub mis: MisHeuristic,
    /// Sample pattern: fixed, random, grid, stratified, lhs or sobol.
    #[arg(long, default_value = "stratified")]
    pub pattern: PatternKind,
    /// Light selection: uniform (the default), power, spatial, adaptive, wald, bvh or
    /// exhaustive.
    #[arg(long, default_value_t = SelectorKind::DEFAULT)]
    pub light_selection: SelectorKind,
    /// Light sampling technique inside `mis`: solid-angle (default) or area.
    #[arg(long, default_value = "solid-angle", value_parser = parse_mode)]
    pub mis_light: penumbra::lights::SamplingMode,
    /// How BSDF lobes are sampled: importance (cosine-power / GGX), cosine or uniform.
    #[arg(long, default_value = "importance")]
    pub bsdf_sampling: penumbra::bsdf::LobeSampling,
    /// PNG exposure in stops.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Number of lights of the many-light built-in scenes.
    #[arg(long)]
    pub light_count: Option<u32>,
    /// Rooms per side of `many-rooms`.
    #[arg(long)]
    pub rooms: Option<u32>,
    /// Triangle count of procedural meshes (`dense`).
    #[arg(long)]
    pub triangles: Option<u32>,
    /// OBJ: treat the MTL ambient colour Ka as emitted radiance (Embree Cornell-box files).
    #[arg(long)]
    pub obj_ka_emission: bool,
    /// OBJ/glTF camera eye X,Y,Z (overrides the file's camera / automatic framing).
    #[arg(long, value_parser = parse_vec3, allow_negative_numbers = true)]
    pub look_from: Option<glam::Vec3>,
    /// OBJ/glTF camera target X,Y,Z.
    #[arg(long, value_parser = parse_vec3, allow_negative_numbers = true)]
    pub look_at: Option<glam::Vec3>,
    /// OBJ/glTF camera up vector X,Y,Z (default 0,1,0).
    #[arg(long, value_parser = parse_vec3, allow_negative_numbers = true)]
    pub up: Option<glam::Vec3>,
    /// OBJ/glTF field of view in degrees along the shorter image axis (default 40).
    #[arg(long)]
    pub fov: Option<f32>,
}

/// Parse `X,Y,Z` (finite numbers).
pub fn parse_vec3(s: &str) -> Result<glam::Vec3, String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|c| c.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("expected X,Y,Z (e.g. 0,1,5), got '{s}'"))?;
    match v[..] {
        [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => {
            Ok(glam::Vec3::new(x, y, z))
        }
        _ => Err(format!("expected three finite numbers X,Y,Z, got '{s}'")),
    }
}

/// Parse a light sampling mode name.
pub fn parse_mode(s: &str) -> Result<penumbra::lights::SamplingMode, String> {
    match s {
        "area" => Ok(penumbra::lights::SamplingMode::Area),
        "solid-angle" => Ok(penumbra::lights::SamplingMode::SolidAngle),
        _ => Err(format!("expected area or solid-angle, got '{s}'")),
    }
}

/// Parse `WxH`.
pub fn parse_res(s: &str) -> Result<UVec2, String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WxH (e.g. 512x512), got '{s}'"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("bad width in '{s}'"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("bad height in '{s}'"))?;
    if w == 0 || h == 0 || w > 65536 || h > 65536 {
        return Err(format!(
            "resolution must be between 1 and 65536 per axis, got '{s}'"
        ));
    }
    Ok(UVec2::new(w, h))
}

/// The load options the render-like commands share.
pub fn load_options(a: &Args) -> LoadOptions {
    LoadOptions {
        builtin: BuiltinOptions {
            light_count: a.light_count,
            rooms: a.rooms,
            triangles: a.triangles,
        },
        obj_ka_emission: a.obj_ka_emission,
        view: ViewOptions {
            look_from: a.look_from,
            look_at: a.look_at,
            up: a.up,
            fov: a.fov,
        },
    }
}

/// Run the command.
pub fn run(args: Args) -> anyhow::Result<()> {
    anyhow::ensure!(args.shadow_rays >= 1, "--shadow-rays must be at least 1");
    anyhow::ensure!(args.exposure.is_finite(), "--exposure must be finite");
    let loaded = load(&args.scene, &load_options(&args))?;
    for w in &loaded.warnings {
        eprintln!("warning: {w}");
    }
    let scene = loaded.scene;
    let res = args.res.unwrap_or(scene.film.resolution);
    let opts = RenderOptions {
        spp: args.spp.or(scene.film.spp).unwrap_or(64),
        shadow_rays: args.shadow_rays,
        seed: args.seed,
        strategy: args.strategy,
        mis: args.mis,
        pattern: args.pattern,
        light_selection: args.light_selection,
        bsdf_sampling: args.bsdf_sampling,
        mis_light: args.mis_light,
        progress: !args.quiet,
    };
    anyhow::ensure!(opts.spp >= 1, "--spp must be at least 1");
    let out = args
        .output
        .clone()
        .or_else(|| scene.film.filename.as_ref().map(PathBuf::from))
        .unwrap_or_else(|| PathBuf::from("penumbra.png"));
    let (img, stats) = match args.threads {
        Some(t) => {
            anyhow::ensure!(t >= 1, "--threads must be at least 1");
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .context("creating the thread pool")?
                .install(|| render(&scene, res, &opts))?
        }
        None => render(&scene, res, &opts)?,
    };
    penumbra::image::io::write_image(&img, &out, args.exposure)
        .with_context(|| format!("writing {}", out.display()))?;
    println!(
        "{}x{}  {} spp x {} shadow rays  {}  {:.3} s  {:.2} M rays  {:.1} Mrays/s  -> {}",
        res.x,
        res.y,
        opts.spp,
        opts.shadow_rays,
        opts.strategy,
        stats.time.as_secs_f64(),
        stats.rays as f64 / 1e6,
        stats.mrays_per_s(),
        out.display()
    );
    Ok(())
}
