"""`skelclimb.labels`: every label's mesh closed and outward, the atlas and the meshes the same
triangles, two labels the binary engine's mesh, dtypes, selections, placement and bad input."""

from collections import Counter

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import skelclimb
from test_skelclimb import assert_gil_released, edges_shared_twice, signed_volume, traced_peak

LABEL_TYPES = ["u1", "u2", "u4", "u8", "i2", "i4"]
MODES = ["embedded", "paper", "steps123"]


def cells(shape, n, seed, dtype=np.uint8):
    """Voronoi cells of `n` random seeds, labelled 0..n-1 (0 the background)."""
    rng = np.random.default_rng(seed)
    centres = rng.random((n, 3)) * shape
    grid = np.stack(np.indices(shape), axis=-1)
    d = ((grid[..., None, :] - centres) ** 2).sum(axis=-1)
    return d.argmin(axis=-1).astype(dtype)


def triangles(vertices, faces):
    """The triangles as sorted tuples of vertex positions, each rotated to start at its least
    vertex: the same for the same oriented triangles, whatever the vertex numbering."""
    out = []
    for t in vertices[faces].tolist():
        t = [tuple(p) for p in t]
        r = t.index(min(t))
        out.append(tuple(t[r:] + t[:r]))
    return sorted(out)


def without_boundary(faces):
    """Every directed edge as often as its reverse: a closed surface, though perhaps not a
    2-manifold (paper mode flattens a lone voxel into two coinciding squares)."""
    directed = Counter(map(tuple, np.concatenate(
        [faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]).tolist()))
    return all(directed[(b, a)] == n for (a, b), n in directed.items())


def check_labels(volume, result, background=0, mode="embedded"):
    """Every label's mesh exactly the atlas's triangles of that label, and closed: outward
    2-manifolds but in paper mode, which merges wherever the paper does."""
    atlas = result.atlas
    pairs = atlas.face_labels
    assert pairs.dtype == volume.dtype
    assert (pairs[:, 0] != pairs[:, 1]).all()
    present = sorted(set(np.unique(volume).tolist()) - {background})
    assert result.labels() == present == list(result)
    assert sorted(set(pairs.ravel().tolist()) - {background}) == present
    for label in present:
        mesh = result[label]
        first, second = pairs[:, 0] == label, pairs[:, 1] == label
        assert len(mesh.faces) == first.sum() + second.sum()
        assert without_boundary(mesh.faces), label
        if mode != "paper":
            assert edges_shared_twice(mesh.faces), label
            assert signed_volume(mesh.vertices, mesh.faces) > 0, label
        # Triangles with the label first keep their winding; with it second they are turned.
        expected = np.concatenate([atlas.faces[first], atlas.faces[second][:, [0, 2, 1]]])
        assert triangles(mesh.vertices, mesh.faces) == triangles(atlas.vertices, expected)
        if mesh.normals is not None:
            assert mesh.normals.shape == mesh.vertices.shape
            # Unit length, but where a folded sheet's two sides cancel (zero, paper mode only).
            lengths = np.linalg.norm(mesh.normals, axis=1)
            unit = np.isclose(lengths, 1, atol=1e-5)
            assert (unit | ((lengths == 0) & (mode == "paper"))).all(), label


# ---- the meshes ----


@st.composite
def label_volumes(draw):
    shape = draw(st.tuples(*[st.integers(1, 6)] * 3))
    dtype = draw(st.sampled_from(LABEL_TYPES))
    count = draw(st.integers(1, 5))
    values = st.sampled_from(draw(st.lists(st.integers(0, 250), min_size=count, max_size=count)))
    return draw(hnp.arrays(np.dtype(dtype), shape, elements=values))


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(label_volumes(), st.sampled_from(MODES))
def test_every_label_s_mesh_is_closed_outward_and_the_atlas_s(volume, mode):
    check_labels(volume, skelclimb.labels(volume, mode=mode), mode=mode)


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("seed", range(3))
def test_voronoi_cells(seed, mode):
    volume = cells((9, 11, 10), 12, seed, np.uint16)
    result = skelclimb.labels(volume, mode=mode)
    check_labels(volume, result, mode=mode)
    assert result.stats["result"]["triangles"] == len(result.atlas.faces)
    assert result.stats["result"]["vertices"] == len(result.atlas.vertices)
    assert result.stats["mode"] == mode
    if mode == "steps123":
        assert result.stats["merged"] == 0


