"""Adaptive mode from Python: the box options reach the runtime, and bad ones are refused by
name. The meshes themselves are checked exhaustively by the Rust suite (tests/tests/adaptive.rs)."""

import numpy as np
import pytest

import skelclimb


def _ball(n=32, r=11.3):
    z, y, x = np.mgrid[:n, :n, :n] - (n - 1) / 2
    return (r - np.sqrt(x * x + y * y + z * z)).astype(np.float32)


def _closed(mesh):
    """Every undirected edge in exactly two faces, in opposite directions."""
    f = mesh.faces
    directed = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    keys = {tuple(e) for e in directed.tolist()}
    return len(keys) == len(directed) and all((b, a) in keys for a, b in keys)


def test_boxes_save_triangles_and_max_box_one_is_steps123():
    v = _ball()
    steps = skelclimb.extract(v, 0.0, mode="steps123")
    one = skelclimb.extract(v, 0.0, mode="adaptive", max_box=1)
    assert np.array_equal(one.faces, steps.faces)
    assert np.array_equal(one.vertices, steps.vertices)
    counts = [
        len(skelclimb.extract(v, 0.0, mode="adaptive", max_box=b).faces) for b in (1, 2, 4, 16)
    ]
    assert counts == sorted(counts, reverse=True) and counts[-1] < counts[0]
    default = skelclimb.extract(v, 0.0, mode="adaptive")
    assert len(default.faces) == counts[-1]
    assert _closed(default)
    # Its boxes shared out over threads: the same mesh.
    for threads in (1, 3):
        again = skelclimb.extract(v, 0.0, mode="adaptive", threads=threads)
        assert np.array_equal(again.faces, default.faces)
        assert np.array_equal(again.vertices, default.vertices)


def test_allowing_wrong_side_never_adds_triangles():
    v = _ball()
    kept = skelclimb.extract(v, 0.0, mode="adaptive", max_error=1, error_units="voxels")
    allowed = skelclimb.extract(
        v, 0.0, mode="adaptive", max_error=1, error_units="voxels", allow_wrong_side=True
    )
    assert len(allowed.faces) < len(kept.faces)
    assert _closed(allowed)


@pytest.mark.parametrize(
    "kwargs, error, words",
    [
        ({"mode": "adaptive", "max_box": 3}, ValueError, "max_box"),
        ({"mode": "adaptive", "max_box": 64}, ValueError, "max_box"),
        ({"mode": "adaptive", "max_box": "2"}, TypeError, "max_box"),
        ({"mode": "embedded", "max_box": 2}, ValueError, "max_box needs adaptive mode"),
        ({"mode": "steps123", "allow_wrong_side": True}, ValueError, "allow_wrong_side"),
        ({"mode": "adaptive", "max_error": -1}, ValueError, "max_error"),
    ],
)
def test_bad_options_are_refused_by_name(kwargs, error, words):
    with pytest.raises(error, match=words):
        skelclimb.extract(_ball(), 0.0, **kwargs)


def test_stats_count_the_samples_on_the_wrong_side():
    v = _ball()
    options = dict(mode="adaptive", max_error=1, error_units="voxels")
    kept = skelclimb.extract(v, 0.0, **options)
    allowed = skelclimb.extract(v, 0.0, allow_wrong_side=True, **options)
    assert kept.stats["wrong_side_samples"] == 0
    assert allowed.stats["wrong_side_samples"] > 0
    # Counted where the extractor placed the mesh, before any other world map.
    swap = np.array([[0, 2, 0, 10], [2, 0, 0, 0], [0, 0, 2, 0], [0, 0, 0, 1]])
    placed = skelclimb.extract(v, 0.0, allow_wrong_side=True, affine=swap, **options)
    assert placed.stats["wrong_side_samples"] == allowed.stats["wrong_side_samples"]
    # A filled border sample opens the surface: not counted, until `pad` closes it.
    v[0, 0, 0] = 1
    assert skelclimb.extract(v, 0.0, **options).stats["wrong_side_samples"] is None
    assert skelclimb.extract(v, 0.0, pad=True, **options).stats["wrong_side_samples"] == 0
    # The other modes do not count them.
    assert "wrong_side_samples" not in skelclimb.extract(v, 0.0, mode="steps123").stats
