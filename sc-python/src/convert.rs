//! NumPy arrays to and from Rust without copying. A C-ordered array of shape `(a, b, c)` is read
//! as `z, y, x` (x fastest in memory, `nx = c`), a Fortran-ordered one as `x, y, z`: either way the
//! buffer is already the runtime's x-fastest layout, so it is borrowed as it is. This is the
//! CLI's NumPy reader's convention.

use numpy::{
    Element, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// The runtime's sample types, in the order error messages list them.
pub const TYPES: &str = "uint8, int8, uint16, int16, uint32, int32, float32 or float64";

/// Calls `$body` with `$t` bound to the Rust type of `$array`'s dtype among `[$ty, ...]`, or
/// returns a `TypeError` that names `$array` and lists `$names`.
macro_rules! with_type {
    ($py:expr, $array:expr, $name:expr, $names:expr, [$($ty:ty),+], $t:ident => $body:expr) => {{
        let dtype = numpy::PyUntypedArrayMethods::dtype($array);
        let is = |other| numpy::PyArrayDescrMethods::is_equiv_to(&dtype, &other);
        $(if is(numpy::dtype::<$ty>($py)) {
            type $t = $ty;
            $body
        } else)+ {
            Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "{}: unsupported dtype {}; use {}",
                $name, dtype, $names
            )))
        }
    }};
}
pub(crate) use with_type;

/// [`with_type`] over the runtime's sample types ([`TYPES`]).
macro_rules! with_element {
    ($py:expr, $array:expr, $name:expr, $t:ident => $body:expr) => {
        $crate::convert::with_type!(
            $py,
            $array,
            $name,
            $crate::convert::TYPES,
            [u8, i8, u16, i16, u32, i32, f32, f64],
            $t => $body
        )
    };
}
pub(crate) use with_element;

/// `[nx, ny, nz]` of a 3-D array whose buffer is contiguous in C or Fortran order.
pub fn dims(array: &Bound<'_, PyUntypedArray>, name: &str) -> PyResult<[usize; 3]> {
    let shape = array.shape();
    let [a, b, c] = <[usize; 3]>::try_from(shape).map_err(|_| {
        PyValueError::new_err(format!(
            "{name}: expected a 3-D array, got {} dimensions",
            shape.len()
        ))
    })?;
    // A contiguous array at an odd byte offset (a view into a byte buffer) cannot be read as
    // its type in place; the Python layer copies it first.
    let aligned = array.getattr("flags")?.getattr("aligned")?.is_truthy()?;
    if !aligned {
        return Err(PyValueError::new_err(format!(
            "{name}: the array is not aligned to its dtype; pass {name}.copy() \
             (skelclimb.extract does this for you, with one copy)"
        )));
    }
    if array.is_c_contiguous() {
        Ok([c, b, a])
    } else if array.is_fortran_contiguous() {
        Ok([a, b, c])
    } else {
        Err(PyValueError::new_err(format!(
            "{name}: the array is not contiguous; pass numpy.ascontiguousarray({name}) \
             (skelclimb.extract does this for you, with one copy)"
        )))
    }
}

/// The samples of `array`, borrowed.
pub fn samples<'a, T: Element>(
    array: &'a Bound<'_, PyUntypedArray>,
    name: &str,
) -> PyResult<numpy::PyReadonlyArrayDyn<'a, T>> {
    let typed = array
        .cast::<numpy::PyArrayDyn<T>>()
        .map_err(|_| PyTypeError::new_err(format!("{name}: dtype changed while reading")))?;
    Ok(typed.readonly())
}

/// A `(n, N)` NumPy array that takes over `rows` without copying them.
pub fn rows<'py, T: Element, const N: usize>(
    py: Python<'py>,
    rows: Vec<[T; N]>,
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let n = rows.len();
    PyArray1::from_vec(py, rows.into_flattened()).reshape([n, N])
}

/// The rows of a C-contiguous `(n, N)` array, borrowed.
pub fn borrow_rows<'a, T: Element, const N: usize>(
    array: &'a PyReadonlyArray2<'_, T>,
    name: &str,
) -> PyResult<&'a [[T; N]]> {
    let shape = array.shape();
    let flat = array
        .as_slice()
        .map_err(|_| PyValueError::new_err(format!("{name}: the array is not C-contiguous")))?;
    match flat.as_chunks::<N>() {
        (rows, []) if shape[1] == N => Ok(rows),
        _ => Err(PyValueError::new_err(format!(
            "{name}: expected shape (n, {N}), got {shape:?}"
        ))),
    }
}
