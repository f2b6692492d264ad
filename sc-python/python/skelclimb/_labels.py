"""Label volumes: every region of a segmentation meshed in one sweep (``docs/labels.md``)."""

from __future__ import annotations

import operator
from collections.abc import Mapping

import numpy as np

from . import Mesh, _index, _mode, _native, _placement, _volume

# The label types the runtime sweeps as they are, smallest first: a volume of another integer
# type is converted to the first of them that holds its values and the background.
_LABEL_TYPES = tuple(np.dtype(t) for t in ("u1", "i2", "u2", "i4", "u4", "u8"))


class Atlas:
    """The surfaces between the regions of a label volume, each interface once.

    Attributes
    ----------
    vertices : (V, 3) float32 array
        Positions, ``(x, y, z)``, as :func:`skelclimb.extract` places them. A vertex on an
        interface exists once, shared by the meshes of the labels on both sides.
    faces : (T, 3) uint32 array
        Vertex indices, wound so that ``(b - a) × (c - a)`` points from ``face_labels[t, 0]``
        to ``face_labels[t, 1]``.
    face_labels : (T, 2) array of the volume's dtype
        Per triangle, the label it faces away from, then the label it faces toward. The
        background is a label here like any other.
    """

    __slots__ = ("vertices", "faces", "face_labels")

    def __init__(self, vertices, faces, face_labels):
        self.vertices = vertices
        self.faces = faces
        self.face_labels = face_labels

    def __repr__(self):
        return f"Atlas({len(self.vertices)} vertices, {len(self.faces)} triangles)"


class Labels(Mapping):
    """The meshes of a label volume's regions, from :func:`labels`.

    A mapping from label (a Python ``int``) to that label's closed :class:`Mesh`, in ascending
    order of label: ``result[7]``, ``len(result)``, ``for label in result``, ``result.items()``.

    The meshes are cut from the atlas the first time one is asked for (``result[7]``,
    ``.items()``, ``.values()``, :meth:`to_pyvista`): every label's at once, with the GIL
    released and the ``threads`` of the call, then kept. Until then a result holds only the
    atlas, and :meth:`labels`, ``len``, ``in``, the keys, :attr:`atlas` and :attr:`stats` cut
    nothing. The meshes share no memory with the atlas: together they hold up to twice its
    triangles, as an interface between two labels is in both their meshes. They are cut from
    the atlas's own arrays, so change those in place only after the meshes are cut, or on a
    copy.

    Attributes
    ----------
    atlas : Atlas
        The shared vertices, the triangles and their two labels; each label's mesh is its
        atlas triangles with that label first, plus those with it second, turned over.
    stats : dict
        As :attr:`Mesh.stats` for the whole atlas (``steps123``, ``result``, ``merged``,
        ``blocked``, ``bounded``, ``reduction_percent``, ``mode``, ``dims``, ``space``), and
        ``background``.
    """

    __slots__ = ("_meshes", "_labels", "_keys", "_cut", "atlas", "stats")

    def __init__(self, atlas, stats, chosen, cut):
        """``chosen``: the labels to mesh, ascending, as an array of the type the atlas was
        swept in; ``cut``: the rest of ``_native.label_meshes``' arguments."""
        self.atlas = atlas
        self.stats = stats
        self._labels = chosen.tolist()
        self._keys = frozenset(self._labels)
        self._cut = (atlas.vertices, atlas.faces, atlas.face_labels, chosen, cut)
        self._meshes = None

    def _built(self):
        """The meshes by label, cut the first time they are asked for."""
        if self._meshes is None:
            vertices, faces, face_labels, chosen, cut = self._cut
            # The labels' own type, if they were converted back to the volume's.
            face_labels = face_labels.astype(chosen.dtype, copy=False)
            meshes = _native.label_meshes(vertices, faces, face_labels, chosen, *cut)
            self._meshes = {label: Mesh(v, f, n, s) for label, v, f, n, s in meshes}
        return self._meshes

    def __getitem__(self, label):
        try:
            key = operator.index(label)
        except TypeError:
            key = None
        if key not in self._keys:
            shown = ", ".join(map(str, self._labels[:10]))
            more = ", …" if len(self._labels) > 10 else ""
            raise KeyError(
                f"label {label!r} has no mesh here; meshed: {shown or 'none'}{more}"
            )
        return self._built()[key]

    def __contains__(self, label):
        try:
            return operator.index(label) in self._keys
        except TypeError:
            return False

    def __iter__(self):
        return iter(self._labels)

    def __len__(self):
        return len(self._labels)

    def __repr__(self):
        return f"Labels({len(self)} labels, {self.atlas!r})"

    def labels(self):
        """The labels meshed, ascending (known from the atlas: no mesh is cut for them)."""
        return list(self._labels)

    def to_pyvista(self):
        """The meshes as a ``pyvista.MultiBlock``, one block per label, named by the label
        (needs the ``pyvista`` package)."""
        import pyvista

        blocks = pyvista.MultiBlock()
        for label, mesh in self._built().items():
            blocks.append(mesh.to_pyvista(), str(label))
        return blocks


