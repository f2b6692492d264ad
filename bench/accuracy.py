#!/usr/bin/env python3
"""Skeleton Climbing against Marching Cubes, Flying Edges and decimation: speed, size, quality
and distance, measured in one run on the same volumes and iso values.

Meshers: VTK `vtkFlyingEdges3D` (1 thread and all threads), `vtkMarchingCubes`, scikit-image's
`marching_cubes`, Flying Edges followed by QEM decimation (fast-simplification) to the triangle
count of our embedded mode, and `skelclimb.extract` in each mode on 1 thread and all threads, and
with `max_error` 0.1 and 0.25 voxel. Normals are off everywhere.

Per mesher and volume: triangles, vertices, extraction time (median of --repeat runs, the
decimation included for "FE + QEM"; no file I/O), ratios to Flying Edges on 1 thread; whether the
mesh of the padded volume is closed (every edge in two triangles), manifold (no edge in more) and
consistently wound (each directed edge once); zero-area triangles; the smallest angle per
triangle (5th percentile and median, degrees); and the symmetric mean and maximum distance to the
Flying Edges surface, in voxels, from 20,000 points sampled by area on each surface (exact
point-to-triangle distances, VTK's vtkDistancePolyDataFilter). On the analytic sphere and torus,
also the mean and maximum distance of 20,000 sampled points to the exact surface.

    target/bench-venv/bin/pip install ./sc-python vtk scikit-image fast-simplification
    SC_DATA_DIR=../shared/data python3 bench/accuracy.py [--quick] [--repeat 5]

Writes a Markdown table (printed, and --md) and every figure as JSON (--json).
"""
import argparse
import json
import os
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from error_bound import distances, sample  # noqa: E402
from compare import cells  # noqa: E402
from python_compare import volumes  # noqa: E402

import fast_simplification  # noqa: E402
import skimage.measure  # noqa: E402
import vtk  # noqa: E402
from vtk.util import numpy_support  # noqa: E402

import skelclimb  # noqa: E402

ALL = os.cpu_count() or 1
N = 256


def torus(n):
    """A torus of radii 0.55 and 0.25 in [-1, 1]³, as a signed distance (inside positive)."""
    x, y, z = cells(n, -1.0, 1.0)
    return 0.25 - np.sqrt((np.sqrt(x * x + y * y) - 0.55) ** 2 + z * z)


def world(v, n):
    """Index coordinates of an n³ built-in volume to its [-1, 1]³ coordinates."""
    return -1.0 + 2.0 * (np.asarray(v, np.float64) + 0.5) / n


# Distance from points (index coordinates) to the exact surface, in voxels.
EXACT = {
    "sphere": lambda p, n: np.abs(np.linalg.norm(world(p, n), axis=1) - 0.8) * n / 2,
    "torus": lambda p, n: np.abs(np.sqrt(
        (np.linalg.norm(world(p, n)[:, :2], axis=1) - 0.55) ** 2 + world(p, n)[:, 2] ** 2)
        - 0.25) * n / 2,
}


def vtk_mesh(algorithm, vol, iso, threads):
    vtk.vtkSMPTools().Initialize(threads)
    image = vtk.vtkImageData()
    nz, ny, nx = vol.shape
    image.SetDimensions(nx, ny, nz)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(vol.ravel(), deep=False))
    f = algorithm()
    f.SetInputData(image)
    f.SetValue(0, iso)
    f.ComputeNormalsOff()
    f.ComputeGradientsOff()
    f.ComputeScalarsOff()
    f.Update()
    out = f.GetOutput()
    if out.GetNumberOfPoints() == 0:
        return np.zeros((0, 3), np.float32), np.zeros((0, 3), np.int64)
    verts = numpy_support.vtk_to_numpy(out.GetPoints().GetData())
    faces = numpy_support.vtk_to_numpy(out.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    return verts, faces


def ours(mode, threads, bound=None):
    def run(vol, iso):
        m = skelclimb.extract(vol, iso, mode=mode, normals=False, threads=threads,
                              max_error=bound, error_units="voxels")
        return m.vertices, m.faces
    return run


def decimated(target):
    def run(vol, iso):
        v, f = vtk_mesh(vtk.vtkFlyingEdges3D, vol, iso, 1)
        reduction = 1 - target / len(f)
        return fast_simplification.simplify(v.astype(np.float32), f.astype(np.int32),
                                            target_reduction=reduction)
    return run


def meshers(target):
    out = {
        "FE, 1 thread": lambda v, i: vtk_mesh(vtk.vtkFlyingEdges3D, v, i, 1),
        f"FE, {ALL} threads": lambda v, i: vtk_mesh(vtk.vtkFlyingEdges3D, v, i, ALL),
        "vtkMarchingCubes": lambda v, i: vtk_mesh(vtk.vtkMarchingCubes, v, i, 1),
        "scikit-image": lambda v, i: (lambda r: (r[0][:, ::-1], r[1]))(
            skimage.measure.marching_cubes(v, i)),
        "FE + QEM to our count": decimated(target),
    }
    for mode in ("steps123", "embedded", "paper"):
        out[f"ours {mode}, 1 thread"] = ours(mode, 1)
        out[f"ours {mode}, {ALL} threads"] = ours(mode, ALL)
    for bound in (0.1, 0.25):
        out[f"ours embedded, max_error {bound}"] = ours("embedded", 1, bound)
    return out


def topology(faces):
    """(closed, manifold, consistently wound) of an indexed mesh."""
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]).astype(np.int64)
    und = np.sort(e, axis=1)
    _, counts = np.unique(und, axis=0, return_counts=True)
    _, directed = np.unique(e, axis=0, return_counts=True)
    return bool((counts == 2).all()), bool((counts <= 2).all()), bool((directed == 1).all())


