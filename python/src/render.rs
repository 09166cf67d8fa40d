//! `load` and `Scene.render`: the CLI's load and render, with arguments checked into
//! `ValueError`s that list the valid choices, the GIL released while the render runs, and
//! Ctrl-C (a pending `KeyboardInterrupt`) stopping it through the render's cancellation flag.

use std::str::FromStr;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{RecvTimeoutError, channel};
use std::time::Duration;

use glam::{UVec2, Vec3};
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use penumbra::bsdf::LobeSampling;
use penumbra::image::Image;
use penumbra::integrator::{IntegratorKind, MisHeuristic, RenderOptions, Strategy, render};
use penumbra::light_selection::SelectorKind;
use penumbra::lights::SamplingMode;
use penumbra::sampling::PatternKind;
use penumbra::scene::builtin::{self, BuiltinOptions};
use penumbra::scene::load::{LoadOptions, load as load_scene};
use penumbra::scene::view::ViewOptions;

use crate::errors::{Kind, not_found, to_py, warn_all};

/// Add `load` and `Scene`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(builtin_scenes, m)?)?;
    Ok(())
}

/// A loaded scene, ready to render any number of times.
#[pyclass(frozen, module = "penumbra")]
pub struct Scene {
    scene: Arc<penumbra::scene::Scene>,
    spec: String,
    warnings: Vec<String>,
    notes: Vec<String>,
}

/// The names and descriptions of the built-in scenes.
#[pyfunction]
fn builtin_scenes() -> Vec<(&'static str, &'static str)> {
    builtin::BUILTINS
        .iter()
        .map(|b| (b.name, b.description))
        .collect()
}

/// Load a built-in scene or a scene file (see `penumbra.load`).
#[pyfunction]
#[pyo3(signature = (spec, light_count=None, rooms=None, triangles=None, obj_ka_emission=false,
                    look_from=None, look_at=None, up=None, fov=None))]
#[allow(clippy::too_many_arguments)]
fn load(
    py: Python<'_>,
    spec: String,
    light_count: Option<u32>,
    rooms: Option<u32>,
    triangles: Option<u32>,
    obj_ka_emission: bool,
    look_from: Option<[f32; 3]>,
    look_at: Option<[f32; 3]>,
    up: Option<[f32; 3]>,
    fov: Option<f32>,
) -> PyResult<Scene> {
    if builtin::find(&spec).is_none() && !std::path::Path::new(&spec).exists() {
        let names: Vec<&str> = builtin::BUILTINS.iter().map(|b| b.name).collect();
        return Err(not_found(
            &format!(
                "neither a built-in scene ({}) nor an existing file",
                names.join(", ")
            ),
            &spec,
        ));
    }
    let opts = LoadOptions {
        builtin: BuiltinOptions {
            light_count,
            rooms,
            triangles,
        },
        obj_ka_emission,
        view: ViewOptions {
            look_from: look_from.map(Vec3::from),
            look_at: look_at.map(Vec3::from),
            up: up.map(Vec3::from),
            fov,
        },
    };
    let loaded = {
        let spec = spec.clone();
        py.detach(move || load_scene(&spec, &opts))
            .map_err(|e| to_py(e, Kind::Scene))?
    };
    warn_all(py, &loaded.warnings)?;
    Ok(Scene {
        scene: Arc::new(loaded.scene),
        spec,
        warnings: loaded.warnings,
        notes: loaded.notes,
    })
}

/// Parse a named choice, or a `ValueError` with the type's own message (which lists them).
fn choice<T: FromStr>(what: &str, s: &str) -> PyResult<T>
where
    T::Err: std::fmt::Display,
{
    T::from_str(s).map_err(|e| PyValueError::new_err(format!("{what}: {e}")))
}

/// Render on this thread, in a pool of `threads` when given (the image does not depend on it).
fn render_image(
    scene: &penumbra::scene::Scene,
    res: UVec2,
    opts: &RenderOptions,
    threads: Option<usize>,
) -> anyhow::Result<Image> {
    let (mut img, _) = match threads {
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()?
            .install(|| render(scene, res, opts))?,
        None => render(scene, res, opts)?,
    };
    // pbrt-v4's film response, as the CLI applies it before writing.
    scene.film.sensor.apply(&mut img);
    Ok(img)
}

