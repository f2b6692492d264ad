#!/usr/bin/env python3
"""A census of the cube constructions of docs/labels.md in real segmentations.

    SC_DATA_DIR=../shared/data python3 bench/label_patterns.py     # needs NumPy

For each padded label volume, counts the surface cubes (two or more labels among the corners)
that are binary cubes, cones (drawn from a face's centre or the cube's) and hubs. The rules are
written here again from docs/labels.md, independently of the runtime; the exhaustive check of
every labelling is the Rust test `every_labelling_of_a_cube` (tests/tests/labels.rs).
"""
import collections
import json
import os

# Each face's corners in cyclic order; corner c sits at (c & 1, c >> 1 & 1, c >> 2 & 1).
FACES = [[0, 2, 6, 4], [1, 3, 7, 5], [0, 1, 5, 4], [2, 3, 7, 6], [0, 1, 3, 2], [4, 5, 7, 6]]


def split(ls):
    """The face rule: ('uniform',), ('cut', connector label, either) or ('centre',)."""
    distinct = set(ls)
    if len(distinct) == 1:
        return ("uniform",)
    if len(distinct) == 2:
        return ("cut", min(ls), not (ls[0] == ls[2] and ls[1] == ls[3]))
    if len(distinct) == 3 and (ls[0] == ls[2] or ls[1] == ls[3]):
        return ("cut", ls[0] if ls[0] == ls[2] else ls[1], False)
    return ("centre",)


def pieces(ls, rule):
    """Groups of a face's positions held by one region."""
    if rule[0] == "uniform":
        return [[0, 1, 2, 3]]
    if rule[0] == "centre":
        return [[i for i in range(4) if ls[i] == label] for label in set(ls)]
    w = rule[1]
    out = [[i for i in range(4) if ls[i] == w]]
    for i in range(4):
        if ls[i] != w and ls[i - 1] != ls[i]:
            run = [i]
            while ls[(run[-1] + 1) % 4] == ls[i]:
                run.append((run[-1] + 1) % 4)
            out.append(run)
    return out


def kind(labels):
    """'binary', 'cone from a face', 'cone from the centre' or 'hub' for a cube of two or more
    labels."""
    rules = [split([labels[c] for c in f]) for f in FACES]
    for w in sorted(set(labels)):
        if all(r[0] == "uniform" or (r[0] == "cut" and (r[1] == w or (r[2] and w in
               [labels[c] for c in f]))) for r, f in zip(rules, FACES)):
            return "binary"
    parent = list(range(8))

    def find(x):
        while parent[x] != x:
            x = parent[x]
        return x
    for f, r in zip(FACES, rules):
        for group in pieces([labels[c] for c in f], r):
            for i in group[1:]:
                parent[find(f[i])] = find(f[group[0]])
    roots = {c: find(c) for c in range(8)}
    regions = len(set(roots.values()))
    one_per_label = all(roots[c] == roots[d] for c in range(8) for d in range(8)
                        if labels[c] == labels[d])
    occupied = sum(labels[a] != labels[b] for a in range(8) for b in range(a + 1, 8)
                   if bin(a ^ b).count("1") == 1)
    centres = sum(r[0] == "centre" for r in rules)
    sides = 0
    for f, r in zip(FACES, rules):
        ls = [labels[c] for c in f]
        if r[0] == "centre":
            sides += sum(ls[i] != ls[(i + 1) % 4] for i in range(4))
        elif r[0] == "cut":
            sides += len(pieces(ls, r)) - 1
    connected = occupied + centres + regions == sides + 2
    if not (connected and one_per_label):
        return "hub"
    return "cone from the centre" if apex_face(labels) is None else "cone from a face"


def apex_face(labels):
    """The face a cone is drawn from: the first whose centre has a side per region (as each
    label holds one region in a cone, a side per label), or None."""
    for f, face in enumerate(FACES):
        ls = [labels[c] for c in face]
        if split(ls)[0] == "centre" and \
                sum(ls[i] != ls[(i + 1) % 4] for i in range(4)) == len(set(labels)):
            return f
    return None


def atlases():
    """Each real label volume of $SC_DATA_DIR/labels, by name, padded by one background voxel."""
    import numpy as np
    data = os.environ["SC_DATA_DIR"]
    for name in ["aal-atlas", "jhu-wm-atlas", "itk-kmeans-seg"]:
        folder = os.path.join(data, "labels", name)
        meta = json.load(open(os.path.join(folder, name + ".json")))
        nx, ny, nz = meta["dims"]
        dtype = {"u8": np.uint8, "u16": np.uint16, "i16": np.int16, "u32": np.uint32}[meta["dtype"]]
        yield name, np.pad(np.fromfile(os.path.join(folder, name + ".raw"), dtype)
                           .reshape(nz, ny, nx), 1)


def cube_corners(v):
    """The eight corner labels of every cube of `v` (axes z, y, x), as an (8, cubes) array."""
    import numpy as np
    z, y, x = (n - 1 for n in v.shape)
    return np.stack([v[a:a + z, b:b + y, c:c + x] for a in (0, 1) for b in (0, 1)
                     for c in (0, 1)]).reshape(8, -1)


def pattern(row):
    """A cube's corner labels renamed 0, 1, ... in ascending order: what its construction
    depends on."""
    order = sorted(set(row))
    return tuple(order.index(label) for label in row)


def census():
    for name, v in atlases():
        corners = cube_corners(v)
        surface = corners[:, corners.min(0) != corners.max(0)].T
        counts, cache = collections.Counter(), {}
        for row in map(tuple, surface):
            key = pattern(row)
            if key not in cache:
                cache[key] = kind(list(key))
            counts[cache[key]] += 1
        total = sum(counts.values())
        print(f"{name}: {total} surface cubes, " + ", ".join(
            f"{k} {100 * counts[k] / total:.2f} %"
            for k in ("binary", "cone from a face", "cone from the centre", "hub")))


if __name__ == "__main__":
    census()
