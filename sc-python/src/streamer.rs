//! `skelclimb.SliceStreamer`: a volume fed one z-slice at a time (from h5py, zarr, a camera),
//! meshed while it arrives, holding four slices rather than the volume.
//!
//! The runtime's streamer borrows its buffers, which a Python object cannot hold alongside them,
//! so it runs on a worker thread that owns them; slices reach it through a channel of two, which
//! bounds memory and lets Python read the next slice while Rust meshes the last. Slices are
//! converted to `f64`: classification and interpolation are done in `f64` for every sample type
//! (`sc_runtime::Scalar`), so the mesh is byte-identical to `extract` on the whole array.

use std::sync::mpsc::{SyncSender, sync_channel};
use std::thread::JoinHandle;

use numpy::{PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyMemoryError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use sc_runtime::{Mesh, Scratch, SliceStreamer as Streamer, Stats};

use crate::{convert, errors, extract};

type Outcome = Result<(Mesh, Stats), sc_runtime::Error>;

/// Meshes a volume of shape `(nz, ny, nx)` from its z-slices, pushed in order.
#[pyclass(module = "skelclimb._native")]
pub struct SliceStreamer {
    dims: [usize; 3],
    level: f64,
    mode: String,
    normals: bool,
    sender: Option<SyncSender<Vec<f64>>>,
    worker: Option<JoinHandle<Outcome>>,
}

#[pymethods]
impl SliceStreamer {
    #[new]
    #[pyo3(signature = (shape, level, spacing, origin, mode, normals))]
    fn new(
        shape: [usize; 3],
        level: f64,
        spacing: [f64; 3],
        origin: [f64; 3],
        mode: String,
        normals: bool,
    ) -> PyResult<Self> {
        let params = extract::params(level, spacing, origin, &mode, normals, None)?;
        let [nz, ny, nx] = shape;
        let dims = [nx, ny, nz];
        let len = Scratch::len(dims).map_err(errors::runtime)?;
        // The ring of four slices and the scratch are allocated here, where a size the process
        // cannot hold is a `MemoryError` (NumPy's word for it) and not an abort on the worker.
        let ring_len = 4u128 * nx as u128 * ny as u128;
        let need = ring_len * 8 + len.bytes as u128 + len.words as u128 * 4;
        let what = format!("shape: streaming a volume of shape ({nz}, {ny}, {nx})");
        sc_io::limits::bytes(need, 1, &what).map_err(PyMemoryError::new_err)?;
        let too_big = || PyMemoryError::new_err(format!("{what} failed to allocate its buffers"));
        let mut bytes = zeroed::<u8>(len.bytes).ok_or_else(too_big)?;
        let mut words = zeroed::<u32>(len.words).ok_or_else(too_big)?;
        let mut ring = zeroed::<f64>(ring_len as usize).ok_or_else(too_big)?;
        let (sender, slices) = sync_channel::<Vec<f64>>(2);
        let worker = std::thread::Builder::new()
            .name("skelclimb-streamer".into())
            .spawn(move || {
                let scratch = Scratch::new(&mut bytes, &mut words, dims)?;
                let mut s = Streamer::new(dims, &params, scratch, &mut ring, Mesh::default())?;
                for slice in slices {
                    s.push(&slice)?;
                }
                s.finish()
            })
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start the worker: {e}")))?;
        Ok(SliceStreamer {
            dims,
            level,
            mode,
            normals,
            sender: Some(sender),
            worker: Some(worker),
        })
    }

    /// Takes the next z-slice, a 2-D array of shape `(ny, nx)`.
    fn push(&mut self, py: Python<'_>, slice: PyReadonlyArray2<'_, f64>) -> PyResult<()> {
        let [nx, ny, _] = self.dims;
        if slice.shape() != [ny, nx] {
            return Err(PyValueError::new_err(format!(
                "slice: expected shape ({ny}, {nx}), got {:?}",
                slice.shape()
            )));
        }
        let samples = slice.as_array().iter().copied().collect::<Vec<f64>>();
        let Some(sender) = &self.sender else {
            return Err(PyValueError::new_err("push: the streamer is finished"));
        };
        if py.detach(|| sender.send(samples)).is_err() {
            // The worker stopped early: its error says why.
            return Err(self.join(py).err().unwrap_or_else(|| {
                PyRuntimeError::new_err("the streamer's worker stopped without an error")
            }));
        }
        Ok(())
    }

    /// Finishes after all `nz` slices; returns `(vertices, faces, normals or None, stats)`.
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let (mesh, stats) = self.join(py)?;
        let [nx, ny, nz] = self.dims;
        let stats = extract::stats(py, &stats, &self.mode, self.level, [nx, ny, nz], None)?;
        let normals = if self.normals {
            Some(convert::rows(py, mesh.normals)?)
        } else {
            None
        };
        (
            convert::rows(py, mesh.positions)?,
            convert::rows(py, mesh.triangles)?,
            normals,
            stats,
        )
            .into_pyobject(py)
    }
}

/// `n` zeros, or `None` when the allocation fails.
fn zeroed<T: Clone + Default>(n: usize) -> Option<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).ok()?;
    v.resize(n, T::default());
    Some(v)
}

impl SliceStreamer {
    /// Closes the channel and waits for the worker's mesh.
    fn join(&mut self, py: Python<'_>) -> PyResult<(Mesh, Stats)> {
        self.sender = None;
        let worker = self
            .worker
            .take()
            .ok_or_else(|| PyValueError::new_err("finish: the streamer is finished"))?;
        match py.detach(|| worker.join()) {
            Ok(outcome) => outcome.map_err(errors::runtime),
            Err(_) => Err(PyRuntimeError::new_err("the streamer's worker panicked")),
        }
    }
}
