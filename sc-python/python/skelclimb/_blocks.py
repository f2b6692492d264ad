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


def block_samples(grid, cubes, *, mode="embedded", max_box=None):
    """The samples a block reads, clipped to the grid.

    ``grid`` is the whole grid's ``(nx, ny, nz)``; ``cubes`` gives ``(start, end)`` per axis,
    ``x, y, z``, of the cubes (by lower corner, ``0 .. n - 1``) the block owns. Returns
    ``(start, end)`` sample ranges per axis. In every mode but ``"adaptive"``, one sample
    before the block and two past its far corners; in adaptive mode, a halo that grows with
    ``max_box`` (``2 * max_box + 2`` cubes before the block and ``3 * max_box + 2`` past it,
    rounded out to multiples of ``max_box``), for the balancing of boxes reaches that far.

    >>> block_samples((100, 100, 100), ((10, 20), (0, 99), (97, 99)))
    ((9, 23), (0, 100), (96, 100))
    >>> block_samples((100, 100, 100), ((20, 40), (0, 99), (97, 99)), mode="adaptive", max_box=4)
    ((8, 57), (0, 100), (84, 100))
    """
    from . import _index, _max_box, _mode

    _mode(mode)
    grid = tuple(_index(n, "grid") for n in grid)
    cubes = tuple((_index(a, "cubes"), _index(b, "cubes")) for a, b in cubes)
    if len(grid) != 3 or len(cubes) != 3:
        raise ValueError("grid and cubes: expected three entries each (x, y, z)")
    if min(grid + sum(cubes, ())) < 0:
        raise ValueError(f"grid and cubes: must not be negative, got {grid}, {cubes}")
    return tuple(_native.block_samples(grid, cubes, mode, _max_box(max_box)))


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
                  mode="embedded", normals=True, max_error=None, error_units="world",
                  max_box=None, allow_wrong_side=False):
    """Meshes the cubes ``cubes`` of a grid of ``grid`` samples from the samples around them.

    ``samples`` is a 3-D array laid out as for :func:`skelclimb.extract` (C order
    ``(z, y, x)``), holding the samples from global index ``at`` (``x, y, z``); it must cover
    :func:`block_samples` ``(grid, cubes, mode=mode, max_box=max_box)``. The other arguments are
    :func:`skelclimb.extract`'s and must be the same for every block of a grid.

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
    from . import _MODES, _bound, _index, _level, _max_box, _triple, _volume

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
        mode, bool(normals), _bound(max_error, error_units), _max_box(max_box),
        bool(allow_wrong_side),
    )
    return BlockMesh(share, mode, level, bool(normals))
