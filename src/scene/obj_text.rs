//! Line numbers for the OBJ loader. `tobj` parses OBJ and MTL files but reports errors without
//! a line, and its meshes do not say where they start; this module finds the lines from the
//! text itself: a failing file is cut at line boundaries and re-parsed by `tobj` until the
//! shortest prefix that fails the same way is found (so the line is exactly where `tobj`
//! stops, whatever its rules), and a one-pass scan maps meshes and MTL statements to lines.
//! MTL text is also made safe for `tobj` here (it panics on `Kd 0.5`, which the MTL format
//! allows).

use std::collections::HashMap;
use std::io::Cursor;

/// Byte ranges of the lines of `bytes` (without the `\n`, nor a `\r` before it).
pub fn lines(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &b) in bytes.iter().enumerate() {
        if b == b'\n' {
            out.push((start, trim_cr(bytes, start, i)));
            start = i + 1;
        }
    }
    if start < bytes.len() {
        out.push((start, trim_cr(bytes, start, bytes.len())));
    }
    out
}

fn trim_cr(bytes: &[u8], start: usize, end: usize) -> usize {
    if end > start && bytes[end - 1] == b'\r' {
        end - 1
    } else {
        end
    }
}

/// Line `line` (1-based) shortened for a message.
pub fn excerpt(bytes: &[u8], ranges: &[(usize, usize)], line: usize) -> String {
    let Some(&(a, b)) = ranges.get(line.wrapping_sub(1)) else {
        return String::new();
    };
    let text = String::from_utf8_lossy(&bytes[a..b]);
    let text = text.trim();
    if text.chars().count() > 60 {
        format!("{}…", text.chars().take(60).collect::<String>())
    } else {
        text.to_string()
    }
}

/// The 1-based line at which `fails` (a parse of a prefix of `bytes`) first fails: the
/// shortest prefix of whole lines that fails, found by bisection (`fails` must fail on the
/// whole text). Parse errors are monotone in the prefix, so this is exactly the line the
/// parser stopped at; `None` if no proper prefix fails (the failure needs the whole file).
pub fn first_failing_line(
    bytes: &[u8],
    ranges: &[(usize, usize)],
    fails: impl Fn(&[u8]) -> bool,
) -> Option<usize> {
    let end_of = |k: usize| -> usize {
        // Include the line's terminator so the parser sees the same line.
        let e = ranges[k - 1].1;
        bytes[e..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| e + i + 1)
    };
    let (mut lo, mut hi) = (1usize, ranges.len());
    if hi == 0 || !fails(&bytes[..end_of(hi)]) {
        return None;
    }
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if fails(&bytes[..end_of(mid)]) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    Some(lo)
}

/// The line of the first face of each mesh `tobj` returns, in its order, by the rules it
/// splits meshes with: an `o`/`g` line ends a mesh that has faces, so does a `usemtl` that
/// changes the material, and the end of the file ends the last one (even without faces).
/// `materials` are the loaded material names in `tobj`'s order. `None` where a mesh has no
/// face line.
pub fn mesh_first_lines(
    bytes: &[u8],
    ranges: &[(usize, usize)],
    materials: &[String],
) -> Vec<Option<usize>> {
    let ids: HashMap<&str, usize> = materials
        .iter()
        .enumerate()
        .map(|(i, n)| (n.as_str(), i))
        .collect();
    let mut out = Vec::new();
    let mut first: Option<usize> = None;
    let mut current: Option<usize> = None;
    for (k, &(a, b)) in ranges.iter().enumerate() {
        let Ok(line) = std::str::from_utf8(&bytes[a..b]) else {
            continue;
        };
        let mut words = line.split_whitespace();
        match words.next() {
            Some("f") | Some("l") => {
                first.get_or_insert(k + 1);
            }
            Some("o") | Some("g") if first.is_some() => out.push(first.take()),
            Some("usemtl") => {
                let name = line.split_once(' ').map_or("", |(_, n)| n).trim();
                if !name.is_empty() {
                    let id = ids.get(name).copied();
                    if id != current && first.is_some() {
                        out.push(first.take());
                    }
                    current = id;
                }
            }
            _ => {}
        }
    }
    out.push(first);
    out
}

/// Number of lines before line `line` (1-based) whose first word is `key` (`v`, `vt`, `vn`).
pub fn count_before(bytes: &[u8], ranges: &[(usize, usize)], line: usize, key: &str) -> usize {
    ranges[..line.saturating_sub(1).min(ranges.len())]
        .iter()
        .filter(|&&(a, b)| {
            std::str::from_utf8(&bytes[a..b])
                .ok()
                .and_then(|l| l.split_whitespace().next())
                == Some(key)
        })
        .count()
}

/// An MTL library as read: the text handed to `tobj` and where each material's colours are.
pub struct MtlText {
    /// File name for messages.
    pub file: String,
    /// The text `tobj` parses (same lines as the file, some rewritten).
    pub bytes: Vec<u8>,
    /// (material, statement) → 1-based line, e.g. ("lamp", "Ke") → 7.
    pub lines: HashMap<(String, String), usize>,
    /// What was rewritten, `file:line: …` each.
    pub warnings: Vec<String>,
}

/// Colour statements `tobj` reads as three numbers.
const COLOURS: [&str; 4] = ["Ka", "Kd", "Ks", "Ke"];

/// Read MTL text: record each material's colour and dissolve (`d`, `map_d`) lines, and rewrite what `tobj` cannot take:
/// `Kd 0.5` (one value means grey, per the MTL format) becomes `Kd 0.5 0.5 0.5`; colours given
/// as `spectral` or `xyz`, which are not supported, are dropped with a warning.
pub fn read_mtl(file: &str, raw: &[u8]) -> MtlText {
    let text = String::from_utf8_lossy(raw);
    let mut out = String::with_capacity(text.len() + 16);
    let mut lines = HashMap::new();
    let mut warnings = Vec::new();
    let mut material = String::new();
    for (k, line) in text.split('\n').enumerate() {
        let n = k + 1;
        if k > 0 {
            out.push('\n');
        }
        let trimmed = line.trim();
        let mut words = trimmed.split_whitespace();
        let key = words.next().unwrap_or("");
        if key == "newmtl" {
            material = trimmed[6..].trim().to_string();
        } else if key == "d" || key == "map_d" {
            lines.insert((material.clone(), key.to_string()), n);
        } else if COLOURS.contains(&key) {
            lines.insert((material.clone(), key.to_string()), n);
            let values: Vec<&str> = words.collect();
            match values.as_slice() {
                [first, ..] if *first == "spectral" || *first == "xyz" => {
                    warnings.push(format!(
                        "{file}:{n}: material '{material}': {key} {first} is not supported; ignored"
                    ));
                    continue;
                }
                [v] => {
                    out.push_str(&format!("{key} {v} {v} {v}"));
                    continue;
                }
                [_, _] => {
                    warnings.push(format!(
                        "{file}:{n}: material '{material}': {key} needs 1 or 3 values, found 2; ignored"
                    ));
                    continue;
                }
                [] => {
                    warnings.push(format!(
                        "{file}:{n}: material '{material}': {key} without values; ignored"
                    ));
                    continue;
                }
                _ => {}
            }
        }
        out.push_str(line);
    }
    MtlText {
        file: file.to_string(),
        bytes: out.into_bytes(),
        lines,
        warnings,
    }
}

/// Whether `tobj` fails on this MTL text.
pub fn mtl_fails(bytes: &[u8]) -> bool {
    tobj::load_mtl_buf(&mut Cursor::new(bytes)).is_err()
}
