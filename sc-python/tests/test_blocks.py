"""Block extraction and the Dask driver: shares joined in any order, and meshes computed one task
per chunk on threads or on a cluster of processes (with a worker killed mid-run), equal
``skelclimb.extract`` of the whole volume exactly."""

import doctest
import os
import random
import sys

import cloudpickle
import dask
import dask.array as da
from dask.delayed import Delayed
import distributed
import numpy as np
import pytest
import zarr

import skelclimb
import skelclimb._blocks
import skelclimb.dask

MODES = ("embedded", "paper", "steps123")


def blobs(shape, seed):
    """Smooth random blobs with integer ties: a surface with many merges and pinches."""
    rng = np.random.default_rng(seed)
    z, y, x = np.indices(shape, dtype=np.float32)
    f = np.zeros(shape, np.float32)
    for _ in range(6):
        c = rng.uniform(0, 1, 3) * np.array(shape)
        r = rng.uniform(0.15, 0.35) * min(shape)
        f += np.exp(-((z - c[0]) ** 2 + (y - c[1]) ** 2 + (x - c[2]) ** 2) / (r * r))
    return np.round(f * 40).astype(np.int16)


def same(a, b):
    assert a.stats == b.stats
    assert np.array_equal(a.vertices, b.vertices)
    assert np.array_equal(a.faces, b.faces)
    if a.normals is None or b.normals is None:
        assert a.normals is None and b.normals is None
    else:
        assert np.array_equal(a.normals, b.normals)


def same_adaptive(blocks, whole, wrong_side):
    """`same`, but for the samples on the wrong side, which only the whole volume's `extract`
    counts (none unless allowed, or None where a border sample is filled)."""
    measured = whole.stats.pop("wrong_side_samples")
    assert measured is None or wrong_side or measured == 0, measured
    same(blocks, whole)


def test_docstring_examples_run():
    for module in (skelclimb, skelclimb._blocks, skelclimb._labels, skelclimb.dask):
        failed, tried = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
        assert failed == 0, module.__name__
        assert tried > 0, module.__name__


def cut(n, rng):
    """Random cube ranges covering ``0 .. n - 1``, some one to three cubes wide."""
    edges = sorted({0, n - 1, *rng.sample(range(1, n - 1), k=min(4, n - 2))})
    return list(zip(edges, edges[1:]))


@pytest.mark.parametrize("mode", MODES)
def test_shares_joined_in_any_order_equal_extract(mode):
    rng = random.Random(7)
    v = blobs((23, 21, 19), 1)
    level = 12
    grid = v.shape[::-1]
    for trial in range(4):
        parts = []
        for cz in cut(grid[2], rng):
            for cy in cut(grid[1], rng):
                for cx in cut(grid[0], rng):
                    cubes = (cx, cy, cz)
                    (x0, x1), (y0, y1), (z0, z1) = skelclimb.block_samples(grid, cubes)
                    parts.append(skelclimb.extract_block(
                        v[z0:z1, y0:y1, x0:x1], level, at=(x0, y0, z0), grid=grid,
                        cubes=cubes, mode=mode, spacing=(0.5, 1, 2), origin=(1, 2, 3)))
        rng.shuffle(parts)
        while len(parts) > 1:
            k = rng.randint(2, 4)
            parts = [parts[0].merge(*parts[1:k]), *parts[k:]]
            rng.shuffle(parts)
        whole = skelclimb.extract(v, level, mode=mode, spacing=(0.5, 1, 2), origin=(1, 2, 3))
        assert whole.faces.shape[0] > 100
        same(parts[0].to_mesh(), whole)


def test_block_errors_are_value_errors():
    v = blobs((12, 12, 12), 2)
    grid = (12, 12, 12)
    cubes = ((2, 6), (0, 11), (0, 11))
    # One sample short before the block along x.
    with pytest.raises(ValueError, match="do not cover"):
        skelclimb.extract_block(v[:, :, 2:9], 12, at=(2, 0, 0), grid=grid, cubes=cubes)
    with pytest.raises(ValueError, match="cubes"):
        skelclimb.block_samples(grid, ((0, 12), (0, 11), (0, 11)))
    half = skelclimb.extract_block(v, 12, at=(0, 0, 0), grid=grid, cubes=cubes)
    with pytest.raises(ValueError, match="cover"):
        half.to_mesh()
    other = skelclimb.extract_block(v, 13, at=(0, 0, 0), grid=grid,
                                    cubes=((6, 11), (0, 11), (0, 11)))
    with pytest.raises(ValueError, match="different settings"):
        half.merge(other)
    with pytest.raises(ValueError, match="own"):
        half.merge(half)


