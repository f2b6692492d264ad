#!/usr/bin/env python3
"""Renders a binary little-endian PLY from `skelclimb` to PNG with its triangle edges drawn,
in the style of the paper's figures. No GPU needed (matplotlib).

    python3 docs/render.py knot.ply docs/knot.png [--title TEXT] [--elev 80 --azim -60]
"""
import argparse
import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from mpl_toolkits.mplot3d.art3d import Poly3DCollection

TYPES = {"float": "<f4", "uchar": "u1", "int": "<i4", "uint": "<u4"}


def read_ply(path):
    with open(path, "rb") as f:
        props, counts, element = {}, {}, None
        while True:
            line = f.readline().decode().strip()
            if line.startswith("element"):
                _, element, n = line.split()
                counts[element] = int(n)
                props[element] = []
            elif line.startswith("property") and element == "vertex":
                props["vertex"].append((line.split()[2], TYPES[line.split()[1]]))
            elif line == "end_header":
                break
        verts = np.frombuffer(f.read(counts["vertex"] * sum(np.dtype(t).itemsize for _, t in props["vertex"])),
                              dtype=np.dtype(props["vertex"]), count=counts["vertex"])
        face = np.dtype([("n", "u1"), ("i", "<i4", 3)])
        faces = np.frombuffer(f.read(counts["face"] * face.itemsize), dtype=face, count=counts["face"])
    return np.stack([verts["x"], verts["y"], verts["z"]], axis=1), faces["i"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("ply")
    ap.add_argument("png")
    ap.add_argument("--title", default="")
    ap.add_argument("--elev", type=float, default=80)
    ap.add_argument("--azim", type=float, default=-60)
    a = ap.parse_args()
    pos, tris = read_ply(a.ply)
    tri = pos[tris]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-12
    light = np.array([0.4, -0.5, 0.75])
    shade = 0.25 + 0.75 * np.clip(normal @ (light / np.linalg.norm(light)), 0, 1)
    colours = np.stack([0.55 * shade, 0.7 * shade, 0.9 * shade, np.ones_like(shade)], axis=1)
    fig = plt.figure(figsize=(6, 6), dpi=120)
    ax = fig.add_subplot(projection="3d")
    ax.add_collection3d(Poly3DCollection(tri, facecolors=colours, edgecolors=(0.1, 0.1, 0.2, 0.6), linewidths=0.15))
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    mid, r = (lo + hi) / 2, (hi - lo).max() / 2
    ax.set_xlim(mid[0] - r, mid[0] + r)
    ax.set_ylim(mid[1] - r, mid[1] + r)
    ax.set_zlim(mid[2] - r, mid[2] + r)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(a.elev, a.azim)
    ax.set_axis_off()
    ax.set_title(a.title or f"{len(tris):,} triangles", fontsize=11)
    fig.savefig(a.png, bbox_inches="tight")


main()
