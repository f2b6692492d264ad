#!/usr/bin/env python3
"""Times VTK's vtkFlyingEdges3D, the peer our README ratios are measured against.

Usage: flying_edges.py VOLUME.raw DIMS(x,y,z) DTYPE ISO [--threads N] [--repeat R]
       flying_edges.py --demo sphere|knot N ISO ...
Prints one JSON line: {"ms": median milliseconds, "triangles": count}.
"""
import argparse, json, math, time
import numpy as np
import vtk
from vtk.util import numpy_support

def demo(name, n):
    c = (np.arange(n) + 0.5) * (2.0 / n) - 1.0
    if name == "sphere":
        z, y, x = np.meshgrid(c, c, c, indexing="ij")
        return 0.8 - np.sqrt(x * x + y * y + z * z)
    c = -3.4 + 6.8 * (np.arange(n) + 0.5) / n
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    rho2 = x * x + y * y + z * z
    d = rho2 + 1
    p, q, r, s = 2 * x / d, 2 * y / d, 2 * z / d, (rho2 - 1) / d
    k1 = p * p - q * q + r ** 3 - 3 * r * s * s
    k2 = 2 * p * q - 3 * r * r * s + s ** 3
    return np.sin(np.pi * (k1 * k1 + k2 * k2) ** (1 / 6))

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--demo")
    ap.add_argument("args", nargs="+")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=10)
    ap.add_argument("--normals", action="store_true")
    a = ap.parse_args()
    if a.demo:
        n, iso = int(a.args[0]), float(a.args[1])
        arr = demo(a.demo, n).astype(np.float32)
    else:
        path, dims, dtype, iso = a.args[0], [int(v) for v in a.args[1].split(",")], a.args[2], float(a.args[3])
        np_type = {"u8": np.uint8, "i16": np.int16, "u16": np.uint16, "f32": np.float32}[dtype]
        arr = np.fromfile(path, dtype=np_type).reshape(dims[2], dims[1], dims[0])
    img = vtk.vtkImageData()
    img.SetDimensions(arr.shape[2], arr.shape[1], arr.shape[0])
    img.GetPointData().SetScalars(numpy_support.numpy_to_vtk(arr.ravel(), deep=True))
    smp = vtk.vtkSMPTools()
    smp.Initialize(a.threads)
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(img)
    fe.SetValue(0, iso)
    fe.SetComputeNormals(a.normals)
    fe.SetComputeGradients(False)
    fe.SetComputeScalars(False)
    times = []
    for _ in range(a.repeat):
        fe.Modified()
        t = time.perf_counter()
        fe.Update()
        times.append(time.perf_counter() - t)
    times.sort()
    print(json.dumps({"ms": 1000 * times[len(times) // 2], "triangles": fe.GetOutput().GetNumberOfCells(),
                      "backend": smp.GetBackend(), "threads": smp.GetEstimatedNumberOfThreads()}))

main()
