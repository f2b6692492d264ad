"""Block extraction: one block of a large grid meshed on its own, and shares joined exactly.

A block's share names its vertices by the grid edge they lie on and its triangles by the cube
that owns them, so shares meshed in other processes or on other machines join, in any order,
into exactly the mesh :func:`skelclimb.extract` makes of the whole grid. The Dask driver
(:mod:`skelclimb.dask`) is built on this; it is public for other schedulers too.
"""

from __future__ import annotations

import numpy as np

from . import _native

__all__ = ["BlockMesh", "block_samples", "extract_block"]


def block_samples(grid, cubes):
    """The samples a block reads: one before it and two past its far corners, clipped.

    ``grid`` is the whole grid's ``(nx, ny, nz)``; ``cubes`` gives ``(start, end)`` per axis,
    ``x, y, z``, of the cubes (by lower corner, ``0 .. n - 1``) the block owns. Returns
    ``(start, end)`` sample ranges per axis.

    >>> block_samples((100, 100, 100), ((10, 20), (0, 99), (97, 99)))
    ((9, 23), (0, 100), (96, 100))
    """
    out = []
    for n, (a, b) in zip(grid, cubes):
        if not 0 <= a <= b <= n - 1:
            raise ValueError(f"cubes: ({a}, {b}) is not inside 0 .. {n - 1}")
        out.append((max(a - 1, 0), min(b + 3, n)))
    return tuple(out)


class BlockMesh:
    """One block's share of a mesh; picklable, so a scheduler can move it between processes.

    Join shares with :meth:`merge` (any order, any tree) and finish with :meth:`to_mesh` once
    they cover the grid.
    """

    __slots__ = ("_share", "mode", "level", "normals")

    def __init__(self, share, mode, level, normals):
        self._share = share
        self.mode = mode
        self.level = level
        self.normals = normals

    def __getstate__(self):
        return (self._share, self.mode, self.level, self.normals)

    def __setstate__(self, state):
        self._share, self.mode, self.level, self.normals = state

    def __repr__(self):
        return f"BlockMesh({len(self._share[1])} vertices, {len(self._share[4])} triangles)"

    @property
    def triangles(self):
        """Triangles this share owns."""
        return len(self._share[4])

    def merge(self, *others):
        """The union of this share and ``others``: a share of the cubes they cover together."""
        for o in others:
            if (o.mode, o.level, o.normals) != (self.mode, self.level, self.normals):
                raise ValueError("merge: block meshes made with different settings")
        joined = _native.merge_blocks([self._share, *(o._share for o in others)])
        return BlockMesh(joined, self.mode, self.level, self.normals)

    def to_mesh(self):
        """The whole mesh; an error unless the joined shares cover every cube of the grid."""
        from . import Mesh

        verts, faces, norms, stats = _native.finish_blocks(self._share, self.mode, self.level)
        return Mesh(verts, faces, norms if self.normals else None, stats)


def extract_block(samples, level, *, at, grid, cubes, spacing=(1, 1, 1), origin=(0, 0, 0),
                  mode="embedded", normals=True, max_error=None, error_units="world"):
    """Meshes the cubes ``cubes`` of a grid of ``grid`` samples from the samples around them.

    ``samples`` is a 3-D array laid out as for :func:`skelclimb.extract` (C order
    ``(z, y, x)``), holding the samples from global index ``at`` (``x, y, z``); it must cover
    :func:`block_samples` ``(grid, cubes)``. The other arguments are :func:`skelclimb.extract`'s
    and must be the same for every block of a grid.

    >>> import numpy as np, skelclimb
    >>> v = np.zeros((10, 10, 10), np.uint8); v[2:8, 2:8, 2:8] = 1
    >>> grid, halves = (10, 10, 10), (((0, 9), (0, 9), (0, 4)), ((0, 9), (0, 9), (4, 9)))
    >>> parts = []
    >>> for cubes in halves:
    ...     (x0, x1), (y0, y1), (z0, z1) = block_samples(grid, cubes)
    ...     parts.append(extract_block(v[z0:z1, y0:y1, x0:x1], 1, at=(x0, y0, z0), grid=grid, cubes=cubes))
    >>> whole = skelclimb.extract(v, 1)
    >>> joined = parts[0].merge(parts[1]).to_mesh()
    >>> bool((joined.vertices == whole.vertices).all() and (joined.faces == whole.faces).all())
    True
    """
    from . import _MODES, _bound, _index, _level, _triple, _volume

    samples = _volume(samples, "samples")
    level = _level(level)
    if mode not in _MODES:
        raise ValueError(f"mode: expected one of {', '.join(map(repr, _MODES))}, got {mode!r}")
    at = tuple(_index(a, "at") for a in at)
    grid = tuple(_index(n, "grid") for n in grid)
    cubes = tuple((_index(a, "cubes"), _index(b, "cubes")) for a, b in cubes)
    if len(at) != 3 or len(grid) != 3 or len(cubes) != 3:
        raise ValueError("at, grid and cubes: expected three entries each (x, y, z)")
    if min(at + grid + sum(cubes, ())) < 0:
        raise ValueError(f"at, grid and cubes: must not be negative, got {at}, {grid}, {cubes}")
    share = _native.extract_block(
        samples, at, grid, cubes, level, _triple(spacing, "spacing"), _triple(origin, "origin"),
        mode, bool(normals), _bound(max_error, error_units),
    )
    return BlockMesh(share, mode, level, bool(normals))
