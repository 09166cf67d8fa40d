//! How errors and warnings reach the terminal: each said once.
//!
//! Context added at several layers (a loader, a reader, the crate underneath) can repeat a
//! prefix ("writing X: writing X: …", "invalid glTF: invalid glTF: …") or an OS error that one
//! layer prints inside its message and also returns as its cause. Consecutive repeats of a
//! `: `-separated part are dropped here, whatever layer produced them.

/// The error and its causes on one line, `a: b: c`, without consecutive repeated parts.
pub fn format_error(e: &anyhow::Error) -> String {
    let joined = e
        .chain()
        .map(|c| c.to_string())
        .collect::<Vec<_>>()
        .join(": ");
    dedup_parts(&joined)
}

/// `text` without consecutive repeated `: `-separated parts (a trailing `:` counts as one).
pub fn dedup_parts(text: &str) -> String {
    let mut parts: Vec<&str> = Vec::new();
    for part in text.split(": ") {
        let key = part.trim_end_matches(':').trim();
        if parts
            .last()
            .is_some_and(|p| p.trim_end_matches(':').trim() == key && !key.is_empty())
        {
            continue;
        }
        parts.push(part);
    }
    parts.join(": ")
}

/// A loader warning as printed: `warning: …`, or the loader's own `file:line: warning: …`.
pub fn format_warning(w: &str) -> String {
    let w = dedup_parts(w);
    if w.starts_with("warning: ") || w.contains(": warning: ") {
        w
    } else {
        format!("warning: {w}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeated_prefixes_and_causes_are_said_once() {
        assert_eq!(
            dedup_parts("writing x.png: writing x.png: No such file or directory (os error 2)"),
            "writing x.png: No such file or directory (os error 2)"
        );
        assert_eq!(
            dedup_parts("a.gltf: invalid glTF: invalid glTF: meshes[0]: index out of range;"),
            "a.gltf: invalid glTF: meshes[0]: index out of range;"
        );
        assert_eq!(
            dedup_parts("reading m.exr: No such file (os error 2): No such file (os error 2)"),
            "reading m.exr: No such file (os error 2)"
        );
        assert_eq!(dedup_parts("a: b: a"), "a: b: a");
        let e = anyhow::anyhow!("No such file")
            .context("writing x")
            .context("writing x");
        assert_eq!(format_error(&e), "writing x: No such file");
    }

    #[test]
    fn warnings_get_one_prefix() {
        assert_eq!(
            format_warning("s.pbrt:1: warning: thing"),
            "s.pbrt:1: warning: thing"
        );
        assert_eq!(
            format_warning("s.pbrt:1: warning: warning: thing"),
            "s.pbrt:1: warning: thing"
        );
        assert_eq!(format_warning("m.obj: no mtl"), "warning: m.obj: no mtl");
    }
}
