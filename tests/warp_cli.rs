//! `penumbra warp`: dumps and pdf tables round-trip exactly (through the binary and through the
//! library), the printed chi-square statistic is the harness's, bad parameters fail cleanly,
//! and every listed routine passes with its defaults.

use glam::{Vec2, Vec3};
use penumbra::Rgb;
use penumbra::bsdf::{Bxdf, Phong};
use penumbra::lab::warp::io::{Table, npy_bytes, parse_npy, read_table, write_table};
use penumbra::lab::warp::run::{pattern_samples, test_samples};
use penumbra::lab::warp::{ROUTINES, RunConfig, build, chi2_config, pdf_at, run};
use penumbra::sampling::PatternKind;
use penumbra::sampling::chi2::{chi2_directions, chi2_directions_from, chi2_points, sidak_alpha};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-warp-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create scratch dir");
    dir
}

fn penumbra(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .arg("warp")
        .args(args)
        .output()
        .expect("run penumbra")
}

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// The value printed on the `key` line of the summary.
fn printed(stdout: &str, key: &str) -> String {
    stdout
        .lines()
        .find_map(|l| l.strip_prefix(key))
        .unwrap_or_else(|| panic!("no {key:?} line in:\n{stdout}"))
        .trim()
        .to_string()
}

// ---------------------------------------------------------------- dump round trips

#[test]
fn dump_round_trips_through_the_binary() {
    let dir = scratch("dump");
    for (routine, ext, cols) in [
        ("cosine-hemisphere", "txt", 3),
        ("phong", "npy", 3),
        ("disk", "txt", 2),
        ("piecewise-2d", "npy", 2),
    ] {
        let file = dir.join(format!("{routine}.{ext}"));
        let f = file.to_str().unwrap();
        let o = penumbra(&[routine, "-n", "3000", "--no-plots", "--dump", f]);
        assert!(o.status.success(), "{routine}: {:?}", text(&o));
        let back: Table<f32> = read_table(&file).unwrap();
        assert_eq!(back.cols, cols, "{routine}");
        // The library call the CLI makes, with the same defaults.
        let warp = build(routine, &[]).unwrap();
        let cfg = RunConfig {
            count: 3000,
            ..Default::default()
        };
        let lib = run(&warp, &cfg);
        let expect: Vec<u32> = lib
            .samples
            .iter()
            .flat_map(|s| s.to_array().into_iter().take(cols))
            .map(f32::to_bits)
            .collect();
        let got: Vec<u32> = back.values.iter().map(|v| v.to_bits()).collect();
        assert_eq!(got.len(), expect.len(), "{routine}: row count");
        assert_eq!(got, expect, "{routine}: values differ after the round trip");
    }
}

#[test]
fn dump_pdf_round_trips_through_the_binary() {
    let dir = scratch("pdf");
    for (routine, ext) in [("ggx", "txt"), ("cone", "npy"), ("triangle", "txt")] {
        let samples = dir.join(format!("{routine}-s.{ext}"));
        let pdfs = dir.join(format!("{routine}-p.{ext}"));
        let (s, q) = (samples.to_str().unwrap(), pdfs.to_str().unwrap());
        let o = penumbra(&[routine, "-n", "2000", "--no-plots", "--dump", s]);
        assert!(o.status.success(), "{routine}: {:?}", text(&o));
        let o = penumbra(&[routine, "--pdf-at", s, "--dump-pdf", q]);
        assert!(o.status.success(), "{routine}: {:?}", text(&o));
        let pts: Table<f32> = read_table(&samples).unwrap();
        let back: Table<f64> = read_table(&pdfs).unwrap();
        let warp = build(routine, &[]).unwrap();
        let lib = pdf_at(&warp, pts.cols, &pts.values).unwrap();
        assert_eq!(back.cols, 1);
        assert_eq!(
            back.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            lib.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            "{routine}"
        );
        // The samples were drawn by the routine, so its pdf is positive at every one of them.
        assert!(
            lib.iter().all(|&v| v > 0.0),
            "{routine}: zero pdf at a sample"
        );
    }
}

