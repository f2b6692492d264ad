#!/usr/bin/env python3
"""Triangles against distance for Step 4's error bound (`max_error`), on the built-in volumes and
the SC_DATA_DIR volumes at their suggested iso values.

For each volume, Steps 1–3 (the Marching-Cubes-sized surface) is the reference, and each bound
is meshed in embedded mode. Reported: triangles (and the cut against Steps 1–3); the maximum
distance from a Steps 1–3 vertex to the bounded surface, which is what the bound limits (a merge
removes a vertex only if it lies closer than the bound to the triangles replacing its four); the
maximum distance from the bounded surface to Steps 1–3, which the bound does not limit (a new
diagonal can pass farther from the old fan than the removed vertex lies from the new triangles),
over 20,000 points sampled uniformly by area; and the symmetric mean distance over 20,000 points
sampled on each surface. Distances are exact
point-to-triangle distances (VTK's vtkDistancePolyDataFilter), in voxels (meshes in index space).

    SC_DATA_DIR=../shared/data python3 bench/error_bound.py [--plot docs/error-bound.png]

Needs numpy, vtk, matplotlib (for --plot) and the volumes of bench/python_compare.py.
"""
import argparse
import json
import os
import sys

import numpy as np
import vtk
from vtk.util import numpy_support

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from python_compare import volumes  # noqa: E402

import skelclimb  # noqa: E402

BOUNDS = (0.05, 0.1, 0.25, 0.5)


def polydata(points, faces=None):
    pd = vtk.vtkPolyData()
    pts = vtk.vtkPoints()
    pts.SetData(numpy_support.numpy_to_vtk(np.ascontiguousarray(points, np.float64), deep=True))
    pd.SetPoints(pts)
    cells = vtk.vtkCellArray()
    if faces is None:
        ids = np.arange(len(points), dtype=np.int64)
        cells.SetData(numpy_support.numpy_to_vtkIdTypeArray(np.arange(0, len(points) + 1, dtype=np.int64), deep=True),
                      numpy_support.numpy_to_vtkIdTypeArray(ids, deep=True))
        pd.SetVerts(cells)
    else:
        offsets = np.arange(0, 3 * len(faces) + 1, 3, dtype=np.int64)
        cells.SetData(numpy_support.numpy_to_vtkIdTypeArray(offsets, deep=True),
                      numpy_support.numpy_to_vtkIdTypeArray(faces.astype(np.int64).ravel(), deep=True))
        pd.SetPolys(cells)
    return pd


def distances(points, mesh):
    """Exact distance from each point to the surface `mesh`."""
    f = vtk.vtkDistancePolyDataFilter()
    f.SignedDistanceOff()
    f.ComputeSecondDistanceOff()
    f.SetInputData(0, polydata(points))
    f.SetInputData(1, polydata(mesh.vertices, mesh.faces))
    f.Update()
    return numpy_support.vtk_to_numpy(f.GetOutput().GetPointData().GetArray("Distance"))


def sample(mesh, n, rng):
    v = mesh.vertices.astype(np.float64)
    t = v[mesh.faces]
    area = 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)
    pick = rng.choice(len(t), n, p=area / area.sum())
    r1, r2 = rng.random(n), rng.random(n)
    s = np.sqrt(r1)
    a, b, c = 1 - s, s * (1 - r2), s * r2
    return a[:, None] * t[pick, 0] + b[:, None] * t[pick, 1] + c[:, None] * t[pick, 2]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--plot", help="write a PNG of triangles against mean distance")
    p.add_argument("--json", default="target/error-bound.json")
    a = p.parse_args()
    rng = np.random.default_rng(0)
    rows = []
    print("| volume | bound (voxel) | triangles | fewer than Steps 1–3 | max, removed vertices "
          "→ ours | max, ours → Steps 1–3 | mean (both ways) |")
    print("|---|---|---|---|---|---|---|")
    for label, vol, iso in volumes(os.environ.get("SC_DATA_DIR")):
        ref = skelclimb.extract(vol, iso, mode="steps123", normals=False)
        ref_pts = sample(ref, 20000, rng)
        for bound in (0.0, *BOUNDS, None):
            m = skelclimb.extract(vol, iso, normals=False, max_error=bound, error_units="voxels")
            d_vert = distances(ref.vertices, m)
            d_ab = distances(ref_pts, m)
            d_ba = distances(sample(m, 20000, rng), ref)
            row = dict(volume=label, bound=bound, triangles=int(len(m.faces)),
                       steps123=int(len(ref.faces)),
                       cut=100 * (1 - len(m.faces) / len(ref.faces)),
                       max_removed=float(d_vert.max()),
                       max_ours=float(d_ba.max()),
                       mean=float((d_ab.mean() + d_ba.mean()) / 2))
            rows.append(row)
            name = "none (embedded)" if bound is None else f"{bound:g}"
            print(f"| {label} | {name} | {row['triangles']:,} | {row['cut']:.1f} % | "
                  f"{row['max_removed']:.3f} | {row['max_ours']:.3f} | {row['mean']:.4f} |", flush=True)
    os.makedirs(os.path.dirname(a.json) or ".", exist_ok=True)
    with open(a.json, "w") as f:
        json.dump(rows, f, indent=1)
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4.5), dpi=100)
        for label in dict.fromkeys(r["volume"] for r in rows):
            rs = [r for r in rows if r["volume"] == label]
            ax.plot([r["mean"] for r in rs], [r["cut"] for r in rs], marker="o", label=label)
        ax.set_xscale("symlog", linthresh=1e-4)
        ax.set_xlabel("symmetric mean distance to Steps 1–3 (voxels)")
        ax.set_ylabel("fewer triangles than Steps 1–3 (%)")
        ax.set_title("Step 4 with max_error = 0, 0.05, 0.1, 0.25, 0.5 voxel, unbounded")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="lower right")
        fig.tight_layout()
        fig.savefig(a.plot)


if __name__ == "__main__":
    main()
