//! Progressive rendering (issue 21), driving the built binary: a signal after the first pass
//! leaves a valid image of the completed samples whose mean agrees with a full render within
//! its noise, `--resume` equals an uninterrupted render to float rounding, the output on disk
//! is a valid image at every moment, and `--time` stops at its budget.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use penumbra::image::Image;
use penumbra::image::parts::read_part;

fn bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_penumbra"))
}

/// A fresh scratch folder per test (tests run in parallel).
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-prog-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Run a render in `dir`; it must succeed.
fn render(dir: &Path, args: &[&str]) -> Output {
    let out = Command::new(bin())
        .arg("render")
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "penumbra render {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn mean(img: &Image) -> f64 {
    img.pixels
        .iter()
        .map(|p| f64::from(p.x + p.y + p.z) / 3.0)
        .sum::<f64>()
        / img.pixels.len() as f64
}

/// Largest |a − b| / max(1, |b|) over all channels.
fn max_rel_diff(a: &Image, b: &Image) -> f32 {
    assert_eq!((a.width, a.height), (b.width, b.height));
    a.pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs() / q[c].abs().max(1.0)))
        .fold(0.0, f32::max)
}

/// SIGINT (exit 130) and SIGTERM (143) after the first pass: the output holds the completed
/// samples, normalised (its mean agrees with a converged render within 5 standard errors of
/// the per-pixel differences), with the count in its header; and at every moment of the run
/// the file on disk decodes as a whole image.
#[test]
fn a_signal_after_the_first_pass_writes_the_completed_samples() {
    for (signal, code) in [("INT", 130), ("TERM", 143)] {
        let dir = scratch(&format!("signal-{signal}"));
        let common = ["cornell", "-q", "--res", "64x64"];
        render(
            &dir,
            &[&common[..], &["--spp", "256", "-o", "ref.exr"]].concat(),
        );
        // An existing output, which must never be seen truncated.
        render(
            &dir,
            &[&common[..], &["--spp", "1", "-o", "out.exr"]].concat(),
        );
        let before = std::fs::metadata(dir.join("out.exr"))
            .unwrap()
            .modified()
            .unwrap();
        let mut child = Command::new(bin())
            .args(["render"])
            .args(common)
            .args(["--spp", "1000000", "--progressive", "-o", "out.exr"])
            .current_dir(&dir)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Wait for the first pass's write (the file is replaced), reading it all along.
        let start = Instant::now();
        let mut reads = 0;
        loop {
            let img = penumbra::image::read_image(&dir.join("out.exr"));
            let img = img.unwrap_or_else(|e| panic!("output unreadable during the run: {e:#}"));
            assert_eq!((img.width, img.height), (64, 64));
            reads += 1;
            let now = std::fs::metadata(dir.join("out.exr"))
                .unwrap()
                .modified()
                .unwrap();
            if now != before
                && read_part(&dir.join("out.exr")).is_ok_and(|p| p.info.spp == 1_000_000)
            {
                break;
            }
            assert!(
                start.elapsed() < Duration::from_secs(30),
                "no pass written in 30 s"
            );
            std::thread::sleep(Duration::from_millis(5));
        }
        std::thread::sleep(Duration::from_millis(300));
        let killed = Command::new("kill")
            .args([&format!("-{signal}"), &child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let t = Instant::now();
        while child.try_wait().unwrap().is_none() {
            // Reading while the final image is written: still always a whole image.
            read_part(&dir.join("out.exr")).expect("output unreadable at the signal");
            assert!(
                t.elapsed() < Duration::from_secs(20),
                "no exit after SIG{signal}"
            );
            std::thread::sleep(Duration::from_millis(5));
        }
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "SIG{signal}: {stderr}");
        let part = read_part(&dir.join("out.exr")).unwrap();
        let reference = read_part(&dir.join("ref.exr"));
        assert!(reference.is_err(), "a plain render writes no part header");
        let reference = penumbra::image::read_image(&dir.join("ref.exr")).unwrap();
        let n = part.info.count();
        assert_eq!(part.info.samples, 0..n);
        assert!((1..1_000_000).contains(&n), "count {n}");
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            stdout.contains(&format!("{n} of 1000000 spp")),
            "summary: {stdout}"
        );
        // Standard error of the image mean from the per-pixel differences (independent
        // pixels: each has its own scrambled samples).
        let d: Vec<f64> = part
            .image
            .pixels
            .iter()
            .zip(&reference.pixels)
            .map(|(a, b)| f64::from((a.x + a.y + a.z) - (b.x + b.y + b.z)) / 3.0)
            .collect();
        let md = d.iter().sum::<f64>() / d.len() as f64;
        let var = d.iter().map(|x| (x - md).powi(2)).sum::<f64>() / (d.len() - 1) as f64;
        let se = (var / d.len() as f64).sqrt();
        let (mp, mr) = (mean(&part.image), mean(&reference));
        assert!(
            (mp - mr).abs() < 5.0 * se + 1e-4 * mr,
            "SIG{signal}: mean {mp} after {n} spp vs {mr} at 256 spp (standard error {se})"
        );
        assert!(reads > 0);
        assert_no_temp_files(&dir);
    }
}

