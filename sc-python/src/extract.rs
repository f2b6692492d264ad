//! `skelclimb._native.extract`: the whole extraction with the GIL released.

use numpy::{Element, PyUntypedArray};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sc_io::separation;
use sc_io::space::{Space, World};
use sc_runtime::{ErrorBound, Figure, Mesh, Mode, Params, Scalar, Stats, Volume, extract_par};

use crate::arguments;
use crate::convert::{self, with_element};
use crate::errors;
use crate::world;

/// Parses a mode name as the CLI spells it.
pub fn mode(name: &str) -> PyResult<Mode> {
    name.parse()
        .map_err(|e| PyValueError::new_err(format!("mode: {e}, got {name:?}")))
}

/// Parses `max_error` and `error_units` as `(value, units)`.
fn bound(bound: Option<(f64, String)>) -> PyResult<Option<ErrorBound>> {
    let Some((d, units)) = bound else {
        return Ok(None);
    };
    if !(d.is_finite() && d >= 0.0) {
        return Err(PyValueError::new_err(format!(
            "max_error: must be a finite number, 0 or more, got {d}"
        )));
    }
    let units = units
        .parse()
        .map_err(|e| PyValueError::new_err(format!("error_units: {e}, got {units:?}")))?;
    Ok(Some(ErrorBound::new(d, units)))
}

/// A spacing (three positive numbers) and an origin, checked.
fn grid(spacing: [f64; 3], origin: [f64; 3]) -> PyResult<([f64; 3], [f64; 3])> {
    let spacing = arguments::triple("spacing", spacing)?;
    if !spacing.iter().all(|s| *s > 0.0) {
        return Err(PyValueError::new_err(format!(
            "spacing: must be three positive numbers, got {spacing:?}"
        )));
    }
    Ok((spacing, arguments::triple("origin", origin)?))
}

/// Where the samples sit: `(spacing, origin, world)`, the extractor working at
/// `index × spacing + origin` and `world` then mapping its vertices, unless it is a translation
/// (then already the origin). From the top three rows of an `affine` if given, as the CLI places
/// a file's mesh, otherwise from `spacing` and `origin`; both checked.
pub fn placement(
    spacing: [f64; 3],
    origin: [f64; 3],
    affine: Option<[[f64; 4]; 3]>,
    space: Option<&str>,
) -> PyResult<([f64; 3], [f64; 3], World)> {
    let space = world::space(space)?;
    let (spacing, world) = match affine {
        Some(rows) => world::from_affine(rows, space)?,
        None => (
            spacing,
            World {
                space,
                ..world::translation(origin)
            },
        ),
    };
    // As the CLI does: a translation is the extractor's origin (the same f32 arithmetic), any
    // other map is applied to the finished mesh.
    let origin = if world.is_translation() {
        world.offset
    } else {
        [0.0; 3]
    };
    let (spacing, origin) = grid(spacing, origin)?;
    Ok((spacing, origin, world))
}

/// Checks the numbers every front end takes and builds the runtime's parameters.
pub fn params(
    level: f64,
    spacing: [f64; 3],
    origin: [f64; 3],
    mode_name: &str,
    normals: bool,
    max_error: Option<(f64, String)>,
) -> PyResult<Params> {
    if !level.is_finite() {
        return Err(PyValueError::new_err(format!(
            "level: must be a finite number, got {level}"
        )));
    }
    let (spacing, origin) = grid(spacing, origin)?;
    Ok(Params {
        mode: mode(mode_name)?,
        max_error: bound(max_error)?,
        normals,
        spacing,
        origin,
        ..Params::new(level)
    })
}

