"""Skeleton Climbing isosurfaces: about 25 % fewer triangles than Marching Cubes.

>>> import numpy as np, skelclimb
>>> z, y, x = np.mgrid[-1:1:32j, -1:1:32j, -1:1:32j]
>>> ball = (0.8 - np.sqrt(x * x + y * y + z * z)).astype(np.float32)
>>> mesh = skelclimb.extract(ball, 0.0)
>>> mesh.faces.shape[0] < mesh.stats["steps123"]["triangles"]
True

Three entry points:

* :func:`extract` is this package's own call: vertices in ``(x, y, z)`` order, where ``x`` is the
  fastest-varying axis in memory (the last axis of a C-ordered array), spacing and origin in the
  same order. This is how the ``skelclimb`` command reads NumPy files. With the ``affine`` that
  :func:`load` returns, the vertices land in the scanner's world, where the command puts them.
* :func:`marching_cubes` is a drop-in for ``skimage.measure.marching_cubes``: vertices in the
  array's own axis order, the same winding, the same return value.
* :func:`labels` meshes every region of an integer label volume (a segmentation) in one sweep:
  a closed :class:`Mesh` per label, and an :class:`Atlas` holding each interface once.
"""

from __future__ import annotations

import operator
from typing import NamedTuple, Optional

import numpy as np

from . import _native

__all__ = [
    "Atlas",
    "BlockMesh",
    "Labels",
    "Mesh",
    "Scan",
    "SliceStreamer",
    "block_samples",
    "extract",
    "extract_block",
    "labels",
    "load",
    "marching_cubes",
    "merge_shards",
    "release_memory",
]

_MODES = tuple(_native.MODES)


class Mesh:
    """An indexed triangle mesh.

    Attributes
    ----------
    vertices : (V, 3) float32 array
        Positions, ``(x, y, z)``: in the scanner's world when made with an ``affine``, otherwise
        index × spacing + origin.
    faces : (T, 3) uint32 array
        Vertex indices, wound so that ``(b - a) × (c - a)`` points out of the region
        ``volume >= level``.
    normals : (V, 3) float32 array or None
        Unit normals pointing out of that region, if asked for.
    stats : dict
        ``steps123`` and ``result`` (vertex and triangle counts), ``merged``, ``blocked`` and
        ``bounded`` grey edges (``bounded``: blocked by ``max_error`` alone),
        ``reduction_percent``, ``mode``, ``iso``, ``dims`` (``[nx, ny, nz]``), and ``space``: the
        world convention of the vertices, ``"RAS"`` or ``"LPS"``, or None (index × spacing +
        origin, or an affine given without a ``space``). From :func:`extract` in adaptive mode,
        also ``wrong_side_samples``: the samples on the wrong side of the surface (0 unless
        ``allow_wrong_side``), or None where a sample on the volume's border is filled (the
        surface is open there; ``pad`` closes it).
    """

    __slots__ = ("vertices", "faces", "normals", "stats")

    def __init__(self, vertices, faces, normals=None, stats=None):
        self.vertices = vertices
        self.faces = faces
        self.normals = normals
        self.stats = {} if stats is None else stats

    def __repr__(self):
        return f"Mesh({len(self.vertices)} vertices, {len(self.faces)} triangles)"

    def save(self, path, *, ascii=False):
        """Writes the mesh to ``path``: ``.ply``, ``.obj``, ``.stl`` or ``.glb`` by extension.

        The file appears whole or not at all (it is written to a temporary file and renamed),
        with the same writers as the ``skelclimb`` command, straight from the arrays (C-ordered
        ones are not copied). ``stats["space"]`` is recorded in the file as the command records
        it.

        >>> mesh.save("ball.ply")  # doctest: +SKIP
        """
        vertices = np.ascontiguousarray(self.vertices, dtype=np.float32)
        faces = np.ascontiguousarray(self.faces, dtype=np.uint32)
        normals = None
        if self.normals is not None:
            normals = np.ascontiguousarray(self.normals, dtype=np.float32)
        _native.save(str(path), vertices, faces, normals, ascii, self.stats.get("space"))

    def to_trimesh(self):
        """The mesh as a ``trimesh.Trimesh`` (needs the ``trimesh`` package)."""
        import trimesh

        return trimesh.Trimesh(
            vertices=self.vertices,
            faces=self.faces,
            vertex_normals=self.normals,
            process=False,
        )

    def to_pyvista(self):
        """The mesh as a ``pyvista.PolyData`` (needs the ``pyvista`` package)."""
        import pyvista

        faces = np.hstack(
            [np.full((len(self.faces), 1), 3, dtype=np.int64), self.faces.astype(np.int64)]
        )
        poly = pyvista.PolyData(np.asarray(self.vertices), faces.ravel())
        if self.normals is not None:
            poly.point_data["Normals"] = self.normals
        return poly


