"""`skelclimb.dask.labels(shards=)`: label shards written by Dask tasks join, through
`skelclimb.merge_shards`, into exactly what `skelclimb.labels` makes of the whole array, and
through `skelclimb merge` into the files `skelclimb extract --labels` writes; damaged, missing
and foreign shards, and labels the files cannot hold, are refused naming the file or the
argument."""

import json
import os
import subprocess

import dask
import dask.array as da
import numpy as np
import pytest

import skelclimb
import skelclimb.dask
from test_dask_labels import CHUNKINGS, same, volume
from test_skelclimb import skelclimb_binary


def sharded(v, directory, chunks=5, **kwargs):
    """The manifest of `v` meshed into label shards in `directory`, on threads."""
    with dask.config.set(scheduler="threads"):
        return skelclimb.dask.labels(da.from_array(v, chunks=chunks), shards=directory,
                                     **kwargs)


@pytest.mark.parametrize("smoothing", [0, 0.75])
@pytest.mark.parametrize("pad", [True, False])
def test_any_chunking_merges_into_labels_of_the_whole(tmp_path, pad, smoothing):
    v = volume()
    assert (v[1:-1, 1:-1, 1:-1] == 0).any()  # a background inside, not only around
    whole = skelclimb.labels(v, pad=pad, smoothing=smoothing)
    assert whole.stats["merged"] > 0 and len(whole) > 3
    files = []
    for n, chunks in enumerate(CHUNKINGS):
        manifest = sharded(v, tmp_path / str(n), chunks, pad=pad, smoothing=smoothing)
        assert manifest == str(tmp_path / str(n) / "manifest.json")
        files.append(len(list((tmp_path / str(n)).glob("block-*.npz"))))
        same(skelclimb.merge_shards(manifest), whole)
    # The last chunking's chunk of 2 samples is joined to its neighbour: one block.
    assert files[0] > 4 and files[-1] == 1


def test_placement_selection_background_normals_and_label_types(tmp_path):
    v = volume(seed=8)
    affine = np.array([[0, 0, -1.5, 3], [0, 2, 0, -1], [0.5, 0, 0, 7], [0, 0, 0, 1]])
    cases = [
        (v, dict(spacing=(0.5, 2.0, 1.5), origin=(10.0, -4.0, 0.25), normals=False)),
        (v, dict(affine=affine, space="LPS", labels=[1, 2], smoothing=1.5)),
        (v, dict(background=1, mode="paper")),
        (v.astype("u2") * 300, dict(labels=[600, 1500])),
        (v.astype("i2") * 3, dict(mode="steps123")),
        (v.astype("i4") * 70000, {}),
        (v.astype("u4") + 4_000_000_000, dict(background=4_000_000_000)),
    ]
    for n, (labels, kwargs) in enumerate(cases):
        manifest = sharded(labels, tmp_path / str(n), (4, 6, 5), **kwargs)
        same(skelclimb.merge_shards(manifest), skelclimb.labels(labels, **kwargs))


def test_converted_types_merge_in_the_type_the_sweep_ran_on(tmp_path):
    v = volume(seed=6).astype("i1")
    whole = skelclimb.labels(v)
    got = skelclimb.merge_shards(sharded(v, tmp_path))
    # Labels 0 to 8: swept as uint8.
    assert whole.atlas.face_labels.dtype == np.int8 and got.atlas.face_labels.dtype == np.uint8
    assert np.array_equal(got.atlas.face_labels, whole.atlas.face_labels)
    assert np.array_equal(got.atlas.faces, whole.atlas.faces) and got.labels() == whole.labels()


def test_a_volume_of_negative_labels_merges_in_python(tmp_path):
    v = volume(seed=3).astype("i2") - 4
    manifest = sharded(v, tmp_path, pad=False)
    same(skelclimb.merge_shards(manifest), skelclimb.labels(v, pad=False))


def test_a_volume_one_sample_thick(tmp_path):
    v = volume((1, 9, 8), 4, 3)
    for pad in (True, False):
        manifest = sharded(v, tmp_path / str(pad), 3, pad=pad)
        same(skelclimb.merge_shards(manifest), skelclimb.labels(v, pad=pad))


@pytest.mark.parametrize("kwargs, message", [
    (dict(dtype="u8"), "shards: the array's labels are uint64"),
    (dict(background=-1, dtype="i2"), "shards: background -1 is negative"),
    (dict(labels=[-3, 1], dtype="i2"), "shards: labels: -3 is negative"),
    (dict(labels=[0, 1]), "labels: 0 is the background"),
    (dict(labels=[]), "labels: the selection is empty"),
])
def test_labels_shards_cannot_hold_are_refused_before_any_file(tmp_path, kwargs, message):
    dtype = kwargs.pop("dtype", "u1")
    v = volume().astype(dtype)
    with pytest.raises(ValueError, match=message):
        sharded(v, tmp_path / "parts", **kwargs)
    assert not (tmp_path / "parts").exists()


