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
