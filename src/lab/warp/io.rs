//! Sample and pdf tables on disk: whitespace-separated text (one row per line) or NumPy `.npy`
//! (format v1.0, little-endian `<f4` / `<f8`, C order), chosen by the file extension.
//!
//! Text is written with Rust's shortest round-trip formatting, so a value read back with the
//! same precision is bit-identical to the one written.

use anyhow::{Context, bail};
use std::fmt::Display;
use std::path::Path;
use std::str::FromStr;

use crate::image::io::write_bytes_atomic;

/// A scalar type a table can hold (f32 for samples, f64 for densities).
pub trait Scalar: Copy + Display + FromStr {
    /// The NumPy `descr` of this type.
    const DESCR: &'static str;
    /// Append the little-endian bytes.
    fn put(self, out: &mut Vec<u8>);
    /// From an f32 stored in a file.
    fn from_f32(x: f32) -> Self;
    /// From an f64 stored in a file (f32 rounds to nearest).
    fn from_f64(x: f64) -> Self;
}

impl Scalar for f32 {
    const DESCR: &'static str = "<f4";
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
    fn from_f32(x: f32) -> Self {
        x
    }
    fn from_f64(x: f64) -> Self {
        x as f32
    }
}

impl Scalar for f64 {
    const DESCR: &'static str = "<f8";
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
    fn from_f32(x: f32) -> Self {
        x as f64
    }
    fn from_f64(x: f64) -> Self {
        x
    }
}

/// A row-major table of `cols` columns.
#[derive(Clone, Debug, PartialEq)]
pub struct Table<T> {
    /// Values per row.
    pub cols: usize,
    /// `rows × cols` values, row-major.
    pub values: Vec<T>,
}

impl<T: Copy> Table<T> {
    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.values.len().checked_div(self.cols).unwrap_or(0)
    }

    /// Row `i`.
    pub fn row(&self, i: usize) -> &[T] {
        &self.values[i * self.cols..(i + 1) * self.cols]
    }
}

/// Whether `path` selects the NumPy format.
fn is_npy(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"))
}

/// Write `table` to `path` (text or `.npy`), creating missing parent directories; a
/// one-column table becomes a 1-D array.
pub fn write_table<T: Scalar>(path: &Path, table: &Table<T>) -> anyhow::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let bytes = if is_npy(path) {
        npy_bytes(table)
    } else {
        let mut s = String::with_capacity(table.values.len() * 12);
        for i in 0..table.rows() {
            let row: Vec<String> = table.row(i).iter().map(|v| v.to_string()).collect();
            s.push_str(&row.join(" "));
            s.push('\n');
        }
        s.into_bytes()
    };
    write_bytes_atomic(path, &bytes)
}

/// The `.npy` v1.0 encoding: magic, version, header length, a Python-dict header padded with
/// spaces to a multiple of 64 bytes (NumPy's alignment), then the raw little-endian data.
pub fn npy_bytes<T: Scalar>(table: &Table<T>) -> Vec<u8> {
    let shape = if table.cols == 1 {
        format!("({},)", table.rows())
    } else {
        format!("({}, {})", table.rows(), table.cols)
    };
    let mut header = format!(
        "{{'descr': '{}', 'fortran_order': False, 'shape': {shape}, }}",
        T::DESCR
    );
    let unpadded = 10 + header.len() + 1;
    header.push_str(&" ".repeat(unpadded.next_multiple_of(64) - unpadded));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + table.values.len() * 8);
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for &v in &table.values {
        v.put(&mut out);
    }
    out
}

/// Read a table from `path` (text or `.npy`). Text: numbers separated by spaces, tabs or
/// commas, blank lines and `#` comments skipped, every row the same length.
pub fn read_table<T: Scalar>(path: &Path) -> anyhow::Result<Table<T>> {
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    if is_npy(path) {
        parse_npy(&bytes).with_context(|| format!("{}: not a valid .npy table", path.display()))
    } else {
        let text = String::from_utf8(bytes)
            .with_context(|| format!("{}: not UTF-8 text", path.display()))?;
        parse_text(&text).with_context(|| format!("reading {}", path.display()))
    }
}

/// Parse the text format.
pub fn parse_text<T: Scalar>(text: &str) -> anyhow::Result<Table<T>> {
    let mut cols = 0;
    let mut values = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let row: Vec<T> = line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|t| !t.is_empty())
            .map(|t| {
                t.parse::<T>()
                    .map_err(|_| anyhow::anyhow!("line {}: cannot parse {t:?} as a number", n + 1))
            })
            .collect::<anyhow::Result<_>>()?;
        if cols == 0 {
            cols = row.len();
        } else if row.len() != cols {
            bail!(
                "line {}: {} values, but earlier rows have {cols}",
                n + 1,
                row.len()
            );
        }
        values.extend(row);
    }
    Ok(Table {
        cols: cols.max(1),
        values,
    })
}

/// Parse a `.npy` file of `<f4` or `<f8` values, 1-D or 2-D, C order.
pub fn parse_npy<T: Scalar>(bytes: &[u8]) -> anyhow::Result<Table<T>> {
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        bail!("missing the \\x93NUMPY magic");
    }
    let (header_len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => bail!("unsupported .npy version {v}"),
    };
    let header = bytes
        .get(start..start + header_len)
        .context("header runs past the end of the file")?;
    let header = std::str::from_utf8(header).context("header is not text")?;
    let field = |key: &str| -> anyhow::Result<&str> {
        let at = header
            .find(&format!("'{key}'"))
            .with_context(|| format!("header has no '{key}'"))?;
        let rest = &header[at + key.len() + 2..];
        Ok(rest.trim_start().trim_start_matches(':').trim_start())
    };
    let descr = field("descr")?;
    let size = if descr.starts_with("'<f4'") {
        4
    } else if descr.starts_with("'<f8'") {
        8
    } else {
        bail!(
            "dtype {:?} is not <f4 or <f8",
            descr.split(',').next().unwrap_or("")
        );
    };
    if !field("fortran_order")?.starts_with("False") {
        bail!("Fortran-ordered arrays are not supported");
    }
    let shape = field("shape")?;
    let inner = shape
        .strip_prefix('(')
        .and_then(|s| s.split(')').next())
        .context("malformed shape")?;
    let dims: Vec<usize> = inner
        .split(',')
        .map(str::trim)
        .filter(|t| !t.is_empty())
        .map(|t| t.parse::<usize>().context("malformed shape"))
        .collect::<anyhow::Result<_>>()?;
    let (rows, cols) = match dims[..] {
        [n] => (n, 1),
        [n, c] => (n, c),
        _ => bail!("shape {shape:?} is not 1-D or 2-D"),
    };
    let count = rows.checked_mul(cols).context("shape overflows")?;
    let data = &bytes[start + header_len..];
    if data.len() != count * size {
        bail!(
            "{} data bytes for shape ({rows}, {cols}) of {size}-byte values",
            data.len()
        );
    }
    let values = if size == 4 {
        data.chunks_exact(4)
            .map(|c| T::from_f32(f32::from_le_bytes(std::array::from_fn(|i| c[i]))))
            .collect()
    } else {
        data.chunks_exact(8)
            .map(|c| T::from_f64(f64::from_le_bytes(std::array::from_fn(|i| c[i]))))
            .collect()
    };
    Ok(Table {
        cols: cols.max(1),
        values,
    })
}