#[test]
fn tables_round_trip_through_the_library() {
    let dir = scratch("tables");
    let f32s = Table {
        cols: 3,
        values: vec![
            0.1f32,
            -0.0,
            1.0e-40,
            f32::MAX,
            -f32::MIN_POSITIVE,
            std::f32::consts::PI,
        ],
    };
    let f64s = Table {
        cols: 1,
        values: vec![0.1f64, 1e-310, -2.5, std::f64::consts::E, 0.0],
    };
    for ext in ["txt", "npy"] {
        let a = dir.join(format!("a.{ext}"));
        write_table(&a, &f32s).unwrap();
        let back: Table<f32> = read_table(&a).unwrap();
        assert_eq!(back.cols, f32s.cols);
        assert_eq!(
            back.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            f32s.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            "{ext}"
        );
        let b = dir.join(format!("b.{ext}"));
        write_table(&b, &f64s).unwrap();
        let back: Table<f64> = read_table(&b).unwrap();
        assert_eq!(
            back.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            f64s.values.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            "{ext}"
        );
    }
    // The NPY v1.0 layout: magic, version 1.0, header padded so the data starts 64-aligned.
    let bytes = npy_bytes(&f32s);
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
    let hlen = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    assert_eq!((10 + hlen) % 64, 0);
    let header = std::str::from_utf8(&bytes[10..10 + hlen]).unwrap();
    assert!(header.contains("'descr': '<f4'") && header.contains("'shape': (2, 3)"));
    assert!(header.ends_with('\n'));
    assert_eq!(bytes.len(), 10 + hlen + 6 * 4);
    let one_d = String::from_utf8_lossy(&npy_bytes(&f64s)).into_owned();
    assert!(one_d.contains("'shape': (5,)"), "{one_d}");
    // Corrupt files are errors, not panics.
    assert!(parse_npy::<f32>(&bytes[..bytes.len() - 1]).is_err());
    assert!(parse_npy::<f32>(b"\x93NUMPY\x01").is_err());
    assert!(parse_npy::<f32>(&bytes[1..]).is_err());
}

// ---------------------------------------------------------------- chi-square statistic

#[test]
fn chi2_printed_statistic_equals_the_harness() {
    let seed = 12345u64;
    let seed_s = seed.to_string();
    let o = penumbra(&["phong", "-n", "20000", "--seed", &seed_s, "--no-plots"]);
    assert!(o.status.success(), "{:?}", text(&o));
    let (stdout, _) = text(&o);
    let stat: f64 = printed(&stdout, "statistic").parse().unwrap();
    let dof: usize = printed(&stdout, "dof").parse().unwrap();
    let pval: f64 = printed(&stdout, "p-value").parse().unwrap();

    // The library function the CLI calls.
    let warp = build("phong", &[]).unwrap();
    let cfg = RunConfig {
        count: 20_000,
        seed,
        ..Default::default()
    };
    let lib = run(&warp, &cfg);
    assert_eq!(stat.to_bits(), lib.chi2.statistic.to_bits());
    assert_eq!(dof, lib.chi2.dof);
    assert_eq!(pval.to_bits(), lib.chi2.p_value.to_bits());

    // The harness called directly on a Phong built here, as tests/bsdf_chi2.rs does.
    let b = Phong::new(Rgb::splat(0.3), Rgb::splat(0.6), 20.0).unwrap();
    let (t, f) = (45f32.to_radians(), 30f32.to_radians());
    let wo = Vec3::new(t.sin() * f.cos(), t.sin() * f.sin(), t.cos());
    let direct = chi2_directions(
        &chi2_config(&warp, &cfg),
        |u| b.sample(wo, u[0], Vec2::new(u[1], u[2])).map(|s| s.wi),
        |wi| b.pdf(wo, wi) as f64,
    );
    assert_eq!(direct.statistic.to_bits(), stat.to_bits());
    assert_eq!(direct.dof, dof);
}

