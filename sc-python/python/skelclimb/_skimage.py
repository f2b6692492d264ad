"""A drop-in for ``skimage.measure.marching_cubes``, meshing with Skeleton Climbing."""

from __future__ import annotations

import numpy as np

from . import _index, _level, _native, _triple, _volume

_METHODS = ("lewiner", "lorensen")

# scikit-image converts anything else to float32; we keep these types as they are.
_NATIVE_TYPES = tuple(
    np.dtype(t) for t in ("u1", "i1", "u2", "i2", "u4", "i4", "f4", "f8")
)


def marching_cubes(
    volume,
    level=None,
    *,
    spacing=(1.0, 1.0, 1.0),
    gradient_direction="descent",
    step_size=1,
    allow_degenerate=True,
    method="lewiner",
    mask=None,
    threads=0,
):
    """Skeleton Climbing with the signature and results of ``skimage.measure.marching_cubes``.

    Replace ``from skimage.measure import marching_cubes`` with
    ``from skelclimb import marching_cubes`` and a script keeps working, with about 25 % fewer
    triangles (Steps 1–4, embedded mode: a closed, consistently oriented surface where the
    volume's border is empty).

    Parameters
    ----------
    volume : (M, N, P) ndarray
        The data. uint8 to int32, float32 and float64 are meshed in their own type without a
        copy (C- or Fortran-ordered); other types are converted to float64, bool to uint8.
    level : float, optional
        The iso value; by default ``(volume.min() + volume.max()) / 2``. A level outside the
        data's range is a ``ValueError``, as in scikit-image.
    spacing : three floats
        Voxel spacing along the array's axes.
    gradient_direction : ``'descent'`` or ``'ascent'``
        Face winding, as scikit-image does it: ``descent`` (the object is where the data is
        greater) and ``ascent`` give opposite windings of the same triangles. Normals point
        down the gradient either way.
    step_size : int
        Mesh every ``step_size``-th sample along each axis (faster, coarser), as scikit-image.
    allow_degenerate : bool
        Accepted for compatibility. Skeleton Climbing never makes zero-area triangles (vertices
        stay at least 1/1024 of an edge from its ends), so there is nothing to remove.
    method : ``'lewiner'`` or ``'lorensen'``
        Checked, otherwise ignored: the surface is always Skeleton Climbing's.
    mask : (M, N, P) bool ndarray, optional
        A numeric mask is read as ``mask != 0``. Keep only triangles in cubes whose upper corner (the largest index along every axis) is
        True, as scikit-image does. A merged triangle spans two cubes and is kept when the cube
        holding its centroid is.
    threads : int
        Not in scikit-image: worker threads, 0 for all cores (the result is the same).

    Returns
    -------
    verts : (V, 3) float32 array
        Positions in the array's axis order, times ``spacing``.
    faces : (F, 3) int32 array
        Vertex indices.
    normals : (V, 3) float32 array
        Unit normals, in the array's axis order.
    values : (V,) float32 array
        The larger of the two samples at the ends of each vertex's grid edge, for colouring.
        (scikit-image takes a maximum over a larger neighbourhood; the figures differ.)
    """
    if not isinstance(volume, np.ndarray) or volume.ndim != 3:
        raise ValueError("Input volume should be a 3D numpy array.")
    if min(volume.shape) < 2:
        raise ValueError("Input array must be at least 2x2x2.")
    if method not in _METHODS:
        raise ValueError(f"method should be either 'lewiner' or 'lorensen', got {method!r}")
    if gradient_direction not in ("descent", "ascent"):
        raise ValueError("Incorrect input gradient_direction.")
    spacing = _triple(spacing, "spacing")
    if not all(np.isfinite(s) and s > 0 for s in spacing):
        raise ValueError(f"spacing: must be three positive numbers, got {spacing}")
    step_size = _index(step_size, "step_size")
    if step_size < 1:
        raise ValueError("step_size must be at least one.")
    threads = _native.threads(threads)
    if mask is not None:
        mask = np.asarray(mask)
        if mask.shape != volume.shape:
            raise ValueError("volume and mask must have the same shape.")
        if mask.dtype != np.bool_:
            # A mask of numbers is a truth value per sample, as NumPy reads it (``mask != 0``),
            # not a list of indices.
            if not np.issubdtype(mask.dtype, np.number):
                raise TypeError(f"mask: expected a bool or numeric array, got dtype {mask.dtype}")
            mask = mask != 0

    if volume.dtype == np.bool_:
        volume = volume.view(np.uint8)
    elif volume.dtype.newbyteorder("=") not in _NATIVE_TYPES:
        volume = volume.astype(np.float64)
    if step_size > 1:
        volume = volume[::step_size, ::step_size, ::step_size]
        if mask is not None:
            mask = mask[::step_size, ::step_size, ::step_size]
    volume = _volume(volume)

    if level is None:
        level = 0.5 * (float(volume.min()) + float(volume.max()))
    else:
        level = _level(level)

    # The native call works in (x, y, z) with x fastest in memory: the array's axes reversed
    # for a C-ordered array, as they are for a Fortran-ordered one. Ours wind outward from
    # `>= level` in (x, y, z). Reversing the axes of a C-ordered array is a reflection, which
    # turns the winding round; scikit-image's 'descent' winds inward in the array's axes
    # (negative signed volume), 'ascent' outward. Its normals point down the gradient either
    # way, as ours do. The sweep emits the coordinates in the array's order and the values as it
    # places each vertex; the winding is turned natively, on the triangles the extraction made.
    c_order = volume.flags.c_contiguous
    axes = [2, 1, 0] if c_order else [0, 1, 2]
    xyz_spacing = tuple(spacing[a] * step_size for a in axes)
    flip = c_order != (gradient_direction == "descent")
    verts, faces, normals, values = _native.skimage_mesh(
        volume, level, xyz_spacing, threads, c_order, flip
    )
    faces = faces.view(np.int32)  # uint32 indices below 2**31: the same bits, no copy
    if len(faces) == 0:
        # Only an empty surface can come from a level outside the data's range (a triangle needs
        # a sample below the level and one at or above it), so the range is read only then: two
        # passes over a large volume cost a fifth of the extraction.
        if level < volume.min() or level > volume.max():
            raise ValueError("Surface level must be within volume data range.")
        raise RuntimeError("No surface found at the given iso value.")
    if mask is not None:
        index = verts / np.asarray([s * step_size for s in spacing], dtype=np.float32)
        faces = _masked(faces, index, mask)
        verts, faces, normals, values = _compact(verts, faces, normals, values)
        if len(faces) == 0:
            raise RuntimeError("No surface found at the given iso value.")
    return verts, faces, normals, values


def _masked(faces, index, mask):
    """The faces whose centroid lies in a cube whose upper corner is True in ``mask``: cube
    ``(i, j, k)`` spans samples ``i..i+1`` (and so on), and scikit-image meshes it when
    ``mask[i + 1, j + 1, k + 1]`` is set."""
    centroid = index[faces].mean(axis=1)
    cube = np.floor(centroid).astype(np.int64)
    cube = np.clip(cube, 0, np.asarray(mask.shape) - 2)
    corner = cube + 1
    return faces[mask[corner[:, 0], corner[:, 1], corner[:, 2]]]


def _compact(verts, faces, normals, values):
    """Drops vertices no face uses, renumbering the faces."""
    used = np.zeros(len(verts), dtype=bool)
    used[faces.ravel()] = True
    new = np.cumsum(used) - 1
    return verts[used], new[faces].astype(np.int32), normals[used], values[used]