def test_a_selection_without_a_surface_is_reported_by_the_merge(tmp_path):
    v = volume()
    manifest = sharded(v, tmp_path, labels=[1, 200])
    with pytest.raises(ValueError, match="200"):
        skelclimb.labels(v, labels=[1, 200])
    with pytest.raises(ValueError, match="200"):
        skelclimb.merge_shards(manifest)


def scan_and_labels(tmp_path):
    """Shards of the same volume as a scan and as labels, in `scan/` and `labels/`: both have
    a `block-0-0-0.npz`."""
    v = volume()
    with dask.config.set(scheduler="threads"):
        scan = skelclimb.dask.extract(da.from_array(v, chunks=6), 1.5, shards=tmp_path / "scan")
    labels = sharded(v, tmp_path / "labels", 6)
    return v, scan, labels


def test_a_shard_of_the_other_kind_is_refused_naming_it(tmp_path):
    v, scan, labels = scan_and_labels(tmp_path)
    same(skelclimb.merge_shards(labels), skelclimb.labels(v))
    name = "block-0-0-0.npz"
    a, b = tmp_path / "scan" / name, tmp_path / "labels" / name
    scan_bytes, label_bytes = a.read_bytes(), b.read_bytes()
    a.write_bytes(label_bytes)
    b.write_bytes(scan_bytes)
    with pytest.raises(OSError, match=f"{name}: a shard of labels, where the manifest lists "
                                      "surface shards"):
        skelclimb.merge_shards(scan)
    with pytest.raises(OSError, match=f"{name}: a shard of surface, where the manifest lists "
                                      "labels shards"):
        skelclimb.merge_shards(labels)


def test_a_manifest_of_the_other_kind_is_refused_naming_it(tmp_path):
    _, scan, labels = scan_and_labels(tmp_path)
    for manifest, kind in [(scan, "labels"), (labels, "surface")]:
        with open(manifest) as f:
            m = json.load(f)
        m["kind"] = kind
        with open(manifest, "w") as f:
            json.dump(m, f)
        with pytest.raises(OSError, match="manifest.json: not a shard manifest: settings"):
            skelclimb.merge_shards(manifest)


def test_a_missing_or_damaged_label_shard_is_refused_naming_it(tmp_path):
    v = volume()
    manifest = sharded(v, tmp_path, 6)
    path = tmp_path / "block-7-7-7.npz"
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(OSError, match="block-7-7-7.npz: not a readable shard"):
        skelclimb.merge_shards(manifest)
    path.write_bytes(data)
    first = tmp_path / "block-0-0-0.npz"
    kept = first.read_bytes()
    with np.load(first) as z:
        arrays = {k: z[k] for k in z.files}
    assert set(arrays) == {"header", "keys", "positions", "triangles", "pairs", "cubes"}
    arrays["pairs"] = arrays["pairs"].astype("u2")
    np.savez(first, **arrays)
    with pytest.raises(OSError, match="block-0-0-0.npz: not a readable shard: array pairs"):
        skelclimb.merge_shards(manifest)
    first.write_bytes(kept)
    same(skelclimb.merge_shards(manifest), skelclimb.labels(v))
    os.remove(path)
    with pytest.raises(OSError, match="block-7-7-7.npz: no such file"):
        skelclimb.merge_shards(manifest)


def test_the_cli_merges_them_into_the_files_extract_writes(tmp_path):
    v = volume()
    nz, ny, nx = v.shape
    v.tofile(tmp_path / "seg.raw")
    run = [skelclimb_binary()]
    subprocess.run(run + ["extract", "-q", str(tmp_path / "seg.raw"), "--dims", f"{nx},{ny},{nz}",
                          "--dtype", "u8", "--labels", "all", "--smoothing", "0.75",
                          "-o", str(tmp_path / "whole.glb")], check=True)
    manifest = sharded(v, tmp_path / "parts", (4, 7, 3), smoothing=0.75)
    subprocess.run(run + ["merge", "-q", manifest, "-o", str(tmp_path / "joined.glb")], check=True)
    whole = (tmp_path / "whole.glb").read_bytes()
    assert len(whole) > 1000 and (tmp_path / "joined.glb").read_bytes() == whole


def test_python_merges_the_clis_label_shards(tmp_path):
    v = volume()
    nz, ny, nx = v.shape
    v.tofile(tmp_path / "seg.raw")
    assert not (v == 3).any() and (v == 2).any()  # the range 1-3 holds labels 1 and 2 only
    subprocess.run([skelclimb_binary(), "extract", "-q", str(tmp_path / "seg.raw"), "--dims",
                    f"{nx},{ny},{nz}", "--dtype", "u8", "--labels", "1-3,5", "--smoothing", "1",
                    "--shards", str(tmp_path / "parts"), "--block", "5"], check=True)
    got = skelclimb.merge_shards(tmp_path / "parts" / "manifest.json")
    same(got, skelclimb.labels(v, labels=[1, 2, 5], smoothing=1))
