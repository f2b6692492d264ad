//! `skelclimb._native.labels`: a label volume's atlas and the meshes of the labels asked for,
//! with the GIL released while either is built. The Python layer (`_labels.py`) converts the
//! integer types the runtime does not take and wraps the arrays.

use std::fmt::Display;

use numpy::{Element, PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArray};
use pyo3::conversion::FromPyObjectOwned;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use sc_io::space::World;
use sc_runtime::labels::{Atlas, AtlasView, Label, LabelParams, extract_labels};
use sc_runtime::{Mesh, Volume};

use crate::convert::{self, with_type};
use crate::{arguments, errors, extract};

/// The label types, in the order error messages list them.
pub const TYPES: &str = "uint8, uint16, uint32, uint64, int16 or int32";

/// How many labels an error message lists before it only counts them.
const LISTED: usize = 10;

/// The atlas of a contiguous 3-D integer array (axes, `spacing`, `origin`, `affine` and `space`
/// as `extract` reads them), and the labels to mesh: those of `selection`, each one with a
/// surface, or every label but the background. Returns
/// `(vertices, faces, face_labels, chosen, cut, stats)`: the atlas, the chosen labels (ascending,
/// of the atlas's label type), and `(normals, threads, mode, space)`, the rest of what
/// [`label_meshes`] cuts their meshes with.
#[pyfunction]
#[pyo3(signature = (volume, spacing, origin, background, mode, pad, normals, threads, smoothing, selection=None, affine=None, space=None))]
#[allow(clippy::too_many_arguments)]
pub fn labels<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyUntypedArray>,
    spacing: [f64; 3],
    origin: [f64; 3],
    background: Bound<'py, PyAny>,
    mode: &str,
    pad: bool,
    normals: bool,
    threads: &Bound<'py, PyAny>,
    smoothing: f64,
    selection: Option<Vec<Bound<'py, PyAny>>>,
    affine: Option<[[f64; 4]; 3]>,
    space: Option<&str>,
) -> PyResult<Bound<'py, PyTuple>> {
    let (spacing, origin, world) = extract::placement(spacing, origin, affine, space)?;
    let request = Request {
        dims: convert::dims(volume, "volume")?,
        spacing,
        origin,
        world,
        background,
        mode,
        pad,
        normals,
        threads: arguments::threads(threads)?,
        smoothing,
        selection,
    };
    with_type!(py, volume, "volume", TYPES, [u8, u16, u32, u64, i16, i32], L => {
        run::<L>(py, volume, request)
    })
}

/// The arguments of [`labels`], checked but for the background, which needs the label type.
struct Request<'a, 'py> {
    dims: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    world: World,
    background: Bound<'py, PyAny>,
    mode: &'a str,
    pad: bool,
    normals: bool,
    threads: usize,
    smoothing: f64,
    selection: Option<Vec<Bound<'py, PyAny>>>,
}

fn run<'py, L>(
    py: Python<'py>,
    volume: &Bound<'py, PyUntypedArray>,
    request: Request<'_, 'py>,
) -> PyResult<Bound<'py, PyTuple>>
where
    L: Label + Element + Display + FromPyObjectOwned<'py> + IntoPyObject<'py>,
{
    let Request {
        dims,
        spacing,
        origin,
        world,
        background,
        mode: mode_name,
        pad,
        normals,
        threads,
        smoothing,
        selection,
    } = request;
    let background = label::<L>(&background)?;
    let params = LabelParams {
        background,
        mode: extract::mode(mode_name)?,
        pad,
        spacing,
        origin,
        threads,
        smoothing,
        ..LabelParams::default()
    };
    let atlas = {
        let samples = convert::samples::<L>(volume, "volume")?;
        let data = samples
            .as_slice()
            .map_err(|_| PyValueError::new_err("volume: the array is not contiguous"))?;
        let volume = Volume::new(data, dims).map_err(errors::runtime)?;
        py.detach(|| extract_labels(volume, &params))
            .map_err(errors::runtime)?
    };
    let reply = Reply {
        dims,
        world,
        background,
        mode: mode_name,
        normals,
        threads,
        selection,
    };
    respond(py, atlas, reply)
}