def _real(value, name):
    """``value`` as a float. A string is refused, though ``float`` would read it: a number
    written as text is a mistake NumPy does not make silently either."""
    if isinstance(value, (str, bytes, bytearray)):
        raise TypeError(f"{name}: expected a number, got {value!r}")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected a number, got {value!r}") from None


def _index(value, name):
    """``value`` as an int, as ``operator.index`` reads it: ``1.5`` is a TypeError, NumPy
    integers are fine."""
    try:
        return operator.index(value)
    except TypeError:
        raise TypeError(f"{name}: expected a whole number, got {value!r}") from None


def _triple(value, name):
    """Three floats, finite and below the command's limit (``_native.triple``)."""
    if isinstance(value, (str, bytes, bytearray)):
        raise TypeError(f"{name}: expected three numbers, got {value!r}")
    try:
        items = tuple(_real(v, name) for v in value)
    except TypeError:
        raise TypeError(f"{name}: expected three numbers, got {value!r}") from None
    if len(items) != 3:
        raise ValueError(f"{name}: expected three numbers, got {len(items)}")
    return _native.triple(items, name)


def _volume(volume, name="volume"):
    """A 3-D array the native code can borrow: C or Fortran contiguous, native byte order."""
    if not isinstance(volume, np.ndarray):
        raise TypeError(f"{name}: expected a NumPy array, got {type(volume).__name__}")
    if volume.ndim != 3:
        raise ValueError(f"{name}: expected a 3-D array, got {volume.ndim} dimensions")
    if volume.dtype == np.bool_:
        volume = volume.view(np.uint8)
    if not volume.dtype.isnative:
        volume = volume.astype(volume.dtype.newbyteorder("="))
    if not (volume.flags.c_contiguous or volume.flags.f_contiguous):
        volume = np.ascontiguousarray(volume)
    elif not volume.flags.aligned:
        # A contiguous view at an odd byte offset: the copy keeps its order and is aligned.
        volume = volume.copy(order="K")
    return volume


def _level(level):
    level = _real(level, "level")
    if not np.isfinite(level):
        raise ValueError(f"level: must be finite, got {level}")
    return level


def _bound(max_error, error_units):
    """``(max_error, error_units)`` for the native calls, or None without a bound."""
    if max_error is None:
        return None
    try:
        max_error = float(max_error)
    except (TypeError, ValueError):
        raise TypeError(f"max_error: expected a number or None, got {max_error!r}") from None
    if not (np.isfinite(max_error) and max_error >= 0):
        raise ValueError(f"max_error: must be a finite number, 0 or more, got {max_error}")
    if error_units not in ("world", "voxels"):
        raise ValueError(f"error_units: expected 'world' or 'voxels', got {error_units!r}")
    return (max_error, error_units)