#[test]
fn chi2_points_and_patterns_equal_the_harness() {
    // Planar routine: chi2_points on the triangle's bounding box.
    let warp = build("triangle", &[]).unwrap();
    let cfg = RunConfig {
        count: 20_000,
        ..Default::default()
    };
    let lib = run(&warp, &cfg);
    let (a, b, c) = (
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::new(2.0, 0.3, 0.0),
        Vec3::new(0.5, 1.2, 0.0),
    );
    let direct = chi2_points(
        &chi2_config(&warp, &cfg),
        [-1.0, 2.0, 0.0, 1.2],
        |u| {
            Some(
                penumbra::sampling::uniform_triangle_point(Vec2::new(u[1], u[2]), a, b, c)
                    .truncate(),
            )
        },
        |p| warp.pdf(p.extend(0.0)),
    );
    assert_eq!(lib.chi2.statistic.to_bits(), direct.statistic.to_bits());
    assert!(lib.chi2.passed, "{}", lib.chi2.summary());

    // Pattern input: the CLI's statistic is chi2_directions_from on the pattern's samples.
    let o = penumbra(&[
        "cosine-power",
        "-n",
        "4096",
        "--pattern",
        "sobol",
        "--no-plots",
    ]);
    assert!(o.status.success(), "{:?}", text(&o));
    let (stdout, _) = text(&o);
    let stat: f64 = printed(&stdout, "statistic").parse().unwrap();
    assert!(printed(&stdout, "verdict").contains("not independent"));
    let warp = build("cosine-power", &[]).unwrap();
    let cfg = RunConfig {
        count: 4096,
        pattern: Some(PatternKind::Sobol),
        ..Default::default()
    };
    let samples = pattern_samples(&warp, PatternKind::Sobol, cfg.seed, 4096);
    let direct = chi2_directions_from(&chi2_config(&warp, &cfg), &samples, 4096, |d| {
        penumbra::sampling::cosine_power_hemisphere_pdf(d, 10.0) as f64
    });
    assert_eq!(stat.to_bits(), direct.statistic.to_bits());
    let again = test_samples(&warp, &chi2_config(&warp, &cfg), &samples, 4096);
    assert_eq!(again.statistic.to_bits(), direct.statistic.to_bits());
}

#[test]
fn chi2_negative_control_wrong_exponent_is_rejected() {
    // Samples of n = 10 judged by the n = 12 routine's pdf through the CLI's own test path:
    // the harness must have the power to tell them apart at the CLI's default count.
    let (drawn, judge) = (
        build("cosine-power", &["n=10".into()]).unwrap(),
        build("cosine-power", &["n=12".into()]).unwrap(),
    );
    let cfg = RunConfig::default();
    let good = run(&drawn, &cfg);
    assert!(good.chi2.passed, "{}", good.chi2.summary());
    let bad = test_samples(&judge, &chi2_config(&judge, &cfg), &good.samples, cfg.count);
    eprintln!("n = 10 vs 12: {}", bad.summary());
    assert!(!bad.passed, "harness has no power: {}", bad.summary());
}

#[test]
fn chi2_rejection_exits_non_zero() {
    // At α = 0.999 a correct sampler is rejected unless p ≥ 0.999: the exit status must say so.
    let o = penumbra(&[
        "sphere",
        "-n",
        "5000",
        "--no-plots",
        "--significance",
        "0.999",
    ]);
    let (stdout, stderr) = text(&o);
    let pval: f64 = printed(&stdout, "p-value").parse().unwrap();
    assert!(pval < 0.999, "choose another seed: p = {pval}");
    assert_eq!(o.status.code(), Some(1), "{stdout}\n{stderr}");
    assert!(stderr.contains("rejected"), "{stderr}");
}

// ---------------------------------------------------------------- bad input