/// `background` as a label of the volume's type `L`.
pub fn label<'py, L: Label + Element + FromPyObjectOwned<'py>>(
    background: &Bound<'py, PyAny>,
) -> PyResult<L> {
    background.extract::<L>().map_err(|_| {
        PyValueError::new_err(format!(
            "background: {background} is not a value of the volume's type ({})",
            numpy::dtype::<L>(background.py())
        ))
    })
}

/// What [`respond`] needs besides the atlas.
pub struct Reply<'a, 'py, L> {
    /// The volume's samples along x, y, z.
    pub dims: [usize; 3],
    pub world: World,
    pub background: L,
    pub mode: &'a str,
    pub normals: bool,
    /// Threads the meshes are cut on (0 for all).
    pub threads: usize,
    pub selection: Option<Vec<Bound<'py, PyAny>>>,
}

/// [`labels`]'s result from an atlas made at `index × spacing + origin`, however it was made
/// (in one sweep, or joined from blocks): the atlas placed in the world, and the labels chosen,
/// whose meshes [`label_meshes`] cuts from the placed atlas when they are asked for.
pub fn respond<'py, L>(
    py: Python<'py>,
    mut atlas: Atlas<L>,
    reply: Reply<'_, 'py, L>,
) -> PyResult<Bound<'py, PyTuple>>
where
    L: Label + Element + Display + FromPyObjectOwned<'py> + IntoPyObject<'py>,
{
    let (world, background, mode_name) = (&reply.world, reply.background, reply.mode);
    if !world.is_translation() {
        py.detach(|| place(world, &mut atlas));
    }
    let chosen = choose(
        &atlas.labels(background, reply.threads),
        background,
        reply.selection,
    )?;

    let stats = PyDict::new(py);
    stats.set_item("dims", reply.dims)?;
    stats.set_item("background", background)?;
    extract::report(&stats, &atlas.stats, mode_name, world.space)?;
    let cut = (
        reply.normals,
        reply.threads,
        mode_name,
        world.space.map(|s| s.name()),
    );
    (
        convert::rows(py, atlas.positions)?,
        convert::rows(py, atlas.triangles)?,
        convert::rows(py, atlas.pairs)?,
        PyArray1::from_vec(py, chosen),
        cut,
        stats,
    )
        .into_pyobject(py)
}

/// The meshes of the labels `chosen` (ascending), cut from the atlas `vertices`, `faces` and
/// `face_labels` (borrowed, as [`labels`] returns them) on `threads` threads with the GIL
/// released, each labelled with `mode` and `space`. Returns
/// `(label, vertices, faces, normals or None, stats)` per label, in the order of `chosen`.
#[pyfunction]
#[pyo3(signature = (vertices, faces, face_labels, chosen, normals, threads, mode, space=None))]
#[allow(clippy::too_many_arguments)]
pub fn label_meshes<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f32>,
    faces: PyReadonlyArray2<'py, u32>,
    face_labels: &Bound<'py, PyUntypedArray>,
    chosen: &Bound<'py, PyUntypedArray>,
    normals: bool,
    threads: usize,
    mode: &str,
    space: Option<&str>,
) -> PyResult<Bound<'py, PyList>> {
    let positions = convert::borrow_rows(&vertices, "vertices")?;
    let triangles = convert::borrow_rows(&faces, "faces")?;
    with_type!(py, face_labels, "face_labels", TYPES, [u8, u16, u32, u64, i16, i32], L => {
        let pairs = face_labels
            .cast::<PyArray2<L>>()
            .map_err(|_| PyValueError::new_err("face_labels: expected a (T, 2) array"))?
            .try_readonly()
            .map_err(|_| PyValueError::new_err("face_labels: the array is being written"))?;
        let chosen = chosen
            .cast::<PyArray1<L>>()
            .map_err(|_| PyTypeError::new_err(format!(
                "chosen: expected a 1-D array of face_labels' type ({})",
                numpy::dtype::<L>(py)
            )))?
            .try_readonly()
            .map_err(|_| PyValueError::new_err("chosen: the array is being written"))?;
        let chosen = chosen
            .as_slice()
            .map_err(|_| PyValueError::new_err("chosen: the array is not contiguous"))?;
        let pairs = convert::borrow_rows(&pairs, "face_labels")?;
        let atlas = AtlasView::new(positions, triangles, pairs).map_err(errors::runtime)?;
        let meshes = py.detach(|| atlas.meshes(chosen, normals, threads));
        let per_label = meshes
            .into_iter()
            .map(|(label, mesh)| mesh_tuple(py, label, mesh, normals, mode, space))
            .collect::<PyResult<Vec<_>>>()?;
        PyList::new(py, per_label)
    })
}