#[pymethods]
impl Scene {
    /// Render the scene; returns a float32 array of shape (height, width, 3), linear RGB, row 0
    /// at the top, with the film's sensor response applied (what `penumbra render` writes).
    ///
    /// Arguments are the CLI's `render` flags: `spp` eye rays per pixel (default: the
    /// scene's, else 64), `shadow_rays` per eye ray, `strategy` (bsdf, light-area,
    /// light-solid-angle, mis), `mis` (power, balance), `light_selection` (default: the
    /// file's `lightsampler`, else bvh; uniform, power, spatial, adaptive, wald, exhaustive), `pattern` (fixed, random, grid, stratified,
    /// lhs, sobol), `integrator` (direct, path; default:
    /// the scene file's), `max_depth` (path: bounces, pbrt-v4's maxdepth; default: the file's,
    /// else 5), `res` ((w, h)
    /// or "WxH"; default: the scene's), `seed`, `threads` (the image does not depend on it),
    /// `mis_light` (solid-angle, area), `bsdf_sampling` (importance, cosine, uniform),
    /// `hide_emitters` (the CLI's `--hide-emitters`, Mitsuba 3's `hide_emitters`: emitters
    /// seen directly by camera rays are black, the light they cast is unchanged).
    ///
    /// `spp_range=(a, b)` renders only sample indices [a, b) of the `spp` of every pixel and
    /// returns their mean; `penumbra.merge` combines such parts into the whole render.
    ///
    /// The GIL is released while rendering; Ctrl-C stops the render and raises
    /// `KeyboardInterrupt`. A bad value raises `ValueError` listing the valid ones.
    #[pyo3(signature = (spp=None, shadow_rays=1, strategy="mis", mis="power",
                        light_selection=None, pattern="stratified", integrator=None,
                        max_depth=None, res=None, seed=0, threads=None, spp_range=None,
                        mis_light="solid-angle", bsdf_sampling="importance",
                        hide_emitters=false))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        spp: Option<u32>,
        shadow_rays: u32,
        strategy: &str,
        mis: &str,
        light_selection: Option<&str>,
        pattern: &str,
        integrator: Option<&str>,
        max_depth: Option<u32>,
        res: Option<&Bound<'_, PyAny>>,
        seed: u64,
        threads: Option<usize>,
        spp_range: Option<(u32, u32)>,
        mis_light: &str,
        bsdf_sampling: &str,
        hide_emitters: bool,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        // As the CLI: the arguments override the scene file's `Integrator`; without either,
        // direct lighting with the default selector.
        let integrator = integrator
            .map(|s| choice::<IntegratorKind>("integrator", s))
            .transpose()?;
        let light_selection = light_selection
            .map(|s| choice::<SelectorKind>("light_selection", s))
            .transpose()?;
        let chosen = self
            .scene
            .integrator_choice(integrator, max_depth, light_selection);
        if chosen.kind == IntegratorKind::Direct && max_depth.is_some_and(|d| d != 1) {
            return Err(PyValueError::new_err(
                "max_depth: the 'direct' integrator is one bounce; use integrator='path'",
            ));
        }
        let spp = spp.or(self.scene.film.spp).unwrap_or(64);
        if spp == 0 || shadow_rays == 0 || threads == Some(0) {
            return Err(PyValueError::new_err(format!(
                "spp ({spp}), shadow_rays ({shadow_rays}) and threads ({}) must be at least 1",
                threads.unwrap_or(1)
            )));
        }
        let res = match res.map(parse_res).transpose()? {
            Some((w, h)) if (1..=65536).contains(&w) && (1..=65536).contains(&h) => {
                UVec2::new(w, h)
            }
            Some((w, h)) => {
                return Err(PyValueError::new_err(format!(
                    "res: resolution must be between 1 and 65536 per axis, got {w}x{h}"
                )));
            }
            None => self.scene.film.resolution,
        };
        let mis_light = match mis_light {
            "solid-angle" => SamplingMode::SolidAngle,
            "area" => SamplingMode::Area,
            other => {
                return Err(PyValueError::new_err(format!(
                    "mis_light: unknown value {other:?} (expected one of: solid-angle, area)"
                )));
            }
        };
        let cancel = Arc::new(AtomicBool::new(false));
        let opts = RenderOptions {
            spp,
            shadow_rays,
            seed,
            strategy: choice::<Strategy>("strategy", strategy)?,
            mis: choice::<MisHeuristic>("mis", mis)?,
            pattern: choice::<PatternKind>("pattern", pattern)?,
            light_selection: chosen.light_selection,
            mis_light,
            bsdf_sampling: choice::<LobeSampling>("bsdf_sampling", bsdf_sampling)?,
            progress: false,
            sample_range: spp_range.map(|(a, b)| a..b),
            cancel: Some(Arc::clone(&cancel)),
            integrator: chosen.kind,
            max_depth: chosen.max_depth,
            hide_emitters,
            ..RenderOptions::default()
        };
        opts.samples()
            .map_err(|e| PyValueError::new_err(format!("spp_range: {e}")))?;

        let scene = Arc::clone(&self.scene);
        let outcome = py.detach(move || -> PyResult<anyhow::Result<Image>> {
            let (tx, rx) = channel();
            let worker = std::thread::spawn(move || {
                let _ = tx.send(render_image(&scene, res, &opts, threads));
            });
            loop {
                match rx.recv_timeout(Duration::from_millis(50)) {
                    Ok(r) => {
                        let _ = worker.join();
                        return Ok(r);
                    }
                    Err(RecvTimeoutError::Timeout) => {
                        // Python's SIGINT handler only records the signal: look for it here.
                        if let Err(e) = Python::attach(|py| py.check_signals()) {
                            cancel.store(true, Ordering::Relaxed);
                            let _ = rx.recv();
                            let _ = worker.join();
                            return Err(e);
                        }
                    }
                    Err(RecvTimeoutError::Disconnected) => {
                        let _ = worker.join();
                        return Ok(Err(anyhow::anyhow!("the render thread panicked")));
                    }
                }
            }
        });
        let img = outcome?.map_err(|e| to_py(e, Kind::Runtime))?;
        to_array(py, &img)
    }

    /// The scene as given to `load` (built-in name or file path).
    #[getter]
    fn name(&self) -> &str {
        &self.spec
    }

    /// The scene's own resolution `(width, height)`, used when `render` gets no `res`.
    #[getter]
    fn resolution(&self) -> (u32, u32) {
        (self.scene.film.resolution.x, self.scene.film.resolution.y)
    }

    /// The scene's own samples per pixel, or `None` (then `render` uses 64).
    #[getter]
    fn spp(&self) -> Option<u32> {
        self.scene.film.spp
    }

    /// Number of lights (every emissive triangle counts as one).
    #[getter]
    fn light_count(&self) -> usize {
        self.scene.lights.len()
    }

    /// The loader's warnings (also issued as `SceneWarning`s when loading).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    /// The loader's notes (e.g. the camera chosen by automatic framing, as CLI flags).
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.notes.clone()
    }

    fn __repr__(&self) -> String {
        let r = self.scene.film.resolution;
        format!(
            "<penumbra.Scene {:?} {}x{}, {} lights>",
            self.spec,
            r.x,
            r.y,
            self.scene.lights.len()
        )
    }
}

/// `res` as `(w, h)`: a pair of integers or a "WxH" string.
fn parse_res(res: &Bound<'_, PyAny>) -> PyResult<(u32, u32)> {
    if let Ok(s) = res.extract::<String>() {
        let parsed = s
            .split_once(['x', 'X'])
            .and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)));
        return parsed.ok_or_else(|| {
            PyValueError::new_err(format!(
                "res: expected \"WxH\" (e.g. \"512x512\"), got {s:?}"
            ))
        });
    }
    res.extract::<(u32, u32)>()
        .map_err(|_| PyValueError::new_err("res: expected (width, height) or \"WxH\""))
}

/// An image as a float32 H×W×3 array (row 0 on top).
pub fn to_array<'py>(py: Python<'py>, img: &Image) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let flat: Vec<f32> = img.pixels.iter().flat_map(|p| p.to_array()).collect();
    let arr = Array3::from_shape_vec((img.height as usize, img.width as usize, 3), flat)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(arr.into_pyarray(py))
}
