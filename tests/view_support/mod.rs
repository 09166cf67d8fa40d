//! Shared by the viewer's tests: start `penumbra view` on a free loopback port and speak
//! plain HTTP/1.1 to it (and to chromedriver) over a `TcpStream`: the tests' client needs no
//! crate of its own.

#![allow(dead_code)]

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A running `penumbra view`, killed when dropped.
pub struct Viewer {
    /// `127.0.0.1:PORT`.
    pub addr: String,
    child: Child,
}

impl Drop for Viewer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Start `penumbra view ARGS --port 0` in `dir` and read the address it prints.
pub fn start_viewer(dir: &Path, args: &[&str]) -> Viewer {
    let mut child = Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .arg("view")
        .args(args)
        .args(["--port", "0"])
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let addr = line
        .split("http://")
        .nth(1)
        .and_then(|s| s.split('/').next())
        .unwrap_or_else(|| panic!("no address in '{line}'"))
        .to_string();
    Viewer { addr, child }
}

/// A response: status, content type, body.
pub struct Response {
    pub status: u16,
    pub content_type: String,
    pub body: Vec<u8>,
}

impl Response {
    pub fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("not JSON ({e}): {}", self.text()))
    }
}

/// One request on a fresh connection; the body is read by its Content-Length.
pub fn http(addr: &str, method: &str, path: &str, body: &str) -> Response {
    let mut s = TcpStream::connect(addr).unwrap_or_else(|e| panic!("connect {addr}: {e}"));
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\
         Content-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    )
    .unwrap();
    let mut r = BufReader::new(s);
    let mut status_line = String::new();
    r.read_line(&mut status_line).unwrap();
    let status: u16 = status_line
        .split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or_else(|| panic!("bad status line '{status_line}'"));
    let (mut len, mut content_type, mut chunked) = (None, String::new(), false);
    loop {
        let mut h = String::new();
        r.read_line(&mut h).unwrap();
        let h = h.trim_end();
        if h.is_empty() {
            break;
        }
        let (k, v) = h.split_once(':').unwrap_or((h, ""));
        match k.to_ascii_lowercase().as_str() {
            "content-length" => len = v.trim().parse::<usize>().ok(),
            "content-type" => content_type = v.trim().to_string(),
            "transfer-encoding" => chunked = v.trim().eq_ignore_ascii_case("chunked"),
            _ => {}
        }
    }
    let mut body = Vec::new();
    if chunked {
        loop {
            let mut size = String::new();
            r.read_line(&mut size).unwrap();
            let n = usize::from_str_radix(size.trim(), 16).unwrap();
            let mut chunk = vec![0; n + 2];
            r.read_exact(&mut chunk).unwrap();
            if n == 0 {
                break;
            }
            body.extend_from_slice(&chunk[..n]);
        }
    } else if let Some(n) = len {
        body.resize(n, 0);
        r.read_exact(&mut body).unwrap();
    } else {
        r.read_to_end(&mut body).unwrap();
    }
    Response {
        status,
        content_type,
        body,
    }
}

pub fn get(addr: &str, path: &str) -> Response {
    http(addr, "GET", path, "")
}

pub fn post(addr: &str, path: &str, body: &str) -> Response {
    http(addr, "POST", path, body)
}

/// Poll `/api/state` until `pred` holds (panics after `limit`).
pub fn wait_state(
    addr: &str,
    limit: Duration,
    what: &str,
    mut pred: impl FnMut(&serde_json::Value) -> bool,
) -> serde_json::Value {
    let start = Instant::now();
    loop {
        let s = get(addr, "/api/state").json();
        if pred(&s) {
            return s;
        }
        assert!(
            start.elapsed() < limit,
            "waited {limit:?} for {what}; state {s}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A fresh scratch folder per test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("penumbra-view-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Decode a PNG body.
pub fn png(r: &Response) -> image::RgbImage {
    assert_eq!(r.status, 200, "{}", r.text());
    assert_eq!(r.content_type, "image/png");
    image::load_from_memory(&r.body).unwrap().to_rgb8()
}
