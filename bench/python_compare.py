#!/usr/bin/env python3
"""`skelclimb.marching_cubes` against the Python meshers people use, in one run on the same data.

Peers: scikit-image's `marching_cubes` (Lewiner), PyMCubes, zmesh (on the thresholded mask: it
meshes labels, so its vertices sit on half-integer positions and are not interpolated) and VTK's
`vtkFlyingEdges3D` called through NumPy (with normals, as skelclimb and scikit-image return them;
PyMCubes and zmesh here return none). Every time is the median of --repeat runs of the whole
call, conversions from and to NumPy included, on one thread (VTK's SMP tools set to 1, skelclimb
with threads=1). Volumes: the built-in 256³ sphere, knot and noisy sphere (as bench/compare.py
builds them), and the raw + JSON volumes of SC_DATA_DIR (folders separated by ':', for example
the shared data and what bench/derive_volumes.py makes of it) at their suggested iso values.

    python3 -m venv target/bench-venv
    target/bench-venv/bin/pip install ./sc-python scikit-image PyMCubes zmesh vtk
    SC_DATA_DIR=../shared/data target/bench-venv/bin/python bench/python_compare.py [--rounds 3]
"""
import argparse
import importlib.metadata
import json
import os
import platform
import statistics
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare import BUILTIN, DTYPES  # noqa: E402  (the same generators as the Rust benchmarks)

import skimage  # noqa: E402
import skimage.measure  # noqa: E402
import vtk  # noqa: E402
from vtk.util import numpy_support  # noqa: E402

import skelclimb  # noqa: E402

DTYPES = dict(DTYPES, f32=np.float32, f64=np.float64, i8=np.int8, u32=np.uint32, i32=np.int32)


def volumes(data_dir, only=()):
    """(label, array, iso) of every volume, or of those whose label starts with one of ``only``:
    a built-in volume takes seconds to make, so only those asked for are made."""
    def wanted(label):
        return not only or any(label.startswith(o) for o in only)

    for name, (make, iso) in BUILTIN.items():
        if wanted(name):
            yield name, make(256).astype(np.float32), iso
    yield from (v for v in data_volumes(data_dir) if wanted(v[0]))


def data_volumes(data_dir):
    """The raw + JSON volumes of ``data_dir`` at each suggested iso value: (label, array, iso)."""
    if not data_dir:
        print("SC_DATA_DIR not set: the real volumes are skipped", file=sys.stderr)
        return
    # Folders separated by os.pathsep, as the Rust benchmarks take them.
    found = [(d, name) for d in data_dir.split(os.pathsep) if d for name in os.listdir(d)]
    for folder, name in sorted(found, key=lambda f: f[1]):
        meta_path = os.path.join(folder, name, name + ".json")
        if not os.path.exists(meta_path):
            continue
        meta = json.load(open(meta_path))
        nx, ny, nz = meta["dims"]
        raw = np.fromfile(os.path.join(folder, name, name + ".raw"), dtype=DTYPES[meta["dtype"]])
        for label, iso in meta.get("iso_suggestions", {}).items():
            if isinstance(iso, (int, float)):
                yield f"{name}@{iso} ({label})", raw.reshape(nz, ny, nx), float(iso)


def flying_edges(vol, iso):
    image = vtk.vtkImageData()
    nz, ny, nx = vol.shape
    image.SetDimensions(nx, ny, nz)
    image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(vol.ravel(), deep=False))
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(image)
    fe.SetValue(0, iso)
    fe.ComputeNormalsOn()  # like skelclimb and scikit-image, which return normals
    fe.ComputeGradientsOff()
    fe.ComputeScalarsOff()
    fe.Update()
    out = fe.GetOutput()
    verts = numpy_support.vtk_to_numpy(out.GetPoints().GetData())
    faces = numpy_support.vtk_to_numpy(out.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    numpy_support.vtk_to_numpy(out.GetPointData().GetNormals())
    return verts, faces


# PyMCubes and zmesh are imported where they are called, so that other scripts can import this
# module's volumes without installing them.
def pymcubes(vol, iso):
    import mcubes

    return mcubes.marching_cubes(vol, iso)


def zmesh_mask(vol, iso):
    import zmesh

    mesher = zmesh.Mesher((1, 1, 1))
    mesher.mesh((vol >= iso).astype(np.uint8))
    mesh = mesher.get(1, normals=False)
    mesher.clear()
    return mesh.vertices, mesh.faces


PEERS = {
    "skelclimb": lambda v, iso: skelclimb.marching_cubes(v, iso, threads=1)[:2],
    "scikit-image": lambda v, iso: skimage.measure.marching_cubes(v, iso)[:2],
    "PyMCubes": pymcubes,
    "zmesh (mask)": zmesh_mask,
    "VTK Flying Edges": flying_edges,
}


def timed(fn, vol, iso, repeat):
    times, faces = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        _, faces = fn(vol, iso)
        times.append(time.perf_counter() - start)
    return 1000 * statistics.median(times), len(faces)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--rounds", type=int, default=1,
                    help="passes over all the volumes; times are medians over the rounds, ratios "
                         "the medians of each round's ratios, with their range")
    ap.add_argument("--only", nargs="*", default=[],
                    help="volume labels to run (prefixes, e.g. mni152-f32@190), to rerun rows")
    a = ap.parse_args()
    vtk.vtkSMPTools().Initialize(1)
    cpu = next(
        (l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")),
        platform.processor(),
    )
    rounds = f", {a.rounds} rounds" if a.rounds > 1 else ""
    print(f"Machine: {cpu}, {os.cpu_count()} threads; one thread per mesher; "
          f"median of {a.repeat}{rounds}")
    print(f"scikit-image {skimage.__version__}, VTK {vtk.vtkVersion.GetVTKVersion()}, "
          f"zmesh {importlib.metadata.version('zmesh')}\n")
    names = list(PEERS)
    chosen = list(volumes(os.environ.get("SC_DATA_DIR"), a.only))
    # Each round times every mesher on every volume, one after the other: the two sides of a
    # ratio are seconds apart, and a drift of the machine's speed shows as a spread of the
    # rounds' ratios rather than as one volume's outlier.
    runs = {label: [] for label, _, _ in chosen}
    for r in range(a.rounds):
        for label, vol, iso in chosen:
            if a.rounds > 1:
                print(f"round {r + 1}/{a.rounds}: {label}", file=sys.stderr, flush=True)
            runs[label].append({n: timed(PEERS[n], vol, iso, a.repeat) for n in names})
    print("| volume | " + " | ".join(f"{n} ms (triangles)" for n in names)
          + " | scikit-image / ours | ours / FE |")
    print("|---" * (len(names) + 3) + "|")

    def ratio(values, digits):
        mid = f"{statistics.median(values):.{digits}f}×"
        if len(values) == 1:
            return mid
        return f"{mid} ({min(values):.{digits}f}–{max(values):.{digits}f})"

    for label, rows in runs.items():
        cells = " | ".join(
            f"{statistics.median(row[n][0] for row in rows):.1f} ({rows[0][n][1]:,})" for n in names)
        speedup = [row["scikit-image"][0] / row["skelclimb"][0] for row in rows]
        against_fe = [row["skelclimb"][0] / row["VTK Flying Edges"][0] for row in rows]
        print(f"| {label} | {cells} | {ratio(speedup, 1)} | {ratio(against_fe, 2)} |",
              flush=True)


if __name__ == "__main__":
    main()
