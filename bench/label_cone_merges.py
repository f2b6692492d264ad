#!/usr/bin/env python3
"""How many more grey edges Step 4 could merge if it merged across cones drawn from a face.

    SC_DATA_DIR=../shared/data python3 bench/label_cone_merges.py     # needs NumPy

In a cone drawn from a face centre (docs/labels.md, rule 3), a node on an edge of the apex's face
has one triangle, an ear in SPEC §5's sense; every other node of a cone has two. For each padded
atlas this counts the occupied grey edges (SPEC §2) with their four cubes inside the grid: those
whose four cubes are all binary (today's merge candidates), those whose junction cubes are all
such cones with an ear at the edge (what merging across cones could add), and the rest. The cube
rules are label_patterns.py's, written independently of the runtime.
"""
import numpy as np

from label_patterns import apex_face, atlases, cube_corners, kind, pattern

BINARY, FACE_CONE, OTHER = 1, 2, 3


def cubes(v):
    """Per cube (z, y, x): its construction, and for a cone drawn from a face, that face."""
    z, y, x = (n - 1 for n in v.shape)
    corners = cube_corners(v)
    code = np.zeros(z * y * x, np.int8)
    face = np.full(z * y * x, -1, np.int8)
    cache = {}
    for idx in np.nonzero(corners.min(0) != corners.max(0))[0]:
        key = pattern(tuple(corners[:, idx]))
        if key not in cache:
            k = kind(list(key))
            cache[key] = ((BINARY, -1) if k == "binary" else
                          (FACE_CONE, apex_face(list(key))) if k == "cone from a face" else
                          (OTHER, -1))
        code[idx], face[idx] = cache[key]
    return code.reshape(z, y, x), face.reshape(z, y, x)


def census(v):
    code, face = cubes(v)
    z, y, x = code.shape
    counts = np.zeros(3, np.int64)
    # Per edge axis (x, y, z): the grey rule on (l, m, n), the step to the edge's far end, and
    # the two cube axes whose faces hold such an edge.
    for axis, grey, step, sides in [
        (0, lambda l, m, n: (m % 2 == 1) & (n % 2 == 1), (0, 0, 1), (1, 2)),
        (1, lambda l, m, n: (l % 2 == 1) & (n % 2 == 0), (0, 1, 0), (0, 2)),
        (2, lambda l, m, n: (l % 2 == 0) & (m % 2 == 0), (1, 0, 0), (0, 1)),
    ]:
        # Per (z, y, x): along the edge every cube; across it, from 1, so both cubes exist.
        first = [0 if a == axis else 1 for a in (2, 1, 0)]
        n_, m_, l_ = np.meshgrid(*[np.arange(a, b) for a, b in zip(first, (z, y, x))],
                                 indexing="ij")
        far = v[n_ + step[0], m_ + step[1], l_ + step[2]]
        chosen = grey(l_, m_, n_) & (v[n_, m_, l_] != far)
        n_, m_, l_ = n_[chosen], m_[chosen], l_[chosen]
        binary = np.ones(len(n_), bool)
        mergeable = np.ones(len(n_), bool)
        for dk, dj, di in [(dk, dj, di) for dk in (0, 1) for dj in (0, 1) for di in (0, 1)
                           if [di, dj, dk][axis] == 0]:
            c = code[n_ - dk, m_ - dj, l_ - di]
            f = face[n_ - dk, m_ - dj, l_ - di]
            offset = {0: di, 1: dj, 2: dk}
            ear = np.zeros(len(n_), bool)
            for a in sides:
                ear |= (f // 2 == a) & (f % 2 == offset[a])
            binary &= c == BINARY
            mergeable &= (c == BINARY) | ((c == FACE_CONE) & ear)
        counts += [binary.sum(), (mergeable & ~binary).sum(), (~mergeable).sum()]
    return counts


def main():
    for name, v in atlases():
        binary, across, rest = census(v)
        print(f"{name}: occupied grey edges, four binary cubes {binary}, binary cubes and cones "
              f"with an ear {across}, touching another junction cube {rest}")


if __name__ == "__main__":
    main()
