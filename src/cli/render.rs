//! `penumbra render`: load a scene, render it with the chosen estimator, write the image.

use anyhow::Context;
use glam::UVec2;
use penumbra::integrator::{IntegratorKind, MisHeuristic, RenderOptions, Strategy, render};
use penumbra::light_selection::SelectorKind;
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
use penumbra::image::parts::{Part, PartInfo, render_key, write_part};
use penumbra::progressive::{Accumulator, PassPolicy, Stop, render_passes};

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
    /// Light (or BSDF) samples per eye ray (M) at the first vertex; path tracing's later
    /// vertices take one light sample and one BSDF sample each.
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
    /// Light transport: direct (emission and direct lighting: the path tracer with max depth
    /// 1) or path (global illumination). Default: the scene file's `Integrator`, else direct.
    #[arg(long)]
    pub integrator: Option<IntegratorKind>,
    /// Path tracing's depth, pbrt-v4's `maxdepth` (N bounces: 1 is direct lighting, 0 emission
    /// only). Default: the scene file's, else 5.
    #[arg(long)]
    pub max_depth: Option<u32>,
    /// Path tracing without Russian roulette (every path runs to --max-depth).
    #[arg(long)]
    pub no_roulette: bool,
    /// Splat each sample into every pixel its filter reaches (a weighted mean per pixel, as
    /// Mitsuba's film does) instead of filter importance sampling: less noise per pixel,
    /// correlated between neighbours. Renders in one pass: a weighted-mean film cannot yet be
    /// combined from parts, so it excludes --spp-range, --progressive, --resume and --time.
    #[arg(long, conflicts_with_all = ["spp_range", "progressive", "resume", "time"])]
    pub splat: bool,
    /// Hide the emitters camera rays see directly (Mitsuba 3's `hide_emitters`): a light's
    /// surface seen straight from the camera shows no emission (only what it reflects), the
    /// environment behind the scene is black; the light they cast (on surfaces, in
    /// reflections, through glass) is unchanged.
    #[arg(long)]
    pub hide_emitters: bool,
    /// Estimator at every path vertex: bsdf, light-area, light-solid-angle or mis.
    #[arg(long, default_value = "mis")]
    pub strategy: Strategy,
    /// MIS heuristic: power (β = 2) or balance.
    #[arg(long, default_value = "power")]
    pub mis: MisHeuristic,
    /// Sample pattern: fixed, random, grid, stratified, lhs or sobol.
    #[arg(long, default_value = "stratified")]
    pub pattern: PatternKind,
    /// Light selection at every path vertex: uniform, power, spatial, adaptive, online, wald,
    /// bvh, exhaustive, ris (ris:K for K power-sampled candidates, default 8) or ris-bvh
    /// (ris-bvh:K: K light-BVH candidates, default 4). `online` learns while the
    /// image renders (rounds of 1, 1, 2, 4, … spp; separate tables for camera-ray hits and
    /// later vertices; deterministic for any thread count); `adaptive` trains in a pre-pass. Default: the scene file's
    /// `lightsampler`, else bvh (the most efficient on average over the built-in scenes,
    /// docs/many-lights.md).
    #[arg(long)]
    pub light_selection: Option<SelectorKind>,
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
    /// Render only sample indices A..B (of the --spp of every pixel) into an EXR part that
    /// records them; `penumbra merge` combines the parts.
    #[arg(long, value_name = "A..B", value_parser = parse_range)]
    pub spp_range: Option<std::ops::Range<u32>>,
    /// Render in passes until SECONDS of render time are spent (or --spp is reached; with
    /// --time the default --spp is 65536, the scene's own count is ignored).
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds, conflicts_with = "spp_range")]
    pub time: Option<f64>,
    /// Render in passes of growing sample count and write the output after every pass
    /// (atomically: the file is always a valid image of the samples so far; an EXR records
    /// the count). Ctrl-C then writes the completed samples and exits 130 (SIGTERM: 143).
    #[arg(long, conflicts_with = "spp_range")]
    pub progressive: bool,
    /// Continue the partial render PART.exr (written by --progressive, --time or an
    /// interrupted pass render, or --spp-range 0..K) to --spp samples; the settings must be
    /// those of the partial render.
    #[arg(long, value_name = "PART.exr", conflicts_with = "spp_range")]
    pub resume: Option<PathBuf>,
}

/// Default sample count of a `--time` render: a cap the budget normally ends first.
pub const TIME_SPP: u32 = 65536;

/// Parse a positive, finite number of seconds.
fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(t) if t.is_finite() && t > 0.0 && t < 1e9 => Ok(t),
        _ => Err(format!("expected a positive number of seconds, got '{s}'")),
    }
}

