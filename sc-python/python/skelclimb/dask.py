"""Meshing a ``dask.array`` one task per block, on whatever Dask scheduler is active.

Each task reads its chunk plus a thin halo (one sample before, two after), meshes it with
:func:`skelclimb.extract_block`, and returns a compact share keyed by global grid edges; a tree
of merges joins the shares into exactly the mesh :func:`skelclimb.extract` makes of the whole
array, whatever the chunking, the scheduler (threads, processes, a ``distributed`` cluster) or
the order tasks finish in. Dask retries a task whose worker dies; since tasks are pure, the
result is still exact.

>>> import dask.array as da, numpy as np, skelclimb.dask
>>> z, y, x = np.mgrid[-1:1:48j, -1:1:48j, -1:1:48j]
>>> ball = da.from_array((0.8 - np.sqrt(x * x + y * y + z * z)).astype(np.float32), chunks=16)
>>> mesh = skelclimb.dask.extract(ball, 0.0)
>>> mesh.stats["result"]["triangles"] == skelclimb.extract(ball.compute(), 0.0).stats["result"]["triangles"]
True
"""

from __future__ import annotations

import numpy as np

from ._blocks import block_samples, extract_block

__all__ = ["extract"]


def _mesh(samples, at, grid, cubes, options):
    return extract_block(np.asarray(samples), at=at, grid=grid, cubes=cubes, **options)


def _merge(*shares):
    return shares[0].merge(*shares[1:])


def _finish(share):
    return share.to_mesh()


def _cube_ranges(chunks, n):
    """Per chunk along one axis, the cubes it owns: those whose lower corner it holds."""
    out, start = [], 0
    for size in chunks:
        out.append((start, min(start + size, n - 1)))
        start += size
    return [r for r in out if r[0] < r[1]]


def extract(array, level, *, spacing=(1, 1, 1), origin=(0, 0, 0), mode="embedded",
            normals=True, max_error=None, error_units="world", split_every=8, compute=True):
    """Meshes the surface ``array == level`` of a 3-D ``dask.array``, block by block.

    Parameters
    ----------
    array : dask.array.Array
        Axes ``(z, y, x)`` as for a C-ordered array in :func:`skelclimb.extract` (so
        ``dask.array.from_zarr`` of a ZYX store works as it is). One task per chunk; chunks of
        64³–256³ samples balance task overhead against memory per task.
    level, spacing, origin, mode, normals, max_error, error_units
        As for :func:`skelclimb.extract`; spacing and origin are ``(x, y, z)``.
    split_every : int
        How many shares each merge task joins (the fan-in of the reduction tree).
    compute : bool
        Return the :class:`skelclimb.Mesh`; with ``False``, a ``dask.delayed`` object that
        computes it, to combine with other work.

    Returns
    -------
    skelclimb.Mesh
        Identical, vertex for vertex and triangle for triangle, to ``skelclimb.extract`` of the
        whole array.
    """
    import dask

    from . import _MODES, _bound, _level, _triple

    level = _level(level)
    spacing, origin = _triple(spacing, "spacing"), _triple(origin, "origin")
    if mode not in _MODES:
        raise ValueError(f"mode: expected one of {', '.join(map(repr, _MODES))}, got {mode!r}")
    if array.ndim != 3:
        raise ValueError(f"array: expected 3 dimensions, got {array.ndim}")
    if int(split_every) < 2:
        raise ValueError(f"split_every: must be at least 2, got {split_every}")
    nz, ny, nx = array.shape
    grid = (nx, ny, nz)
    if min(grid) < 2:
        raise ValueError(f"array: every axis needs at least 2 samples, got shape {array.shape}")
    _bound(max_error, error_units)
    options = dict(level=level, spacing=spacing, origin=origin, mode=mode, normals=normals,
                   max_error=max_error, error_units=error_units)
    zc, yc, xc = array.chunks
    mesh = dask.delayed(_mesh, pure=True)
    shares = []
    for cz in _cube_ranges(zc, nz):
        for cy in _cube_ranges(yc, ny):
            for cx in _cube_ranges(xc, nx):
                cubes = (cx, cy, cz)
                (x0, x1), (y0, y1), (z0, z1) = block_samples(grid, cubes)
                shares.append(mesh(array[z0:z1, y0:y1, x0:x1], (x0, y0, z0), grid, cubes,
                                   options))
    merge = dask.delayed(_merge, pure=True)
    while len(shares) > 1:
        shares = [merge(*shares[i:i + split_every])
                  for i in range(0, len(shares), int(split_every))]
    result = dask.delayed(_finish, pure=True)(shares[0])
    return result.compute() if compute else result