@pytest.mark.parametrize("normals", [True, False])
def test_dask_threads_with_uneven_chunks(normals):
    v = blobs((40, 37, 33), 3)
    arr = da.from_array(v, chunks=((7, 1, 20, 12), (16, 16, 5), (2, 31)))
    with dask.config.set(scheduler="threads"):
        got = skelclimb.dask.extract(arr, 12, normals=normals, split_every=3)
    same(got, skelclimb.extract(v, 12, normals=normals))


@pytest.mark.parametrize("max_box, wrong_side", [(2, False), (4, True), (None, False)])
def test_adaptive_shares_joined_in_any_order_equal_extract(max_box, wrong_side):
    rng = random.Random(5)
    v = blobs((30, 27, 25), 4)
    grid = v.shape[::-1]
    options = dict(mode="adaptive", max_box=max_box, allow_wrong_side=wrong_side, max_error=1,
                   error_units="voxels", spacing=(0.5, 1, 2))
    whole = skelclimb.extract(v, 12, **options)
    assert len(whole.faces) < skelclimb.extract(v, 12, mode="steps123").stats["steps123"]["triangles"]
    parts = []
    for cz in cut(grid[2], rng):
        for cx in cut(grid[0], rng):
            cubes = (cx, (0, grid[1] - 1), cz)
            (x0, x1), (y0, y1), (z0, z1) = skelclimb.block_samples(
                grid, cubes, mode="adaptive", max_box=max_box)
            parts.append(skelclimb.extract_block(
                v[z0:z1, y0:y1, x0:x1], 12, at=(x0, y0, z0), grid=grid, cubes=cubes, **options))
    rng.shuffle(parts)
    same_adaptive(parts[0].merge(*parts[1:]).to_mesh(), whole, wrong_side)


@pytest.mark.parametrize("max_box, wrong_side", [(2, True), (4, False)])
def test_dask_adaptive_equals_extract(max_box, wrong_side):
    v = blobs((40, 37, 33), 3)
    arr = da.from_array(v, chunks=((7, 1, 20, 12), (16, 16, 5), (2, 31)))
    options = dict(mode="adaptive", max_box=max_box, allow_wrong_side=wrong_side)
    with dask.config.set(scheduler="threads"):
        got = skelclimb.dask.extract(arr, 12, split_every=3, **options)
    same_adaptive(got, skelclimb.extract(v, 12, **options), wrong_side)


def test_dask_checks_its_arguments():
    arr = da.zeros((4, 4), chunks=2)
    with pytest.raises(ValueError, match="3 dimensions"):
        skelclimb.dask.extract(arr, 0.5)
    with pytest.raises(ValueError, match="level"):
        skelclimb.dask.extract(da.zeros((4, 4, 4), chunks=2), float("nan"))


def test_dask_delayed_result_and_a_single_chunk():
    v = blobs((20, 19, 18), 6)
    with dask.config.set(scheduler="threads"):
        for chunks in (6, v.shape):
            result = skelclimb.dask.extract(da.from_array(v, chunks=chunks), 12, compute=False)
            assert isinstance(result, Delayed)
            same(result.compute(), skelclimb.extract(v, 12))


def test_dask_tasks_are_prioritised_by_z_layer():
    # A distributed worker runs lower z layers first, so it drops a layer's chunks before it
    # loads many more; the priorities must survive into the graph the scheduler gets.
    arr = da.from_array(blobs((24, 10, 10), 7), chunks=(6, 5, 10))
    graph = skelclimb.dask.extract(arr, 12, compute=False).__dask_graph__()
    priorities = {}
    for layer in graph.layers.values():
        p = (layer.annotations or {}).get("priority")
        for key in layer if p is not None else ():
            # Dask may merge layers and keep their annotations as a function of the key.
            value = p(key) if callable(p) else p
            if isinstance(value, int):
                name = key if isinstance(key, str) else key[0]
                priorities.setdefault(name.rsplit("-", 1)[0], set()).add(value)
    assert priorities.get("skelclimb-block") == {0, -1, -2, -3}
    assert priorities.get("skelclimb-shell") == {0, -1, -2, -3}


