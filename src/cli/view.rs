//! `penumbra view`: a local web server that shows a progressive render converging live.
//!
//! The server (tiny_http, synchronous) lives here in the CLI, not in the library: it only
//! calls the library's pass loop ([`penumbra::progressive::render_passes`]) on a worker
//! thread per channel and serves snapshots of its accumulator. Two channels, A and B, render
//! concurrently on one thread pool (so, roughly, at equal time) for the A/B comparison.
//!
//! Endpoints (all answers JSON unless said; bad parameters are 400 with the reason as text):
//! - `GET /`: the page (embedded with `include_str!`).
//! - `GET /api/state`: settings, sample count, time, Mrays/s, ETA and relMSE of both channels.
//! - `GET /api/image?ch=a|b&view=srgb|false|error&exposure=STOPS`: the current image as PNG.
//! - `GET /api/pixel?ch=a|b&x=X&y=Y`: the pixel's value, the surface it sees and the
//!   light-selection pmf of every light at that shading point.
//! - `POST /api/render`: JSON `{"channel": "a"|"b", ...settings}` restarts a channel.

use std::io::{Read, Write};
use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use anyhow::Context;
use glam::{UVec2, Vec2};
use penumbra::Rgb;
use penumbra::bsdf::{Bxdf, LobeSampling};
use penumbra::geometry::RayQuery;
use penumbra::image::Image;
use penumbra::image::colormap::viridis;
use penumbra::image::io::{encode_png, read_image, srgb_to_linear, to_rgb8};
use penumbra::image::metrics::{compare, error_image};
use penumbra::integrator::{IntegratorKind, MisHeuristic, RenderOptions, Strategy};
use penumbra::light_selection::{SelectorKind, ShadingPoint, make_selector};
use penumbra::progressive::{Accumulator, PassPolicy, render_passes};
use penumbra::sampling::PatternKind;
use penumbra::scene::Scene;
use penumbra::scene::load::load;
use serde::Deserialize;
use serde_json::json;

use super::messages;
use super::render::{self as render_cmd, TIME_SPP, load_options};

/// The page: HTML, CSS and script in one file, compiled into the binary.
const PAGE: &str = include_str!("view.html");

/// Default sample count of a viewer channel (without --spp): enough to watch converge.
pub const VIEW_SPP: u32 = 1024;

/// Largest sample count the page may ask for.
const MAX_SPP: u32 = 1 << 20;

/// Arguments of `penumbra view`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// The render options (scene, --spp, --strategy, --res...); --spp defaults to 1024.
    #[command(flatten)]
    pub render: render_cmd::Args,
    /// Port to listen on (0: any free port; the address is printed).
    #[arg(long, default_value_t = 8417)]
    pub port: u16,
    /// Address to listen on: loopback only by default; 0.0.0.0 opens the viewer to the network.
    #[arg(long, default_value = "127.0.0.1")]
    pub host: IpAddr,
    /// Reference image (EXR/PFM/HDR of the same size) for relMSE and the error image.
    #[arg(long)]
    pub reference: Option<PathBuf>,
}

/// What a channel renders: the settings the page can change.
#[derive(Clone, Debug, PartialEq)]
struct Settings {
    strategy: Strategy,
    light_selection: SelectorKind,
    pattern: PatternKind,
    mis: MisHeuristic,
    bsdf_sampling: LobeSampling,
    spp: u32,
    shadow_rays: u32,
    integrator: IntegratorKind,
    max_depth: u32,
    roulette: bool,
    /// `--hide-emitters` (not changed by the page).
    hide_emitters: bool,
}

impl Settings {
    /// The JSON the page reads.
    fn to_json(&self) -> serde_json::Value {
        json!({
            "strategy": self.strategy.name(),
            "light_selection": self.light_selection.name(),
            "pattern": self.pattern.name(),
            "mis": match self.mis { MisHeuristic::Power => "power", MisHeuristic::Balance => "balance" },
            "bsdf_sampling": lobe_name(self.bsdf_sampling),
            "spp": self.spp,
            "shadow_rays": self.shadow_rays,
            "integrator": self.integrator.name(),
            "max_depth": self.max_depth,
        })
    }

