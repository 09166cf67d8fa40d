//! Stable-toolchain guard for the fuzz targets (fuzz/, cargo-fuzz on nightly): every input of
//! the committed seeds (`fuzz/seeds/TARGET/`), every crash, timeout and OOM a campaign found
//! (`fuzz/regressions/TARGET/`), the local campaign corpus when there is one
//! (`fuzz/corpus/TARGET/`, not committed) and the third-party scenes of `../shared/scenes/`
//! go through the very harness the fuzzers run: load, render 4×4, finite non-negative pixels.

#[path = "../fuzz/src/harness.rs"]
mod harness;

use std::path::{Path, PathBuf};
use std::time::Instant;

/// A fuzz target's entry point.
type Target = fn(&[u8]);

const TARGETS: [(&str, Target); 5] = [
    ("pbrt", harness::pbrt),
    ("obj", harness::obj),
    ("gltf", harness::gltf),
    ("ply", harness::ply),
    ("image", harness::image),
];

fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.flatten()
                .map(|e| e.path())
                .filter(|p| p.is_file() && p.file_name().is_none_or(|n| n != ".keep"))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

/// The third-party scene files for `target`, as the fuzzers' seeds take them.
fn shared_inputs(target: &str) -> Vec<Vec<u8>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/scenes");
    let mut out = Vec::new();
    let mut stack = vec![root];
    while let Some(dir) = stack.pop() {
        for p in files_in(&dir) {
            let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
            let keep = match target {
                "pbrt" => ext == "pbrt",
                "obj" => ext == "obj",
                "gltf" => ext == "gltf" || ext == "glb",
                // Small meshes only: the replay must stay fast.
                "ply" => ext == "ply" && std::fs::metadata(&p).is_ok_and(|m| m.len() < 200_000),
                _ => false,
            };
            if keep {
                out.push(std::fs::read(&p).unwrap());
            }
        }
        if let Ok(rd) = std::fs::read_dir(&dir) {
            stack.extend(rd.flatten().map(|e| e.path()).filter(|p| p.is_dir()));
        }
    }
    out
}

#[test]
fn every_saved_fuzz_input_loads_or_fails_cleanly_and_renders_finite_pixels() {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/scenes");
    assert!(
        shared.is_dir(),
        "../shared/scenes/ is missing: the replay of the third-party seeds needs it"
    );
    let start = Instant::now();
    let mut counts = Vec::new();
    for (target, run) in TARGETS {
        let mut inputs: Vec<Vec<u8>> = ["seeds", "regressions", "corpus"]
            .iter()
            .flat_map(|d| files_in(&fuzz.join(d).join(target)))
            // A running campaign may remove corpus files under our feet.
            .filter_map(|p| std::fs::read(p).ok())
            .collect();
        let committed = inputs.len();
        inputs.extend(shared_inputs(target));
        for input in &inputs {
            run(input);
        }
        counts.push(format!("{target}: {} ({committed} in fuzz/)", inputs.len()));
        if target != "image" {
            assert!(
                inputs.len() > committed,
                "{target}: no seed from ../shared/scenes"
            );
        }
    }
    eprintln!("replayed {} in {:?}", counts.join(", "), start.elapsed());
}

#[test]
fn every_committed_seed_and_regression_is_in_a_folder_the_replay_reads() {
    // The replay reads `fuzz/seeds/TARGET/` and `fuzz/regressions/TARGET/` one level deep: a
    // crash saved anywhere else (a misspelt target, a subfolder, the top level) would never
    // be replayed, and CI would not notice the bug coming back.
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let mut stray = Vec::new();
    let mut replayed = 0;
    for kind in ["seeds", "regressions"] {
        let mut stack = vec![fuzz.join(kind)];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).unwrap().flatten() {
                let p = entry.path();
                if p.is_dir() {
                    stack.push(p);
                    continue;
                }
                if p.file_name().is_some_and(|n| n == ".keep") {
                    continue;
                }
                let rel = p.strip_prefix(fuzz.join(kind)).unwrap();
                let in_target = rel.components().count() == 2
                    && TARGETS.iter().any(|(t, _)| rel.starts_with(t));
                if in_target {
                    replayed += 1;
                } else {
                    stray.push(p.display().to_string());
                }
            }
        }
    }
    assert!(stray.is_empty(), "not replayed: {stray:?}");
    let listed: usize = TARGETS
        .iter()
        .flat_map(|(t, _)| ["seeds", "regressions"].map(|k| files_in(&fuzz.join(k).join(t))))
        .map(|v| v.len())
        .sum();
    assert_eq!(
        listed, replayed,
        "the replay's file listing misses some inputs"
    );
    assert!(replayed > 0);
}