/// Extracts the surface `volume = level` of a contiguous 3-D array (x fastest in memory; see
/// `convert`), at `index × spacing + origin` or, given the top three rows of an `affine`, in the
/// world it maps to (`spacing` and `origin` are then ignored). Returns
/// `(vertices, faces, normals or None, stats)`.
#[pyfunction]
#[pyo3(signature = (volume, level, spacing, origin, mode, normals, threads, max_error=None, affine=None, space=None, max_box=None, allow_wrong_side=false))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn extract<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyUntypedArray>,
    level: f64,
    spacing: [f64; 3],
    origin: [f64; 3],
    mode: &str,
    normals: bool,
    threads: &Bound<'py, PyAny>,
    max_error: Option<(f64, String)>,
    affine: Option<[[f64; 4]; 3]>,
    space: Option<&str>,
    max_box: Option<u32>,
    allow_wrong_side: bool,
) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
    let threads = arguments::threads(threads)?;
    let (spacing, origin, world) = placement(spacing, origin, affine, space)?;
    let params = Params {
        max_box,
        allow_wrong_side,
        ..params(level, spacing, origin, mode, normals, max_error)?
    };
    let dims = convert::dims(volume, "volume")?;
    let (mut mesh, wrong_side) = with_element!(py, volume, "volume", T => {
        run_measured::<T>(py, volume, dims, &params, threads, true)
    })?;
    if !world.is_translation() {
        py.detach(|| world.place(&mut mesh));
    }
    let stats = stats(py, &mesh.stats, mode, level, dims, world.space)?;
    if params.mode == Mode::Adaptive {
        stats.set_item(separation::WRONG_SIDE_SAMPLES, wrong_side)?;
    }
    let Mesh {
        positions,
        normals: vertex_normals,
        triangles,
        ..
    } = mesh;
    let normals = if normals {
        Some(convert::rows(py, vertex_normals)?)
    } else {
        None
    };
    (
        convert::rows(py, positions)?,
        convert::rows(py, triangles)?,
        normals,
        stats,
    )
        .into_pyobject(py)
}

/// [`run`], and with `measure` in adaptive mode the samples left on the wrong side of its mesh
/// (not yet placed in the world), `None` where a border sample is filled. Only adaptive mode
/// counts them: the count is one more sweep of the volume, under 1 % of adaptive mode's time
/// but about twice the other modes' whole extraction, and Python's stats are always made, never
/// asked for.
fn run_measured<T: Scalar + Element>(
    py: Python<'_>,
    volume: &Bound<'_, PyUntypedArray>,
    dims: [usize; 3],
    params: &Params,
    threads: usize,
    measure: bool,
) -> PyResult<(Mesh, Option<u64>)> {
    let samples = convert::samples::<T>(volume, "volume")?;
    let data = samples
        .as_slice()
        .map_err(|_| PyValueError::new_err("volume: the array is not contiguous"))?;
    let volume = Volume::new(data, dims).map_err(errors::runtime)?;
    py.detach(|| {
        let mesh = extract_par(&volume, params, threads, &|_| {})?;
        let wrong = (measure && params.mode == Mode::Adaptive)
            .then(|| separation::wrong_side_samples(&volume, params, &mesh))
            .flatten();
        Ok((mesh, wrong))
    })
    .map_err(errors::runtime)
}

pub(crate) fn run<T: Scalar + Element>(
    py: Python<'_>,
    volume: &Bound<'_, PyUntypedArray>,
    dims: [usize; 3],
    params: &Params,
    threads: usize,
) -> PyResult<Mesh> {
    Ok(run_measured::<T>(py, volume, dims, params, threads, false)?.0)
}

/// The figures the CLI's `--stats-json` reports, as a dict, with the world convention of the
/// vertices (`"RAS"`, `"LPS"`, or `None` for index × spacing + origin or an unstated one).
pub fn stats<'py>(
    py: Python<'py>,
    s: &Stats,
    mode: &str,
    level: f64,
    dims: [usize; 3],
    space: Option<Space>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("dims", dims)?;
    d.set_item("iso", level)?;
    report(&d, s, mode, space)?;
    Ok(d)
}

/// Adds to `d` the mode, the world convention and the runtime's figures ([`Stats::report`]),
/// under the names every front end gives them.
pub fn report(d: &Bound<'_, PyDict>, s: &Stats, mode: &str, space: Option<Space>) -> PyResult<()> {
    let py = d.py();
    let counts = |v: u64, t: u64| -> PyResult<Bound<'_, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("vertices", v)?;
        d.set_item("triangles", t)?;
        Ok(d)
    };
    d.set_item("mode", mode)?;
    d.set_item("space", space.map(Space::name))?;
    for (name, figure) in s.report() {
        match figure {
            Figure::Mesh {
                vertices,
                triangles,
            } => d.set_item(name, counts(vertices, triangles)?)?,
            Figure::Edges(n) => d.set_item(name, n)?,
        }
    }
    d.set_item("reduction_percent", s.reduction_percent())
}
