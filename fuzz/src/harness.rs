//! What each fuzz target does with one input: load it as a scene (or read it as an image and
//! light a scene with it), render a tiny image, and require finite, non-negative pixels. An
//! error is a fine answer to bad input; a panic, a hang, an abort or a bad pixel is a bug.
//!
//! Shared by the cargo-fuzz targets (`fuzz/fuzz_targets/`, nightly) and the stable replay test
//! `tests/fuzz_replay.rs`, which runs every saved corpus file and crash through the same code.

use std::path::{Path, PathBuf};

use glam::UVec2;
use penumbra::image::read_image;
use penumbra::integrator::{RenderOptions, render};
use penumbra::scene::Scene;
use penumbra::scene::load::LoadOptions;
use penumbra::scene::pbrt::parse_pbrt_str;

/// The tiny render every target ends with.
const RES: UVec2 = UVec2::new(4, 4);

/// A private scratch folder for the files the loaders want (per process: libFuzzer's `-jobs`
/// and parallel tests must not share one), on tmpfs where there is one.
fn scratch() -> PathBuf {
    let base = if Path::new("/dev/shm").is_dir() {
        PathBuf::from("/dev/shm")
    } else {
        std::env::temp_dir()
    };
    let dir = base.join(format!("penumbra-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// Write `data` as `name` in a fresh per-call subfolder of the scratch folder (so that a
/// reference to a sibling file only ever finds what this input made).
fn file(name: &str, data: &[u8]) -> PathBuf {
    use std::sync::atomic::{AtomicU64, Ordering};
    static N: AtomicU64 = AtomicU64::new(0);
    let dir = scratch().join(N.fetch_add(1, Ordering::Relaxed).to_string());
    std::fs::create_dir_all(&dir).expect("scratch subfolder");
    let path = dir.join(name);
    std::fs::write(&path, data).expect("scratch file");
    path
}

/// Remove the per-call folder `file` made.
fn cleanup(path: &Path) {
    if let Some(dir) = path.parent() {
        let _ = std::fs::remove_dir_all(dir);
    }
}

/// Render `scene` tiny and insist on finite, non-negative pixels.
pub fn render_and_check(scene: &Scene) {
    let opts = RenderOptions {
        spp: 1,
        ..RenderOptions::default()
    };
    // A render may refuse a scene (an error); it may not panic or produce bad pixels.
    if let Ok((img, _)) = render(scene, RES, &opts) {
        for (i, p) in img.pixels.iter().enumerate() {
            assert!(
                p.is_finite() && p.min_element() >= 0.0,
                "pixel {i} is {p:?}"
            );
        }
    }
}

/// A pbrt-v4 file, parsed from memory (Include/Import and file references resolve in an
/// empty folder), built and rendered.
pub fn pbrt(data: &[u8]) {
    let Ok(src) = std::str::from_utf8(data) else {
        return;
    };
    let dir = scratch();
    let Ok(parsed) = parse_pbrt_str("fuzz.pbrt", src, &dir) else {
        return;
    };
    let Ok((builder, camera, film, _)) = parsed.into_builder() else {
        return;
    };
    if let Ok(scene) = builder.build(camera, film) {
        render_and_check(&scene);
    }
}

/// An OBJ file (its `mtllib` resolves beside it, where there is nothing), loaded and rendered.
pub fn obj(data: &[u8]) {
    let path = file("fuzz.obj", data);
    if let Ok(loaded) = penumbra::scene::obj::load_obj(&path, &LoadOptions::default()) {
        render_and_check(&loaded.scene);
    }
    cleanup(&path);
}

/// A glTF 2.0 file, binary (`glTF` magic) or JSON, loaded and rendered.
pub fn gltf(data: &[u8]) {
    let name = if data.starts_with(b"glTF") {
        "fuzz.glb"
    } else {
        "fuzz.gltf"
    };
    let path = file(name, data);
    // The loader turns a panic inside the gltf crates (gltf-json 1.4.1 indexes
    // accessors unchecked, mesh.rs:151; gltf 1.4.1 mesh/mod.rs:396 reaches unreachable!) into
    // an error with catch_unwind; libFuzzer's panic
    // hook would abort on it all the same. Such panics are let through; any other panic,
    // ours included, still aborts.
    let previous = std::sync::Arc::new(std::panic::take_hook());
    let chained = std::sync::Arc::clone(&previous);
    std::panic::set_hook(Box::new(move |info| {
        let in_gltf_json = info.location().is_some_and(|l| l.file().contains("/gltf-"));
        if !in_gltf_json {
            chained(info);
        }
    }));
    let loaded = penumbra::scene::gltf::load_gltf(&path, &LoadOptions::default());
    let _ = std::panic::take_hook();
    if let Ok(previous) = std::sync::Arc::try_unwrap(previous) {
        std::panic::set_hook(previous);
    }
    if let Ok(loaded) = loaded {
        render_and_check(&loaded.scene);
    }
    cleanup(&path);
}

/// A small pbrt scene around the fuzzed bytes as a `plymesh`.
pub fn ply(data: &[u8]) {
    let path = file("fuzz.ply", data);
    let src = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 60\n\
               WorldBegin\nLightSource \"point\" \"rgb I\" [10 10 10] \"point3 from\" [0 0 4]\n\
               Shape \"plymesh\" \"string filename\" \"fuzz.ply\"\n";
    let dir = path.parent().unwrap_or(Path::new("."));
    if let Ok(parsed) = parse_pbrt_str("fuzz.pbrt", src, dir)
        && let Ok((builder, camera, film, _)) = parsed.into_builder()
        && let Ok(scene) = builder.build(camera, film)
    {
        render_and_check(&scene);
    }
    cleanup(&path);
}

/// The image formats the readers take, chosen by the input's first byte; the rest is the file.
const IMAGE_EXTENSIONS: [&str; 4] = ["exr", "pfm", "png", "hdr"];

/// An image file (EXR, PFM, PNG or HDR by the first byte), read, then used as the environment
/// map lighting a diffuse sphere.
pub fn image(data: &[u8]) {
    let Some((&which, bytes)) = data.split_first() else {
        return;
    };
    let ext = IMAGE_EXTENSIONS[which as usize % IMAGE_EXTENSIONS.len()];
    let name = format!("fuzz.{ext}");
    let path = file(&name, bytes);
    if let Ok(img) = read_image(&path) {
        assert_eq!(
            img.pixels.len(),
            img.width as usize * img.height as usize,
            "{ext}: pixel count"
        );
        let src = format!(
            "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 60\nWorldBegin\n\
             LightSource \"infinite\" \"string filename\" \"{name}\"\n\
             Shape \"sphere\" \"float radius\" 1\n"
        );
        let dir = path.parent().unwrap_or(Path::new("."));
        if let Ok(parsed) = parse_pbrt_str("fuzz.pbrt", &src, dir)
            && let Ok((builder, camera, film, _)) = parsed.into_builder()
            && let Ok(scene) = builder.build(camera, film)
        {
            render_and_check(&scene);
        }
    }
    cleanup(&path);
}