    /// Apply the fields of a `POST /api/render` body; an unknown field or value is an error
    /// that says which.
    fn update(&mut self, body: &Change) -> Result<(), String> {
        if let Some(s) = &body.strategy {
            self.strategy = s.parse()?;
        }
        if let Some(s) = &body.light_selection {
            self.light_selection = s.parse()?;
        }
        if let Some(s) = &body.pattern {
            self.pattern = s
                .parse()
                .map_err(|e: penumbra::sampling::SamplingError| e.to_string())?;
        }
        if let Some(s) = &body.mis {
            self.mis = s.parse()?;
        }
        if let Some(s) = &body.bsdf_sampling {
            self.bsdf_sampling = s.parse().map_err(|e: String| e)?;
        }
        if let Some(n) = body.spp {
            if !(1..=MAX_SPP).contains(&n) {
                return Err(format!("spp must be between 1 and {MAX_SPP}, got {n}"));
            }
            self.spp = n;
        }
        if let Some(s) = &body.integrator {
            self.integrator = s.parse()?;
        }
        if let Some(n) = body.max_depth {
            if !(1..=1024).contains(&n) {
                return Err(format!("max_depth must be between 1 and 1024, got {n}"));
            }
            self.max_depth = n;
        }
        if let Some(n) = body.shadow_rays {
            if !(1..=1024).contains(&n) {
                return Err(format!("shadow_rays must be between 1 and 1024, got {n}"));
            }
            self.shadow_rays = n;
        }
        Ok(())
    }
}

/// The CLI name of a lobe-sampling mode.
fn lobe_name(l: LobeSampling) -> &'static str {
    match l {
        LobeSampling::Importance => "importance",
        LobeSampling::Cosine => "cosine",
        LobeSampling::Uniform => "uniform",
    }
}

/// Body of `POST /api/render`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Change {
    channel: String,
    /// `false` stops channel B (A cannot be turned off).
    enabled: Option<bool>,
    strategy: Option<String>,
    light_selection: Option<String>,
    pattern: Option<String>,
    mis: Option<String>,
    bsdf_sampling: Option<String>,
    spp: Option<u32>,
    shadow_rays: Option<u32>,
    integrator: Option<String>,
    max_depth: Option<u32>,
}

/// The latest completed pass of a channel.
#[derive(Clone)]
struct Snapshot {
    image: Arc<Image>,
    count: u32,
    time: Duration,
    rays: u64,
    rel_mse: Option<f64>,
}

/// One rendering channel (A or B).
struct Channel {
    settings: Settings,
    enabled: bool,
    /// Bumped at every restart; a worker whose generation is stale stores nothing.
    generation: u64,
    cancel: Arc<AtomicBool>,
    snapshot: Option<Snapshot>,
    started: Instant,
    done: bool,
    error: Option<String>,
}

/// Everything the server and the workers share.
struct Shared {
    scene: Scene,
    res: UVec2,
    seed: u64,
    budget: Option<Duration>,
    /// `--exposure`: where the page's exposure slider starts.
    exposure: f32,
    reference: Option<Image>,
    pool: Option<rayon::ThreadPool>,
    channels: Mutex<[Channel; 2]>,
}