def angles(v, f):
    t = v[f].astype(np.float64)
    def angle(a, b, c):
        u, w = b - a, c - a
        cos = (u * w).sum(1) / (np.linalg.norm(u, axis=1) * np.linalg.norm(w, axis=1) + 1e-300)
        return np.degrees(np.arccos(np.clip(cos, -1, 1)))
    smallest = np.minimum(np.minimum(angle(t[:, 0], t[:, 1], t[:, 2]),
                                     angle(t[:, 1], t[:, 2], t[:, 0])),
                          angle(t[:, 2], t[:, 0], t[:, 1]))
    area = 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)
    return np.percentile(smallest, 5), np.median(smallest), int((area < 1e-12).sum())


class Mesh:
    def __init__(self, v, f):
        self.vertices, self.faces = np.asarray(v, np.float64), np.asarray(f, np.int64)


def padded(vol, iso):
    fill = vol.min() if vol.min() < iso else np.nextafter(np.float64(iso), -np.inf)
    return np.pad(vol, 1, constant_values=np.asarray(fill).astype(vol.dtype))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--quick", action="store_true", help="two volumes, three runs")
    p.add_argument("--md", default="target/accuracy.md")
    p.add_argument("--json", default="target/accuracy.json")
    a = p.parse_args()
    repeat = 3 if a.quick else max(a.repeat, 5)
    rng = np.random.default_rng(0)
    rows, lines = [], []
    head = ("| volume | mesher | triangles | vertices | ms | time / FE | triangles / FE | "
            "closed, manifold, wound | zero-area | min angle p5, median | "
            "to FE mean, max (voxel) | to exact surface mean, max |")
    lines += [head, "|---" * 12 + "|"]
    print("\n".join(lines), flush=True)
    chosen = [(f"torus-{N}", torus(N).astype(np.float32), 0.0),
              *volumes(os.environ.get("SC_DATA_DIR"))]
    if a.quick:
        chosen = [c for c in chosen if c[0].startswith(("torus", "brainsmall"))]
    for label, vol, iso in chosen:
        target = len(skelclimb.extract(vol, iso, normals=False).faces)
        fe_v, fe_f = vtk_mesh(vtk.vtkFlyingEdges3D, vol, iso, 1)
        fe = Mesh(fe_v, fe_f)
        fe_pts = sample(fe, 20000, rng)
        fe_ms = None
        pad = padded(vol, iso)
        for name, run in meshers(target).items():
            times = []
            for _ in range(repeat):
                t = time.perf_counter()
                v, f = run(vol, iso)
                times.append(1000 * (time.perf_counter() - t))
            ms = statistics.median(times)
            fe_ms = fe_ms or ms
            m = Mesh(v, f)
            closed, manifold, wound = topology(np.asarray(run(pad, iso)[1]))
            p5, med, zero = angles(m.vertices, m.faces)
            d_to = distances(sample(m, 20000, rng), fe)
            d_from = distances(fe_pts, m)
            row = dict(volume=label, mesher=name, triangles=len(m.faces),
                       vertices=len(m.vertices), ms=ms, time_ratio=ms / fe_ms,
                       triangle_ratio=len(m.faces) / len(fe.faces), closed=closed,
                       manifold=manifold, wound=wound, zero_area=zero, min_angle_p5=p5,
                       min_angle_median=med, mean_to_fe=(d_to.mean() + d_from.mean()) / 2,
                       max_to_fe=max(d_to.max(), d_from.max()))
            exact = ""
            shape = label.split("-")[0]
            if shape in EXACT:
                d = EXACT[shape](sample(m, 20000, rng), vol.shape[0])
                row["mean_to_exact"], row["max_to_exact"] = float(d.mean()), float(d.max())
                exact = f"{d.mean():.4f}, {d.max():.3f}"
            rows.append(row)
            flags = "".join("✓" if x else "✗" for x in (closed, manifold, wound))
            line = (f"| {label} | {name} | {row['triangles']:,} | {row['vertices']:,} | {ms:.1f} | "
                    f"{row['time_ratio']:.2f} | {row['triangle_ratio']:.2f} | {flags} | {zero} | "
                    f"{p5:.1f}°, {med:.1f}° | {row['mean_to_fe']:.4f}, {row['max_to_fe']:.3f} | "
                    f"{exact} |")
            lines.append(line)
            print(line, flush=True)
    for path, text in ((a.md, "\n".join(lines) + "\n"), (a.json, json.dumps(rows, indent=1))):
        os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
        with open(path, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
