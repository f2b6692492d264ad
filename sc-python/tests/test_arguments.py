"""Python's arguments refused as the command line refuses them, in its words, before any work:
thread counts, coordinates, sizes, types; and the arrays and masks the docs promise to accept."""

import subprocess
import sys
import time

import dask.array as da
import numpy as np
import pytest

import skelclimb
import skelclimb.dask

# The command line's words for a spacing or origin (sc_io::limits::THREE_COORDINATES).
THREE = "expected three finite numbers X,Y,Z (below 1e30: vertices are f32)"


def cube(n=8, dtype=np.uint8):
    v = np.zeros((n, n, n), dtype)
    v[2:6, 2:6, 3:6] = 1
    return v


def unaligned(v):
    """A C-contiguous copy of ``v`` one byte into a buffer: contiguous, not aligned."""
    buf = np.zeros(v.nbytes + 1, np.uint8)[1:]
    out = buf.view(v.dtype).reshape(v.shape)
    out[...] = v
    assert out.flags.c_contiguous and not out.flags.aligned
    return out


def same(a, b):
    return np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)


@pytest.mark.parametrize("n", [1025, 10**6, 2**31, 2**64, 2**100])
def test_thread_counts_beyond_the_limit_are_refused_at_once(n):
    v = cube()
    start = time.monotonic()
    for call in (lambda: skelclimb.extract(v, 1, threads=n),
                 lambda: skelclimb.marching_cubes(v, 0.5, threads=n)):
        with pytest.raises(ValueError, match=f"threads: at most 1024 threads .*, not {n}$"):
            call()
    assert time.monotonic() - start < 5


def test_thread_counts_must_be_whole_and_not_negative():
    v = cube()
    for bad in (1.5, "2", None):
        with pytest.raises(TypeError, match="threads"):
            skelclimb.extract(v, 1, threads=bad)
        with pytest.raises(TypeError, match="threads"):
            skelclimb.marching_cubes(v, 0.5, threads=bad)
    with pytest.raises(ValueError, match="threads: must be 0"):
        skelclimb.extract(v, 1, threads=-1)
    whole = skelclimb.extract(v, 1)
    for good in (np.int64(3), np.uint16(1024), 1):
        assert same(skelclimb.extract(v, 1, threads=good), whole)


@pytest.mark.parametrize("bad", [1e30, -1e30, 1e308, float("inf"), float("nan")])
def test_coordinates_beyond_the_limit_are_refused_on_every_entry_point(bad):
    v = cube()
    triple = (1.0, bad, 1.0)
    calls = {
        "spacing": [
            lambda: skelclimb.extract(v, 1, spacing=triple),
            lambda: skelclimb.marching_cubes(v, 0.5, spacing=triple),
            lambda: skelclimb.SliceStreamer(v.shape, 1, spacing=triple),
            lambda: skelclimb.extract_block(v, 1, at=(0, 0, 0), grid=(8, 8, 8),
                                            cubes=((0, 7),) * 3, spacing=triple),
            lambda: skelclimb.dask.extract(da.from_array(v, chunks=4), 1, spacing=triple),
        ],
        "origin": [
            lambda: skelclimb.extract(v, 1, origin=triple),
            lambda: skelclimb.SliceStreamer(v.shape, 1, origin=triple),
            lambda: skelclimb.extract_block(v, 1, at=(0, 0, 0), grid=(8, 8, 8),
                                            cubes=((0, 7),) * 3, origin=triple),
            lambda: skelclimb.dask.extract(da.from_array(v, chunks=4), 1, origin=triple),
        ],
    }
    for name, entries in calls.items():
        for call in entries:
            with pytest.raises(ValueError) as e:
                call()
            assert str(e.value).startswith(f"{name}: {THREE}"), e.value
    affine = np.diag([1.0, 1.0, 1.0, 1.0])
    for entry in [(0, 0), (1, 2), (2, 3)]:
        a = affine.copy()
        a[entry] = bad
        with pytest.raises(ValueError, match="affine: "):
            skelclimb.extract(v, 1, affine=a)


def test_coordinates_just_below_the_limit_give_finite_vertices():
    v = cube()
    m = skelclimb.extract(v, 1, spacing=(1e20,) * 3, origin=(-9.9e29, 0, 9.9e29))
    assert len(m.faces) > 0 and np.isfinite(m.vertices).all()
    a = np.diag([1e25, 1e25, 1e25, 1.0])
    a[:3, 3] = 5e29
    m = skelclimb.extract(v, 1, affine=a)
    assert len(m.faces) > 0 and np.isfinite(m.vertices).all()


@pytest.mark.parametrize("dtype", ["i8", "u1", "f4", "i2"])
def test_a_numeric_mask_is_a_truth_value(dtype):
    rng = np.random.default_rng(4)
    v = rng.random((12, 11, 10)).astype(np.float32)
    truth = rng.random(v.shape) < 0.6
    numbers = np.where(truth, rng.integers(1, 5, v.shape), 0).astype(dtype)
    expected = skelclimb.marching_cubes(v, 0.5, mask=truth)
    got = skelclimb.marching_cubes(v, 0.5, mask=numbers)
    for a, b in zip(expected, got):
        assert np.array_equal(a, b)
    # All ones keep every triangle, as no mask does.
    full = skelclimb.marching_cubes(v, 0.5, mask=np.ones(v.shape, dtype))
    assert np.array_equal(full[1], skelclimb.marching_cubes(v, 0.5)[1])
    with pytest.raises(TypeError, match="mask"):
        skelclimb.marching_cubes(v, 0.5, mask=np.full(v.shape, "x"))