impl Shared {
    fn lock(&self) -> std::sync::MutexGuard<'_, [Channel; 2]> {
        self.channels.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// Run the command: load the scene, start channel A, serve until killed.
pub fn run(args: Args) -> anyhow::Result<()> {
    let r = &args.render;
    anyhow::ensure!(
        r.output.is_none() && r.spp_range.is_none() && r.resume.is_none() && !r.progressive,
        "view writes no file: -o, --spp-range, --resume and --progressive are render options"
    );
    anyhow::ensure!(r.shadow_rays >= 1, "--shadow-rays must be at least 1");
    anyhow::ensure!(
        r.exposure.is_finite() && r.exposure.abs() <= 8.0,
        "--exposure must be within ±8 stops in the viewer"
    );
    anyhow::ensure!(r.spp != Some(0), "--spp must be at least 1");
    anyhow::ensure!(r.threads != Some(0), "--threads must be at least 1");
    let loaded = load(&r.scene, &load_options(r))?;
    for w in &loaded.warnings {
        eprintln!("{}", messages::format_warning(w));
    }
    let scene = loaded.scene;
    // `render`'s defaults: the flags, else the scene file's `Integrator`, else direct lighting
    // with the default selector.
    let choice = scene.integrator_choice(r.integrator, r.max_depth, r.light_selection);
    let res = r.res.unwrap_or(scene.film.resolution);
    let reference = match &args.reference {
        Some(p) => {
            let img = read_image(p)?;
            anyhow::ensure!(
                img.width == res.x && img.height == res.y,
                "{}: the reference is {}x{}, the render {}x{}",
                p.display(),
                img.width,
                img.height,
                res.x,
                res.y
            );
            Some(img)
        }
        None => None,
    };
    let spp = match r.time {
        Some(_) => r.spp.unwrap_or(TIME_SPP),
        None => r.spp.unwrap_or(VIEW_SPP),
    };
    let settings = Settings {
        strategy: r.strategy,
        light_selection: choice.light_selection,
        pattern: r.pattern,
        mis: r.mis,
        bsdf_sampling: r.bsdf_sampling,
        spp,
        shadow_rays: r.shadow_rays,
        integrator: choice.kind,
        max_depth: choice.max_depth,
        roulette: !r.no_roulette,
        hide_emitters: r.hide_emitters,
    };
    let pool = match r.threads {
        Some(t) => Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .context("creating the thread pool")?,
        ),
        None => None,
    };
    let channel = |enabled| Channel {
        settings: settings.clone(),
        enabled,
        generation: 0,
        cancel: Arc::new(AtomicBool::new(false)),
        snapshot: None,
        started: Instant::now(),
        done: false,
        error: None,
    };
    let shared = Arc::new(Shared {
        scene,
        res,
        seed: r.seed,
        budget: r.time.map(Duration::from_secs_f64),
        exposure: r.exposure,
        reference,
        pool,
        channels: Mutex::new([channel(true), channel(false)]),
    });
    let addr = SocketAddr::new(args.host, args.port);
    let server = tiny_http::Server::http(addr)
        .map_err(|e| anyhow::anyhow!("cannot listen on {addr}: {e}"))?;
    let local = server
        .server_addr()
        .to_ip()
        .context("the server has no IP address")?;
    restart(&shared, 0);
    let mut out = std::io::stdout();
    writeln!(
        out,
        "penumbra view: http://{local}/  ({}x{} {})",
        res.x, res.y, r.scene
    )
    .and_then(|()| out.flush())
    .context("writing to standard output")?;
    for request in server.incoming_requests() {
        handle(&shared, request);
    }
    Ok(())
}

/// Stop channel `ch`'s render (if any) and start a new one with its current settings.
fn restart(shared: &Arc<Shared>, ch: usize) {
    let (opts, generation, cancel) = {
        let mut chans = shared.lock();
        let c = &mut chans[ch];
        c.cancel.store(true, std::sync::atomic::Ordering::SeqCst);
        c.generation += 1;
        c.cancel = Arc::new(AtomicBool::new(false));
        c.snapshot = None;
        c.started = Instant::now();
        c.done = false;
        c.error = None;
        if !c.enabled {
            return;
        }
        let s = &c.settings;
        let opts = RenderOptions {
            spp: s.spp,
            shadow_rays: s.shadow_rays,
            seed: shared.seed,
            strategy: s.strategy,
            mis: s.mis,
            pattern: s.pattern,
            light_selection: s.light_selection,
            bsdf_sampling: s.bsdf_sampling,
            integrator: s.integrator,
            max_depth: s.max_depth,
            roulette: s.roulette,
            hide_emitters: s.hide_emitters,
            ..RenderOptions::default()
        };
        (opts, c.generation, Arc::clone(&c.cancel))
    };
    let shared = Arc::clone(shared);
    std::thread::spawn(move || {
        let work = || worker(&shared, ch, generation, &opts, &cancel);
        let result = match &shared.pool {
            Some(pool) => pool.install(work),
            None => work(),
        };
        let mut chans = shared.lock();
        let c = &mut chans[ch];
        if c.generation == generation {
            c.done = true;
            if let Err(e) = result {
                c.error = Some(messages::format_error(&e));
            }
        }
    });
}

