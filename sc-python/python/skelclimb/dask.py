"""Meshing a ``dask.array`` one task per block, on whatever Dask scheduler is active.

Each task reads its chunk plus a halo (one sample before, three after; in adaptive mode up to
``3 * max_box + 1`` before and ``4 * max_box + 2`` after), meshes it with
:func:`skelclimb.extract_block`, and returns a compact share keyed by global grid edges; a tree
of merges joins the shares into exactly the mesh :func:`skelclimb.extract` makes of the whole
array, whatever the chunking, the scheduler (threads, processes, a ``distributed`` cluster) or
the order tasks finish in. Dask retries a task whose worker dies; since tasks are pure, the
result is still exact. For a mesh too large for one machine, ``shards=DIR`` has each task
write its share to a file instead, joined later by :func:`skelclimb.merge_shards` or
``skelclimb merge``.

>>> import dask.array as da, numpy as np, skelclimb.dask
>>> z, y, x = np.mgrid[-1:1:48j, -1:1:48j, -1:1:48j]
>>> ball = da.from_array((0.8 - np.sqrt(x * x + y * y + z * z)).astype(np.float32), chunks=16)
>>> mesh = skelclimb.dask.extract(ball, 0.0)
>>> mesh.stats["result"]["triangles"] == skelclimb.extract(ball.compute(), 0.0).stats["result"]["triangles"]
True
"""

from __future__ import annotations

import os

import numpy as np

from . import _native
from ._blocks import extract_block

__all__ = ["extract", "labels"]


def _halo(mode, max_box):
    """Samples before and past a chunk's sides that its cubes read, the most wherever the chunk
    starts: from what the runtime says one-cube blocks in the middle of a large grid read
    (:func:`skelclimb.block_samples`). Adaptive mode's halo is rounded out to the lattice of
    its largest box (at most 16 cubes), so sixteen starts in a row meet every rounding."""
    from ._blocks import block_samples

    before = after = 0
    for s in range(512, 528):
        need = block_samples((1024,) * 3, ((s, s + 1),) * 3, mode=mode, max_box=max_box)[0]
        before, after = max(before, s - need[0]), max(after, need[1] - (s + 1))
    return before, after


# A neighbour's place relative to a block, per axis (z, y, x): -1 before it, +1 after it.
_OFFSETS = [tuple(c - 1 for c in o) for o in np.ndindex(3, 3, 3) if o != (1, 1, 1)]


def _shell(block, before, after):
    """The pieces of ``block`` its 26 neighbours read, one per offset in ``_OFFSETS`` (the
    offset at which the reading block sees this one): thin faces, edges and corners, copied so
    that they do not keep the chunk alive. Along an axis, a neighbour after this block reads
    its last ``before`` samples, one level with it all of them, one before it its first
    ``after``."""
    pick = {-1: slice(-before, None), 0: slice(None), 1: slice(0, after)}
    b = np.asarray(block)
    return [b[tuple(pick[c] for c in o)].copy() for o in _OFFSETS]


def _extended(block, shells):
    """``block`` with its halo, in one array: ``shells`` holds, per offset in ``_OFFSETS``, that
    neighbour's :func:`_shell` (``None`` past the grid's ends); each piece is copied once."""
    core = np.asarray(block)
    pieces = {o: s[n] for n, (o, s) in enumerate(zip(_OFFSETS, shells)) if s is not None}
    if not pieces:
        return core

    def thickness(axis, side):
        piece = pieces.get(tuple(side if d == axis else 0 for d in range(3)))
        return 0 if piece is None else piece.shape[axis]

    # Per axis, the samples from the neighbour before, the chunk's, the neighbour after's.
    sizes = [(thickness(a, -1), core.shape[a], thickness(a, 1)) for a in range(3)]
    out = np.empty([sum(n) for n in sizes], core.dtype)

    def region(offset):
        """Where the piece of the neighbour at ``offset`` (``(0, 0, 0)``: the chunk) goes."""
        return tuple(slice(sum(n[:side + 1]), sum(n[:side + 2]))
                     for n, side in zip(sizes, offset))

    out[region((0, 0, 0))] = core
    for offset, piece in pieces.items():
        out[region(offset)] = piece
    return out