def test_a_streamer_too_large_for_memory_is_refused_before_it_starts():
    with pytest.raises(MemoryError) as e:
        skelclimb.SliceStreamer((3, 10**4, 10**6), 0.5)
    message = str(e.value)
    assert "shape" in message and "(3, 10000, 1000000)" in message and "GB" in message
    with pytest.raises(MemoryError, match="shape"):
        skelclimb.SliceStreamer((2**64, 2, 2), 0.5)
    with pytest.raises(TypeError, match="shape"):
        skelclimb.SliceStreamer((3.5, 4, 4), 0.5)


def test_a_streamer_refusal_under_an_address_space_limit_does_not_abort():
    """Under ``ulimit -v`` (6 GB) a streamer that would need more is a MemoryError, and the
    interpreter lives on to say so."""
    script = (
        "import skelclimb\n"
        "for shape in [(3, 10**4, 10**6), (4, 3 * 10**4, 3 * 10**4)]:\n"
        "    try:\n"
        "        skelclimb.SliceStreamer(shape, 0.5)\n"
        "    except MemoryError as e:\n"
        "        print('refused', e)\n"
        "print('alive')\n"
    )
    run = subprocess.run(["bash", "-c", f'ulimit -v 6000000; exec "{sys.executable}" -c "$0"',
                          script], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    assert run.stdout.count("refused shape:") == 2 and run.stdout.endswith("alive\n"), run.stdout


@pytest.mark.parametrize("dtype", ["u2", "i4", "f4", "f8"])
def test_unaligned_contiguous_arrays_are_copied_and_mesh_the_same(dtype):
    v = (cube(10).astype(np.float64) * 7).astype(dtype)
    odd = unaligned(v)
    assert same(skelclimb.extract(odd, 3), skelclimb.extract(v, 3))
    for a, b in zip(skelclimb.marching_cubes(odd, 3), skelclimb.marching_cubes(v, 3)):
        assert np.array_equal(a, b)
    args = dict(at=(0, 0, 0), grid=(10, 10, 10), cubes=((0, 9),) * 3)
    assert same(skelclimb.extract_block(odd, 3, **args).to_mesh(),
                skelclimb.extract_block(v, 3, **args).to_mesh())
    s = skelclimb.SliceStreamer(v.shape, 3)
    for z in range(v.shape[0]):
        s.push(unaligned(v[z]))
    assert same(s.finish(), skelclimb.extract(v, 3))


def test_non_integral_sizes_and_text_levels_are_refused():
    v = cube()
    with pytest.raises(TypeError, match="step_size"):
        skelclimb.marching_cubes(v, 0.5, step_size=1.5)
    for bad in ("0.5", b"0.5", np.str_("0.5")):
        with pytest.raises(TypeError, match="level"):
            skelclimb.extract(v, bad)
        with pytest.raises(TypeError, match="level"):
            skelclimb.marching_cubes(v, bad)
        with pytest.raises(TypeError, match="level"):
            skelclimb.SliceStreamer(v.shape, bad)
    with pytest.raises(TypeError, match="spacing"):
        skelclimb.extract(v, 1, spacing=("1", "1", "1"))
    with pytest.raises(TypeError, match="at"):
        skelclimb.extract_block(v, 1, at=(0.5, 0, 0), grid=(8, 8, 8), cubes=((0, 7),) * 3)
    with pytest.raises(ValueError, match="negative"):
        skelclimb.extract_block(v, 1, at=(-1, 0, 0), grid=(8, 8, 8), cubes=((0, 7),) * 3)
    with pytest.raises(TypeError, match="split_every"):
        skelclimb.dask.extract(da.from_array(v, chunks=4), 1, split_every=2.5)
    # NumPy's scalars are numbers like any other.
    assert same(skelclimb.extract(v, np.float32(1)), skelclimb.extract(v, 1))
    a = skelclimb.marching_cubes(v, np.float64(0.5), step_size=np.int32(2))
    b = skelclimb.marching_cubes(v, 0.5, step_size=2)
    assert all(np.array_equal(x, y) for x, y in zip(a, b))


def test_the_dask_driver_takes_numpy_arrays_and_explains_unknown_chunks():
    v = cube(12)
    assert same(skelclimb.dask.extract(v, 1), skelclimb.extract(v, 1))
    d = da.from_array(v, chunks=6)
    unknown = d[d[:, 0, 0] == 0]  # boolean indexing: Dask cannot know the chunks' sizes
    assert np.isnan(unknown.chunks[0][0])
    with pytest.raises(ValueError, match=r"compute_chunk_sizes\(\)"):
        skelclimb.dask.extract(unknown, 1)
    with pytest.raises(TypeError, match="array: expected a dask.array or a NumPy array"):
        skelclimb.dask.extract(object(), 1)


def test_merge_shards_takes_paths_only():
    with pytest.raises(TypeError):
        skelclimb.merge_shards(123)
    with pytest.raises(OSError, match="no-such"):
        skelclimb.merge_shards(b"/no-such/manifest.json")