def _pad(volume, level):
    """``volume`` with one layer around it that is empty at ``level``, so every surface closes.

    The fill is the command's: the smallest finite sample if it is empty, so caps sit where the
    data puts them, otherwise the largest value of the type below ``level``.
    """
    finite = volume if np.issubdtype(volume.dtype, np.integer) else volume[np.isfinite(volume)]
    low = finite.min() if finite.size else None
    if low is not None and low < level:
        fill = low
    elif np.issubdtype(volume.dtype, np.integer):
        below = np.ceil(level) - 1
        info = np.iinfo(volume.dtype)
        if below < info.min:
            raise ValueError(f"pad: no {volume.dtype} value is below level {level}")
        fill = volume.dtype.type(min(below, info.max))
    else:
        with np.errstate(over="ignore"):  # a level beyond the type's range rounds to inf
            fill = volume.dtype.type(level)
        if not fill < level:
            fill = np.nextafter(fill, volume.dtype.type(-np.inf))
    order = "F" if volume.flags.f_contiguous and not volume.flags.c_contiguous else "C"
    return np.pad(volume, 1, constant_values=fill), order


def _affine(affine, spacing, origin):
    """``affine`` as a checked 4×4 float64 copy, or None; any ``spacing`` and ``origin`` given
    beside it must agree with it."""
    if affine is None:
        return None
    try:
        affine = np.array(affine, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"affine: expected a 4×4 array of numbers, got {affine!r}") from None
    if affine.shape != (4, 4):
        raise ValueError(f"affine: expected a 4×4 array, got shape {affine.shape}")
    _native.affine(affine[:3].tolist())
    if not np.array_equal(affine[3], [0, 0, 0, 1]):
        raise ValueError(f"affine: the last row must be (0, 0, 0, 1), got {affine[3]}")
    # A spacing or origin beside the affine is allowed only if it says the same.
    lengths = np.linalg.norm(affine[:3, :3], axis=0)
    if spacing is not None and not np.allclose(
        _triple(spacing, "spacing"), lengths, rtol=1e-6, atol=0
    ):
        raise ValueError(
            f"spacing: {tuple(spacing)} contradicts the affine's column lengths {tuple(lengths)}; "
            "give the affine alone"
        )
    if origin is not None and not np.allclose(
        _triple(origin, "origin"), affine[:3, 3], rtol=1e-9, atol=1e-6
    ):
        raise ValueError(
            f"origin: {tuple(origin)} contradicts the affine's translation "
            f"{tuple(affine[:3, 3])}; give the affine alone"
        )
    return affine


def _placement(affine, spacing, origin):
    """``(affine, spacing, origin)`` checked, with the defaults filled in: the affine as
    :func:`_affine` gives it (or None), the spacing ``(1, 1, 1)`` and the origin zero."""
    affine = _affine(affine, spacing, origin)
    spacing = _triple((1, 1, 1) if spacing is None else spacing, "spacing")
    origin = _triple((0, 0, 0) if origin is None else origin, "origin")
    return affine, spacing, origin


def _mode(mode):
    if mode not in _MODES:
        raise ValueError(f"mode: expected one of {', '.join(map(repr, _MODES))}, got {mode!r}")