def test_meshes_share_the_atlas_vertices():
    """A vertex on an interface exists once: the meshes' positions are atlas positions."""
    result = skelclimb.labels(cells((8, 8, 8), 6, 4))
    atlas = {tuple(p) for p in result.atlas.vertices.tolist()}
    assert len(atlas) == len(result.atlas.vertices)
    for label, mesh in result.items():
        assert {tuple(p) for p in mesh.vertices.tolist()} <= atlas, label


def cut(atlas, label, normals):
    """`label`'s mesh cut from `atlas` in NumPy, as the runtime cuts it: the atlas's triangles
    in order, those with the label second turned over, the vertices renumbered in order of
    first use; normals the normalised float64 sums of the triangles' area normals."""
    first, second = atlas.face_labels[:, 0] == label, atlas.face_labels[:, 1] == label
    faces = np.where(second[:, None], atlas.faces[:, [0, 2, 1]], atlas.faces)[first | second]
    used, at, local = np.unique(faces.ravel(), return_index=True, return_inverse=True)
    order = np.argsort(at)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    vertices = atlas.vertices[used[order]]
    faces = rank[local].reshape(-1, 3).astype(np.uint32)
    if not normals:
        return vertices, faces, None
    a, b, c = (vertices[faces[:, k]].astype(np.float64) for k in range(3))
    sums = np.zeros((len(vertices), 3))
    np.add.at(sums, faces.ravel(), np.repeat(np.cross(b - a, c - a), 3, axis=0))
    length = np.sqrt((sums ** 2).sum(axis=1))[:, None]
    unit = np.divide(sums, length, out=np.zeros_like(sums), where=length > 0)
    return vertices, faces, unit.astype(np.float32)


@pytest.mark.parametrize("normals", [True, False])
def test_meshes_are_cut_once_when_first_asked_for(monkeypatch, normals):
    """The call builds the atlas alone; the first mesh asked for cuts every label's, once, and
    those are the bytes the atlas gives (labels converted from int64 and back, placed by an
    affine that mirrors)."""
    calls = []
    native = skelclimb._labels._native.label_meshes

    def counted(*args):
        calls.append(args[3].tolist())
        return native(*args)

    monkeypatch.setattr(skelclimb._labels._native, "label_meshes", counted)
    volume = cells((7, 8, 9), 7, 14).astype(np.int64) * 1000 - 3000
    mirror = np.array([[0, 2, 0, 10], [2, 0, 0, 0], [0, 0, 2, 0], [0, 0, 0, 1]], dtype=float)
    result = skelclimb.labels(volume, background=-3000, affine=mirror, space="LPS",
                              normals=normals, threads=2)
    present = sorted(set(np.unique(volume).tolist()) - {-3000})
    assert result.labels() == list(result) == list(result.keys()) == present
    assert len(result) == 6 and present[2] in result and 5 not in result and "0" not in result
    with pytest.raises(KeyError, match=r"label 5 has no mesh here; meshed: -2000, -1000, 0, "):
        result[5]
    assert repr(result) == f"Labels(6 labels, {result.atlas!r})"
    assert calls == [] and result._meshes is None
    assert result.atlas.face_labels.dtype == np.int64
    for label, mesh in result.items():
        vertices, faces, normals_ = cut(result.atlas, label, normals)
        assert mesh.vertices.tobytes() == vertices.tobytes(), label
        assert mesh.faces.tobytes() == faces.tobytes(), label
        assert (mesh.normals is None) == (normals_ is None)
        assert normals_ is None or mesh.normals.tobytes() == normals_.tobytes(), label
        assert mesh.stats == {"label": label, "mode": "embedded", "space": "LPS",
                              "result": {"vertices": len(vertices), "triangles": len(faces)}}
    assert [m.faces.tobytes() for m in result.values()] == [
        result[label].faces.tobytes() for label in present]
    assert calls == [present]


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("seed", range(4))
def test_two_labels_give_extract_s_mesh_of_the_indicator(seed, mode):
    volume = np.where(cells((10, 9, 11), 5, seed) % 2 == 1, 7, 0).astype(np.uint16)
    spacing, origin = (1.0, 1.25, 0.75), (-3.0, -0.25, -0.25)
    result = skelclimb.labels(volume, spacing=spacing, origin=origin, mode=mode)
    binary = skelclimb.extract(
        (volume == 7).astype(np.float32), 0.5, spacing=spacing, origin=origin, mode=mode,
        pad=True,
    )
    assert (result.atlas.face_labels == [7, 0]).all()
    assert triangles(result.atlas.vertices, result.atlas.faces) == triangles(
        binary.vertices, binary.faces
    )
    assert result.stats["merged"] == binary.stats["merged"]