def _mesh(block, at, grid, cubes, *shells_and_options):
    """Meshes a block from its chunk and its neighbours' shells."""
    *shells, options = shells_and_options
    return extract_block(_extended(block, shells), at=at, grid=grid, cubes=cubes, **options)


def _native_settings(options):
    """The settings as the native shard writer takes them: one tuple, in extract_block's order."""
    from . import _bound

    return (options["level"], options["spacing"], options["origin"], options["mode"],
            bool(options["normals"]), _bound(options["max_error"], options["error_units"]))


def _label_settings(o):
    """A label volume's settings as the native label shard writer takes them: one tuple."""
    return (o["background"], o["mode"], o["pad"], o["spacing"], o["origin"], o["smoothing"],
            o["affine"], o["space"], o["normals"], o["selection"])


def _surface_shard(share, directory, cubes, options):
    return _native.write_shard(share._share, directory, cubes, _native_settings(options))


def _surface_manifest(directory, grid, records, options):
    return _native.write_manifest(directory, grid, records, _native_settings(options))


def _label_shard(share, directory, cubes, options):
    return _native.write_label_shard(share, directory, cubes, _label_settings(options))


def _label_manifest(directory, grid, records, options):
    return _native.write_label_manifest(directory, grid, records, options["dtype"],
                                        _label_settings(options))


def _shard(directory, mesh, write, block, at, grid, cubes, *shells_and_options):
    """Meshes one block with ``mesh`` and writes its share as a shard with ``write`` (one of
    the ``_*_shard`` functions); returns only the manifest's small record, so the worker keeps
    no mesh."""
    share = mesh(block, at, grid, cubes, *shells_and_options)
    return write(share, directory, cubes, shells_and_options[-1])


def _manifest(directory, write, grid, options, *records):
    """Writes the manifest listing ``records`` with ``write`` (a ``_*_manifest`` function)."""
    return str(write(directory, grid, list(records), options))


def _merge(*shares):
    return shares[0].merge(*shares[1:]) if len(shares) > 1 else shares[0]


def _finish(share):
    return share.to_mesh()


def _starts(chunks):
    """Each chunk's first sample along one axis."""
    return np.cumsum((0,) + tuple(chunks[:-1])).tolist()


def _cube_ranges(chunks, n, pad=False):
    """Per chunk along one axis, the cubes it owns: those whose lower corner it holds. With
    ``pad``, the grid's cubes are those of the padded grid, cube ``c`` lying between samples
    ``c - 1`` and ``c``: the first chunk also owns cube 0, whose lower corner is padding."""
    if not pad:
        return [(s, min(s + size, n - 1)) for s, size in zip(_starts(chunks), chunks)]
    return [(0 if s == 0 else s + 1, s + size + 1) for s, size in zip(_starts(chunks), chunks)]


def _at_least(chunks, m):
    """``chunks`` with any chunk smaller than ``m`` joined to its neighbour, so that a halo of
    ``m`` samples comes from one neighbour only."""
    out = []
    for c in chunks:
        if out and (out[-1] < m or c < m):
            out[-1] += c
        else:
            out.append(c)
    return tuple(out)