/// Render channel `ch` in passes, publishing a snapshot after each.
fn worker(
    shared: &Shared,
    ch: usize,
    generation: u64,
    opts: &RenderOptions,
    cancel: &Arc<AtomicBool>,
) -> anyhow::Result<()> {
    let mut acc = Accumulator::new(shared.res);
    let policy = PassPolicy {
        budget: shared.budget,
        max_pass: Duration::from_millis(250),
    };
    let sensor = &shared.scene.film.sensor;
    let post = |img: &mut Image| sensor.apply(img);
    let (mut time, mut rays) = (Duration::ZERO, 0u64);
    render_passes(
        &shared.scene,
        opts,
        &mut acc,
        &policy,
        cancel,
        &post,
        &mut |acc, pass| {
            time += pass.time;
            rays += pass.rays;
            let image = acc.image();
            let rel_mse = match &shared.reference {
                Some(r) => Some(compare(&image, r)?.rel_mse),
                None => None,
            };
            let mut chans = shared.lock();
            let c = &mut chans[ch];
            if c.generation == generation {
                c.snapshot = Some(Snapshot {
                    image: Arc::new(image),
                    count: acc.count(),
                    time,
                    rays,
                    rel_mse,
                });
            }
            Ok(())
        },
    )?;
    Ok(())
}

/// An answer: status, content type, body.
struct Reply {
    status: u16,
    kind: &'static str,
    body: Vec<u8>,
}

impl Reply {
    fn json(v: &serde_json::Value) -> Self {
        Self {
            status: 200,
            kind: "application/json",
            body: v.to_string().into_bytes(),
        }
    }
    fn text(status: u16, msg: impl Into<String>) -> Self {
        Self {
            status,
            kind: "text/plain; charset=utf-8",
            body: msg.into().into_bytes(),
        }
    }
    fn bad(msg: impl Into<String>) -> Self {
        Self::text(400, msg)
    }
}

/// Answer one request (never panics on bad input: every problem is a 4xx with a reason).
fn handle(shared: &Arc<Shared>, mut request: tiny_http::Request) {
    let url = request.url().to_string();
    let (path, query) = url.split_once('?').unwrap_or((url.as_str(), ""));
    let method = request.method().clone();
    let reply = match (&method, path) {
        (tiny_http::Method::Get, "/" | "/index.html") => Reply {
            status: 200,
            kind: "text/html; charset=utf-8",
            body: PAGE.as_bytes().to_vec(),
        },
        (tiny_http::Method::Get, "/api/state") => Reply::json(&state(shared)),
        (tiny_http::Method::Get, "/api/image") => parse_query(query)
            .and_then(|q| image(shared, &q))
            .unwrap_or_else(Reply::bad),
        (tiny_http::Method::Get, "/api/pixel") => parse_query(query)
            .and_then(|q| pixel(shared, &q))
            .map_or_else(Reply::bad, |v| Reply::json(&v)),
        (tiny_http::Method::Post, "/api/render") => {
            let mut body = String::new();
            match request.as_reader().take(1 << 16).read_to_string(&mut body) {
                Ok(_) => change(shared, &body).map_or_else(Reply::bad, |v| Reply::json(&v)),
                Err(e) => Reply::bad(format!("cannot read the request body: {e}")),
            }
        }
        (_, "/" | "/index.html" | "/api/state" | "/api/image" | "/api/pixel" | "/api/render") => {
            Reply::text(405, format!("{method} is not allowed on {path}"))
        }
        _ => Reply::text(404, format!("no such page: {path}")),
    };
    let header = tiny_http::Header::from_bytes("Content-Type", reply.kind)
        .expect("a constant header is valid");
    let no_cache = tiny_http::Header::from_bytes("Cache-Control", "no-store")
        .expect("a constant header is valid");
    let response = tiny_http::Response::from_data(reply.body)
        .with_status_code(reply.status)
        .with_header(header)
        .with_header(no_cache);
    // A client that went away is no error of the server's.
    let _ = request.respond(response);
}

/// `a=1&b=2` into pairs; only plain characters are accepted (the page sends nothing else).
fn parse_query(q: &str) -> Result<Vec<(String, String)>, String> {
    q.split('&')
        .filter(|kv| !kv.is_empty())
        .map(|kv| {
            let (k, v) = kv.split_once('=').unwrap_or((kv, ""));
            let ok = |s: &str| {
                s.chars()
                    .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
            };
            if ok(k) && ok(v) {
                Ok((k.to_string(), v.to_string()))
            } else {
                Err(format!("bad query parameter '{kv}'"))
            }
        })
        .collect()
}

/// The value of `key` in `q`, or `default`; `None` default means required.
fn param<'a>(
    q: &'a [(String, String)],
    key: &str,
    default: Option<&'a str>,
) -> Result<&'a str, String> {
    q.iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
        .or(default)
        .ok_or_else(|| format!("missing query parameter '{key}'"))
}

