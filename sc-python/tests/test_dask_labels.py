"""`skelclimb.dask.labels`: a label volume meshed one task per chunk equals `skelclimb.labels` of
the whole array exactly, for any chunking, mode, label type, padding and smoothing; bad input is
refused as `skelclimb.labels` refuses it, and damaged shares are refused when joined."""

import pickle

import dask
import dask.array as da
import numpy as np
import pytest
from dask.delayed import Delayed

import skelclimb
import skelclimb.dask
from skelclimb import _native
from test_labels import cells

MODES = ["embedded", "paper", "steps123"]


def same(got, whole):
    """Equal vertex for vertex, triangle for triangle: the atlas, each label's mesh, the stats."""
    # Every path to a result leaves its meshes to be cut when one is asked for.
    assert got._meshes is None
    assert got.stats == whole.stats
    assert got.labels() == whole.labels()
    for name in ("vertices", "faces", "face_labels"):
        a, b = getattr(got.atlas, name), getattr(whole.atlas, name)
        assert a.dtype == b.dtype and np.array_equal(a, b), name
    for label in whole:
        g, w = got[label], whole[label]
        assert g.stats == w.stats
        assert np.array_equal(g.vertices, w.vertices) and np.array_equal(g.faces, w.faces)
        assert (g.normals is None) == (w.normals is None)
        assert g.normals is None or np.array_equal(g.normals, w.normals)


def volume(shape=(14, 13, 12), n=9, seed=4, dtype=np.uint8):
    """Voronoi cells with some background between them, so Step 4 merges and pinches."""
    v = cells(shape, n, seed, dtype)
    v[v % 4 == 3] = 0
    return v


CHUNKINGS = [5, (4, 7, 3), ((1, 6, 7), (13,), (3, 3, 3, 3)), ((14,), (2, 11), (12,))]


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("pad", [True, False])
def test_any_chunking_equals_labels_of_the_whole(mode, pad):
    v = volume()
    whole = skelclimb.labels(v, mode=mode, pad=pad)
    assert whole.stats["merged"] > 0 or mode == "steps123"
    with dask.config.set(scheduler="threads"):
        for chunks in CHUNKINGS:
            got = skelclimb.dask.labels(da.from_array(v, chunks=chunks), mode=mode, pad=pad,
                                        split_every=3)
            same(got, whole)


@pytest.mark.parametrize("dtype", ["u1", "u2", "u4", "i4", "i1", "i8"])
def test_every_label_type(dtype):
    v = volume(seed=6).astype(dtype)
    if np.dtype(dtype).kind == "i":
        v = np.where(v > 0, v - 3, 0).astype(dtype)
    whole = skelclimb.labels(v)
    with dask.config.set(scheduler="threads"):
        same(skelclimb.dask.labels(da.from_array(v, chunks=(4, 6, 5))), whole)


@pytest.mark.parametrize("smoothing", [0.5, 0.75, 2.0])
@pytest.mark.parametrize("pad", [True, False])
def test_smoothing_reaches_across_chunks(smoothing, pad):
    v = volume((13, 12, 11), 8, 2)
    whole = skelclimb.labels(v, smoothing=smoothing, pad=pad)
    with dask.config.set(scheduler="threads"):
        for chunks in [4, ((6, 7), (12,), (3, 8))]:
            got = skelclimb.dask.labels(da.from_array(v, chunks=chunks), smoothing=smoothing,
                                        pad=pad)
            same(got, whole)


def test_placement_selection_background_and_normals():
    v = volume(seed=8)
    affine = np.array([[0, 0, -1.5, 3], [0, 2, 0, -1], [0.5, 0, 0, 7], [0, 0, 0, 1]])
    cases = [
        dict(spacing=(0.5, 2.0, 1.5), origin=(10.0, -4.0, 0.25), normals=False),
        dict(affine=affine, space="LPS", labels=[1, 2]),
        dict(background=1, mode="paper"),
    ]
    with dask.config.set(scheduler="threads"):
        for kwargs in cases:
            got = skelclimb.dask.labels(da.from_array(v, chunks=5), **kwargs)
            same(got, skelclimb.labels(v, **kwargs))


def test_numpy_input_a_single_chunk_and_a_delayed_result():
    v = volume(seed=1)
    whole = skelclimb.labels(v)
    same(skelclimb.dask.labels(v), whole)
    with dask.config.set(scheduler="threads"):
        result = skelclimb.dask.labels(da.from_array(v, chunks=v.shape), compute=False)
        assert isinstance(result, Delayed)
        same(result.compute(), whole)


