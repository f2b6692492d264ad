//! Rust errors as the Python exceptions a NumPy user expects: bad arguments are `ValueError`,
//! files that cannot be read or written are `OSError`, and nothing is ever a panic.

use pyo3::PyErr;
use pyo3::exceptions::{PyOSError, PyValueError};

/// An extraction error: always about the arguments (sizes, lengths, limits).
pub fn runtime(e: sc_runtime::Error) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A reader or writer error: usage mistakes are `ValueError`, file problems `OSError`.
pub fn io(e: sc_io::Error) -> PyErr {
    match e {
        sc_io::Error::Usage(message) => PyValueError::new_err(message),
        sc_io::Error::Extract(e) => runtime(e),
        other => PyOSError::new_err(other.to_string()),
    }
}
