#!/usr/bin/env python3
"""Skeleton Climbing against VTK's vtkFlyingEdges3D, measured in one run on the same volumes.

Runs `cargo bench -p sc-runtime --bench extract` (criterion), then times FlyingEdges on each
volume the benchmarks used (the built-in 256³ volumes, rebuilt here sample for sample, and the
SC_DATA_DIR volumes), and prints the README's tables: times, ratios and triangle counts.

    pip install vtk numpy
    SC_DATA_DIR=../shared/data python3 bench/compare.py [--skip-cargo] [--repeat 10]

FlyingEdges runs with normals, gradients and scalars off, like the benchmarks (normals off), on
one thread: the times in the table are milliseconds, single-threaded unless the column says
otherwise.
"""
import argparse, glob, json, os, platform, subprocess, sys, time
import numpy as np
import vtk
from vtk.util import numpy_support

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def cells(n, lo, hi):
    c = lo + (hi - lo) / n * (np.arange(n) + 0.5)
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    return x, y, z


def sphere(n):
    x, y, z = cells(n, -1.0, 1.0)
    return 0.8 - np.sqrt(x * x + y * y + z * z)


def knot(n):
    x, y, z = cells(n, -3.4, 3.4)
    rho2 = x * x + y * y + z * z
    d = rho2 + 1.0
    p, q, r, s = 2 * x / d, 2 * y / d, 2 * z / d, (rho2 - 1.0) / d
    k1 = p * p - q * q + r * r * r - 3 * r * s * s
    k2 = 2 * p * q - 3 * r * r * s + s * s * s
    return np.sin(np.pi * (k1 * k1 + k2 * k2) ** (1.0 / 6.0))


def noise(n):
    """sc_runtime::demo::sphere_noise: splitmix64 noise of amplitude 0.05, empty border."""
    i = np.arange(n ** 3, dtype=np.uint64)
    z = i + np.uint64(0x9E3779B97F4A7C15)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    z ^= z >> np.uint64(31)
    u = (z >> np.uint64(11)).astype(np.float64) / float(1 << 52) - 1.0
    f = sphere(n) + 0.05 * u.reshape(n, n, n)
    f[[0, -1], :, :] = -1.0
    f[:, [0, -1], :] = -1.0
    f[:, :, [0, -1]] = -1.0
    return f


BUILTIN = {"sphere-256": (sphere, 0.0), "knot-256": (knot, 0.9), "noise-256": (noise, 0.0)}
DTYPES = {"u8": np.uint8, "i16": np.int16, "u16": np.uint16}


def volume(group):
    """The array (z, y, x) and iso of a benchmark group name."""
    if group in BUILTIN:
        f, iso = BUILTIN[group]
        return f(256).astype(np.float32), iso
    name, iso = group.rsplit("@", 1)
    meta = json.load(open(os.path.join(os.environ["SC_DATA_DIR"], name, name + ".json")))
    nx, ny, nz = meta["dims"]
    raw = np.fromfile(os.path.join(os.environ["SC_DATA_DIR"], name, name + ".raw"), dtype=DTYPES[meta["dtype"]])
    return raw.reshape(nz, ny, nx), float(iso)


def flying_edges(arr, iso, threads, repeat):
    img = vtk.vtkImageData()
    img.SetDimensions(arr.shape[2], arr.shape[1], arr.shape[0])
    img.GetPointData().SetScalars(numpy_support.numpy_to_vtk(np.ascontiguousarray(arr).ravel(), deep=True))
    vtk.vtkSMPTools().Initialize(threads)
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(img)
    fe.SetValue(0, iso)
    fe.SetComputeNormals(False)
    fe.SetComputeGradients(False)
    fe.SetComputeScalars(False)
    times = []
    for _ in range(repeat):
        fe.Modified()
        t = time.perf_counter()
        fe.Update()
        times.append(time.perf_counter() - t)
    return 1000 * sorted(times)[len(times) // 2], fe.GetOutput().GetNumberOfCells()


def criterion_ms(group, fn, threads):
    pattern = os.path.join(ROOT, "target", "criterion", group, fn, f"{threads}t", "new", "estimates.json")
    hits = glob.glob(pattern)
    if not hits:
        return None
    return json.load(open(hits[0]))["median"]["point_estimate"] / 1e6


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--skip-cargo", action="store_true", help="reuse target/criterion results")
    ap.add_argument("--repeat", type=int, default=10)
    a = ap.parse_args()
    if not a.skip_cargo:
        subprocess.run(["cargo", "bench", "-p", "sc-runtime", "--bench", "extract"], cwd=ROOT, check=True)
    all_t = os.cpu_count() or 1
    groups = sorted(os.listdir(os.path.join(ROOT, "target", "criterion")))
    groups = [g for g in groups if g in BUILTIN or "@" in g]
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), platform.processor())
    print(f"\nMachine: {cpu}, {all_t} threads; VTK {vtk.vtkVersion.GetVTKVersion()} (SMP backend {vtk.vtkSMPTools().GetBackend()})\n")
    print("| volume (MC triangles) | Flying Edges | Steps 1–3 | embedded | paper | **embedded / FE** | embedded, all threads | speed-up | Step 4 cost |")
    print("|---|---|---|---|---|---|---|---|---|")
    for g in groups:
        arr, iso = volume(g)
        fe1, tris = flying_edges(arr, iso, 1, a.repeat)
        s1, e1, p1 = (criterion_ms(g, f, 1) for f in ("steps123", "embedded", "paper"))
        e_all = criterion_ms(g, "embedded", all_t)
        if None in (s1, e1, p1, e_all):
            print(f"| {g} | missing criterion results |")
            continue
        print(f"| {g} ({tris:,}) | {fe1:.1f} | {s1:.1f} | {e1:.1f} | {p1:.1f} | **{e1 / fe1:.2f}×** | {e_all:.1f} | {e1 / e_all:.2f}× | {100 * (e1 / s1 - 1):+.0f}% |")


if __name__ == "__main__":
    main()