/// The channel index of `ch=a|b`.
fn channel_of(q: &[(String, String)]) -> Result<usize, String> {
    channel_index(param(q, "ch", Some("a"))?)
}

fn channel_index(s: &str) -> Result<usize, String> {
    match s {
        "a" | "A" => Ok(0),
        "b" | "B" => Ok(1),
        other => Err(format!("unknown channel '{other}' (expected a or b)")),
    }
}

/// `GET /api/state`.
fn state(shared: &Shared) -> serde_json::Value {
    let chans = shared.lock();
    let ch = |c: &Channel| {
        let snap = c.snapshot.as_ref();
        let count = snap.map_or(0, |s| s.count);
        let time = snap.map_or(0.0, |s| s.time.as_secs_f64());
        let mrays = snap.map_or(0.0, |s| {
            s.rays as f64 / s.time.as_secs_f64().max(1e-9) / 1e6
        });
        let eta = if c.done || count == 0 {
            None
        } else {
            let rate = f64::from(count) / time.max(1e-9);
            let mut eta = f64::from(c.settings.spp.saturating_sub(count)) / rate;
            if let Some(b) = shared.budget {
                eta = eta.min((b.as_secs_f64() - time).max(0.0));
            }
            Some(eta)
        };
        json!({
            "enabled": c.enabled,
            "settings": c.settings.to_json(),
            "generation": c.generation,
            "samples": count,
            "time": time,
            "wall": c.started.elapsed().as_secs_f64(),
            "mrays_per_s": mrays,
            "eta": eta,
            "done": c.done,
            "rel_mse": snap.and_then(|s| s.rel_mse),
            "error": c.error,
        })
    };
    json!({
        "width": shared.res.x,
        "height": shared.res.y,
        "reference": shared.reference.is_some(),
        "budget": shared.budget.map(|b| b.as_secs_f64()),
        "exposure": shared.exposure,
        "lights": shared.scene.lights.len(),
        "channels": { "a": ch(&chans[0]), "b": ch(&chans[1]) },
        "choices": {
            "strategy": Strategy::ALL.iter().map(|s| s.name()).collect::<Vec<_>>(),
            "light_selection": SelectorKind::ALL.iter().map(|k| k.name()).collect::<Vec<_>>(),
            "pattern": PatternKind::ALL.iter().map(|p| p.name()).collect::<Vec<_>>(),
            "mis": ["power", "balance"],
            "bsdf_sampling": ["importance", "cosine", "uniform"],
            "integrator": ["direct", "path"],
        },
    })
}

/// False colour of luminance: log10 over [-3, 1] through viridis, as linear values.
fn false_colour(img: &Image, exposure: f32) -> Image {
    let k = exposure.exp2();
    let pixels = img
        .pixels
        .iter()
        .map(|p| {
            let l = penumbra::luminance(*p * k).max(1e-30);
            let s = viridis((l.log10() + 3.0) / 4.0);
            Rgb::new(
                srgb_to_linear(s.x),
                srgb_to_linear(s.y),
                srgb_to_linear(s.z),
            )
        })
        .collect();
    Image {
        width: img.width,
        height: img.height,
        pixels,
    }
}

/// `GET /api/image`.
fn image(shared: &Shared, q: &[(String, String)]) -> Result<Reply, String> {
    let ch = channel_of(q)?;
    let view = param(q, "view", Some("srgb"))?;
    let exposure: f32 = param(q, "exposure", Some("0"))?
        .parse()
        .ok()
        .filter(|e: &f32| e.is_finite() && e.abs() <= 64.0)
        .ok_or("exposure must be a number of stops within ±64")?;
    let img = {
        let chans = shared.lock();
        match &chans[ch].snapshot {
            Some(s) => Arc::clone(&s.image),
            None => Arc::new(Image::new(shared.res.x, shared.res.y)),
        }
    };
    let shown = match view {
        "srgb" => to_rgb8(&img, exposure),
        "false" => to_rgb8(&false_colour(&img, exposure), 0.0),
        "error" => match &shared.reference {
            Some(r) => to_rgb8(&error_image(&img, r).map_err(|e| e.to_string())?, 0.0),
            None => return Err("view=error needs a reference image (--reference)".into()),
        },
        other => {
            return Err(format!(
                "unknown view '{other}' (expected srgb, false or error)"
            ));
        }
    };
    let body = encode_png(&shown).map_err(|e| e.to_string())?;
    Ok(Reply {
        status: 200,
        kind: "image/png",
        body,
    })
}