fn assert_no_temp_files(dir: &Path) {
    for e in std::fs::read_dir(dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.contains(".tmp-"), "temp file left: {name}");
    }
}

/// `--resume` of a part (from `--spp-range 0..K`, and from a `--time` render) continues to
/// the spp and equals the uninterrupted render within float rounding.
#[test]
fn resume_equals_an_uninterrupted_render() {
    let dir = scratch("resume");
    let base = ["cornell", "-q", "--res", "48x40", "--pattern", "sobol"];
    let common = [&base[..], &["--seed", "7"]].concat();
    render(
        &dir,
        &[&common[..], &["--spp", "24", "-o", "full.exr"]].concat(),
    );
    render(
        &dir,
        &[
            &common[..],
            &["--spp", "24", "--spp-range", "0..5", "-o", "part.exr"],
        ]
        .concat(),
    );
    let out = render(
        &dir,
        &[
            &common[..],
            &["--spp", "24", "--resume", "part.exr", "-o", "resumed.exr"],
        ]
        .concat(),
    );
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("24 of 24 spp (resumed from 5)"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let full = penumbra::image::read_image(&dir.join("full.exr")).unwrap();
    let resumed = read_part(&dir.join("resumed.exr")).unwrap();
    assert_eq!(resumed.info.samples, 0..24);
    let diff = max_rel_diff(&resumed.image, &full);
    assert!(
        diff < 1e-5,
        "resumed differs from the whole render by {diff}"
    );
    // A different image would be far off: the same test against another seed fails.
    render(
        &dir,
        &[
            &base[..],
            &["--spp", "24", "--seed", "8", "-o", "other.exr"],
        ]
        .concat(),
    );
    let other = penumbra::image::read_image(&dir.join("other.exr")).unwrap();
    assert!(max_rel_diff(&resumed.image, &other) > 1e-3);

    // A time-budget part resumed in place (input = output).
    let big = ["cornell", "-q", "--res", "96x96", "--spp", "512"];
    render(&dir, &[&big[..], &["-o", "big.exr"]].concat());
    render(
        &dir,
        &[&big[..], &["--time", "0.05", "-o", "t.exr"]].concat(),
    );
    let k = read_part(&dir.join("t.exr")).unwrap().info.count();
    render(
        &dir,
        &[&big[..], &["--resume", "t.exr", "-o", "t.exr"]].concat(),
    );
    let done = read_part(&dir.join("t.exr")).unwrap();
    assert_eq!(done.info.count(), 512, "resumed from {k}");
    let big_full = penumbra::image::read_image(&dir.join("big.exr")).unwrap();
    let diff = max_rel_diff(&done.image, &big_full);
    assert!(
        diff < 1e-5,
        "time part of {k} spp resumed differs by {diff}"
    );
}

/// A part of other settings or another spp is refused with the reason.
#[test]
fn resume_refuses_a_part_of_another_render() {
    let dir = scratch("resume-bad");
    let common = ["cornell", "-q", "--res", "16x16"];
    render(
        &dir,
        &[
            &common[..],
            &["--spp", "8", "--spp-range", "0..2", "-o", "p.exr"],
        ]
        .concat(),
    );
    render(
        &dir,
        &[
            &common[..],
            &["--spp", "8", "--spp-range", "2..4", "-o", "q.exr"],
        ]
        .concat(),
    );
    let fail = |args: &[&str]| {
        let out = Command::new(bin())
            .arg("render")
            .args(common)
            .args(args)
            .current_dir(&dir)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let e = fail(&[
        "--spp",
        "8",
        "--strategy",
        "bsdf",
        "--resume",
        "p.exr",
        "-o",
        "x.exr",
    ]);
    assert!(e.contains("p.exr") && e.contains("other settings"), "{e}");
    let e = fail(&["--spp", "16", "--resume", "p.exr", "-o", "x.exr"]);
    assert!(e.contains("8-spp render") && e.contains("--spp 8"), "{e}");
    let e = fail(&["--spp", "8", "--resume", "q.exr", "-o", "x.exr"]);
    assert!(e.contains("samples 2..4"), "{e}");
    let e = fail(&["--spp", "8", "--resume", "missing.exr", "-o", "x.exr"]);
    assert!(e.contains("missing.exr"), "{e}");
    assert!(!dir.join("x.exr").exists());
}

/// `--time` stops when its budget is spent, well before the spp, within about one pass.
#[test]
fn time_budget_stops_the_render() {
    let dir = scratch("time");
    let t = Instant::now();
    let out = render(
        &dir,
        &[
            "cornell", "-q", "--res", "64x64", "--time", "0.6", "-o", "t.png",
        ],
    );
    let wall = t.elapsed();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("of 65536 spp") && stdout.contains("time budget 0.6 s"),
        "{stdout}"
    );
    let render_s: f64 = stdout
        .split("render ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no render time in {stdout}"));
    assert!(
        (0.3..1.2).contains(&render_s),
        "render {render_s} s for a 0.6 s budget"
    );
    assert!(wall < Duration::from_secs(20));
    assert!(image::open(dir.join("t.png")).is_ok());
}