def extract(
    volume,
    level,
    *,
    affine=None,
    space=None,
    spacing=None,
    origin=None,
    mode="embedded",
    pad=False,
    normals=True,
    threads=0,
    max_error=None,
    error_units="world",
    max_box=None,
    allow_wrong_side=False,
):
    """Meshes the surface ``volume == level``; samples ``>= level`` are inside.

    Parameters
    ----------
    volume : 3-D ndarray
        uint8, int8, uint16, int16, uint32, int32, float32 or float64 (bool is read as uint8).
        A C-ordered array of shape ``(nz, ny, nx)`` or a Fortran-ordered one of shape
        ``(nx, ny, nz)`` is used **without copying**; a non-contiguous view (a slice with a step,
        a transposed C array that is neither order) is copied once, and so is an array in
        non-native byte order.
    level : float
        The iso value. Integer volumes are compared exactly in their own type.
    affine : (4, 4) array, optional
        The map from sample index ``(x, y, z, 1)`` to the scanner's world, as :func:`load`
        returns it: ``x`` is the last axis of a C-ordered array, the first of a Fortran-ordered
        one (so nibabel's ``img.affine`` fits ``np.asfortranarray(img.get_fdata())``). Vertices
        and normals are mapped into that world exactly as the ``skelclimb`` command maps them (a
        mirroring affine reverses the winding, so that faces still point out). It must be finite
        and invertible with ``(0, 0, 0, 1)`` as its last row.
    space : ``"RAS"``, ``"LPS"`` or None
        The world's convention, recorded in ``stats["space"]`` and in saved files; :func:`load`
        returns it beside the affine.
    spacing, origin : three floats, ``(x, y, z)``
        Without an affine, vertex positions are ``index × spacing + origin`` (by default
        ``(1, 1, 1)`` and ``(0, 0, 0)``). Beside an affine they must agree with its column
        lengths and translation.
    mode : ``"embedded"`` (default), ``"paper"``, ``"steps123"`` or ``"adaptive"``
        ``embedded`` merges only where the surface stays a closed 2-manifold, ``paper`` merges
        every interior grey edge as the paper does, ``steps123`` does not merge (the Marching
        Cubes triangle count), ``adaptive`` meshes boxes of up to 16³ cubes as one where they
        stay within ``max_error`` of the Steps 1–3 surface (default: half the smallest
        spacing; one thread; not for blocks or Dask).
    pad : bool
        Surround the volume with one layer of empty samples (a copy), so every surface is
        closed; positions stay in the unpadded volume's coordinates.
    normals : bool
        Compute per-vertex normals.
    threads : int
        Worker threads, 0 for all cores. The mesh is identical for any number. The GIL is
        released while the mesh is built.
    max_error : float or None
        A bound on how far merging moves the surface: a grey edge merges only if the vertex it
        removes lies closer than this to the two triangles that replace its four, and their new
        diagonal closer than this to the four. ``0`` merges
        nothing (Steps 1–3's triangles); ``None`` merges what ``mode`` allows.
        ``stats["bounded"]`` counts the merges the bound refused.
    error_units : ``"world"`` (default) or ``"voxels"``
        ``max_error`` in world units (index × spacing) or in grid steps.
    max_box : int or None
        Adaptive mode's largest box, in cubes per side: 1, 2, 4, 8 or 16 (the default), no
        larger than the volume. Other modes refuse it.
    allow_wrong_side : bool
        Adaptive mode: let boxes leave samples on the wrong side of the surface, as the 1998
        paper does, for fewer triangles. By default every sample keeps its side. Other modes
        refuse it.

    Returns
    -------
    Mesh

    Examples
    --------
    >>> import numpy as np, skelclimb
    >>> v = np.zeros((8, 8, 8), np.uint8); v[2:6, 2:6, 2:6] = 1
    >>> m = skelclimb.extract(v, 1)
    >>> m.stats["result"]["triangles"] < m.stats["steps123"]["triangles"]
    True

    An affine that swaps x and y (a mirror) moves the vertices and keeps the faces outward:

    >>> swap = np.array([[0, 2, 0, 10], [2, 0, 0, 0], [0, 0, 2, 0], [0, 0, 0, 1]])
    >>> w = skelclimb.extract(v, 1, affine=swap, space="RAS")
    >>> np.allclose(w.vertices, m.vertices[:, [1, 0, 2]] * 2 + [10, 0, 0]), w.stats["space"]
    (True, 'RAS')
    """
    volume = _volume(volume)
    level = _level(level)
    affine, spacing, origin = _placement(affine, spacing, origin)
    _mode(mode)
    threads = _native.threads(threads)
    if pad:
        volume, order = _pad(volume, level)
        volume = np.asarray(volume, order=order)
        # Sample (0, 0, 0) is now one step back along each axis.
        origin = tuple(o - s for o, s in zip(origin, spacing))
        if affine is not None:
            affine[:3, 3] -= affine[:3, :3].sum(axis=1)
    verts, faces, norms, stats = _native.extract(
        volume, level, spacing, origin, mode, bool(normals), threads,
        _bound(max_error, error_units), None if affine is None else affine[:3].tolist(), space,
        _max_box(max_box), bool(allow_wrong_side),
    )
    return Mesh(verts, faces, norms, stats)