def _label_volume(volume, background):
    """``volume`` as a 3-D array of a label type the native code borrows, and its own dtype."""
    if isinstance(volume, np.ndarray):
        _integers(volume.dtype, "volume")
    volume = _volume(volume)
    dtype = volume.dtype
    target = _label_type(dtype, background, lambda: (volume.min(), volume.max()), volume.size,
                         "volume")
    # astype keeps the memory order, so the axes read the same.
    return (volume if target == dtype else volume.astype(target)), dtype


def _integers(dtype, name):
    """A ``TypeError`` naming ``name`` unless ``dtype`` is an integer type."""
    if dtype.kind not in "iu":
        raise TypeError(
            f"{name} holds {dtype}; label volumes need integers "
            "(uint8, uint16, uint32, uint64, int16, int32; other integer types are converted)"
        )


def _label_type(dtype, background, bounds, size, name):
    """The label type a volume of integer ``dtype`` is meshed as: its own if the runtime takes
    it, else the smallest that holds its values and the background; ``bounds()`` gives the
    values' least and greatest, and is only called then (``size``: the number of samples)."""
    info = np.iinfo(dtype)
    if not info.min <= background <= info.max:
        raise ValueError(f"background: {background} is not a value of the {name}'s {dtype}")
    if dtype in _LABEL_TYPES:
        return dtype
    low, high = (int(b) for b in bounds()) if size else (background, background)
    low, high = min(low, background), max(high, background)
    for target in _LABEL_TYPES:
        t = np.iinfo(target)
        if t.min <= low and high <= t.max:
            return target
    raise ValueError(
        f"{name}: its {dtype} labels run from {low} to {high}, which no label type holds "
        "(uint8, uint16, uint32, uint64, int16, int32)"
    )


def _selection(labels):
    """The labels asked for, as Python ints, or None for all."""
    if labels is None:
        return None
    if isinstance(labels, (str, bytes, bytearray)):
        raise TypeError(f"labels: expected an iterable of whole numbers, got {labels!r}")
    try:
        items = iter(labels)
    except TypeError:
        raise TypeError(f"labels: expected an iterable of whole numbers, got {labels!r}") from None
    return sorted({_index(v, "labels") for v in items})


def _smoothing(width):
    """``width`` as a float in 0..=4, or a ``TypeError``/``ValueError`` naming ``smoothing``."""
    if isinstance(width, bool) or not isinstance(width, (int, float, np.integer, np.floating)):
        raise TypeError(f"smoothing: {width!r} is not a number")
    width = float(width)
    if not 0.0 <= width <= 4.0:
        raise ValueError(f"smoothing: {width} is not a width in voxels from 0 to 4")
    return width


