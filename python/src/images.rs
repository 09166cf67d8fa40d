//! Image files, the CLI's error metrics, and merging sample-range parts.

use std::path::Path;

use numpy::{PyArray3, PyReadonlyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use penumbra::Rgb;
use penumbra::image::Image;
use penumbra::image::io::WriteControl;
use penumbra::image::metrics::comparison_warnings;
use penumbra::image::parts::{Part, PartInfo, merge, read_part, write_part};

use crate::errors::{Kind, not_found, to_py, warn_all};
use crate::render::to_array;

/// Add the image functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_image, m)?)?;
    m.add_function(wrap_pyfunction!(write_image, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(merge_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(merge_files, m)?)?;
    Ok(())
}

/// A float32 H×W×3 array as an image.
pub fn from_array(a: &PyReadonlyArray3<'_, f32>) -> PyResult<Image> {
    let v = a.as_array();
    let (h, w, c) = v.dim();
    if c != 3 {
        return Err(PyValueError::new_err(format!(
            "expected an H×W×3 array, got shape ({h}, {w}, {c})"
        )));
    }
    let (width, height) = (u32::try_from(w), u32::try_from(h));
    let (Ok(width), Ok(height)) = (width, height) else {
        return Err(PyValueError::new_err("image too large"));
    };
    Ok(Image::from_fn(width, height, |x, y| {
        let (x, y) = (x as usize, y as usize);
        Rgb::new(v[[y, x, 0]], v[[y, x, 1]], v[[y, x, 2]])
    }))
}

/// Fail with `FileNotFoundError` naming `path` when it does not exist.
fn must_exist(path: &str) -> PyResult<()> {
    if Path::new(path).exists() {
        Ok(())
    } else {
        Err(not_found("No such file or directory", path))
    }
}

/// Read an image file as linear RGB.
#[pyfunction]
fn read_image<'py>(py: Python<'py>, path: &str) -> PyResult<Bound<'py, PyArray3<f32>>> {
    must_exist(path)?;
    let img = penumbra::image::read_image(Path::new(path)).map_err(|e| to_py(e, Kind::Value))?;
    to_array(py, &img)
}

/// Write an image file (atomically); the extension picks the format.
#[pyfunction]
#[pyo3(signature = (path, array, exposure=0.0))]
fn write_image(path: &str, array: PyReadonlyArray3<'_, f32>, exposure: f32) -> PyResult<()> {
    let img = from_array(&array)?;
    penumbra::image::write_image(&img, Path::new(path), exposure).map_err(|e| to_py(e, Kind::Value))
}

/// MSE, relMSE and MAE of `test` against `reference`; names are used in warnings.
#[pyfunction]
fn compare<'py>(
    py: Python<'py>,
    test: PyReadonlyArray3<'_, f32>,
    reference: PyReadonlyArray3<'_, f32>,
    test_name: &str,
    reference_name: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let (t, r) = (from_array(&test)?, from_array(&reference)?);
    let warnings = comparison_warnings((&t, Path::new(test_name)), (&r, Path::new(reference_name)))
        .map_err(|e| to_py(e, Kind::Value))?;
    warn_all(py, &warnings)?;
    let s = penumbra::image::compare(&t, &r).map_err(|e| to_py(e, Kind::Value))?;
    let d = PyDict::new(py);
    d.set_item("mse", s.mse)?;
    d.set_item("rel_mse", s.rel_mse)?;
    d.set_item("mae", s.mae)?;
    Ok(d)
}

/// Merge in-memory parts `(array, start, end)` of an `spp`-sample render.
#[pyfunction]
fn merge_arrays<'py>(
    py: Python<'py>,
    parts: Vec<(PyReadonlyArray3<'_, f32>, u32, u32)>,
    spp: u32,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let parts = parts
        .iter()
        .map(|(a, start, end)| {
            if start >= end {
                return Err(PyValueError::new_err(format!(
                    "part range {start}..{end} is empty"
                )));
            }
            Ok(Part {
                image: from_array(a)?,
                info: PartInfo {
                    samples: *start..*end,
                    spp,
                    render: String::new(),
                },
            })
        })
        .collect::<PyResult<Vec<_>>>()?;
    let merged = merge(&parts).map_err(|e| to_py(e, Kind::Value))?;
    to_array(py, &merged.image)
}

/// Merge part files (from `penumbra render --spp-range`); write the result to `out` if given.
#[pyfunction]
#[pyo3(signature = (paths, out=None))]
fn merge_files<'py>(
    py: Python<'py>,
    paths: Vec<String>,
    out: Option<String>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let mut parts = Vec::with_capacity(paths.len());
    for p in &paths {
        must_exist(p)?;
        parts.push(read_part(Path::new(p)).map_err(|e| to_py(e, Kind::Value))?);
    }
    let merged = merge(&parts).map_err(|e| to_py(e, Kind::Value))?;
    if let Some(out) = out {
        let out = Path::new(&out);
        let exr = out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        if exr {
            write_part(&merged, out, &WriteControl::default())
        } else {
            penumbra::image::write_image(&merged.image, out, 0.0)
        }
        .map_err(|e| to_py(e, Kind::Value))?;
    }
    to_array(py, &merged.image)
}
