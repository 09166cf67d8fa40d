//! One entry point for "a scene name or a scene file": built-ins first, then files by extension.

use super::Scene;
use super::builtin::{self, BuiltinOptions};
use super::view::ViewOptions;
use anyhow::{Context, bail};
use std::path::Path;

/// Options that loaders and built-in scenes may use.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Scaling knobs of the built-in scenes.
    pub builtin: BuiltinOptions,
    /// OBJ: treat `Ka` as emitted radiance (`--obj-ka-emission`).
    pub obj_ka_emission: bool,
    /// Camera placement flags (OBJ, glTF).
    pub view: ViewOptions,
}

/// A loaded scene and the warnings the loader emitted (unsupported features, approximations).
pub struct Loaded {
    /// The scene.
    pub scene: Scene,
    /// Human-readable warnings, each naming file and line where known.
    pub warnings: Vec<String>,
}

/// Load `spec`: a built-in scene name or a path to a scene file.
pub fn load(spec: &str, opts: &LoadOptions) -> anyhow::Result<Loaded> {
    if let Some(b) = builtin::find(spec) {
        let scene = (b.build)(&opts.builtin)
            .with_context(|| format!("building built-in scene '{spec}'"))?;
        return Ok(Loaded {
            scene,
            warnings: Vec::new(),
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
    match ext.as_str() {
        "pbrt" => {
            let (scene, warnings) = super::pbrt::load_pbrt(path)?;
            Ok(Loaded { scene, warnings })
        }
        "obj" => super::obj::load_obj(path, opts),
        "gltf" | "glb" => super::gltf::load_gltf(path, opts),
        other => bail!(
            "{}: unsupported scene format '.{other}' (expected .pbrt, .obj, .gltf or .glb)",
            path.display()
        ),
    }
}
