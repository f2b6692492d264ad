#!/usr/bin/env python3
"""Checks of docs/labels.md's face rule, exhaustive over a cube's labellings, and a census of
junction cubes in real segmentations.

    python3 bench/label_patterns.py                       # the exhaustive check (about 30 s)
    SC_DATA_DIR=../shared/data python3 bench/label_patterns.py --census   # needs NumPy

The check enumerates every ordered labelling of a cube's eight corners (each set partition of
the corners, with every order of its blocks: 545,835), applies the face rule (the smallest label
on a face connects, every maximal run of another label is cut off by one side), and counts the
cubes whose side graph has a node of degree other than two (junction cubes). For the others
(simple cubes) it asserts that each side's pair is the same at both its ends, and that every side
is a side of the binary case whose filled corners carry the larger label of its pair.
"""
import collections
import itertools
import json
import os
import sys

# Each face's corners in cyclic order; corner c sits at (c & 1, c >> 1 & 1, c >> 2 & 1).
FACES = []
for axis in range(3):
    others = [a for a in range(3) if a != axis]
    cycle = {(0, 0): 0, (1, 0): 1, (1, 1): 2, (0, 1): 3}
    for side in (0, 1):
        corners = [c for c in range(8) if (c >> axis) & 1 == side]
        corners.sort(key=lambda c: cycle[((c >> others[0]) & 1, (c >> others[1]) & 1)])
        FACES.append(corners)


def edge(a, b):
    return (min(a, b), max(a, b))


def face_sides(labels, face):
    """The face rule: (edge, edge, cap label, the face's smallest label) per side."""
    ls = [labels[c] for c in face]
    m = min(ls)
    if all(l == m for l in ls):
        return []
    start = next(i for i in range(4) if ls[i] != ls[i - 1])
    sides, i, seen = [], start, 0
    while seen < 4:
        j = i
        while ls[(j + 1) % 4] == ls[i % 4] and j + 1 - i < 4:
            j += 1
        if ls[i % 4] != m:
            first = edge(face[(i - 1) % 4], face[i % 4])
            last = edge(face[j % 4], face[(j + 1) % 4])
            sides.append((first, last, ls[i % 4], m))
        seen += j - i + 1
        i = (j + 1) % 4
    return sides


def cube_sides(labels):
    return [s for f in FACES for s in face_sides(labels, f)]


def patterns():
    """Restricted growth strings of the eight corners, each with every order of its blocks."""
    def rgs(prefix, top):
        if len(prefix) == 8:
            yield prefix
            return
        for v in range(top + 2):
            yield from rgs(prefix + [v], max(top, v))
    for blocks in rgs([0], 0):
        k = max(blocks) + 1
        for order in itertools.permutations(range(k)):
            yield [order[b] for b in blocks], k


def check():
    counts = collections.Counter()
    for labels, k in patterns():
        sides = cube_sides(labels)
        if not sides:
            continue
        degree = collections.Counter(e for s in sides for e in s[:2])
        if any(d != 2 for d in degree.values()):
            counts["junction", k] += 1
            continue
        counts["simple", k] += 1
        pairs = collections.defaultdict(set)
        for a, b, x, y in sides:
            pairs[a].add((x, y))
            pairs[b].add((x, y))
        assert all(len(p) == 1 for p in pairs.values()), labels
        for a, b, x, y in sides:
            binary = [int(l == x) for l in labels]
            assert (a, b) in {s[:2] for s in cube_sides(binary)}, labels
    for key in sorted(counts):
        print(*key, counts[key])
    print("simple:", sum(v for (kind, _), v in counts.items() if kind == "simple"),
          "junction:", sum(v for (kind, _), v in counts.items() if kind == "junction"))


def census():
    import numpy as np
    data = os.environ["SC_DATA_DIR"]
    for name in ["aal-atlas", "jhu-wm-atlas", "itk-kmeans-seg"]:
        folder = os.path.join(data, "labels", name)
        meta = json.load(open(os.path.join(folder, name + ".json")))
        nx, ny, nz = meta["dims"]
        dtype = {"u8": np.uint8, "u16": np.uint16, "i16": np.int16, "u32": np.uint32}[meta["dtype"]]
        v = np.pad(np.fromfile(os.path.join(folder, name + ".raw"), dtype).reshape(nz, ny, nx), 1)
        z, y, x = (n - 1 for n in v.shape)
        corners = np.stack([v[a:a + z, b:b + y, c:c + x] for a in (0, 1) for b in (0, 1)
                            for c in (0, 1)]).reshape(8, -1)
        surface = corners[:, corners.min(0) != corners.max(0)]
        k = 1 + (np.diff(np.sort(surface, axis=0), axis=0) != 0).sum(0)
        print(f"{name}: {surface.shape[1]} surface cubes, 2 labels {np.mean(k == 2):.3f}, "
              f"3 labels {np.mean(k == 3):.3f}, 4 or more {np.mean(k >= 4):.3f}")


if __name__ == "__main__":
    census() if "--census" in sys.argv else check()