def test_the_background_is_any_label():
    volume = cells((7, 8, 9), 5, 1)
    result = skelclimb.labels(volume, background=3)
    check_labels(volume, result, background=3)
    assert 0 in result and 3 not in result
    assert result.stats["background"] == 3


def test_padding_is_a_layer_of_background():
    """`pad=True` meshes the volume surrounded by one sample of background, in the unpadded
    volume's coordinates (merges follow the grid's parity, so only that identity is exact)."""
    volume = cells((6, 7, 8), 5, 12).astype(np.int32) - 2
    spacing = (0.5, 1.0, 2.0)
    padded = skelclimb.labels(volume, spacing=spacing, background=-2)
    around = skelclimb.labels(np.pad(volume, 1, constant_values=-2), spacing=spacing,
                              origin=(-0.5, -1.0, -2.0), background=-2, pad=False)
    for name in ("vertices", "faces", "face_labels"):
        assert np.array_equal(getattr(padded.atlas, name), getattr(around.atlas, name)), name
    # Without padding, a label that meets the border is open there.
    halves = np.zeros((3, 3, 3), np.uint8)
    halves[:, :, 1:] = 1
    assert not edges_shared_twice(skelclimb.labels(halves, pad=False)[1].faces)


def test_without_normals():
    result = skelclimb.labels(cells((5, 5, 5), 3, 0), normals=False)
    assert all(mesh.normals is None for mesh in result.values())


def test_an_empty_selection_of_nothing_but_background():
    result = skelclimb.labels(np.zeros((4, 4, 4), np.uint8))
    assert len(result) == 0 and result.labels() == [] and len(result.atlas.faces) == 0


# ---- types ----


@pytest.mark.parametrize("dtype", LABEL_TYPES)
def test_every_label_type_gives_the_same_meshes(dtype):
    volume = cells((6, 7, 8), 5, 2)
    reference = skelclimb.labels(volume)
    result = skelclimb.labels(volume.astype(dtype))
    check_labels(volume.astype(dtype), result)
    assert result.atlas.face_labels.dtype == np.dtype(dtype)
    assert np.array_equal(result.atlas.vertices, reference.atlas.vertices)
    assert np.array_equal(result.atlas.faces, reference.atlas.faces)
    assert np.array_equal(result.atlas.face_labels, reference.atlas.face_labels)


@pytest.mark.parametrize(
    "dtype, offset", [("i1", -10), ("i8", -10), ("i8", 2**40), ("i8", -(2**20)), (">u2", 0)]
)
def test_other_integer_types_are_converted(dtype, offset):
    volume = cells((6, 7, 8), 5, 3).astype(np.int64)
    labelled = np.where(volume > 0, volume + offset, 0).astype(dtype)
    result = skelclimb.labels(labelled)
    assert result.atlas.face_labels.dtype == np.dtype(dtype).newbyteorder("=")
    check_labels(labelled.astype(np.dtype(dtype).newbyteorder("=")), result)
    reference = skelclimb.labels(volume)
    assert np.array_equal(result.atlas.faces, reference.atlas.faces)
    assert np.array_equal(result.atlas.face_labels, np.where(
        reference.atlas.face_labels > 0, reference.atlas.face_labels + offset, 0))


def test_int64_labels_that_no_label_type_holds_are_refused():
    volume = np.zeros((3, 3, 3), np.int64)
    volume[1, 1, 1] = -(2**40)
    with pytest.raises(ValueError, match=r"volume: .*int64.*-1099511627776"):
        skelclimb.labels(volume)


def test_labels_near_the_top_of_uint64():
    volume = np.zeros((4, 4, 5), np.uint64)
    volume[1:3, 1:3, 1:3] = 2**64 - 1
    volume[1:3, 1:3, 3] = 2**64 - 2
    result = skelclimb.labels(volume)
    check_labels(volume, result)
    assert result.labels() == [2**64 - 2, 2**64 - 1]


@pytest.mark.parametrize("dtype", ["f4", "f8", "?"])
def test_floats_and_bools_are_refused(dtype):
    name = np.dtype(dtype).name
    with pytest.raises(TypeError, match=f"volume holds {name}; label volumes need integers"):
        skelclimb.labels(np.zeros((3, 3, 3), dtype))