def _max_box(max_box):
    """``max_box`` as an int for the native call (the runtime checks its range), or None."""
    if max_box is None:
        return None
    if isinstance(max_box, bool) or not isinstance(max_box, (int, np.integer)):
        raise TypeError(f"max_box: expected an int or None, got {max_box!r}")
    if not 0 <= max_box < 2**32:
        raise ValueError(f"max_box: must be a power of two from 1 to 16, got {max_box}")
    return int(max_box)


class Scan(NamedTuple):
    """A volume read by :func:`load`, and where it sits in the scanner's world.

    Unpacks as ``volume, affine, space = skelclimb.load(path)``.
    """

    volume: np.ndarray
    """The samples, C-ordered, of shape ``(nz, ny, nx)``."""
    affine: np.ndarray
    """(4, 4) float64: sample index ``(x, y, z, 1)`` (``x`` the last array axis) to world."""
    space: Optional[str]
    """The world's convention, ``"RAS"`` or ``"LPS"``, or None for a file without one."""

    @property
    def spacing(self):
        """The distance between samples along x, y and z: the affine's column lengths."""
        return tuple(float(v) for v in np.linalg.norm(self.affine[:3, :3], axis=0))

    @property
    def origin(self):
        """Where sample ``(0, 0, 0)`` sits in the world: the affine's translation."""
        return tuple(float(v) for v in self.affine[:3, 3])


def load(path, **options):
    """Reads a volume file with the ``skelclimb`` command's readers.

    NIfTI (``.nii``, ``.nii.gz``), NRRD (``.nrrd``, ``.nhdr``), MetaImage (``.mha``, ``.mhd``),
    NumPy (``.npy``, ``.npz``; ``array=`` picks an array), a DICOM series (a directory, searched
    recursively; ``series=`` picks one by UID or number, ``resample_gaps=True`` resamples a
    series with missing slices), a Zarr v2/v3 array or OME-Zarr image (``zarr_level=`` picks a
    multiscale level), raw samples with ``dims=(nx, ny, nz), dtype="i16"`` (and ``endian=``,
    ``header_bytes=``), or raw samples with a JSON sidecar. For Zarr stores larger than memory,
    use :func:`skelclimb.dask.extract`.

    Returns a :class:`Scan` ``(volume, affine, space)``:

    * ``volume``: a C-ordered array of shape ``(nz, ny, nx)``, with any rescale slope and
      intercept in the file applied;
    * ``affine``: the 4×4 map from sample index ``(x, y, z, 1)`` to world coordinates, as the
      file states it (NIfTI sform or qform, NRRD space directions, MetaImage TransformMatrix,
      DICOM orientation and position; index × spacing + origin for raw and NumPy files);
    * ``space``: the convention of that world as the file states it, ``"RAS"`` (NIfTI, NRRD in
      RAS space) or ``"LPS"`` (DICOM, MetaImage, most NRRD), or None for a file without one.

    Given to :func:`extract`, the affine and space put the mesh where the ``skelclimb``
    command puts it. ``Scan.spacing`` and ``Scan.origin`` are the affine's column lengths and
    translation.

    >>> volume, affine, space = skelclimb.load("head.nii.gz")  # doctest: +SKIP
    >>> mesh = skelclimb.extract(volume, 300, affine=affine, space=space)  # doctest: +SKIP
    """
    if "dims" in options and options["dims"] is not None:
        options["dims"] = tuple(_index(d, "dims") for d in options["dims"])
    return Scan(*_native.load(str(path), **options))