def labels(
    volume,
    *,
    affine=None,
    space=None,
    spacing=None,
    origin=None,
    labels=None,
    background=0,
    mode="embedded",
    pad=True,
    normals=True,
    threads=0,
    smoothing=0,
):
    """Meshes every region of a label volume in one sweep: a closed mesh per label, whose
    neighbours share their interfaces exactly.

    Parameters
    ----------
    volume : 3-D integer ndarray
        One region per value. Its axes, ``affine``, ``space``, ``spacing`` and ``origin`` are
        read as :func:`skelclimb.extract` reads them: a C-ordered array of shape
        ``(nz, ny, nx)`` or a Fortran-ordered one of shape ``(nx, ny, nz)``. uint8, uint16,
        uint32, uint64, int16 and int32 are used **without copying** when contiguous; other
        integer types (int8, int64) are converted to the smallest of those that holds every
        value and the background (a ``ValueError`` if none does). Float and bool arrays are a
        ``TypeError``: labels are integers.
    affine, space, spacing, origin
        Where the samples sit, exactly as for :func:`skelclimb.extract`.
    labels : iterable of int, optional
        The labels to mesh; each must have a surface in the volume (a ``ValueError`` lists some
        that do). By default every label but the background.
    background : int
        The label of "no region" (default 0): never meshed, and what lies outside the volume.
    mode : ``"embedded"`` (default), ``"paper"`` or ``"steps123"``
        ``embedded`` merges grey edges only where every label's surface stays a closed
        2-manifold, ``paper`` wherever the four cubes around an edge hold two labels,
        ``steps123`` nowhere.
    pad : bool
        Surround the volume with background (default, without a copy), so every label's mesh
        is closed where it touches the volume's border.
    normals : bool
        Per-vertex normals of each label's mesh, pointing out of the label (area-weighted).
    threads : int
        Threads to build the atlas and cut the meshes on, 0 (the default) for every core; the
        result does not depend on it.
    smoothing : float
        0 (the default) puts every vertex at the midpoint of its grid edge. A width in voxels
        (up to 4; 0.75 gives spheres their area within 1 %) slides each vertex along its own
        edge to where the Gaussian-smoothed regions on either side balance: every sample stays
        on its own side, and the triangles are the same.

    Returns
    -------
    Labels
        ``result[label]`` is that label's :class:`Mesh`; ``result.atlas`` holds every interface
        once. The call builds the atlas, with the GIL released; the meshes are cut from it the
        first time one is asked for, all at once, again with the GIL released and ``threads``
        (see :class:`Labels`). A selection is checked here, whether or not a mesh is asked for.

    Examples
    --------
    >>> import numpy as np, skelclimb
    >>> v = np.zeros((6, 6, 8), np.uint8); v[1:5, 1:5, 1:4] = 1; v[1:5, 1:5, 4:7] = 2
    >>> result = skelclimb.labels(v)
    >>> result.labels()
    [1, 2]

    The interface between 1 and 2 is in the atlas once, and in both meshes:

    >>> between = int(np.isin(result.atlas.face_labels, [1, 2]).all(axis=1).sum())
    >>> len(result[1].faces) + len(result[2].faces) == len(result.atlas.faces) + between > 0
    True
    """
    background = _index(background, "background")
    volume, dtype = _label_volume(volume, background)
    selection = _selection(labels)
    affine, spacing, origin = _placement(affine, spacing, origin)
    _mode(mode)
    return _result(_native.labels(
        volume, spacing, origin, background, mode, bool(pad), bool(normals), threads,
        _smoothing(smoothing), selection,
        None if affine is None else affine[:3].tolist(), space,
    ), dtype)


def _result(native, dtype=None):
    """The :class:`Labels` of what ``_native.labels`` returns, its labels of ``dtype`` (by
    default, of the type they come in); the meshes are cut when first asked for."""
    verts, faces, face_labels, chosen, cut, stats = native
    if dtype is not None and face_labels.dtype != dtype:
        face_labels = face_labels.astype(dtype)
    return Labels(Atlas(verts, faces, face_labels), stats, chosen, cut)