def extract(array, level, *, spacing=(1, 1, 1), origin=(0, 0, 0), mode="embedded",
            normals=True, max_error=None, error_units="world", max_box=None,
            allow_wrong_side=False, split_every=8, shards=None, compute=True):
    """Meshes the surface ``array == level`` of a 3-D ``dask.array``, block by block.

    Parameters
    ----------
    array : dask.array.Array or numpy.ndarray
        A NumPy array is wrapped with ``dask.array.from_array`` (automatic chunks). Axes ``(z, y, x)`` as for a C-ordered array in :func:`skelclimb.extract` (so
        ``dask.array.from_zarr`` of a ZYX store works as it is). One task per chunk; chunks of
        64³–256³ samples balance task overhead against memory per task.
    level, spacing, origin, mode, normals, max_error, error_units, max_box, allow_wrong_side
        As for :func:`skelclimb.extract`; spacing and origin are ``(x, y, z)``. In adaptive
        mode a chunk reads a wider halo (up to 49 samples before it and 66 past it with boxes
        of 16 cubes, see :func:`skelclimb.block_samples`), and chunks smaller than that are
        joined to their neighbours.
    split_every : int
        How many shares each merge task joins (the fan-in of the reduction tree).
    shards : str or os.PathLike, optional
        A directory (made if missing) on storage every worker can write to. Each task then
        writes its block's share there as a shard file and returns only a small record, and
        the result is the path of ``manifest.json`` listing them: no process holds the mesh.
        Join the shards with :func:`skelclimb.merge_shards` or ``skelclimb merge`` on a
        machine that can hold the result.
    compute : bool
        Return the result; with ``False``, a ``dask.delayed`` object that computes it, to
        combine with other work.

    Returns
    -------
    skelclimb.Mesh or str
        The mesh, identical vertex for vertex and triangle for triangle to
        ``skelclimb.extract`` of the whole array; with ``shards``, the manifest's path, whose
        shards join into that same mesh.

    Examples
    --------
    >>> import dask.array as da, numpy as np, os, tempfile, skelclimb, skelclimb.dask
    >>> z, y, x = np.mgrid[-1:1:40j, -1:1:40j, -1:1:40j]
    >>> ball = (0.8 - np.sqrt(x * x + y * y + z * z)).astype(np.float32)
    >>> parts = os.path.join(tempfile.mkdtemp(), "parts")
    >>> manifest = skelclimb.dask.extract(da.from_array(ball, chunks=16), 0.0, shards=parts)
    >>> joined, whole = skelclimb.merge_shards(manifest), skelclimb.extract(ball, 0.0)
    >>> bool((joined.vertices == whole.vertices).all() and (joined.faces == whole.faces).all())
    True
    """
    from dask.base import tokenize

    from . import _MODES, _bound, _level, _triple

    array = _dask_array(array)
    level = _level(level)
    spacing, origin = _triple(spacing, "spacing"), _triple(origin, "origin")
    if mode not in _MODES:
        raise ValueError(f"mode: expected one of {', '.join(map(repr, _MODES))}, got {mode!r}")
    if array.ndim != 3:
        raise ValueError(f"array: expected 3 dimensions, got {array.ndim}")
    split_every = _split_every(split_every)
    nz, ny, nx = array.shape
    grid = (nx, ny, nz)
    if min(grid) < 2:
        raise ValueError(f"array: every axis needs at least 2 samples, got shape {array.shape}")
    _bound(max_error, error_units)
    before, after = _halo(mode, max_box)
    options = dict(level=level, spacing=spacing, origin=origin, mode=mode, normals=normals,
                   max_error=max_error, error_units=error_units, max_box=max_box,
                   allow_wrong_side=bool(allow_wrong_side))
    directory = None if shards is None else os.fspath(shards)
    if directory is not None:
        os.makedirs(directory, exist_ok=True)
    token = tokenize(array.name, options, split_every, directory)
    shards = None if directory is None else (directory, _surface_shard, _surface_manifest)
    array, name, blocks, shares = _blocks(
        array, token, before, after, False, _mesh, options, shards)
    return _run(array, name, blocks, shares, token, split_every, compute, _merge, _finish,
                shards=shards, grid=grid, options=options)