class SliceStreamer:
    """Meshes a volume of shape ``(nz, ny, nx)`` fed one z-slice at a time, holding four slices.

    For volumes read slice by slice (h5py, zarr, a microscope): memory stays that of a few
    slices plus the mesh, and the mesh equals :func:`extract`'s on the whole array. Rust meshes
    on its own thread while Python reads the next slice.

    >>> s = skelclimb.SliceStreamer((nz, ny, nx), level=300)  # doctest: +SKIP
    >>> for z in range(nz):  # doctest: +SKIP
    ...     s.push(dataset[z])
    >>> mesh = s.finish()  # doctest: +SKIP
    """

    def __init__(self, shape, level, *, spacing=(1, 1, 1), origin=(0, 0, 0), mode="embedded",
                 normals=True):
        shape = tuple(_index(n, "shape") for n in shape)
        if len(shape) != 3 or min(shape) < 0:
            raise ValueError(f"shape: expected (nz, ny, nx), got {shape!r}")
        if max(shape) >= 2**64:
            raise MemoryError(f"shape: streaming a volume of shape {shape} is beyond any memory")
        _mode(mode)
        self._native = _native.SliceStreamer(
            shape, _level(level), _triple(spacing, "spacing"), _triple(origin, "origin"), mode,
            bool(normals),
        )

    def push(self, slice):
        """Takes the next z-slice: a 2-D array of shape ``(ny, nx)`` of any real dtype."""
        slice = np.asarray(slice)
        if slice.ndim != 2:
            raise ValueError(f"slice: expected a 2-D array, got {slice.ndim} dimensions")
        self._native.push(np.require(slice, np.float64, ["C_CONTIGUOUS", "ALIGNED"]))

    def finish(self):
        """Finishes after all ``nz`` slices and returns the :class:`Mesh`."""
        verts, faces, norms, stats = self._native.finish()
        return Mesh(verts, faces, norms, stats)


def merge_shards(manifest):
    """Joins the shards a manifest lists: a :class:`Mesh` for shards of a scan, a
    :class:`Labels` for those of a label volume.

    ``manifest`` is the path :func:`skelclimb.dask.extract` or :func:`skelclimb.dask.labels`
    returns with ``shards=``, or the ``manifest.json`` that ``skelclimb extract --shards``
    writes. The result is exactly what a single :func:`extract` or :func:`labels` of the whole
    volume gives with the settings the manifest records. One function for both kinds, as
    ``skelclimb merge`` is one command: the manifest names its kind, so a caller need not.
    Labels come back in the type the sweep ran on (the volume's own, but for int8, int64 and
    uint64 volumes, which :func:`labels` converts). A missing, damaged or foreign shard (of
    another volume, other settings or the other kind), or blocks missing or listed twice, raise
    ``OSError`` naming the file.

    >>> import numpy as np, tempfile, skelclimb, skelclimb.dask, dask.array as da
    >>> v = np.zeros((12, 12, 12), np.uint8); v[3:9, 3:9, 3:9] = 1
    >>> path = skelclimb.dask.extract(da.from_array(v, chunks=6), 1, shards=tempfile.mkdtemp())
    >>> skelclimb.merge_shards(path).faces.shape == skelclimb.extract(v, 1).faces.shape
    True
    >>> path = skelclimb.dask.labels(da.from_array(v, chunks=6), shards=tempfile.mkdtemp())
    >>> skelclimb.merge_shards(path)[1].faces.shape == skelclimb.labels(v)[1].faces.shape
    True
    """
    import os

    manifest = os.fsdecode(manifest)
    if _native.shard_kind(manifest) == "labels":
        from ._labels import _result

        return _result(_native.merge_label_shards(manifest))
    verts, faces, norms, stats = _native.merge_shards(manifest)
    return Mesh(verts, faces, norms, stats)


def release_memory():
    """Gives back now the memory of dropped meshes that skelclimb keeps for its next call.

    A mesh's arrays are NumPy's without a copy. When they are dropped, blocks of 4 MiB and more
    (up to 256 MiB in all) are kept for the next extraction, which then writes into pages it
    already has instead of fresh ones the system must zero first: on a mesh of 2.7 million
    triangles, a call takes 0.84 times as long. Returns how many bytes were freed.

    >>> import numpy as np, skelclimb
    >>> mesh = skelclimb.extract(np.random.default_rng(0).random((64, 64, 64)), 0.5)
    >>> del mesh
    >>> skelclimb.release_memory() > 0
    True
    """
    return _native.release_memory()


from ._blocks import BlockMesh, block_samples, extract_block  # noqa: E402  (needs Mesh above)
from ._labels import Atlas, Labels, labels  # noqa: E402  (needs Mesh and the checks above)
from ._skimage import marching_cubes  # noqa: E402  (needs extract above)
