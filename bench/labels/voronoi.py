#!/usr/bin/env python3
"""Deterministic synthetic label volumes for the label-volume benchmark (docs/labels-benchmark.md).

    python3 bench/labels/voronoi.py [--out target/labelbench] [--only NAME ...] [--list]

Each volume is written as `<out>/<name>.npy` (C-ordered, shape (nz, ny, nx), x the last axis)
and `<out>/<name>.json` (dims as [nx, ny, nz], dtype as "u8"/"u16"/"u32", the labels in it,
how it was made), the same description the real atlases in data/labels/ carry. Every volume has
a one-voxel border of background (label 0), so every region is enclosed and each mesher's
per-label output can be checked for closedness without a `close` option; the stated sizes
include that border (258³ is 256³ of cells inside it).

Volumes (the same bytes on every run: seeds come from fixed NumPy generators):

* voronoi-258-u16: 1,000 Voronoi cells, distinct random u16 labels.
* voronoi-258-u32: the same cells, distinct random u32 labels (most above 65,535).
* voronoi-512-u32: ~3,000 Voronoi cells in 512³ u32, labelled slab by slab so that memory stays
  at the output array (written through a memory map) plus one slab of work.
* shells-258-u8: 31 nested spherical shells 4 voxels thick, labels 1..31 from the inside out.
* checker-130-u8: a 3-D checkerboard of 4-voxel cubes in two labels: every cube edge is a
  four-way junction a,b,a,b, the case that makes meshers duplicate or split vertices.
* all255-194-u8: 255 Voronoi cells labelled 1..255, every non-zero value of a u8.

Voronoi cells are the nearest-seed regions (Euclidean, ties to the lower seed index, found with
SciPy's cKDTree on one thread), seeds uniform in the interior.
"""
import argparse
import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_OUT = os.path.join(ROOT, "target", "labelbench")
DTYPE_NAMES = {np.dtype(np.uint8): "u8", np.dtype(np.uint16): "u16", np.dtype(np.uint32): "u32"}


def distinct_labels(rng, count, dtype):
    """`count` distinct non-zero labels drawn uniformly from `dtype`'s range, in seed order."""
    top = np.iinfo(dtype).max
    out = np.empty(0, dtype=np.int64)
    while out.size < count:
        draw = rng.integers(1, top, size=2 * count, endpoint=True)
        _, first = np.unique(np.concatenate([out, draw]), return_index=True)
        out = np.concatenate([out, draw])[np.sort(first)]
    return out[:count].astype(dtype)


def voronoi_into(out, seeds, labels, slab=16):
    """Fills the interior of `out` (all but a one-voxel border) with each voxel's nearest seed's
    label, `slab` z-planes at a time: the work arrays are one slab, whatever the volume."""
    from scipy.spatial import cKDTree

    tree = cKDTree(seeds)
    nz, ny, nx = out.shape
    y, x = np.meshgrid(np.arange(1, ny - 1), np.arange(1, nx - 1), indexing="ij")
    plane = np.stack([x.ravel(), y.ravel()], axis=1).astype(np.float64)
    for z0 in range(1, nz - 1, slab):
        z1 = min(z0 + slab, nz - 1)
        pts = np.concatenate(
            [np.column_stack([plane, np.full(len(plane), z, dtype=np.float64)]) for z in range(z0, z1)]
        )
        _, nearest = tree.query(pts, k=1, workers=1)
        out[z0:z1, 1:-1, 1:-1] = labels[nearest].reshape(z1 - z0, ny - 2, nx - 2)
    border(out)


def border(out):
    out[0], out[-1] = 0, 0
    out[:, 0], out[:, -1] = 0, 0
    out[:, :, 0], out[:, :, -1] = 0, 0


def voronoi(path, n, cells, dtype, seed, label_seed):
    rng = np.random.default_rng(seed)
    # Seeds in voxel coordinates (x, y, z) of the interior 1..n-2.
    seeds = rng.uniform(1, n - 2, size=(cells, 3))
    labels = distinct_labels(np.random.default_rng(label_seed), cells, dtype)
    out = np.lib.format.open_memmap(path, mode="w+", dtype=dtype, shape=(n, n, n))
    voronoi_into(out, seeds, labels)
    out.flush()
    return out, {"generator": "voronoi", "cells": cells, "seed": seed, "label_seed": label_seed}