#[test]
fn bad_params_fail_cleanly() {
    let dir = scratch("bad");
    let wrong_cols = dir.join("two.txt");
    std::fs::write(&wrong_cols, "0.1 0.2\n0.3 0.4\n").unwrap();
    let ragged = dir.join("ragged.txt");
    std::fs::write(&ragged, "0 0 1\n0 1\n").unwrap();
    let garbage = dir.join("garbage.npy");
    std::fs::write(&garbage, b"not numpy").unwrap();
    let w = wrong_cols.to_str().unwrap();
    let r = ragged.to_str().unwrap();
    let g = garbage.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["cosine-power", "-p", "n=-1"], "n=\"-1\""),
        (vec!["cosine-power", "-p", "n=abc"], "n=\"abc\""),
        (vec!["cosine-power", "-p", "n=inf"], "finite"),
        (vec!["cosine-power", "-p", "n"], "KEY=VALUE"),
        (vec!["cosine-power", "-p", "m=2"], "no parameter \"m\""),
        (vec!["sphere", "-p", "n=2"], "takes no parameters"),
        (vec!["no-such-warp"], "unknown routine"),
        (
            vec!["triangle", "-p", "a=0,0", "-p", "b=1,1", "-p", "c=2,2"],
            "degenerate",
        ),
        (vec!["triangle", "-p", "a=0,0,0"], "expected 2"),
        (
            vec!["spherical-triangle", "-p", "a=1,0,0", "-p", "b=2,0,0"],
            "degenerate",
        ),
        (
            vec!["spherical-rectangle", "-p", "ex=1,0,0", "-p", "ey=1,1,0"],
            "degenerate",
        ),
        (vec!["cone", "-p", "angle=0"], "angle"),
        (vec!["cone", "-p", "angle=200"], "angle"),
        (vec!["phong", "-p", "kd=0.7", "-p", "ks=0.6"], "exceeds 1"),
        (vec!["phong", "-p", "n=-3"], "exponent"),
        (vec!["phong", "-p", "theta=95"], "theta"),
        (vec!["phong", "-p", "wo=0,0,-1"], "wo"),
        (vec!["ggx", "-p", "alpha=-0.1"], "alpha"),
        (vec!["ggx", "-p", "sampling=best"], "sampling"),
        (vec!["coated-diffuse", "-p", "eta=0.5"], "eta"),
        (
            vec!["piecewise-2d", "-p", "image=/no/such/file.png"],
            "image",
        ),
        (vec!["cosine-hemisphere", "-n", "0"], "count"),
        (
            vec!["cosine-hemisphere", "--significance", "2"],
            "significance",
        ),
        (vec!["cosine-hemisphere", "--pattern", "halton"], "halton"),
        (vec!["cosine-hemisphere", "--pdf-at", w], "coordinates"),
        (vec!["cosine-hemisphere", "--pdf-at", r], "line 2"),
        (vec!["cosine-hemisphere", "--pdf-at", g], "npy"),
        (
            vec!["cosine-hemisphere", "--pdf-at", "/no/such/points.txt"],
            "points.txt",
        ),
    ];
    for (args, needle) in cases {
        let mut a = args.clone();
        a.push("--no-plots");
        let o = penumbra(&a);
        let (stdout, stderr) = text(&o);
        assert!(!o.status.success(), "{args:?} succeeded:\n{stdout}");
        assert!(!stderr.contains("panicked"), "{args:?} panicked:\n{stderr}");
        assert!(
            matches!(o.status.code(), Some(1) | Some(2)),
            "{args:?}: exit {:?}\n{stderr}",
            o.status.code()
        );
        assert!(
            stderr.contains(needle),
            "{args:?}: {needle:?} not in:\n{stderr}"
        );
    }
}

// ---------------------------------------------------------------- every routine

#[test]
fn chi2_every_listed_routine_passes_with_defaults() {
    let o = penumbra(&["--list"]);
    assert!(o.status.success());
    let (list, _) = text(&o);
    // Šidák: the family of routines at an overall 1%.
    let alpha = sidak_alpha(0.01, ROUTINES.len());
    for r in ROUTINES {
        assert!(list.contains(r.name), "--list misses {}", r.name);
        for p in r.params {
            assert!(list.contains(p.key), "--list misses {}.{}", r.name, p.key);
        }
        let warp = r.build(&[]).unwrap_or_else(|e| panic!("{}: {e:#}", r.name));
        let cfg = RunConfig {
            count: 20_000,
            ..Default::default()
        };
        let res = run(&warp, &cfg);
        eprintln!("{}: {}", r.name, res.chi2.summary());
        assert!(
            res.chi2.p_value >= alpha,
            "{}: {}",
            r.name,
            res.chi2.summary()
        );
        assert!(res.chi2.dof > 10, "{}: too coarse a test", r.name);
    }
}

#[test]
fn plots_are_written() {
    let dir = scratch("plots");
    let d = dir.to_str().unwrap();
    for routine in ["spherical-rectangle", "piecewise-2d"] {
        let o = penumbra(&[routine, "-n", "5000", "--out", d, "--pattern", "stratified"]);
        assert!(o.status.success(), "{:?}", text(&o));
        for suffix in ["", "_samples", "_histogram", "_pdf", "_difference"] {
            let f = Path::new(d).join(format!("{routine}{suffix}.png"));
            let img = image::open(&f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
            assert!(img.width() > 32 && img.height() > 32, "{}", f.display());
        }
    }
}