/// `GET /api/pixel`: the pixel's value and what the channel's light selector thinks of every
/// light at the surface point the pixel's centre sees.
fn pixel(shared: &Shared, q: &[(String, String)]) -> Result<serde_json::Value, String> {
    let ch = channel_of(q)?;
    let coord = |k: &str, max: u32| -> Result<u32, String> {
        let v = param(q, k, None)?;
        v.parse::<u32>()
            .ok()
            .filter(|&v| v < max)
            .ok_or_else(|| format!("{k} must be a whole number in 0..{max}, got '{v}'"))
    };
    let (x, y) = (coord("x", shared.res.x)?, coord("y", shared.res.y)?);
    let (settings, value, count) = {
        let chans = shared.lock();
        let c = &chans[ch];
        let value = c
            .snapshot
            .as_ref()
            .map(|s| s.image.pixels[(y * shared.res.x + x) as usize]);
        (
            c.settings.clone(),
            value,
            c.snapshot.as_ref().map_or(0, |s| s.count),
        )
    };
    let scene = &shared.scene;
    let ray = scene
        .camera
        .rays(shared.res)
        .generate(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
    let light_sampling = settings.strategy != Strategy::Bsdf;
    let mut out = json!({
        "x": x, "y": y,
        "value": value.map(|v| [v.x, v.y, v.z]),
        "samples": count,
        "light_selection": settings.light_selection.name(),
        "light_sampling": light_sampling,
        "hit": null,
        "lights": [],
    });
    let Some(hit) = scene.geometry.intersect(&ray) else {
        return Ok(out);
    };
    let wo = -ray.d;
    let front = hit.ng.dot(wo) > 0.0;
    let n = if front { hit.ng } else { -hit.ng };
    // As the integrator does: a transmitting BSDF gathers from both sides, so the selector
    // sees no normal.
    let transmits = scene
        .materials
        .get(hit.material as usize)
        .is_some_and(|m| m.bsdf(&hit, front).transmits());
    let sp = ShadingPoint {
        p: hit.p,
        n: if transmits { glam::Vec3::ZERO } else { n },
        wo,
    };
    let selector = make_selector(settings.light_selection, scene, shared.seed);
    let mut lights: Vec<serde_json::Value> = Vec::new();
    let mut total = 0.0f64;
    for (i, l) in scene.lights.iter().enumerate() {
        use penumbra::lights::LightSource;
        let pmf = selector.pmf(&sp, i as u32);
        total += f64::from(pmf);
        if pmf <= 0.0 {
            continue;
        }
        let at = l
            .bounds()
            .filter(|b| b.min.is_finite() && b.max.is_finite() && !l.is_infinite())
            .and_then(|b| scene.camera.project((b.min + b.max) * 0.5, shared.res))
            .map(|p| [p.x, p.y]);
        lights.push(json!({ "index": i, "pmf": pmf, "raster": at }));
    }
    lights.sort_by(|a, b| {
        b["pmf"]
            .as_f64()
            .partial_cmp(&a["pmf"].as_f64())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    lights.truncate(256);
    out["hit"] = json!({
        "p": hit.p.to_array(),
        "n": sp.n.to_array(),
        "material": hit.material,
        "transmits": transmits,
    });
    out["lights"] = serde_json::Value::Array(lights);
    out["pmf_sum"] = json!(total);
    Ok(out)
}

/// `POST /api/render`.
fn change(shared: &Arc<Shared>, body: &str) -> Result<serde_json::Value, String> {
    let c: Change = serde_json::from_str(body).map_err(|e| format!("bad JSON body: {e}"))?;
    let ch = channel_index(&c.channel)?;
    {
        let mut chans = shared.lock();
        let chan = &mut chans[ch];
        let mut s = chan.settings.clone();
        s.update(&c)?;
        if let Some(e) = c.enabled {
            if ch == 0 && !e {
                return Err("channel a cannot be disabled".into());
            }
            chan.enabled = e;
        } else if ch == 1 {
            // Changing B's settings means showing it.
            chan.enabled = true;
        }
        chan.settings = s;
    }
    restart(shared, ch);
    Ok(state(shared))
}