def test_other_shapes_and_objects_are_refused():
    with pytest.raises(ValueError, match="volume: expected a 3-D array, got 2"):
        skelclimb.labels(np.zeros((3, 3), np.uint8))
    with pytest.raises(TypeError, match="volume: expected a NumPy array"):
        skelclimb.labels([[[1]]])


def test_a_background_outside_the_type_is_refused():
    with pytest.raises(ValueError, match="background: 300 is not a value of the volume's uint8"):
        skelclimb.labels(np.zeros((3, 3, 3), np.uint8), background=300)
    with pytest.raises(TypeError, match="background: expected a whole number"):
        skelclimb.labels(np.zeros((3, 3, 3), np.uint8), background=0.5)


def test_no_copy_of_a_contiguous_input():
    volume = np.zeros((128, 128, 128), np.uint32)
    volume[20:100, 20:100, 20:60] = 1
    volume[20:100, 20:100, 60:100] = 2
    result, peak = traced_peak(lambda: skelclimb.labels(volume, normals=False))
    assert result.labels() == [1, 2]
    assert peak < volume.nbytes // 16, peak


def test_the_gil_is_released():
    volume = np.random.default_rng(5).integers(0, 50, (96, 96, 96), dtype=np.uint16)
    result = []
    assert_gil_released(lambda: result.append(skelclimb.labels(volume, normals=False)))
    # And while the meshes are cut, when the first is asked for.
    assert_gil_released(lambda: result[0][1])


# ---- selections ----


def test_a_selection_meshes_those_labels_alone():
    volume = cells((7, 8, 9), 6, 6)
    everything = skelclimb.labels(volume)
    some = skelclimb.labels(volume, labels=np.array([4, 2, 4]))
    assert some.labels() == [2, 4]
    for label in (2, 4):
        assert np.array_equal(some[label].vertices, everything[label].vertices)
        assert np.array_equal(some[label].faces, everything[label].faces)
    # The atlas is the whole volume's, whatever is selected.
    assert np.array_equal(some.atlas.faces, everything.atlas.faces)
    with pytest.raises(KeyError, match="label 3 has no mesh here; meshed: 2, 4"):
        some[3]
    with pytest.raises(KeyError):
        some["2"]
    assert 3 not in some and 2 in some and np.int64(4) in some


def test_selection_errors():
    volume = cells((7, 8, 9), 14, 7)
    with pytest.raises(ValueError, match=r"labels: 20, 99 not in the volume; those with a "
                       r"surface are 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, … \(13 in all\)"):
        skelclimb.labels(volume, labels=[99, 3, 20])
    with pytest.raises(ValueError, match="labels: -1 not in the volume"):
        skelclimb.labels(volume, labels=[-1])
    with pytest.raises(ValueError, match="labels: the selection is empty"):
        skelclimb.labels(volume, labels=[])
    with pytest.raises(ValueError, match="labels: 0 is the background"):
        skelclimb.labels(volume, labels=[0, 1])
    with pytest.raises(TypeError, match="labels: expected a whole number, got 1.5"):
        skelclimb.labels(volume, labels=[1.5])
    with pytest.raises(TypeError, match="labels: expected an iterable"):
        skelclimb.labels(volume, labels="12")
    with pytest.raises(TypeError, match="labels: expected an iterable"):
        skelclimb.labels(volume, labels=3)
    with pytest.raises(ValueError, match="mode: expected one of"):
        skelclimb.labels(volume, mode="fast")


# ---- where the vertices go ----


def test_spacing_and_origin():
    volume = cells((6, 7, 8), 5, 8)
    unit = skelclimb.labels(volume)
    spacing, origin = (0.5, 2.0, 1.5), (10.0, -4.0, 0.25)
    placed = skelclimb.labels(volume, spacing=spacing, origin=origin)
    assert np.array_equal(placed.atlas.faces, unit.atlas.faces)
    assert np.allclose(placed.atlas.vertices, unit.atlas.vertices * spacing + origin, atol=1e-5)
    for label in unit:
        assert np.allclose(placed[label].vertices, unit[label].vertices * spacing + origin,
                           atol=1e-5)
    with pytest.raises(ValueError, match="spacing: must be three positive numbers"):
        skelclimb.labels(volume, spacing=(1, 0, 1))