impl Args {
    /// Whether the render runs in passes (time budget, progressive output or resume).
    pub fn passes(&self) -> bool {
        self.time.is_some() || self.progressive || self.resume.is_some()
    }
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
    if args.spp_range.is_some() && !is_exr(args.output.as_deref()) {
        anyhow::bail!("--spp-range writes a part that records its samples: give -o PART.exr");
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
    let choice = scene.integrator_choice(args.integrator, args.max_depth, args.light_selection);
    let spp = match args.time {
        Some(_) => args.spp.unwrap_or(TIME_SPP),
        None => args.spp.or(scene.film.spp).unwrap_or(64),
    };
    let opts = RenderOptions {
        spp,
        shadow_rays: args.shadow_rays,
        seed: args.seed,
        strategy: args.strategy,
        mis: args.mis,
        pattern: args.pattern,
        light_selection: choice.light_selection,
        bsdf_sampling: args.bsdf_sampling,
        mis_light: args.mis_light,
        integrator: choice.kind,
        max_depth: choice.max_depth,
        roulette: !args.no_roulette,
        splat: args.splat,
        hide_emitters: args.hide_emitters,
        progress: !args.quiet,
        sample_range: args.spp_range.clone(),
        ..RenderOptions::default()
    };
    opts.samples()
        .map_err(|e| anyhow::anyhow!("--spp-range: {e}"))?;
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
    if args.passes() {
        let setup = Setup {
            args: &args,
            scene: &scene,
            res,
            opts,
            out,
            start,
            load_time: load_time.saturating_sub(bvh_time),
            bvh_time,
        };
        return with_threads(args.threads, || run_passes(&setup, &interrupt));
    }

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
    interrupt.writing(test_write_pause(), |ctl| match &args.spp_range {
        Some(samples) => {
            let part = Part {
                image: img,
                info: PartInfo {
                    samples: samples.clone(),
                    spp: opts.spp,
                    render: render_key(&args.scene, &load_options(&args), res, &opts),
                },
            };
            write_part(&part, &out, ctl)
        }
        None => write_image_with(&img, &out, args.exposure, ctl),
    })?;
    let write_time = write_start.elapsed();

    let memory = memory::peak_resident()
        .map(|peak| format!("  peak memory {}", memory::human(peak)))
        .unwrap_or_default();
    let secs = |d: Duration| d.as_secs_f64();
    let samples = match &args.spp_range {
        Some(r) => format!(" (samples {}..{})", r.start, r.end),
        None => String::new(),
    };
    let line = format!(
        "{}x{}  {} spp{samples} x {} shadow rays  {}  load {:.3} s  bvh {:.3} s  render {:.3} s  \
         write {:.3} s  total {:.3} s  {:.2} M rays  {:.1} Mrays/s{memory}  -> {}",
        res.x,
        res.y,
        opts.spp,
        opts.shadow_rays,
        match opts.integrator {
            IntegratorKind::Direct => opts.strategy.to_string(),
            IntegratorKind::Path => format!("{} path depth {}", opts.strategy, opts.max_depth),
        },
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

/// Run `f` on a pool of `threads` workers (default: rayon's global pool).
fn with_threads<T: Send>(
    threads: Option<usize>,
    f: impl FnOnce() -> anyhow::Result<T> + Send,
) -> anyhow::Result<T> {
    match threads {
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .context("creating the thread pool")?
            .install(f),
        None => f(),
    }
}

/// What a pass render needs from `run`.
struct Setup<'a> {
    args: &'a Args,
    scene: &'a penumbra::scene::Scene,
    res: UVec2,
    opts: RenderOptions,
    out: PathBuf,
    start: Instant,
    load_time: Duration,
    bvh_time: Duration,
}

/// Write the image of the samples in `acc` to `out`: an EXR as a part of samples
/// `0..count` of the render (so `--resume` can continue it), other formats as plain images.
pub fn write_accumulated(
    acc: &Accumulator,
    out: &Path,
    key: &str,
    spp: u32,
    exposure: f32,
    ctl: &penumbra::image::io::WriteControl,
) -> anyhow::Result<()> {
    let image = acc.image();
    if is_exr(Some(out)) {
        let part = Part {
            image,
            info: PartInfo {
                samples: 0..acc.count(),
                spp,
                render: key.to_string(),
            },
        };
        write_part(&part, out, ctl)
    } else {
        write_image_with(&image, out, exposure, ctl)
    }
}

/// Read `--resume PART` and check that it is a partial render of these settings.
pub fn resume_from(path: &Path, key: &str, spp: u32, res: UVec2) -> anyhow::Result<Accumulator> {
    let part = penumbra::image::parts::read_part(path)?;
    let i = &part.info;
    anyhow::ensure!(
        i.samples.start == 0,
        "{}: holds samples {}..{}; only a render of samples 0..K can be resumed",
        path.display(),
        i.samples.start,
        i.samples.end
    );
    anyhow::ensure!(
        i.spp == spp,
        "{}: is part of a {}-spp render, this one has {spp} spp (the patterns stratify over \
         the spp, so the samples differ): give --spp {}",
        path.display(),
        i.spp,
        i.spp
    );
    anyhow::ensure!(
        part.image.width == res.x && part.image.height == res.y,
        "{}: is {}x{}, this render is {}x{}",
        path.display(),
        part.image.width,
        part.image.height,
        res.x,
        res.y
    );
    anyhow::ensure!(
        i.render == key,
        "{}: was rendered with other settings:\n  its:  {}\n  these: {key}",
        path.display(),
        i.render
    );
    Ok(Accumulator::from_mean(&part.image, i.count()))
}

/// The pass loop of `--time`, `--progressive` and `--resume`: passes until the spp or the
/// budget is reached or a signal comes, the output written after every pass (with
/// `--progressive`) and at the end, even after a signal (then exit 128 + signal).
fn run_passes(s: &Setup, interrupt: &Interrupt) -> anyhow::Result<()> {
    let args = s.args;
    let key = render_key(&args.scene, &load_options(args), s.res, &s.opts);
    let mut acc = match &args.resume {
        Some(part) => resume_from(part, &key, s.opts.spp, s.res)?,
        None => Accumulator::new(s.res),
    };
    let resumed = acc.count();
    let opts = RenderOptions {
        progress: false,
        ..s.opts.clone()
    };
    let policy = PassPolicy {
        budget: args.time.map(Duration::from_secs_f64),
        ..PassPolicy::default()
    };
    let sensor = &s.scene.film.sensor;
    let post = |img: &mut penumbra::image::Image| sensor.apply(img);
    let mut write_time = Duration::ZERO;
    let progress = interrupt.passes(|cancel| {
        render_passes(
            s.scene,
            &opts,
            &mut acc,
            &policy,
            cancel,
            &post,
            &mut |acc, pass| {
                if !args.quiet {
                    eprintln!(
                        "pass: samples {}..{} in {:.3} s ({:.1} Mrays/s)",
                        pass.samples.start,
                        pass.samples.end,
                        pass.time.as_secs_f64(),
                        pass.rays as f64 / pass.time.as_secs_f64().max(1e-9) / 1e6
                    );
                }
                if args.progressive && acc.count() < opts.spp {
                    let t = Instant::now();
                    write_accumulated(
                        acc,
                        &s.out,
                        &key,
                        opts.spp,
                        args.exposure,
                        &Default::default(),
                    )?;
                    write_time += t.elapsed();
                }
                Ok(())
            },
        )
    })?;
    let signal = interrupt.signal();
    if acc.count() == 0 {
        match signal {
            Some(signal) => {
                eprintln!("no pass completed: {} was not written", s.out.display());
                return Err(super::interrupt::Interrupted { signal }.into());
            }
            None => anyhow::bail!("no pass completed"),
        }
    }
    let t = Instant::now();
    interrupt
        .final_write(|ctl| write_accumulated(&acc, &s.out, &key, opts.spp, args.exposure, ctl))?;
    write_time += t.elapsed();
    let secs = |d: Duration| d.as_secs_f64();
    let why = match progress.stop {
        Stop::Done => "done".to_string(),
        Stop::Budget => format!("time budget {} s", args.time.unwrap_or(0.0)),
        Stop::Cancelled => "interrupted".to_string(),
    };
    let resumed = if resumed > 0 {
        format!(" (resumed from {resumed})")
    } else {
        String::new()
    };
    let line = format!(
        "{}x{}  {} of {} spp{resumed} in {} passes ({why}) x {} shadow rays  {}  load {:.3} s  \
         bvh {:.3} s  render {:.3} s  write {:.3} s  total {:.3} s  {:.2} M rays  {:.1} Mrays/s  \
         -> {}",
        s.res.x,
        s.res.y,
        acc.count(),
        opts.spp,
        progress.passes,
        opts.shadow_rays,
        opts.strategy,
        secs(s.load_time),
        secs(s.bvh_time),
        secs(progress.time),
        secs(write_time),
        secs(s.start.elapsed()),
        progress.rays as f64 / 1e6,
        progress.rays as f64 / secs(progress.time).max(1e-9) / 1e6,
        s.out.display()
    );
    writeln!(std::io::stdout(), "{line}").context("writing to standard output")?;
    match signal {
        Some(signal) => Err(super::interrupt::Interrupted { signal }.into()),
        None => Ok(()),
    }
}

/// Parse `A..B` for `--spp-range`.
fn parse_range(s: &str) -> Result<std::ops::Range<u32>, String> {
    penumbra::image::parts::parse_range(s)
}

/// Whether `out` is given and names an EXR file.
fn is_exr(out: Option<&Path>) -> bool {
    out.and_then(|o| o.extension())
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
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

/// Test hook: `PENUMBRA_TEST_WRITE_PAUSE_MS` pauses the image write after every 1 MiB (a
/// signal ends the pause) so the tests can interrupt a write in progress.
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