def labels(array, *, affine=None, space=None, spacing=None, origin=None, labels=None,
           background=0, mode="embedded", pad=True, normals=True, smoothing=0, split_every=8,
           shards=None, compute=True):
    """Meshes every region of a 3-D integer ``dask.array``, block by block: exactly what
    :func:`skelclimb.labels` makes of the whole array.

    Each task reads its chunk plus a halo (two samples before, three after; with
    ``smoothing``, one more than the Gaussian's reach ``ceil(3 * smoothing)`` when that is
    further) and meshes the cubes it owns into a share of the atlas; a tree of merges joins the
    shares, and the meshes per label are cut from the joined atlas where the result is wanted,
    the first time one is asked for (as :class:`skelclimb.Labels` says).

    Parameters
    ----------
    array : dask.array.Array or numpy.ndarray
        Axes ``(z, y, x)``, as for :func:`skelclimb.dask.extract`. uint8, uint16, uint32,
        uint64, int16 and int32 are meshed as they are; other integer types are converted to
        the smallest of those holding every value and the background, which costs one more
        pass over the array to find its least and greatest label. Float and bool arrays are a
        ``TypeError``.
    affine, space, spacing, origin, labels, background, mode, pad, normals, smoothing
        As for :func:`skelclimb.labels`.
    split_every : int
        How many shares each merge task joins (the fan-in of the reduction tree).
    shards : str or os.PathLike, optional
        A directory (made if missing) on storage every worker can write to. Each task then
        writes its block's share of the atlas there as a label shard, the files
        ``skelclimb extract --labels --shards`` writes, and the result is the path of
        ``manifest.json`` listing them. :func:`skelclimb.merge_shards` joins them into the
        :class:`skelclimb.Labels` this call would return, ``skelclimb merge`` into the files
        ``skelclimb extract --labels`` writes. Label shards hold the labels of the command
        line: uint64 volumes, negative labels and a negative background are a ``ValueError``
        here, and a volume holding negative labels merges in Python only. A selection
        (``labels``) naming a label without a surface is reported by the merge.
    compute : bool
        Return the result; with ``False``, a ``dask.delayed`` object that computes it.

    Returns
    -------
    skelclimb.Labels or str
        Equal, vertex for vertex and triangle for triangle, to ``skelclimb.labels`` of the
        whole array with the same arguments, whatever the chunking; with ``shards``, the
        manifest's path.

    Examples
    --------
    >>> import dask.array as da, numpy as np, skelclimb, skelclimb.dask
    >>> v = np.zeros((12, 12, 12), np.uint8); v[2:9, 2:9, 2:6] = 1; v[2:9, 2:9, 6:10] = 2
    >>> joined = skelclimb.dask.labels(da.from_array(v, chunks=5))
    >>> whole = skelclimb.labels(v)
    >>> bool((joined.atlas.vertices == whole.atlas.vertices).all()) and joined.labels()
    [1, 2]
    """
    from dask.base import tokenize

    from . import _index, _mode, _placement
    from ._labels import _integers, _label_type, _selection, _smoothing

    given = dict(affine=affine, space=space, spacing=spacing, origin=origin, labels=labels,
                 background=background, mode=mode, pad=pad, normals=normals,
                 smoothing=smoothing)
    array = _dask_array(array)
    if array.ndim != 3:
        raise ValueError(f"array: expected 3 dimensions, got {array.ndim}")
    _integers(array.dtype, "array")
    background = _index(background, "background")
    dtype = array.dtype
    target = _label_type(dtype, background, lambda: _bounds(array), array.size, "array")
    source = array
    if target != dtype:
        array = array.astype(target)
    selection = _selection(labels)
    affine, spacing, origin = _placement(affine, spacing, origin)
    _mode(mode)
    smoothing = _smoothing(smoothing)
    split_every = _split_every(split_every)
    affine = None if affine is None else affine[:3].tolist()
    nz, ny, nx = array.shape
    grid = (nx, ny, nz)
    pad = bool(pad)
    # The halo, from the samples the runtime says a block in the middle of a large grid reads.
    middle = ((50, 51),) * 3
    need = _native.label_block_samples((100,) * 3, middle, pad, smoothing)[0]
    before, after = 50 - pad - need[0], need[1] - 51 + pad
    block = dict(spacing=spacing, origin=origin, background=background, mode=mode, pad=pad,
                 smoothing=smoothing, affine=affine, space=space)
    finish = dict(background=background, mode=mode, normals=bool(normals), selection=selection,
                  affine=affine, space=space, dtype=dtype)
    directory = None if shards is None else os.fspath(shards)
    if directory is not None:
        block.update(_label_shard_settings(target, background, selection), normals=bool(normals))
        os.makedirs(directory, exist_ok=True)
    token = tokenize(array.name, block, finish, split_every, directory)
    shards = None if directory is None else (directory, _label_shard, _label_manifest)
    array, name, blocks, shares = _blocks(
        array, token, before, after, pad, _label_mesh, block, shards)
    if not shares and shards is None:
        # No cube at all (an axis of one sample, unpadded): no blocks to split it into.
        import dask

        from . import labels as whole

        result = dask.delayed(whole)(source, **given)
        return result.compute() if compute else result
    return _run(array, name, blocks, shares, token, split_every, compute, _label_merge,
                lambda share: _label_finish(share, finish), shards=shards, grid=grid,
                options=block)


