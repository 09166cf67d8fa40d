//! One entry point for "a scene name or a scene file": built-ins first, then files by extension.
//! Here too what every format shares: the camera flags applied to a scene's own camera, a
//! warning for a scene without lights, and one warning for flags a scene does not take.

use super::Scene;
use super::builtin::{self, BuiltinOptions};
use super::view::{ViewOptions, apply_view_flags};
use crate::lights::LightSource;
use anyhow::{Context, bail};
use std::path::Path;

/// Options that loaders and built-in scenes may use.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Scaling knobs of the built-in scenes.
    pub builtin: BuiltinOptions,
    /// OBJ: treat `Ka` as emitted radiance (`--obj-ka-emission`).
    pub obj_ka_emission: bool,
    /// Camera placement flags (any scene: they refine its camera or the automatic one).
    pub view: ViewOptions,
}

/// A loaded scene and what the loader has to tell about it.
pub struct Loaded {
    /// The scene.
    pub scene: Scene,
    /// Warnings (unsupported features, approximations, repairs), each `location: text` with
    /// file and line where known, or the pbrt parser's `file:line: warning: text`; the CLI
    /// prints each with exactly one `warning:`.
    pub warnings: Vec<String>,
    /// Information that is no warning: the camera used when the flags or automatic framing
    /// placed it, as flags to paste.
    pub notes: Vec<String>,
}

/// Load `spec`: a built-in scene name or a path to a scene file.
pub fn load(spec: &str, opts: &LoadOptions) -> anyhow::Result<Loaded> {
    if let Some(b) = builtin::find(spec) {
        let mut warnings = Vec::new();
        let given = [
            ("light-count", opts.builtin.light_count.is_some()),
            ("rooms", opts.builtin.rooms.is_some()),
            ("triangles", opts.builtin.triangles.is_some()),
        ];
        let ignored: Vec<String> = given
            .iter()
            .filter(|(k, on)| *on && !b.knobs.contains(k))
            .map(|(k, _)| format!("--{k}"))
            .collect();
        if !ignored.is_empty() {
            warnings.push(format!(
                "{spec}: {} ignored: the built-in scene '{spec}' {}",
                ignored.join(", "),
                takes(b.knobs)
            ));
        }
        let mut scene = (b.build)(&opts.builtin)
            .with_context(|| format!("building built-in scene '{spec}'"))?;
        let notes = apply_view_flags(&mut scene, &opts.view)
            .with_context(|| format!("{spec}: camera flags"))?
            .map(|n| format!("{spec}: {n}"))
            .into_iter()
            .collect();
        return Ok(Loaded {
            scene,
            warnings,
            notes,
        });
    }
    let path = Path::new(spec);
    if !path.exists() {
        let names: Vec<&str> = builtin::BUILTINS.iter().map(|b| b.name).collect();
        bail!(
            "'{spec}' is neither a built-in scene ({}) nor an existing file",
            names.join(", ")
        );
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let mut loaded = match ext.as_str() {
        "pbrt" => {
            let (mut scene, mut warnings) = super::pbrt::load_pbrt(path)?;
            let notes = apply_view_flags(&mut scene, &opts.view)
                .with_context(|| format!("{spec}: camera flags"))?
                .map(|n| format!("{spec}: {n}"))
                .into_iter()
                .collect();
            if scene.geometry.is_empty() {
                warnings.push(format!(
                    "{spec}: the scene has no geometry (none given, or every mesh was dropped)"
                ));
            }
            warn_if_unlit(&scene, spec, "", &mut warnings);
            Loaded {
                scene,
                warnings,
                notes,
            }
        }
        "obj" => super::obj::load_obj(path, opts)?,
        "gltf" | "glb" => super::gltf::load_gltf(path, opts)?,
        other => bail!(
            "{}: unsupported scene format '.{other}' (expected .pbrt, .obj, .gltf or .glb)",
            path.display()
        ),
    };
    let b = &opts.builtin;
    let ignored: Vec<&str> = [
        ("--light-count", b.light_count.is_some()),
        ("--rooms", b.rooms.is_some()),
        ("--triangles", b.triangles.is_some()),
    ]
    .iter()
    .filter(|(_, on)| *on)
    .map(|(k, _)| *k)
    .collect();
    if !ignored.is_empty() {
        loaded.warnings.push(format!(
            "{spec}: {} ignored: only built-in scenes take it",
            ignored.join(", ")
        ));
    }
    if opts.obj_ka_emission && ext != "obj" {
        loaded.warnings.push(format!(
            "{spec}: --obj-ka-emission ignored: not an OBJ file"
        ));
    }
    Ok(loaded)
}

fn takes(knobs: &[&str]) -> String {
    match knobs {
        [] => "takes none of these".to_string(),
        ks => format!(
            "takes only {}",
            ks.iter()
                .map(|k| format!("--{k}"))
                .collect::<Vec<_>>()
                .join(" and ")
        ),
    }
}

/// A scene without lights, or whose lights all have zero power, renders black: say so
/// (pbrt-v4 warns too), with `hint` if the loader knows why.
pub fn warn_if_unlit(scene: &Scene, file: &str, hint: &str, warnings: &mut Vec<String>) {
    let n = scene.lights.len();
    if n == 0 {
        warnings.push(format!(
            "{file}: the scene has no lights, so the image will be black{hint}"
        ));
    } else if scene.lights.iter().all(|l| !(l.power() > 0.0)) {
        warnings.push(format!(
            "{file}: none of its {n} lights emits (all have zero power), so the image will be black{hint}"
        ));
    }
}
