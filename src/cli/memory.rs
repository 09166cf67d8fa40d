//! How much memory a render needs and how much the machine can give, checked before the
//! render starts so that too large a film is a clear error instead of an allocation abort.
//!
//! The scene (meshes, BVHs, textures) is resident once it is loaded, so what is compared with
//! the available memory is what the render adds: the film and the per-thread state.

use glam::UVec2;
use std::path::Path;

/// Film bytes per pixel at the render's peak: the finished 16×16 tiles (12 B per RGB pixel plus
/// the allocator's header per tile) and the assembled image (12 B) are alive together. Writing
/// needs less (the image plus an encoded copy of at most 12 B per pixel). Measured: 24.3 B per
/// pixel of peak RSS at 3000×3000 for .png, .exr and .pfm.
pub const FILM_BYTES_PER_PIXEL: u64 = 25;

/// Per worker thread: sample pools, packet scratch and the stack.
pub const THREAD_BYTES: u64 = 4 << 20;

/// Per light: the light-selection tables (the 8-wide light BVH: about 158 B per light; alias tables).
pub const LIGHT_BYTES: u64 = 192;

/// The memory a render adds to the loaded scene.
#[derive(Clone, Copy, Debug)]
pub struct Need {
    /// Resolution.
    pub res: UVec2,
    /// Film bytes.
    pub film: u64,
    /// Worker threads.
    pub threads: usize,
    /// Bytes for all threads' state and the light tables.
    pub other: u64,
}

impl Need {
    /// Estimate for `res` with `threads` workers and `lights` lights.
    pub fn new(res: UVec2, threads: usize, lights: usize) -> Need {
        Need {
            res,
            film: res.x as u64 * res.y as u64 * FILM_BYTES_PER_PIXEL,
            threads,
            other: threads as u64 * THREAD_BYTES + lights as u64 * LIGHT_BYTES,
        }
    }

    /// Total bytes.
    pub fn total(&self) -> u64 {
        self.film + self.other
    }
}

/// Memory the process may still take, and which limit says so.
#[derive(Clone, Debug)]
pub struct Available {
    /// Bytes.
    pub bytes: u64,
    /// Where the number comes from.
    pub source: String,
}

/// The tightest of the limits we can read: the kernel's MemAvailable, the memory cgroup's
/// limit less its usage (v2 and v1), and the address-space limit (`ulimit -v`) less this
/// process's size. `None` where none can be read (not Linux).
pub fn available() -> Option<Available> {
    let mut best: Option<Available> = None;
    let mut offer = |bytes: u64, source: String| {
        if best.as_ref().is_none_or(|b| bytes < b.bytes) {
            best = Some(Available { bytes, source });
        }
    };
    if let Some(kb) = read_kb_field("/proc/meminfo", "MemAvailable:") {
        offer(kb * 1024, "MemAvailable in /proc/meminfo".into());
    }
    for (limit, usage) in cgroup_files() {
        if let (Some(l), Some(u)) = (read_u64(&limit), read_u64(&usage)) {
            // v1 reports "no limit" as a huge number; it then loses to MemAvailable.
            offer(
                l.saturating_sub(u),
                format!("the memory cgroup's limit, {}", limit.display()),
            );
            break;
        }
    }
    if let (Some(limit), Some(size_kb)) = (
        address_space_limit(),
        read_kb_field("/proc/self/status", "VmSize:"),
    ) {
        offer(
            limit.saturating_sub(size_kb * 1024),
            "the address-space limit (ulimit -v)".into(),
        );
    }
    best
}

/// Peak resident set size of this process (VmHWM), in bytes.
pub fn peak_resident() -> Option<u64> {
    read_kb_field("/proc/self/status", "VmHWM:").map(|kb| kb * 1024)
}

/// Fail with the estimate and the limit when `need` exceeds what is available.
pub fn check(need: &Need, available: Option<&Available>) -> anyhow::Result<()> {
    let Some(avail) = available else {
        return Ok(());
    };
    if need.total() <= avail.bytes {
        return Ok(());
    }
    anyhow::bail!(
        "not enough memory for a {}x{} render: it needs about {} (film {} at {} B per pixel, \
         {} thread(s) and light tables {}) but only {} is available ({}); lower --res",
        need.res.x,
        need.res.y,
        human(need.total()),
        human(need.film),
        FILM_BYTES_PER_PIXEL,
        need.threads,
        human(need.other),
        human(avail.bytes),
        avail.source
    )
}

/// Bytes as "12.3 GB" / "45 MB" (powers of 1000, as `free -h` users read them loosely).
pub fn human(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else {
        format!("{:.0} MB", (b / 1e6).ceil())
    }
}

/// The `KEY: N kB` field of a /proc file, in kB.
fn read_kb_field(file: &str, key: &str) -> Option<u64> {
    let text = std::fs::read_to_string(file).ok()?;
    let line = text.lines().find(|l| l.starts_with(key))?;
    line[key.len()..].split_whitespace().next()?.parse().ok()
}

/// A file holding one number ("max" and unparsable values give `None`).
fn read_u64(path: &Path) -> Option<u64> {
    std::fs::read_to_string(path).ok()?.trim().parse().ok()
}

/// Candidate (limit, usage) files of this process's memory cgroup, v2 then v1, at the path
/// /proc/self/cgroup names and at the mount's root (inside a container's namespace).
fn cgroup_files() -> Vec<(std::path::PathBuf, std::path::PathBuf)> {
    let root = Path::new("/sys/fs/cgroup");
    let mut out = Vec::new();
    let text = std::fs::read_to_string("/proc/self/cgroup").unwrap_or_default();
    for line in text.lines() {
        let mut parts = line.splitn(3, ':');
        let (_, controllers, path) = match (parts.next(), parts.next(), parts.next()) {
            (Some(a), Some(b), Some(c)) => (a, b, c.trim_start_matches('/')),
            _ => continue,
        };
        if controllers.is_empty() {
            out.push((
                root.join(path).join("memory.max"),
                root.join(path).join("memory.current"),
            ));
        } else if controllers.split(',').any(|c| c == "memory") {
            let dir = root.join("memory");
            out.push((
                dir.join(path).join("memory.limit_in_bytes"),
                dir.join(path).join("memory.usage_in_bytes"),
            ));
            out.push((
                dir.join("memory.limit_in_bytes"),
                dir.join("memory.usage_in_bytes"),
            ));
        }
    }
    out.push((root.join("memory.max"), root.join("memory.current")));
    out
}

/// The soft address-space limit of this process in bytes, `None` when unlimited.
fn address_space_limit() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = text.lines().find(|l| l.starts_with("Max address space"))?;
    line["Max address space".len()..]
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_film_estimate_scales_with_pixels_and_names_the_limit() {
        let need = Need::new(UVec2::new(20000, 20000), 2, 0);
        assert_eq!(need.film, 20000 * 20000 * FILM_BYTES_PER_PIXEL);
        let avail = Available {
            bytes: 4_000_000_000,
            source: "test".into(),
        };
        let err = check(&need, Some(&avail)).unwrap_err().to_string();
        assert!(err.contains("10.0 GB") && err.contains("4.0 GB") && err.contains("test"));
        let small = Need::new(UVec2::new(512, 512), 2, 10);
        assert!(check(&small, Some(&avail)).is_ok());
        assert!(check(&need, None).is_ok());
    }

    #[test]
    fn linux_reports_some_available_memory() {
        if Path::new("/proc/meminfo").exists() {
            let a = available().expect("MemAvailable");
            assert!(a.bytes > 0, "{a:?}");
        }
    }
}