def test_a_volume_one_sample_thick():
    for dtype in ("u1", "i8"):
        v = volume((1, 9, 8), 4, 3).astype(dtype)
        for pad in (True, False):
            same(skelclimb.dask.labels(da.from_array(v, chunks=3), pad=pad),
                 skelclimb.labels(v, pad=pad))


@pytest.mark.parametrize("dtype", ["f4", "f8", "?"])
def test_floats_and_bools_are_refused(dtype):
    name = np.dtype(dtype).name
    with pytest.raises(TypeError, match=f"array holds {name}; label volumes need integers"):
        skelclimb.dask.labels(da.zeros((3, 3, 3), dtype=dtype, chunks=2))


def test_bad_arguments_are_refused_as_labels_refuses_them():
    v = da.from_array(volume(), chunks=5)
    cases = [
        (ValueError, "array: expected 3 dimensions", dict(array=da.zeros((3, 3), np.uint8))),
        (ValueError, "background: 300 is not a value of the array's uint8",
         dict(background=300)),
        (TypeError, "background: expected a whole number", dict(background=0.5)),
        (ValueError, "smoothing: 4.5 is not a width", dict(smoothing=4.5)),
        (ValueError, "mode: expected one of", dict(mode="marching")),
        (ValueError, "label volumes have no adaptive mode", dict(mode="adaptive")),
        (ValueError, "labels: 99 not in the volume", dict(labels=[99])),
        (ValueError, "split_every: must be at least 2", dict(split_every=1)),
        (ValueError, "spacing: must be three positive numbers", dict(spacing=(1, 0, 1))),
        (TypeError, "array: expected a dask.array or a NumPy array", dict(array="volume")),
    ]
    for error, message, kwargs in cases:
        array = kwargs.pop("array", v)
        with pytest.raises(error, match=message):
            with dask.config.set(scheduler="threads"):
                skelclimb.dask.labels(array, **kwargs)
    with pytest.raises(ValueError, match=r"array: .*int64.*-1099511627776"):
        big = np.zeros((3, 3, 3), np.int64)
        big[1, 1, 1] = -(2**40)
        skelclimb.dask.labels(da.from_array(big, chunks=2))


def share(v, cubes, pad=True):
    """A block's share from the native layer, meshed from the samples it asks for."""
    nz, ny, nx = v.shape
    need = _native.label_block_samples((nx, ny, nz), cubes, pad, 0.0)
    (x0, x1), (y0, y1), (z0, z1) = need
    samples = np.ascontiguousarray(v[z0:z1, y0:y1, x0:x1])
    return _native.extract_label_block(samples, (x0, y0, z0), (nx, ny, nz), cubes,
                                       (1.0, 1.0, 1.0), (0.0, 0.0, 0.0), 0, "embedded", pad, 0.0)


def test_shares_survive_pickling_and_damaged_ones_are_refused():
    v = volume((8, 7, 6), 5, 3)
    low = pickle.loads(pickle.dumps(share(v, ((0, 7), (0, 8), (0, 4)))))
    high = share(v, ((0, 7), (0, 8), (4, 9)))
    joined = _native.merge_label_blocks([high, low])
    got = skelclimb._labels._result(
        _native.finish_label_blocks(joined, 0, "embedded", True), v.dtype)
    same(got, skelclimb.labels(v))
    with pytest.raises(ValueError, match="cover .* of the grid's"):
        _native.finish_label_blocks(low, 0, "embedded", True)
    with pytest.raises(ValueError, match="both own cube"):
        _native.merge_label_blocks([low, low])
    damaged = list(low)
    damaged[5] = damaged[5][:-1]
    with pytest.raises(ValueError, match="triangle and pair arrays differ"):
        _native.merge_label_blocks([tuple(damaged), high])
    with pytest.raises(ValueError, match="samples .* do not cover"):
        _native.extract_label_block(v[:3].copy(), (0, 0, 0), (6, 7, 8), ((0, 7), (0, 8), (0, 4)),
                                    (1.0,) * 3, (0.0,) * 3, 0, "embedded", True, 0.0)
    with pytest.raises(ValueError, match="cubes 0..9 along x leave a grid"):
        _native.label_block_samples((6, 7, 8), ((0, 9), (0, 1), (0, 1)), False, 0.0)