def test_axes_are_read_as_extract_reads_them():
    """A C array (z, y, x) and the Fortran array of its transpose (x, y, z) are one volume."""
    volume = cells((5, 6, 7), 4, 9) + 1
    c, f = skelclimb.labels(volume), skelclimb.labels(volume.T)
    assert volume.T.flags.f_contiguous
    assert np.array_equal(c.atlas.vertices, f.atlas.vertices)
    assert np.array_equal(c.atlas.faces, f.atlas.faces)
    # A strided view is copied once, and reads the same.
    wide = np.zeros((5, 6, 14), np.uint8)
    wide[:, :, ::2] = volume
    assert np.array_equal(skelclimb.labels(wide[:, :, ::2]).atlas.faces, c.atlas.faces)
    # x is the last axis, the first coordinate: the labels fill the volume, and the padded
    # border's faces lie half a step outside it.
    extent = c.atlas.vertices.max(axis=0) - c.atlas.vertices.min(axis=0)
    assert np.array_equal(extent, [7, 6, 5])


def test_a_mirroring_affine_keeps_every_mesh_outward():
    volume = cells((6, 7, 8), 5, 10)
    unit = skelclimb.labels(volume)
    swap = np.array([[0, 2, 0, 10], [2, 0, 0, 0], [0, 0, 2, 0], [0, 0, 0, 1]], dtype=float)
    placed = skelclimb.labels(volume, affine=swap, space="RAS")
    assert placed.stats["space"] == "RAS"
    assert np.allclose(placed.atlas.vertices, unit.atlas.vertices[:, [1, 0, 2]] * 2 + [10, 0, 0])
    check_labels(volume, placed)
    assert all(m.stats["space"] == "RAS" for m in placed.values())


# ---- PyVista ----


def test_to_pyvista_gives_a_block_per_label():
    pyvista = pytest.importorskip("pyvista")
    result = skelclimb.labels(cells((6, 6, 6), 4, 11))
    blocks = result.to_pyvista()
    assert isinstance(blocks, pyvista.MultiBlock)
    assert list(blocks.keys()) == [str(label) for label in result]
    for label, mesh in result.items():
        assert blocks[str(label)].n_cells == len(mesh.faces)


def test_any_thread_count_gives_the_same_atlas():
    rng = np.random.default_rng(5)
    seeds = rng.uniform(0, 40, size=(12, 3))
    grid = np.stack(np.meshgrid(*(np.arange(n) for n in (40, 9, 8)), indexing="ij"), -1)
    volume = np.argmin(((grid[..., None, :] - seeds) ** 2).sum(-1), -1).astype(np.uint16)
    one = skelclimb.labels(volume, threads=1)
    for threads in (2, 3, 0):
        other = skelclimb.labels(volume, threads=threads)
        np.testing.assert_array_equal(other.atlas.vertices, one.atlas.vertices)
        np.testing.assert_array_equal(other.atlas.faces, one.atlas.faces)
        np.testing.assert_array_equal(other.atlas.face_labels, one.atlas.face_labels)
    with pytest.raises(ValueError):
        skelclimb.labels(volume, threads=-1)


def test_smoothing_moves_vertices_along_their_edges_only():
    z, y, x = np.mgrid[:24, :24, :24]
    ball = (((x - 11.5) ** 2 + (y - 11.5) ** 2 + (z - 11.5) ** 2) <= 81).astype(np.uint8)
    plain = skelclimb.labels(ball)
    smooth = skelclimb.labels(ball, smoothing=0.75)
    np.testing.assert_array_equal(plain.atlas.faces, smooth.atlas.faces)
    moved = plain.atlas.vertices != smooth.atlas.vertices
    assert moved.any() and (moved.sum(axis=1) <= 1).all()  # along one axis: its edge's
    assert (np.abs(plain.atlas.vertices - smooth.atlas.vertices) < 0.5).all()
    def area(m):
        v, f = m.vertices, m.faces
        return 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1).sum()
    exact = 4 * np.pi * 81
    assert area(plain[1]) / exact - 1 > 0.05
    assert abs(area(smooth[1]) / exact - 1) < 0.01
    for bad in (-1, 5, float("nan")):
        with pytest.raises(ValueError, match="smoothing"):
            skelclimb.labels(ball, smoothing=bad)
    with pytest.raises(TypeError, match="smoothing"):
        skelclimb.labels(ball, smoothing="0.5")
