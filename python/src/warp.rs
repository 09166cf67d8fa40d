//! The lab's warp registry (`penumbra warp`): samples and the density each routine claims, so
//! external chi-square harnesses can test penumbra's samplers.

use glam::Vec3;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use penumbra::lab::warp::run::pattern_samples;
use penumbra::lab::warp::{ROUTINES, RunConfig, Warp, build, pdf_at, run};
use penumbra::sampling::PatternKind;

use crate::errors::{Kind, to_py};

/// Add the warp functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(warp_sample, m)?)?;
    m.add_function(wrap_pyfunction!(warp_pdf, m)?)?;
    m.add_function(wrap_pyfunction!(warp_list, m)?)?;
    Ok(())
}

/// Build routine `name` with `params` (`KEY=VALUE` each); errors list names or keys.
fn routine(name: &str, params: &[String]) -> PyResult<Warp> {
    build(name, params).map_err(|e| to_py(e, Kind::Value))
}

/// A routine's parameter as Python sees it: (key, default, help).
type ParamRow = (&'static str, &'static str, &'static str);

/// Samples (m × dim) and their pdfs, as numpy arrays.
type SamplesPdf<'py> = (Bound<'py, PyArray2<f32>>, Bound<'py, PyArray1<f64>>);

/// Every routine: (name, summary, [(key, default, help)]).
#[pyfunction]
fn warp_list() -> Vec<(&'static str, &'static str, Vec<ParamRow>)> {
    ROUTINES
        .iter()
        .map(|r| {
            let p = r
                .params
                .iter()
                .map(|s| (s.key, s.default, s.help))
                .collect();
            (r.name, r.summary, p)
        })
        .collect()
}

/// `n` sampling attempts of routine `name`: the accepted samples (m × dim, float32) and the
/// routine's pdf at each (float64).
#[pyfunction]
#[pyo3(signature = (name, n, params, pattern=None, seed=None))]
fn warp_sample<'py>(
    py: Python<'py>,
    name: &str,
    n: usize,
    params: Vec<String>,
    pattern: Option<&str>,
    seed: Option<u64>,
) -> PyResult<SamplesPdf<'py>> {
    const MAX: usize = 100_000_000;
    if n == 0 || n > MAX {
        return Err(PyValueError::new_err(format!(
            "n must be in 1..={MAX}, got {n}"
        )));
    }
    let warp = routine(name, &params)?;
    let pattern = pattern
        .map(|p| p.parse::<PatternKind>())
        .transpose()
        .map_err(|e| PyValueError::new_err(format!("pattern: {e}")))?;
    let seed = seed.unwrap_or(RunConfig::default().seed);
    let (samples, pdf) = py.detach(|| {
        let samples = match pattern {
            // The chi-square harness's own stream: the very samples the test suite draws.
            None => {
                let cfg = RunConfig {
                    count: n,
                    seed,
                    ..RunConfig::default()
                };
                run(&warp, &cfg).samples
            }
            Some(kind) => pattern_samples(&warp, kind, seed, n),
        };
        let pdf: Vec<f64> = samples.iter().map(|&s| warp.pdf(s)).collect();
        (samples, pdf)
    });
    let dim = warp.dim();
    let flat: Vec<f32> = samples
        .iter()
        .flat_map(|s: &Vec3| s.to_array().into_iter().take(dim))
        .collect();
    let arr = Array2::from_shape_vec((samples.len(), dim), flat)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok((arr.into_pyarray(py), pdf.into_pyarray(py)))
}

/// The pdf routine `name` claims at each row of `points` (m × dim).
#[pyfunction]
#[pyo3(signature = (name, points, params))]
fn warp_pdf<'py>(
    py: Python<'py>,
    name: &str,
    points: PyReadonlyArray2<'_, f32>,
    params: Vec<String>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let warp = routine(name, &params)?;
    let v = points.as_array();
    let cols = v.ncols();
    let flat: Vec<f32> = v.iter().copied().collect();
    let pdf = pdf_at(&warp, cols, &flat).map_err(|e| to_py(e, Kind::Value))?;
    let out = pdf.into_pyarray(py);
    Ok(out)
}
