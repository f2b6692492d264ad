"""Zarr stores that lie, through ``skelclimb.load``: a header claiming far more samples than
memory holds is refused before anything is allocated by it (the interpreter survives, under a
6 GB address-space limit), a FIFO among the store's files is refused instead of hanging, missing
chunks read as the fill value with a ``UserWarning`` that counts them, and a wrong separator or a
non-numeric OME-Zarr scale is an error naming it."""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import skelclimb


def v2_store(path, shape, chunks=(4, 4, 4), extra=None, chunk=b"\xc8" * 64):
    """A v2 store of u8 samples (fill value 0) with one chunk file, ``0.0.0``."""
    os.makedirs(path)
    meta = {"zarr_format": 2, "shape": list(shape), "chunks": list(chunks), "dtype": "|u1",
            "compressor": None, "fill_value": 0, "order": "C", "filters": None, **(extra or {})}
    with open(os.path.join(path, ".zarray"), "w") as f:
        json.dump(meta, f)
    with open(os.path.join(path, "0.0.0"), "wb") as f:
        f.write(chunk)
    return str(path)


def load_in_child(path):
    """``skelclimb.load(path)`` in a child interpreter limited to 6 GB of address space and 20
    seconds: its exit code and what it printed (an abort would be -6, a hang a timeout)."""
    code = textwrap.dedent(f"""
        import resource, skelclimb
        resource.setrlimit(resource.RLIMIT_AS, (6_000_000_000, 6_000_000_000))
        try:
            skelclimb.load({str(path)!r})
        except OSError as e:
            print("refused:", e)
    """)
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=20)
    return run.returncode, run.stdout + run.stderr


@pytest.mark.parametrize("shape, size", [
    ((10**6, 10**6, 10**6), "1000000 × 1000000 samples"),
    ((10**12, 4, 4), "4 × 4 × 1000000000000 samples would need 16.0 TB"),
    ((2**63, 4, 4), "4 × 4 × 9223372036854775808 samples"),
    ((4, 4, 2**63 - 1), "9223372036854775807 × 4 samples"),
])
def test_a_lying_header_is_refused_and_the_interpreter_survives(tmp_path, shape, size):
    store = v2_store(tmp_path / "lie.zarr", shape)
    code, out = load_in_child(store)
    assert code == 0, out
    assert "refused:" in out and "lie.zarr" in out and size in out, out
    assert "more than the" in out


def test_a_fifo_in_the_store_is_refused_not_opened(tmp_path):
    store = v2_store(tmp_path / "fifo.zarr", (8, 4, 4))
    os.mkfifo(os.path.join(store, "1.0.0"))
    code, out = load_in_child(store)
    assert code == 0, out
    assert "refused:" in out and "fifo.zarr/1.0.0" in out and "not a regular file" in out, out


def test_missing_chunks_warn_with_their_count(tmp_path):
    store = v2_store(tmp_path / "half.zarr", (8, 4, 4))
    with pytest.warns(UserWarning, match=r"1 of its 2 chunks have no file \(such as 1\.0\.0\)"):
        volume, _, _ = skelclimb.load(store)
    expected = np.zeros((8, 4, 4), np.uint8)
    expected[:4] = 200
    assert np.array_equal(volume, expected)
    # Every chunk present: no warning.
    with open(os.path.join(store, "1.0.0"), "wb") as f:
        f.write(b"\0" * 64)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        skelclimb.load(store)


def test_a_wrong_separator_is_an_error_naming_it(tmp_path):
    store = v2_store(tmp_path / "sep.zarr", (8, 4, 4), extra={"dimension_separator": "/"})
    with pytest.raises(OSError, match=r'0\.0\.0 exists: the chunk files separate their indices '
                                      r'with "\.", not the "/"'):
        skelclimb.load(store)


def test_a_non_numeric_ome_scale_is_an_error_naming_the_field(tmp_path):
    root = tmp_path / "ome.zarr"
    v2_store(root / "0", (4, 4, 4))
    with open(root / ".zgroup", "w") as f:
        json.dump({"zarr_format": 2}, f)
    with open(root / ".zattrs", "w") as f:
        json.dump({"multiscales": [{"datasets": [{"path": "0", "coordinateTransformations": [
            {"type": "scale", "scale": ["a", 1, 1]}]}]}]}, f)
    with pytest.raises(OSError, match=r'OME-Zarr dataset 0 \(0\): its `scale` transformation is '
                                      r'\["a",1,1\], not a list of 3 numbers'):
        skelclimb.load(str(root))
