//! Library errors as Python exceptions, and loader warnings as Python warnings.

use std::ffi::CString;

use pyo3::exceptions::{PyFileNotFoundError, PyKeyboardInterrupt, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use crate::messages::{format_error, format_warning};

pyo3::create_exception!(
    penumbra,
    SceneError,
    PyValueError,
    "A scene file that cannot be loaded; the message names file and line."
);
pyo3::create_exception!(
    penumbra,
    SceneWarning,
    pyo3::exceptions::PyUserWarning,
    "A loader repaired or approximated something (the message names file and line)."
);

/// Add the exception and warning classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("SceneWarning", py.get_type::<SceneWarning>())?;
    Ok(())
}

/// What kind of Python exception an error becomes when nothing more specific applies.
#[derive(Clone, Copy)]
pub enum Kind {
    /// Bad input data (a scene or image file): `SceneError` (a `ValueError`).
    Scene,
    /// Bad argument values: `ValueError`.
    Value,
    /// Anything else: `RuntimeError`.
    Runtime,
}

/// `e` as a Python exception: a missing file is `FileNotFoundError` naming it, a cancelled
/// render `KeyboardInterrupt`, else `kind`'s class; the message is the CLI's `error:` text.
pub fn to_py(e: anyhow::Error, kind: Kind) -> PyErr {
    let msg = format_error(&e);
    if e.is::<penumbra::integrator::Cancelled>() {
        return PyKeyboardInterrupt::new_err(msg);
    }
    let missing = e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::NotFound)
    });
    if missing {
        return PyFileNotFoundError::new_err(msg);
    }
    match kind {
        Kind::Scene => SceneError::new_err(msg),
        Kind::Value => PyValueError::new_err(msg),
        Kind::Runtime => PyRuntimeError::new_err(msg),
    }
}

/// `FileNotFoundError(ENOENT, why, path)`: `str()` names the file, `.filename` holds it.
pub fn not_found(why: &str, path: &str) -> PyErr {
    const ENOENT: i32 = 2;
    PyFileNotFoundError::new_err((ENOENT, why.to_string(), path.to_string()))
}

/// Issue each loader warning as a [`SceneWarning`], worded as the CLI prints it.
pub fn warn_all(py: Python<'_>, warnings: &[String]) -> PyResult<()> {
    let category = py.get_type::<SceneWarning>();
    for w in warnings {
        let text = CString::new(format_warning(w).replace('\0', " "))
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        PyErr::warn(py, category.as_any(), &text, 2)?;
    }
    Ok(())
}
