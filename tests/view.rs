//! `penumbra view` over HTTP (issue 21): every endpoint, bad requests answered 400 with the
//! reason, the server bound to loopback, and the image it serves equal to the CLI's render.

mod view_support;

use std::time::Duration;
use view_support::{get, png, post, scratch, start_viewer, wait_state};

const LIMIT: Duration = Duration::from_secs(60);

#[test]
fn endpoints_answer_and_bad_requests_are_400_with_a_reason() {
    let dir = scratch("endpoints");
    let v = start_viewer(&dir, &["cornell", "--res", "40x30", "--spp", "100000"]);
    assert!(v.addr.starts_with("127.0.0.1:"), "{}", v.addr);

    // Bound to loopback: the listening socket's local address is 127.0.0.1 (/proc/net/tcp
    // writes it as little-endian hex 0100007F).
    let port: u16 = v.addr.rsplit(':').next().unwrap().parse().unwrap();
    let tcp = std::fs::read_to_string("/proc/net/tcp").unwrap();
    let listen = tcp
        .lines()
        .filter_map(|l| {
            l.split_whitespace()
                .nth(1)
                .map(|a| (a.to_string(), l.split_whitespace().nth(3) == Some("0A")))
        })
        .find(|(a, listening)| *listening && a.ends_with(&format!(":{port:04X}")))
        .unwrap_or_else(|| panic!("port {port} not listening in /proc/net/tcp"));
    assert_eq!(listen.0, format!("0100007F:{port:04X}"));

    let page = get(&v.addr, "/");
    assert_eq!(page.status, 200);
    assert!(page.content_type.starts_with("text/html"));
    assert!(page.text().contains("penumbra view") && page.text().contains("/api/state"));

    // The sample count rises pass after pass.
    let count = |s: &serde_json::Value| s["channels"]["a"]["samples"].as_u64().unwrap();
    let s1 = wait_state(&v.addr, LIMIT, "a first pass", |s| count(s) > 0);
    let s2 = wait_state(&v.addr, LIMIT, "a second pass", |s| count(s) > count(&s1));
    assert_eq!(
        (s2["width"].as_u64(), s2["height"].as_u64()),
        (Some(40), Some(30))
    );
    let a = &s2["channels"]["a"];
    assert_eq!(a["settings"]["strategy"], "mis");
    assert_eq!(a["settings"]["spp"], 100000);
    assert!(a["mrays_per_s"].as_f64().unwrap() > 0.0);
    assert!(a["eta"].as_f64().unwrap() > 0.0);
    assert!(a["rel_mse"].is_null(), "no reference given");
    assert_eq!(s2["channels"]["b"]["enabled"], false);
    assert_eq!(s2["exposure"], 0.0);
    assert!(s2["choices"]["light_selection"].as_array().unwrap().len() >= 7);

    for view in ["srgb", "false"] {
        let img = png(&get(
            &v.addr,
            &format!("/api/image?ch=a&view={view}&exposure=1.5"),
        ));
        assert_eq!(img.dimensions(), (40, 30));
        assert!(img.pixels().any(|p| p.0 != [0, 0, 0]), "{view} is black");
    }
    // More exposure, brighter picture.
    let sum = |e: &str| -> u64 {
        let img = png(&get(&v.addr, &format!("/api/image?ch=a&exposure={e}")));
        img.pixels()
            .map(|p| p.0.iter().map(|&c| u64::from(c)).sum::<u64>())
            .sum()
    };
    assert!(sum("2") > sum("-2"));

    let px = get(&v.addr, "/api/pixel?ch=a&x=20&y=15");
    assert_eq!(px.status, 200, "{}", px.text());
    let px = px.json();
    assert!(
        px["hit"].is_object(),
        "the centre of the Cornell box sees a surface: {px}"
    );
    assert_eq!(px["light_sampling"], true);
    let value = px["value"].as_array().unwrap();
    assert!(
        value
            .iter()
            .all(|c| c.as_f64().unwrap().is_finite() && c.as_f64().unwrap() >= 0.0)
    );
    // Uniform selection: every light has 1/N, and the pmf sums to one.
    let lights = px["lights"].as_array().unwrap();
    let n = s2["lights"].as_u64().unwrap() as f64;
    assert!(!lights.is_empty());
    for l in lights {
        assert!((l["pmf"].as_f64().unwrap() - 1.0 / n).abs() < 1e-6, "{l}");
    }
    assert!((px["pmf_sum"].as_f64().unwrap() - 1.0).abs() < 1e-5);
    // The lights of the Cornell box are on the ceiling, in the upper part of the image.
    for l in lights {
        let y = l["raster"][1].as_f64().unwrap();
        assert!((0.0..15.0).contains(&y), "{l}");
    }

    // Restart B with another strategy and light selection; A keeps going.
    let r = post(
        &v.addr,
        "/api/render",
        r#"{"channel":"b","strategy":"bsdf","light_selection":"power","spp":64,"integrator":"path","max_depth":2}"#,
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let b = &r.json()["channels"]["b"];
    assert_eq!(b["enabled"], true);
    assert_eq!(b["settings"]["strategy"], "bsdf");
    assert_eq!(b["settings"]["light_selection"], "power");
    assert_eq!(b["settings"]["integrator"], "path");
    assert_eq!(b["settings"]["max_depth"], 2);
    let done = wait_state(&v.addr, LIMIT, "B done", |s| {
        s["channels"]["b"]["done"] == true
    });
    assert_eq!(done["channels"]["b"]["samples"], 64);
    assert_eq!(done["channels"]["b"]["error"], serde_json::Value::Null);
    let px = get(&v.addr, "/api/pixel?ch=b&x=20&y=15").json();
    assert_eq!(px["light_sampling"], false, "bsdf samples no light");
    assert_eq!(px["light_selection"], "power");
    // Restart A: its generation rises and its count starts again.
    let g0 = done["channels"]["a"]["generation"].as_u64().unwrap();
    let r = post(
        &v.addr,
        "/api/render",
        r#"{"channel":"a","pattern":"sobol"}"#,
    )
    .json();
    assert_eq!(r["channels"]["a"]["generation"].as_u64(), Some(g0 + 1));
    assert_eq!(r["channels"]["a"]["settings"]["pattern"], "sobol");
    let r = post(&v.addr, "/api/render", r#"{"channel":"b","enabled":false}"#).json();
    assert_eq!(r["channels"]["b"]["enabled"], false);

    // Bad requests: 400 and a reason that names the problem.
    let bad = [
        ("GET", "/api/image?ch=c", "", "unknown channel 'c'"),
        ("GET", "/api/image?view=nope", "", "unknown view 'nope'"),
        ("GET", "/api/image?exposure=abc", "", "exposure must be"),
        ("GET", "/api/image?view=error", "", "--reference"),
        ("GET", "/api/image?ch=%41", "", "bad query parameter"),
        ("GET", "/api/pixel?x=1", "", "missing query parameter 'y'"),
        (
            "GET",
            "/api/pixel?x=40&y=0",
            "",
            "x must be a whole number in 0..40",
        ),
        ("GET", "/api/pixel?x=-1&y=0", "", "x must be"),
        ("POST", "/api/render", "{", "bad JSON body"),
        (
            "POST",
            "/api/render",
            r#"{"channel":"a","colour":1}"#,
            "unknown field `colour`",
        ),
        (
            "POST",
            "/api/render",
            r#"{"strategy":"mis"}"#,
            "missing field `channel`",
        ),
        (
            "POST",
            "/api/render",
            r#"{"channel":"c"}"#,
            "unknown channel",
        ),
        (
            "POST",
            "/api/render",
            r#"{"channel":"a","strategy":"x"}"#,
            "unknown strategy 'x'",
        ),
        (
            "POST",
            "/api/render",
            r#"{"channel":"a","light_selection":"x"}"#,
            "unknown light selection 'x'",
        ),
        (
            "POST",
            "/api/render",
            r#"{"channel":"a","integrator":"x"}"#,
            "x",
        ),
        (
            "POST",
            "/api/render",
            r#"{"channel":"a","max_depth":0}"#,
            "max_depth must be between 1 and 1024",
        ),
        (
            "POST",
            "/api/render",
            r#"{"channel":"a","pattern":"x"}"#,
            "x",
        ),
        (
            "POST",
            "/api/render",
            r#"{"channel":"a","mis":"x"}"#,
            "unknown MIS heuristic",
        ),
        (
            "POST",
            "/api/render",
            r#"{"channel":"a","bsdf_sampling":"x"}"#,
            "x",
        ),
        (
            "POST",
            "/api/render",
            r#"{"channel":"a","spp":0}"#,
            "spp must be between 1",
        ),
        (
            "POST",
            "/api/render",
            r#"{"channel":"a","spp":-3}"#,
            "bad JSON body",
        ),
        (
            "POST",
            "/api/render",
            r#"{"channel":"a","shadow_rays":0}"#,
            "shadow_rays must be",
        ),
        (
            "POST",
            "/api/render",
            r#"{"channel":"a","enabled":false}"#,
            "cannot be disabled",
        ),
    ];
    for (method, path, body, reason) in bad {
        let r = view_support::http(&v.addr, method, path, body);
        assert_eq!(r.status, 400, "{method} {path} {body}: {}", r.text());
        assert!(
            r.text().contains(reason),
            "{method} {path} {body}: '{}' lacks '{reason}'",
            r.text()
        );
    }
    let r = get(&v.addr, "/nope");
    assert_eq!(r.status, 404);
    assert!(r.text().contains("/nope"));
    let r = post(&v.addr, "/api/state", "");
    assert_eq!(r.status, 405);
    // A bad request changed nothing.
    let s = get(&v.addr, "/api/state").json();
    assert_eq!(s["channels"]["a"]["settings"]["strategy"], "mis");
    assert_eq!(s["channels"]["a"]["settings"]["pattern"], "sobol");
}

/// With `--reference` a render of the same settings, the viewer's finished image is the CLI's
/// to float rounding (relMSE ~ 0), its relMSE falls as samples grow, and the error view works.
#[test]
fn the_viewer_renders_what_the_cli_renders() {
    let dir = scratch("reference");
    let args = ["cornell", "--res", "32x24", "--spp", "64", "--seed", "3"];
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .arg("render")
        .args(args)
        .args(["-q", "-o", "ref.exr"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = start_viewer(&dir, &[&args[..], &["--reference", "ref.exr"]].concat());
    let s = wait_state(&v.addr, LIMIT, "A done", |s| {
        s["channels"]["a"]["done"] == true
    });
    assert_eq!(s["reference"], true);
    let rel = s["channels"]["a"]["rel_mse"].as_f64().unwrap();
    assert!(rel < 1e-9, "viewer vs CLI relMSE {rel}");
    let err = png(&get(&v.addr, "/api/image?ch=a&view=error"));
    assert_eq!(err.dimensions(), (32, 24));
    // Another strategy at few samples is far from the reference, and B's relMSE says so.
    let r = post(
        &v.addr,
        "/api/render",
        r#"{"channel":"b","strategy":"light-area","spp":2}"#,
    );
    assert_eq!(r.status, 200, "{}", r.text());
    let s = wait_state(&v.addr, LIMIT, "B done", |s| {
        s["channels"]["b"]["done"] == true
    });
    let rel_b = s["channels"]["b"]["rel_mse"].as_f64().unwrap();
    assert!(
        rel_b > 1e-4,
        "2 spp of light-area vs 64 spp of mis: relMSE {rel_b}"
    );
}

#[test]
fn a_reference_of_another_size_is_refused() {
    let dir = scratch("bad-reference");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args([
            "render", "cornell", "-q", "--res", "8x8", "--spp", "1", "-o", "r.exr",
        ])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(out.status.success());
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args([
            "view",
            "cornell",
            "--res",
            "16x8",
            "--reference",
            "r.exr",
            "--port",
            "0",
        ])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("r.exr") && e.contains("8x8") && e.contains("16x8"),
        "{e}"
    );
}
