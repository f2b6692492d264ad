"""Shards and manifests as a hostile or careless user leaves them: arrays rewritten by NumPy in
Fortran order, numbers no mesh can hold, names that are not the runtime's, overlapping boxes and
files that are not files. Each is merged exactly or refused with a message naming the file,
never a wrong mesh, an infinity in the output or a hang."""

import json
import os
import subprocess
import sys
import zipfile

import dask
import dask.array as da
import numpy as np
import pytest

import skelclimb
import skelclimb.dask
from test_blocks import blobs


@pytest.fixture
def shards(tmp_path):
    """A manifest of 27 shards of a (24, 23, 22) volume, and the mesh one extract gives."""
    v = blobs((24, 23, 22), 3)
    with dask.config.set(scheduler="sync"):
        manifest = skelclimb.dask.extract(da.from_array(v, chunks=8), 12, shards=tmp_path / "p")
    return manifest, skelclimb.extract(v, 12)


def edit(manifest, change):
    with open(manifest) as f:
        m = json.load(f)
    change(m)
    with open(manifest, "w") as f:
        json.dump(m, f)


def test_fortran_order_shards_merge_as_c_order_ones(shards):
    manifest, whole = shards
    c_order = skelclimb.merge_shards(manifest)
    np.testing.assert_array_equal(c_order.faces, whole.faces)
    folder = os.path.dirname(manifest)
    fortran = 0
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".npz"):
            continue
        path = os.path.join(folder, name)
        with np.load(path) as z:
            arrays = {k: np.asfortranarray(z[k]) for k in z.files}
        np.savez(path, **arrays)
        with zipfile.ZipFile(path) as z:
            fortran += b"'fortran_order': True" in z.read("triangles.npy")[:128]
    assert fortran > 10
    merged = skelclimb.merge_shards(manifest)
    np.testing.assert_array_equal(merged.faces, c_order.faces)
    np.testing.assert_array_equal(merged.vertices, c_order.vertices)
    np.testing.assert_array_equal(merged.normals, c_order.normals)


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf")])
@pytest.mark.parametrize("array", ["positions", "normals"])
def test_a_non_finite_number_in_a_shard_is_refused_naming_it(shards, array, value):
    manifest, _ = shards
    path = os.path.join(os.path.dirname(manifest), "block-8-8-8.npz")
    with np.load(path) as z:
        arrays = {k: z[k] for k in z.files}
    assert len(arrays[array]) > 2
    arrays[array][2, 1] = value
    np.savez(path, **arrays)
    with pytest.raises(OSError, match=f"block-8-8-8.npz: not a readable shard: {array} row 2"):
        skelclimb.merge_shards(manifest)


@pytest.mark.parametrize("at, value, message", [
    (("world", "linear", 1, 1), 1e308, r"world: linear row \[0.0,1e\+308,0.0\]"),
    (("world", "offset", 0), "a", r'world: offset \["a",'),
    (("settings", "spacing", 2), 1e30, "below 1e30"),
    (("settings", "mode", None), "fastest",
     "mode \"fastest\": expected 'embedded', 'paper', 'steps123' or 'adaptive'"),
])
def test_a_manifest_s_numbers_and_names_are_checked(shards, at, value, message):
    manifest, _ = shards

    def change(m):
        *path, last = [k for k in at if k is not None]
        for k in path:
            m = m[k]
        m[last] = value

    edit(manifest, change)
    with pytest.raises(OSError, match=f"manifest.json: not a shard manifest: .*{message}"):
        skelclimb.merge_shards(manifest)


def test_a_placement_past_f32_is_refused_not_written_as_infinity(tmp_path):
    v = blobs((20, 20, 20), 4)
    with dask.config.set(scheduler="sync"):
        manifest = skelclimb.dask.extract(da.from_array(v, chunks=10), 12,
                                          spacing=(1e20, 1e20, 1e20), shards=tmp_path)
    edit(manifest, lambda m: m["world"]["linear"][2].__setitem__(2, 1e29))
    with pytest.raises(OSError, match="beyond what 32-bit floats hold"):
        skelclimb.merge_shards(manifest)


def test_overlapping_boxes_name_both_shards_and_the_cubes(shards):
    manifest, _ = shards
    edit(manifest, lambda m: m["shards"][0]["cubes"][0].__setitem__(1, 10))
    with pytest.raises(OSError, match=r"shards block-0-0-0.npz and block-8-0-0.npz both own the "
                                      r"cubes \[8\.\.10, 0\.\.8, 0\.\.8\]"):
        skelclimb.merge_shards(manifest)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="FIFOs are a POSIX thing")
@pytest.mark.parametrize("victim", ["block-0-8-0.npz", "manifest.json"])
def test_a_fifo_is_refused_not_waited_on(shards, victim):
    manifest, _ = shards
    path = os.path.join(os.path.dirname(manifest), victim)
    os.remove(path)
    os.mkfifo(path)
    # In a child, so that a hang fails this test instead of stopping the suite.
    code = f"import skelclimb; skelclimb.merge_shards({manifest!r})"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=20)
    assert run.returncode != 0
    assert f"{victim}: is not a regular file" in run.stderr