def _label_shard_settings(dtype, background, selection):
    """What label shards record besides the sweep's settings: the label type, the selection;
    a ``ValueError`` for the labels they cannot hold (as the command line's ``--labels`` and
    ``--background``: 0 or more, in uint8, int16, uint16, uint32 or int32)."""
    if dtype == np.uint64:
        raise ValueError("shards: the array's labels are uint64; label shards hold uint8, "
                         "int16, uint16, uint32 or int32")
    if background < 0:
        raise ValueError(f"shards: background {background} is negative; label shards hold "
                         "labels 0 or more")
    if selection is not None:
        if not selection:
            raise ValueError("labels: the selection is empty; pass None to mesh every label")
        if selection[0] < 0:
            raise ValueError(f"shards: labels: {selection[0]} is negative; label shards hold "
                             "labels 0 or more")
        if background in selection:
            raise ValueError(f"labels: {background} is the background, which is not meshed; "
                             "pass background= another value to mesh it")
    return dict(dtype=np.dtype(dtype).name, selection=selection)


def _blocks(array, token, before, after, pad, mesh, options, shards=None):
    """The tasks meshing ``array`` block by block: ``(array, name, blocks, shares)``, the array
    rechunked so that a halo comes from one neighbour, the blocks' layer name, its tasks (the
    shells, then ``mesh(chunk, at, grid, cubes, *shells, options)`` per chunk owning cubes,
    keyed ``(name, *idx)``; with ``shards``, ``(directory, write, _)``, that share written by
    :func:`_shard` instead) and those blocks' keys. A block's task gets its chunk plus the halo it
    reads, ``before`` samples before it and ``after`` past it, cut from its 26 neighbours'
    shells (see _shell): three tasks per chunk (read, shell, mesh) where dask.array.overlap
    makes some 24, and every chunk read once."""
    array = array.rechunk(tuple(_at_least(c, max(before, after)) for c in array.chunks))
    nz, ny, nx = array.shape
    grid = (nx, ny, nz)
    # The graph is written out here, task by task, rather than by calling dask.delayed
    # functions: each such call merges and culls its arguments' graphs, which grows with the
    # number of tasks and dominates a large array's graph building.
    keys = array.__dask_keys__()
    shape = tuple(len(c) for c in array.chunks)
    chunks = {idx: keys[idx[0]][idx[1]][idx[2]] for idx in np.ndindex(shape)}
    shell = "skelclimb-shell-" + token
    blocks = {}
    if shape != (1, 1, 1):
        blocks = {(shell, *idx): (_shell, chunks[idx], before, after)
                  for idx in np.ndindex(shape)}

    def shells(idx):
        near = [tuple(i + c for i, c in zip(idx, o)) for o in _OFFSETS]
        return [(shell, *n) if all(0 <= i < m for i, m in zip(n, shape)) else None for n in near]

    name = "skelclimb-block-" + token
    shares = []
    zc, yc, xc = array.chunks
    starts = [_starts(c) for c in (xc, yc, zc)]
    for iz, cz in enumerate(_cube_ranges(zc, nz, pad)):
        for iy, cy in enumerate(_cube_ranges(yc, ny, pad)):
            for ix, cx in enumerate(_cube_ranges(xc, nx, pad)):
                if cz[0] == cz[1] or cy[0] == cy[1] or cx[0] == cx[1]:
                    continue
                first = (starts[0][ix], starts[1][iy], starts[2][iz])
                at = tuple(max(s - before, 0) for s in first)
                idx = (iz, iy, ix)
                key = (name, *idx)
                task = (chunks[idx], at, grid, (cx, cy, cz), *shells(idx), options)
                blocks[key] = ((mesh, *task) if shards is None
                               else (_shard, shards[0], mesh, shards[1], *task))
                shares.append(key)
    return array, name, blocks, shares


