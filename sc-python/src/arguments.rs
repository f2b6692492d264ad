//! The limits every front end shares (`sc_io::limits`), applied to Python's arguments in the
//! command line's words: thread counts, spacings, origins and affine entries. The native calls
//! check their arguments with these, and the Python layer calls them first too, so that nothing
//! (padding a copy, building a Dask graph) is done for arguments that will be refused.

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyInt;
use sc_io::limits;

/// A thread count as Python's `operator.index` reads it (so `1.5` is a `TypeError` and a NumPy
/// integer is fine), 0 for every core, at most [`limits::MAX_THREADS`].
pub fn threads(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    let py = value.py();
    let n = py
        .import("operator")?
        .call_method1("index", (value,))
        .map_err(|_| {
            PyTypeError::new_err(format!(
                "threads: expected a whole number, got {}",
                repr(value)
            ))
        })?;
    let n = n.cast_into::<PyInt>()?;
    if n.lt(0)? {
        return Err(PyValueError::new_err(format!(
            "threads: must be 0 (all cores) or more, got {n}"
        )));
    }
    let checked = match n.extract::<u64>() {
        Ok(n) => limits::threads(n),
        Err(_) => Err(limits::too_many_threads(&n)),
    };
    checked.map_err(|e| PyValueError::new_err(format!("threads: {e}")))
}

/// A spacing or an origin: three finite numbers below [`limits::MAX_COORDINATE`].
pub fn triple(name: &str, v: [f64; 3]) -> PyResult<[f64; 3]> {
    limits::triple(v).map_err(|e| {
        PyValueError::new_err(format!("{name}: {e}, got ({}, {}, {})", v[0], v[1], v[2]))
    })
}

/// The entries of an affine's top three rows: each finite and below
/// [`limits::MAX_COORDINATE`], as a spacing or origin is.
pub fn affine(rows: &[[f64; 4]; 3]) -> PyResult<()> {
    if rows.iter().flatten().all(|&v| limits::coordinate(v)) {
        return Ok(());
    }
    Err(PyValueError::new_err(format!(
        "affine: must be finite, every entry below {:e} in magnitude (vertices are f32), \
         got {rows:?}",
        limits::MAX_COORDINATE
    )))
}

fn repr(value: &Bound<'_, PyAny>) -> String {
    value
        .repr()
        .map_or_else(|_| "an object".into(), |r| r.to_string())
}

/// `threads` checked as every entry point checks it (see [`threads`]).
#[pyfunction(name = "threads")]
pub fn check_threads(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    threads(value)
}

/// `value`, three floats, checked as every entry point checks a spacing or an origin.
#[pyfunction(name = "triple")]
pub fn check_triple(value: [f64; 3], name: &str) -> PyResult<(f64, f64, f64)> {
    let [x, y, z] = triple(name, value)?;
    Ok((x, y, z))
}

/// The top three rows of an affine, checked as [`affine`] does.
#[pyfunction(name = "affine")]
pub fn check_affine(rows: [[f64; 4]; 3]) -> PyResult<()> {
    affine(&rows)
}
