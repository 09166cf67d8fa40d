//! The lab end to end at a tiny resolution: every promised file is written, the JSON and HTML
//! agree with what was rendered, the reference is cached, and bad input is an error.

use glam::UVec2;
use penumbra::image::{read_image, write_image};
use penumbra::lab::{LabOptions, lecture_figures, run_lab};
use std::path::{Path, PathBuf};

/// A fresh, empty output directory unique to this test.
fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("penumbra-lab-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn small(out: &Path) -> LabOptions {
    LabOptions {
        out: out.to_path_buf(),
        res: Some(UVec2::new(32, 32)),
        reference_spp: 64,
        convergence_spp: 4,
        progress: false,
        ..LabOptions::default()
    }
}

fn assert_file(dir: &Path, name: &str) {
    let p = dir.join(name);
    let len = std::fs::metadata(&p)
        .unwrap_or_else(|e| panic!("{} missing: {e}", p.display()))
        .len();
    assert!(len > 0, "{} is empty", p.display());
}

#[test]
fn lab_writes_every_promised_file() {
    let out = out_dir("all");
    let opts = small(&out);
    let r = run_lab(&opts).expect("lab runs");
    assert_eq!(r.resolution, [32, 32]);
    assert_eq!(r.figures.len(), lecture_figures().len());

    // Figures 1–4 run on the main scene and always render every panel.
    for f in r.figures.iter().take(4) {
        let def = lecture_figures()
            .into_iter()
            .find(|d| d.id == f.id)
            .unwrap();
        assert_eq!(
            f.panels.len(),
            def.panels.len(),
            "{}: {:?}",
            f.id,
            f.skipped
        );
        let montage = f.montage.as_ref().expect("montage written");
        assert_file(&out, montage);
        for p in &f.panels {
            for name in [&p.exr, &p.png, &p.error_png] {
                assert_file(&out, name);
            }
            let img = read_image(&out.join(&p.exr)).unwrap();
            assert_eq!((img.width, img.height), (32, 32));
            assert!(
                p.time_s > 0.0 && p.rays > 0,
                "{}: no work measured",
                p.label
            );
            assert!(
                p.rel_mse.is_finite() && p.rel_mse > 0.0,
                "{}: relMSE {}",
                p.label,
                p.rel_mse
            );
            assert!(p.smooth_rel_mse.is_finite() && p.smooth_rel_mse <= p.rel_mse * 10.0);
        }
    }
    // Figures 5–6 either render or say why not.
    for f in r.figures.iter().skip(4) {
        assert!(
            f.montage.is_some() || f.skipped.iter().any(|s| !s.is_empty()),
            "{} neither rendered nor skipped with a reason",
            f.id
        );
    }

    // Convergence: four strategies at spp 1, 2, 4, plotted as SVG and PNG.
    assert_eq!(r.convergence.len(), 4);
    for s in &r.convergence {
        let spps: Vec<u32> = s.points.iter().map(|p| p.spp).collect();
        assert_eq!(spps, vec![1, 2, 4], "{}", s.strategy);
    }
    assert_file(&out, "convergence.svg");
    assert_file(&out, "convergence.png");
    assert!(
        std::fs::read_to_string(out.join("convergence.svg"))
            .unwrap()
            .contains("<svg")
    );

    // Reports: JSON round-trips the panels; HTML links every image relatively.
    assert_file(&out, "results.json");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    assert_eq!(json["figures"].as_array().unwrap().len(), r.figures.len());
    assert_eq!(json["figures"][0]["panels"][1]["strategy"], "light-area");
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>") && html.trim_end().ends_with("</html>"));
    for f in &r.figures {
        if let Some(m) = &f.montage {
            assert!(
                html.contains(&format!("src=\"{m}\"")),
                "html lacks montage {m}"
            );
        }
        for p in &f.panels {
            assert!(
                html.contains(&format!("href=\"{}\"", p.exr)),
                "html lacks {}",
                p.exr
            );
        }
    }
    assert!(!html.contains("src=\"/"), "links must be relative");

    // The reference was rendered once and is reused by a second run.
    assert_eq!(r.references[0].source, "rendered");
    assert_file(&out, &r.references[0].path);
    let again = run_lab(&LabOptions {
        figures: vec!["fig2".into()],
        convergence_spp: 0,
        ..opts
    })
    .expect("second run");
    assert_eq!(again.references[0].source, "cache");
    assert_eq!(again.figures.len(), 1);
    assert!(again.convergence.is_empty());
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn lab_uses_given_reference_and_rejects_bad_input() {
    let out = out_dir("ref");
    std::fs::create_dir_all(&out).unwrap();
    // A constant grey "reference": the lab must adopt its size and report it as a file.
    let grey = penumbra::image::Image::from_fn(24, 16, |_, _| glam::Vec3::splat(0.5));
    let ref_path = out.join("given.exr");
    write_image(&grey, &ref_path, 0.0).unwrap();
    let r = run_lab(&LabOptions {
        res: None,
        reference: Some(ref_path.clone()),
        figures: vec!["fig2".into()],
        convergence_spp: 0,
        ..small(&out)
    })
    .expect("lab with a given reference");
    assert_eq!(r.resolution, [24, 16]);
    assert_eq!(r.references[0].source, "file");

    // Size mismatch, unknown figure, missing reference, unknown scene: errors, not panics.
    let bad = |o: LabOptions| run_lab(&o).map(|_| ()).unwrap_err().to_string();
    let e = bad(LabOptions {
        reference: Some(ref_path),
        ..small(&out)
    });
    assert!(e.contains("24x16"), "{e}");
    let e = bad(LabOptions {
        figures: vec!["fig99".into()],
        ..small(&out)
    });
    assert!(e.contains("fig99"), "{e}");
    assert!(
        run_lab(&LabOptions {
            reference: Some(out.join("missing.exr")),
            ..small(&out)
        })
        .is_err()
    );
    assert!(
        run_lab(&LabOptions {
            scene: "no-such-scene".into(),
            ..small(&out)
        })
        .is_err()
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn lab_cli_runs_one_figure() {
    let out = out_dir("cli");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args([
            "lab",
            "cornell",
            "--res",
            "16x16",
            "--quiet",
            "--figures",
            "fig2",
        ])
        .args(["--reference-spp", "8", "--convergence-spp", "1", "--out"])
        .arg(&out)
        .output()
        .expect("penumbra runs");
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    assert!(String::from_utf8_lossy(&status.stdout).contains("relMSE"));
    for f in ["fig2.png", "index.html", "results.json", "convergence.png"] {
        assert_file(&out, f);
    }
    let bad = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args(["lab", "--res", "0x5", "--out"])
        .arg(&out)
        .output()
        .expect("penumbra runs");
    assert!(!bad.status.success());
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn lab_figures_use_the_lectures_sample_counts() {
    let figs = lecture_figures();
    let counts = |id: &str| -> Vec<(String, u32, u32)> {
        figs.iter()
            .find(|f| f.id == id)
            .unwrap()
            .panels
            .iter()
            .map(|p| (p.label.clone(), p.spp, p.shadow_rays))
            .collect()
    };
    let c = |l: &str, n, m| (l.to_string(), n, m);
    assert_eq!(counts("fig1"), [c("bsdf", 4, 100), c("light-area", 4, 100)]);
    assert_eq!(counts("fig2"), [c("fixed", 4, 1), c("random", 4, 1)]);
    assert_eq!(counts("fig3"), [c("grid", 4, 64), c("stratified", 4, 64)]);
    assert_eq!(
        counts("fig4"),
        [c("stratified", 4, 16), c("stratified", 64, 1)]
    );
    // Every panel's files are distinct within its figure.
    for f in &figs {
        let mut slugs: Vec<String> = f.panels.iter().map(|p| p.slug()).collect();
        slugs.sort();
        slugs.dedup();
        assert_eq!(
            slugs.len(),
            f.panels.len(),
            "{}: duplicate panel file names",
            f.id
        );
    }
}