def _run(array, name, blocks, shares, token, split_every, compute, merge, finish,
         shards=None, grid=None, options=None):
    """Runs the blocks' graph: their shares joined by ``merge`` in a tree of fan-in
    ``split_every``, the last join and ``finish`` here (or, without ``compute``, a delayed
    object doing both); with ``shards`` (``(directory, _, write_manifest)``), the path of the
    manifest listing the shards the blocks wrote instead."""
    import dask
    from dask.delayed import Delayed
    from dask.highlevelgraph import HighLevelGraph, MaterializedLayer

    layers = dict(array.__dask_graph__().layers)
    dependencies = dict(array.__dask_graph__().dependencies)
    # Lower z layers first: a distributed worker then meshes and drops a layer's chunks before
    # it loads many more (1024³ in 128³ chunks on 2 workers: peaks of 447–466 MiB without
    # priorities, 247–267 MiB with them).
    layers[name] = MaterializedLayer(blocks, annotations={**dask.get_annotations(),
                                                          "priority": _by_z_layer})
    dependencies[name] = set(array.__dask_layers__())
    joins, last = {}, name
    if shards is not None:
        joins["skelclimb-manifest-" + token] = (_manifest, shards[0], shards[2], grid, options,
                                                *shares)
        shares = ["skelclimb-manifest-" + token]
    else:
        level_key = 0
        while len(shares) > split_every:
            merged = []
            for i in range(0, len(shares), split_every):
                key = ("skelclimb-merge-" + token, level_key, len(merged))
                joins[key] = (merge, *shares[i:i + split_every])
                merged.append(key)
            shares, level_key = merged, level_key + 1
        if not compute:
            joins["skelclimb-mesh-" + token] = (merge, *shares)
            joins["skelclimb-finish-" + token] = (finish, "skelclimb-mesh-" + token)
            shares = ["skelclimb-finish-" + token]
    if joins:
        last = "skelclimb-join-" + token
        layers[last] = MaterializedLayer(joins)
        dependencies[last] = {name}
    graph = HighLevelGraph(layers, dependencies)
    results = [Delayed(key, graph, layer=last) for key in shares]
    if shards is not None or not compute:
        return results[0].compute() if compute else results[0]
    # The last merge runs here, where the mesh is wanted anyway, so that no worker has to hold
    # the whole mesh (and its inputs) on top of its chunks.
    return finish(merge(*dask.compute(*results)))


def _split_every(split_every):
    from . import _index

    split_every = _index(split_every, "split_every")
    if split_every < 2:
        raise ValueError(f"split_every: must be at least 2, got {split_every}")
    return split_every


def _bounds(array):
    """The least and greatest value of a ``dask.array``, in one pass."""
    import dask

    return dask.compute(array.min(), array.max())


def _label_mesh(block, at, grid, cubes, *shells_and_options):
    """Meshes a block of a label volume from its chunk and its neighbours' shells."""
    *shells, o = shells_and_options
    samples = np.ascontiguousarray(_extended(block, shells))
    return _native.extract_label_block(
        samples, at, grid, cubes, o["spacing"], o["origin"], o["background"], o["mode"],
        o["pad"], o["smoothing"], o["affine"], o["space"])


def _label_merge(*shares):
    return _native.merge_label_blocks(list(shares)) if len(shares) > 1 else shares[0]


def _label_finish(share, o):
    """The :class:`skelclimb.Labels` of the joined shares."""
    from ._labels import _result

    return _result(_native.finish_label_blocks(
        share, o["background"], o["mode"], o["normals"], o["selection"], o["affine"],
        o["space"]), o["dtype"])


def _dask_array(array):
    """``array`` as a ``dask.array`` with known chunk sizes: a NumPy array (or anything with
    ``__array__``) is wrapped in one, with Dask's automatic chunks."""
    import dask.array as da

    if not isinstance(array, da.Array):
        if not (isinstance(array, np.ndarray) or hasattr(array, "__array__")):
            raise TypeError(f"array: expected a dask.array or a NumPy array, got "
                            f"{type(array).__name__}")
        array = da.from_array(array)
    if any(np.isnan(c) for axis in array.chunks for c in axis):
        raise ValueError("array: its chunk sizes are unknown (NaN), as after boolean indexing; "
                         "call array.compute_chunk_sizes() first")
    return array


def _by_z_layer(key):
    """A block's or a shell's priority: its z layer's index, negated (Dask runs higher
    priorities first). The layer's index is third from the end of every such key."""
    return -key[-3]