/// A label's mesh as `(label, vertices, faces, normals or None, stats)`.
fn mesh_tuple<'py, L: Copy + IntoPyObject<'py>>(
    py: Python<'py>,
    label: L,
    mesh: Mesh,
    normals: bool,
    mode: &str,
    space: Option<&str>,
) -> PyResult<Bound<'py, PyTuple>> {
    let counts = PyDict::new(py);
    counts.set_item("vertices", mesh.stats.vertices)?;
    counts.set_item("triangles", mesh.stats.triangles)?;
    let s = PyDict::new(py);
    s.set_item("label", label)?;
    s.set_item("mode", mode)?;
    s.set_item("space", space)?;
    s.set_item("result", counts)?;
    let vertex_normals = match normals {
        true => Some(convert::rows(py, mesh.normals)?),
        false => None,
    };
    (
        label,
        convert::rows(py, mesh.positions)?,
        convert::rows(py, mesh.triangles)?,
        vertex_normals,
        s,
    )
        .into_pyobject(py)
}

/// Maps the atlas from `index × spacing` into `world`, as the CLI places a file's mesh; a
/// mirroring map turns every triangle, so each still faces from its first label to its second.
fn place<L>(world: &World, atlas: &mut Atlas<L>) {
    let mut mesh = Mesh {
        positions: std::mem::take(&mut atlas.positions),
        triangles: std::mem::take(&mut atlas.triangles),
        ..Mesh::default()
    };
    world.place(&mut mesh);
    atlas.positions = mesh.positions;
    atlas.triangles = mesh.triangles;
}

/// The labels to mesh: all of `present` (the labels with a surface), or the selection, each of
/// which must be one of them.
fn choose<'py, L: Label + Display + FromPyObjectOwned<'py>>(
    present: &[L],
    background: L,
    selection: Option<Vec<Bound<'py, PyAny>>>,
) -> PyResult<Vec<L>> {
    let Some(selection) = selection else {
        return Ok(present.to_vec());
    };
    if selection.is_empty() {
        return Err(PyValueError::new_err(
            "labels: the selection is empty; pass None to mesh every label",
        ));
    }
    let mut chosen = Vec::with_capacity(selection.len());
    let mut missing = Vec::new();
    for wanted in &selection {
        match wanted.extract::<L>() {
            Ok(l) if l == background => {
                return Err(PyValueError::new_err(format!(
                    "labels: {wanted} is the background, which is not meshed; \
                     pass background= another value to mesh it"
                )));
            }
            Ok(l) if present.binary_search(&l).is_ok() => chosen.push(l),
            _ => missing.push(wanted),
        }
    }
    if !missing.is_empty() {
        let present_list = match present.len() {
            0 => "none has a surface".to_string(),
            n => format!("those with a surface are {} ({n} in all)", list(present)),
        };
        return Err(PyValueError::new_err(format!(
            "labels: {} not in the volume; {present_list}",
            list(&missing)
        )));
    }
    chosen.sort_unstable();
    chosen.dedup();
    Ok(chosen)
}

/// The first [`LISTED`] of `items`, comma-separated, with an ellipsis for the rest.
fn list<T: Display>(items: &[T]) -> String {
    let mut out: Vec<String> = items.iter().take(LISTED).map(T::to_string).collect();
    if items.len() > LISTED {
        out.push("…".into());
    }
    out.join(", ")
}