def _die_once(block, marker):
    """Kills the worker process running it, the first time any worker runs it."""
    try:
        os.close(os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
    except FileExistsError:
        return block
    os._exit(1)


@pytest.fixture(scope="module")
def cluster():
    # Workers are fresh processes that cannot import this test module: send its functions.
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as c, distributed.Client(c) as client:
        yield client


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    v = blobs((150, 140, 130), 4)
    path = str(tmp_path_factory.mktemp("zarr") / "blobs.zarr")
    z = zarr.create_array(store=path, shape=v.shape, chunks=(64, 64, 64), dtype=v.dtype)
    z[:] = v
    return path, v


def test_cluster_of_two_processes_meshes_a_zarr_store_exactly(cluster, store):
    path, v = store
    arr = da.from_zarr(path)
    assert arr.chunksize == (64, 64, 64)
    got = skelclimb.dask.extract(arr, 12)
    same(got, skelclimb.extract(v, 12))
    # Both workers took part.
    assert len(cluster.scheduler_info()["workers"]) == 2


def test_a_killed_worker_is_retried_and_the_mesh_is_still_exact(cluster, store, tmp_path):
    path, v = store
    marker = str(tmp_path / "died")
    # `meta` keeps Dask from calling the function here to learn its output type.
    arr = da.from_zarr(path).map_blocks(_die_once, marker, meta=np.empty((0, 0, 0), v.dtype))
    got = skelclimb.dask.extract(arr, 12, mode="paper")
    assert os.path.exists(marker), "a worker was killed"
    same(got, skelclimb.extract(v, 12, mode="paper"))


def test_dask_with_an_error_bound():
    v = blobs((30, 29, 28), 5)
    arr = da.from_array(v, chunks=(9, 10, 11))
    with dask.config.set(scheduler="threads"):
        got = skelclimb.dask.extract(arr, 12, max_error=0.2, error_units="voxels")
    want = skelclimb.extract(v, 12, max_error=0.2, error_units="voxels")
    assert want.stats["bounded"] > 0
    same(got, want)


@pytest.mark.parametrize("mode", MODES)
def test_dask_shards_on_threads_merge_into_extract(mode, tmp_path):
    v = blobs((40, 37, 33), 6)
    arr = da.from_array(v, chunks=((7, 1, 20, 12), (16, 16, 5), (2, 31)))
    with dask.config.set(scheduler="threads"):
        manifest = skelclimb.dask.extract(arr, 12, mode=mode, shards=tmp_path / "parts")
    assert manifest == str(tmp_path / "parts" / "manifest.json")
    shards = sorted(p.name for p in (tmp_path / "parts").glob("*.npz"))
    assert len(shards) > 4
    same(skelclimb.merge_shards(manifest), skelclimb.extract(v, 12, mode=mode))
    # A shard is a plain NumPy archive.
    with np.load(tmp_path / "parts" / shards[0]) as z:
        assert set(z.files) == {"header", "keys", "positions", "normals", "triangles", "cubes"}
        assert z["positions"].shape == (len(z["keys"]), 3)


def test_dask_shards_without_normals_and_with_a_bound(tmp_path):
    v = blobs((30, 29, 28), 5)
    arr = da.from_array(v, chunks=(9, 10, 11))
    with dask.config.set(scheduler="threads"):
        manifest = skelclimb.dask.extract(arr, 12, normals=False, max_error=0.2,
                                          error_units="voxels", shards=tmp_path)
    same(skelclimb.merge_shards(manifest),
         skelclimb.extract(v, 12, normals=False, max_error=0.2, error_units="voxels"))


def test_merge_shards_names_a_missing_or_foreign_shard(tmp_path):
    v = blobs((30, 29, 28), 5)
    with dask.config.set(scheduler="threads"):
        manifest = skelclimb.dask.extract(da.from_array(v, chunks=10), 12, shards=tmp_path / "a")
        skelclimb.dask.extract(da.from_array(v, chunks=10), 13, shards=tmp_path / "b")
    victim = "block-10-0-10.npz"
    os.replace(tmp_path / "b" / victim, tmp_path / "a" / victim)
    with pytest.raises(OSError, match=f"{victim}: made with other settings"):
        skelclimb.merge_shards(manifest)
    os.remove(tmp_path / "a" / victim)
    with pytest.raises(OSError, match=f"{victim}: no such file"):
        skelclimb.merge_shards(manifest)


def test_cluster_of_two_processes_writes_shards_that_merge_exactly(cluster, store, tmp_path):
    path, v = store
    manifest = skelclimb.dask.extract(da.from_zarr(path), 12, shards=tmp_path / "parts")
    same(skelclimb.merge_shards(manifest), skelclimb.extract(v, 12))


def test_cluster_of_two_processes_writes_label_shards_that_merge_exactly(cluster, tmp_path):
    from test_dask_labels import same as same_labels, volume

    v = volume((30, 28, 26), 12, 5)
    manifest = skelclimb.dask.labels(da.from_array(v, chunks=10), smoothing=0.75,
                                     shards=tmp_path / "labels")
    same_labels(skelclimb.merge_shards(manifest), skelclimb.labels(v, smoothing=0.75))
