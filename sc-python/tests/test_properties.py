"""Property-based tests of the Python API with Hypothesis: any shape (0- and 1-sized axes
too), dtype, memory layout (Fortran, strided, reversed, unaligned), level (NaN and infinities
too), spacing, mask and thread count either give a valid mesh or raise one of the documented
exceptions; nothing crashes or hangs. Examples are few so the suite stays fast."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import skelclimb

SETTINGS = settings(max_examples=60, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
DOCUMENTED = (ValueError, TypeError, MemoryError)
DTYPES = ["u1", "i1", "u2", "i2", "u4", "i4", "f4", "f8", "bool", "i8", "f2", ">f4", "<u2"]

shapes = st.tuples(*[st.integers(0, 6)] * 3)
levels = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.integers(-300, 300),
    st.sampled_from([0.5, 1, 2.5]),
)
coordinates = st.one_of(
    st.floats(-10, 10),
    st.sampled_from([0.0, 1.0, 1e-30, 1e29, 1e30, 1e308, float("inf"), float("nan")]),
)
triples = st.tuples(coordinates, coordinates, coordinates)
threads = st.sampled_from([0, 1, 2, 3, 1024, 1025, 2**31, 2**70, -1, 1.5, np.int64(2)])


@st.composite
def volumes(draw):
    """An array of any shape and dtype, in one of the layouts a caller might pass."""
    dtype = np.dtype(draw(st.sampled_from(DTYPES)))
    if dtype.kind == "f":
        elements = st.floats(allow_nan=True, allow_infinity=True, width=8 * min(dtype.itemsize, 4))
    elif dtype.kind == "b":
        elements = st.booleans()
    else:
        info = np.iinfo(dtype)
        elements = st.integers(max(int(info.min), -5), min(int(info.max), 5))
    base = draw(hnp.arrays(dtype, draw(shapes), elements=elements))
    layout = draw(st.sampled_from(["C", "F", "transposed", "reversed", "strided", "unaligned"]))
    if layout == "F":
        return np.asfortranarray(base)
    if layout == "transposed":
        return base.transpose(1, 0, 2)
    if layout == "reversed":
        return base[::-1, :, ::-1]
    if layout == "strided":
        return np.repeat(base, 2, axis=1)[:, ::2]
    if layout == "unaligned" and dtype.itemsize > 1:
        buf = np.zeros(base.nbytes + 1, np.uint8)[1:].view(dtype).reshape(base.shape)
        buf[...] = base
        return buf
    return base


def check_mesh(verts, faces, normals=None):
    assert verts.ndim == 2 and verts.shape[1] == 3
    assert faces.ndim == 2 and faces.shape[1] == 3
    assert np.isfinite(verts).all(), "non-finite vertices"
    if len(faces):
        assert faces.min() >= 0 and faces.max() < len(verts), "face indices out of range"
    if normals is not None:
        assert normals.shape == verts.shape and np.isfinite(normals).all()


@SETTINGS
@given(volume=volumes(), level=levels, spacing=triples, origin=triples, threads=threads,
       mode=st.sampled_from(["embedded", "paper", "steps123"]), pad=st.booleans())
def test_extract_gives_a_valid_mesh_or_a_documented_error(volume, level, spacing, origin,
                                                          threads, mode, pad):
    try:
        m = skelclimb.extract(volume, level, spacing=spacing, origin=origin, threads=threads,
                              mode=mode, pad=pad)
    except DOCUMENTED:
        return
    check_mesh(m.vertices, m.faces, m.normals)
    # The same call with one thread gives the same mesh: threads never change it.
    one = skelclimb.extract(volume, level, spacing=spacing, origin=origin, threads=1,
                            mode=mode, pad=pad)
    assert np.array_equal(one.faces, m.faces) and np.array_equal(one.vertices, m.vertices)


@SETTINGS
@given(volume=volumes(), level=st.one_of(st.none(), levels), spacing=triples,
       step=st.sampled_from([1, 2, 3, 7, 1.5, np.int16(2)]), threads=threads,
       mask=st.sampled_from([None, "bool", "i8", "f4"]), seed=st.integers(0, 3))
def test_marching_cubes_gives_a_valid_mesh_or_a_documented_error(volume, level, spacing, step,
                                                                 threads, mask, seed):
    if mask is not None:
        mask = (np.random.default_rng(seed).random(volume.shape) < 0.7).astype(mask)
    try:
        verts, faces, normals, values = skelclimb.marching_cubes(
            volume, level, spacing=spacing, step_size=step, threads=threads, mask=mask)
    except DOCUMENTED + (RuntimeError,):  # RuntimeError: no surface, as scikit-image says
        return
    check_mesh(verts, faces, normals)
    assert faces.dtype == np.int32 and len(values) == len(verts)


@SETTINGS
@given(volume=volumes(), level=levels, spacing=triples, origin=triples)
def test_the_streamer_gives_extract_s_mesh_or_a_documented_error(volume, level, spacing, origin):
    try:
        s = skelclimb.SliceStreamer(volume.shape, level, spacing=spacing, origin=origin)
        for z in range(volume.shape[0]):
            s.push(volume[z])
        m = s.finish()
    except DOCUMENTED:
        return
    check_mesh(m.vertices, m.faces, m.normals)
    # The streamer took the slices along the first axis, as a C-ordered array's z; `extract`
    # reads a Fortran-ordered array's axes as (x, y, z), so it is given the C-ordered copy.
    whole = skelclimb.extract(np.ascontiguousarray(volume, dtype=np.float64), level,
                              spacing=spacing, origin=origin)
    assert np.array_equal(whole.faces, m.faces) and np.array_equal(whole.vertices, m.vertices)


@SETTINGS
@given(volume=volumes(), level=levels, spacing=triples,
       at=st.tuples(*[st.integers(-1, 3)] * 3), grid=st.tuples(*[st.integers(0, 9)] * 3),
       ends=st.tuples(*[st.tuples(st.integers(-1, 9), st.integers(-1, 9))] * 3))
def test_blocks_give_a_valid_share_or_a_documented_error(volume, level, spacing, at, grid, ends):
    try:
        share = skelclimb.extract_block(volume, level, at=at, grid=grid, cubes=ends,
                                        spacing=spacing)
    except DOCUMENTED:
        return
    try:
        m = share.to_mesh()  # refused unless the block covers the grid
    except DOCUMENTED:
        return
    check_mesh(m.vertices, m.faces, m.normals)


@pytest.mark.parametrize("level", [float("nan"), float("inf"), -float("inf")])
def test_levels_that_are_not_numbers_are_refused(level):
    v = np.zeros((3, 3, 3), np.float32)
    with pytest.raises(ValueError, match="level"):
        skelclimb.extract(v, level)
    with pytest.raises(ValueError, match="level"):
        skelclimb.marching_cubes(v, level)
