//! `penumbra render`: load a scene, render it with the chosen estimator, write the image.

use anyhow::Context;
use glam::UVec2;
use penumbra::integrator::{MisHeuristic, RenderOptions, Strategy, render};
use penumbra::sampling::PatternKind;
use penumbra::scene::builtin::BuiltinOptions;
use penumbra::scene::load::{LoadOptions, load};
use penumbra::scene::view::ViewOptions;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use super::interrupt::Interrupt;
use super::memory::{self, Need};
use super::messages;
use penumbra::image::io::{check_output_path, remove_stale_temps, write_image_with};

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
    /// Light selection strategy.
    #[arg(long, default_value = "uniform")]
    pub light_selection: String,
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
    /// Camera eye X,Y,Z (replaces the eye of the scene's camera or of automatic framing).
    #[arg(long, value_parser = parse_vec3, allow_negative_numbers = true)]
    pub look_from: Option<glam::Vec3>,
    /// Camera target X,Y,Z (default with --look-from: the scene's centre).
    #[arg(long, value_parser = parse_vec3, allow_negative_numbers = true)]
    pub look_at: Option<glam::Vec3>,
    /// Camera up vector X,Y,Z (default: the scene camera's, 0,1,0 for automatic framing).
    #[arg(long, value_parser = parse_vec3, allow_negative_numbers = true)]
    pub up: Option<glam::Vec3>,
    /// Field of view in degrees along the shorter image axis (default: the scene camera's, 40
    /// for automatic framing).
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

/// Run the command: check the output and the memory, load, render, write, print the summary.
pub fn run(args: Args) -> anyhow::Result<()> {
    let start = Instant::now();
    let interrupt = Interrupt::install()?;
    anyhow::ensure!(args.shadow_rays >= 1, "--shadow-rays must be at least 1");
    anyhow::ensure!(args.exposure.is_finite(), "--exposure must be finite");
    anyhow::ensure!(args.spp != Some(0), "--spp must be at least 1");
    anyhow::ensure!(args.threads != Some(0), "--threads must be at least 1");
    // Everything that can be checked before the scene is loaded is checked now: a bad output
    // path or too large a film must not cost a load and a render first.
    if let Some(out) = &args.output {
        prepare_output(out)?;
    }
    let threads = args.threads.unwrap_or_else(rayon::current_num_threads);
    if let Some(res) = args.res {
        memory::check(&Need::new(res, threads, 0), memory::available().as_ref())?;
    }

    let load_start = Instant::now();
    let loaded = with_spinner(!args.quiet, &format!("loading {}", args.scene), || {
        load(&args.scene, &load_options(&args))
    })?;
    let load_time = load_start.elapsed();
    for w in &loaded.warnings {
        eprintln!("{}", messages::format_warning(w));
    }
    for n in &loaded.notes {
        eprintln!("note: {n}");
    }
    let scene = loaded.scene;
    // The loaders build the BVHs (scene and emitters) as their last step and time them.
    let bvh_time = scene.geometry.build_time + scene.emitters.build_time;
    let res = args.res.unwrap_or(scene.film.resolution);
    let opts = RenderOptions {
        spp: args.spp.or(scene.film.spp).unwrap_or(64),
        shadow_rays: args.shadow_rays,
        seed: args.seed,
        strategy: args.strategy,
        mis: args.mis,
        pattern: args.pattern,
        light_selection: args.light_selection.clone(),
        bsdf_sampling: args.bsdf_sampling,
        mis_light: args.mis_light,
        progress: !args.quiet,
    };
    anyhow::ensure!(
        opts.spp >= 1,
        "the scene's pixel samples must be at least 1"
    );
    let out = match &args.output {
        Some(out) => out.clone(),
        None => {
            let out = scene
                .film
                .filename
                .as_ref()
                .map_or_else(|| PathBuf::from("penumbra.png"), PathBuf::from);
            prepare_output(&out).map_err(|e| {
                anyhow::anyhow!(
                    "{} (the scene names this output; -o chooses another)",
                    messages::format_error(&e)
                )
            })?;
            out
        }
    };
    let need = Need::new(res, threads, scene.lights.len());
    memory::check(&need, memory::available().as_ref())?;

    let render_start = Instant::now();
    let (img, stats) = match args.threads {
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .context("creating the thread pool")?
            .install(|| render(&scene, res, &opts))?,
        None => render(&scene, res, &opts)?,
    };
    let render_time = render_start.elapsed();
    // pbrt-v4's film response (ISO, exposure, white balance); the identity leaves it untouched.
    let mut img = img;
    scene.film.sensor.apply(&mut img);

    let write_start = Instant::now();
    interrupt.writing(test_write_pause(), |ctl| {
        write_image_with(&img, &out, args.exposure, ctl)
    })?;
    let write_time = write_start.elapsed();

    let memory = memory::peak_resident()
        .map(|peak| format!("  peak memory {}", memory::human(peak)))
        .unwrap_or_default();
    let secs = |d: Duration| d.as_secs_f64();
    let line = format!(
        "{}x{}  {} spp x {} shadow rays  {}  load {:.3} s  bvh {:.3} s  render {:.3} s  \
         write {:.3} s  total {:.3} s  {:.2} M rays  {:.1} Mrays/s{memory}  -> {}",
        res.x,
        res.y,
        opts.spp,
        opts.shadow_rays,
        opts.strategy,
        secs(load_time.saturating_sub(bvh_time)),
        secs(bvh_time),
        secs(render_time),
        secs(write_time),
        secs(start.elapsed()),
        stats.rays as f64 / 1e6,
        stats.rays as f64 / secs(render_time).max(1e-9) / 1e6,
        out.display()
    );
    writeln!(std::io::stdout(), "{line}").context("writing to standard output")?;
    Ok(())
}

/// Check that `out` can be written and remove the temp files killed runs left beside it.
fn prepare_output(out: &Path) -> anyhow::Result<()> {
    check_output_path(out)?;
    for stale in remove_stale_temps(out) {
        eprintln!(
            "removed {}, left by an interrupted earlier run",
            stale.display()
        );
    }
    Ok(())
}

/// Test hook: `PENUMBRA_TEST_WRITE_PAUSE_MS` pauses the image write after every 1 MiB so the
/// tests can interrupt a write in progress.
fn test_write_pause() -> Duration {
    std::env::var("PENUMBRA_TEST_WRITE_PAUSE_MS")
        .ok()
        .and_then(|v| v.parse().ok())
        .map_or(Duration::ZERO, Duration::from_millis)
}

/// Run `f` under a spinner with the elapsed time on stderr (when it is a terminal): loading a
/// large scene takes seconds, and a silent terminal looks like a hang.
fn with_spinner<T>(show: bool, msg: &str, f: impl FnOnce() -> T) -> T {
    use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
    if !show || !std::io::stderr().is_terminal() {
        return f();
    }
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} {elapsed}") {
        bar.set_style(style);
    }
    bar.set_message(msg.to_string());
    bar.enable_steady_tick(Duration::from_millis(100));
    let r = f();
    bar.finish_and_clear();
    r
}
