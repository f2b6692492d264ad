//! The scanner's world in Python: a 4×4 affine from `(x, y, z, 1)` index to world coordinates,
//! split into the spacing the extractor works in and the [`World`] map the CLI places its meshes
//! with, so that both front ends put a scan's vertices in the same place.

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use sc_io::space::{Coordinates, Frame, Space, World};
use sc_io::volume::Grid;

/// The conventions by the names files, summaries and `stats["space"]` use.
const SPACES: [Space; 2] = [Space::Ras, Space::Lps];

/// The convention named `name` (`"RAS"` or `"LPS"`), or `None` for none.
pub fn space(name: Option<&str>) -> PyResult<Option<Space>> {
    let Some(name) = name else {
        return Ok(None);
    };
    SPACES
        .into_iter()
        .find(|s| s.name() == name)
        .map(Some)
        .ok_or_else(|| {
            PyValueError::new_err(format!(
                "space: expected 'RAS', 'LPS' or None, got {name:?}"
            ))
        })
}

/// `(spacing, world)` for the top three rows of an affine: the columns' lengths are the spacing,
/// their directions and the last column the map [`World::place`] applies afterwards, exactly as
/// for a file read by the CLI. Refuses what no placement can be built from.
pub fn from_affine(rows: [[f64; 4]; 3], space: Option<Space>) -> PyResult<([f64; 3], World)> {
    crate::arguments::affine(&rows)?;
    let columns = [0, 1, 2].map(|c| rows.map(|r| r[c]));
    let offset = rows.map(|r| r[3]);
    let frame = Frame::from_columns(columns, space.unwrap_or(Space::Ras))
        .filter(|_| offset.iter().all(|v| v.is_finite()));
    let Some((frame, spacing)) = frame else {
        return Err(PyValueError::new_err(format!(
            "affine: must be finite and invertible, got {rows:?}"
        )));
    };
    let world = World {
        linear: frame.direction,
        offset,
        space,
    };
    Ok((spacing, world))
}

/// The map that puts samples at `index × spacing + origin`, unrotated and in no convention.
pub fn translation(origin: [f64; 3]) -> World {
    World::new(None, origin, Coordinates::Index)
}

/// The 4×4 affine of a grid read from a file (`(x, y, z, 1)` index to world, in the file's
/// convention) and that convention, or `None` for a file without a world frame.
pub fn affine<'py>(
    py: Python<'py>,
    grid: &Grid,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Option<&'static str>)> {
    let direction = grid
        .frame
        .map_or(translation(grid.origin).linear, |f| f.direction);
    let mut entries = Vec::with_capacity(16);
    for (r, row) in direction.iter().enumerate() {
        entries.extend((0..3).map(|c| row[c] * grid.spacing[c]));
        entries.push(grid.origin[r]);
    }
    entries.extend([0.0, 0.0, 0.0, 1.0]);
    let affine = PyArray1::from_vec(py, entries).reshape([4, 4])?;
    Ok((affine, grid.frame.map(|f| f.space.name())))
}