def shells(path, n, thickness, dtype):
    c = (n - 1) / 2.0
    z, y, x = np.ogrid[:n, :n, :n]
    r = np.sqrt((x - c) ** 2 + (y - c) ** 2 + (z - c) ** 2)
    count = int((n - 2) / 2 // thickness) - 1
    lab = (r // thickness).astype(np.int64) + 1
    lab[lab > count] = 0
    out = np.lib.format.open_memmap(path, mode="w+", dtype=dtype, shape=(n, n, n))
    out[...] = lab
    border(out)
    out.flush()
    return out, {"generator": "shells", "thickness": thickness, "shells": count}


def checker(path, n, cube, dtype):
    z, y, x = np.ogrid[:n, :n, :n]
    lab = ((x - 1) // cube + (y - 1) // cube + (z - 1) // cube) % 2 + 1
    out = np.lib.format.open_memmap(path, mode="w+", dtype=dtype, shape=(n, n, n))
    out[...] = lab
    border(out)
    out.flush()
    return out, {"generator": "checkerboard", "cube": cube, "labels_used": [1, 2]}


def all255(path, n, seed):
    rng = np.random.default_rng(seed)
    seeds = rng.uniform(1, n - 2, size=(255, 3))
    labels = np.arange(1, 256, dtype=np.uint8)
    out = np.lib.format.open_memmap(path, mode="w+", dtype=np.uint8, shape=(n, n, n))
    voronoi_into(out, seeds, labels)
    out.flush()
    return out, {"generator": "voronoi", "cells": 255, "seed": seed, "labels_used": "1..255"}


VOLUMES = {
    "voronoi-258-u16": lambda p: voronoi(p, 258, 1000, np.uint16, seed=47, label_seed=1016),
    "voronoi-258-u32": lambda p: voronoi(p, 258, 1000, np.uint32, seed=47, label_seed=1032),
    "voronoi-512-u32": lambda p: voronoi(p, 512, 3000, np.uint32, seed=512, label_seed=3032),
    "shells-258-u8": lambda p: shells(p, 258, 4, np.uint8),
    "checker-130-u8": lambda p: checker(p, 130, 4, np.uint8),
    "all255-194-u8": lambda p: all255(p, 194, seed=255),
}


def census(vol, slab=32):
    """Labels present and their voxel counts, slab by slab (the 512³ does not fit twice)."""
    counts = {}
    for z0 in range(0, vol.shape[0], slab):
        u, c = np.unique(vol[z0:z0 + slab], return_counts=True)
        for a, b in zip(u.tolist(), c.tolist()):
            counts[a] = counts.get(a, 0) + b
    return counts


def make(name, out_dir):
    path = os.path.join(out_dir, name + ".npy")
    t = time.perf_counter()
    vol, how = VOLUMES[name](path)
    counts = census(vol)
    background = counts.pop(0, 0)
    meta = {
        "dims": [vol.shape[2], vol.shape[1], vol.shape[0]],
        "dtype": DTYPE_NAMES[vol.dtype],
        "spacing": [1.0, 1.0, 1.0],
        "kind": "labels",
        "background": 0,
        "labels": len(counts),
        "background_voxels": background,
        "label_values": sorted(counts),
        "made_by": "bench/labels/voronoi.py",
        **how,
    }
    with open(os.path.join(out_dir, name + ".json"), "w") as f:
        json.dump(meta, f, indent=1)
    print(f"{name}: {meta['dims']} {meta['dtype']}, {len(counts)} labels, "
          f"{time.perf_counter() - t:.1f} s -> {path}", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=DEFAULT_OUT, help="folder for the .npy + .json pairs")
    ap.add_argument("--only", nargs="+", metavar="NAME", choices=sorted(VOLUMES),
                    help="make only these volumes")
    ap.add_argument("--list", action="store_true", help="print the volumes' names and stop")
    args = ap.parse_args()
    if args.list:
        print("\n".join(VOLUMES))
        return 0
    os.makedirs(args.out, exist_ok=True)
    for name in args.only or VOLUMES:
        make(name, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
