//! The bad-input catalogue: every file under tests/data/pbrt/bad/ must fail with an error that
//! names the file and line (`# expect-line:`) and says what went wrong (`# expect:`), never
//! panic; every file under tests/data/pbrt/repaired/ holds something a renderer can repair and
//! must load with one warning naming the file and line (`# expect-warning-line:`) and saying
//! what was repaired (`# expect-warning:`). Plus truncation and byte-mutation fuzzing of a real
//! scene.

use penumbra::scene::pbrt::{load_pbrt, parse_pbrt, parse_pbrt_str};
use std::path::{Path, PathBuf};

fn catalogue() -> Vec<PathBuf> {
    files_in("tests/data/pbrt/bad")
}

fn files_in(rel: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("catalogue dir")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "pbrt"))
        .collect();
    v.sort();
    v
}

fn header(src: &str, key: &str) -> String {
    src.lines()
        .find_map(|l| l.strip_prefix(&format!("# {key}: ")))
        .unwrap_or_else(|| panic!("missing '# {key}:'"))
        .trim()
        .to_string()
}

#[test]
fn catalogue_has_at_least_25_files_and_each_is_a_located_error() {
    let files = catalogue();
    assert!(files.len() >= 25, "only {} catalogue files", files.len());
    let mut failures = Vec::new();
    for path in &files {
        let src = std::fs::read_to_string(path).unwrap();
        let line = header(&src, "expect-line");
        let what = header(&src, "expect");
        let name = path.file_name().unwrap().to_str().unwrap();
        match parse_pbrt(path) {
            Ok(_) => failures.push(format!("{name}: parsed without error")),
            Err(e) => {
                let msg = e.to_string();
                let located = msg.contains(&format!("{name}:{line}:"));
                if !located || !msg.contains(&what) {
                    failures.push(format!(
                        "{name}: want '{name}:{line}:' and '{what}', got: {msg}"
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn repaired_catalogue_loads_with_one_located_warning_each() {
    let files = files_in("tests/data/pbrt/repaired");
    assert!(files.len() >= 8, "only {} repaired files", files.len());
    let mut failures = Vec::new();
    for path in &files {
        let src = std::fs::read_to_string(path).unwrap();
        let line = header(&src, "expect-warning-line");
        let what = header(&src, "expect-warning");
        let name = path.file_name().unwrap().to_str().unwrap();
        match load_pbrt(path) {
            Err(e) => failures.push(format!("{name}: refused: {e:#}")),
            Ok((_, warnings)) => {
                let at = format!("{name}:{line}:");
                let n = warnings
                    .iter()
                    .filter(|w| w.contains(&at) && w.contains(&what))
                    .count();
                if n != 1 {
                    failures.push(format!(
                        "{name}: want one warning with '{at}' and '{what}', got {warnings:?}"
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

fn cornell() -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/scenes/cornell-box-bitterli/scene-v4.pbrt");
    std::fs::read_to_string(&p)
        .or_else(|_| {
            std::fs::read_to_string("/work/shared/scenes/cornell-box-bitterli/scene-v4.pbrt")
        })
        .expect("cornell scene")
}

/// Deterministic 64-bit LCG (tests must be reproducible).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 33
    }
}

#[test]
fn truncated_scenes_never_panic_and_errors_are_located() {
    let src = cornell();
    let mut rng = Lcg(7);
    let mut errors = 0;
    for _ in 0..300 {
        let cut = (rng.next() as usize) % src.len();
        let text = String::from_utf8_lossy(&src.as_bytes()[..cut]).to_string();
        match parse_pbrt_str("trunc.pbrt", &text, Path::new(".")) {
            Ok(_) => {}
            Err(e) => {
                errors += 1;
                let m = e.to_string();
                assert!(
                    m.starts_with("trunc.pbrt:"),
                    "unlocated error at cut {cut}: {m}"
                );
            }
        }
    }
    // Most cuts land inside a directive or before WorldBegin.
    assert!(errors > 150, "only {errors} of 300 truncations were errors");
}

#[test]
fn mutated_scenes_never_panic() {
    let src = cornell().into_bytes();
    let mut rng = Lcg(11);
    let alphabet = b"[]\"#-.e0123456789 \nxAWS";
    for _ in 0..300 {
        let mut s = src.clone();
        for _ in 0..1 + rng.next() % 4 {
            let i = (rng.next() as usize) % s.len();
            s[i] = alphabet[(rng.next() as usize) % alphabet.len()];
        }
        let text = String::from_utf8_lossy(&s).to_string();
        if let Err(e) = parse_pbrt_str("mut.pbrt", &text, Path::new(".")) {
            assert!(e.to_string().starts_with("mut.pbrt:"), "{e}");
        }
    }
}
