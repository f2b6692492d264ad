#!/usr/bin/env python3
"""How far, how clean and how fast: Skeleton Climbing against Marching Cubes, Flying Edges and
Flying Edges followed by decimation, on the same volumes and iso values, in one run.

Meshers, per volume:

* VTK ``vtkFlyingEdges3D`` — the reference of every ratio and distance — on one thread (SMP
  backend Sequential) and on all threads (backend STDThread);
* VTK ``vtkMarchingCubes`` and scikit-image's ``marching_cubes`` (Lewiner; it always computes
  normals, which no other mesher here is asked for);
* Flying Edges decimated to our embedded triangle count by fast-simplification (quadric error
  metric, target reduction 1 − ours/FE); its time is Flying Edges on one thread plus the
  decimation;
* ``skelclimb.extract`` in each mode (steps123, embedded, paper), on one thread and on all, and,
  when the installed skelclimb has ``max_error``, embedded mode bounded at 0.05, 0.1, 0.25 and
  0.5 voxel.

Measured:

* time: median of --repeat runs of the extraction alone, the volume already in memory (VTK:
  ``Update()`` on an image built beforehand; skelclimb and scikit-image: the whole call, NumPy
  output included);
* triangles and vertices of that mesh, and whether the all-threads mesh is the one-thread mesh;
* everything else on the volume padded with one layer of its minimum (below the iso value), so
  that every surface closes, positions shifted back: closed (every edge in exactly two
  triangles), oriented (those two run the edge in opposite directions), manifold vertices (the
  triangles around each vertex form a single fan), zero-area triangles (< 1e-12 voxel²), the
  smallest angle of each triangle (5th percentile and median, degrees);
* distance to the Flying Edges surface: 20,000 points sampled uniformly by area on each surface,
  the exact point-to-triangle distance of each to the other surface; the symmetric mean (the mean
  of the two directions' means) and the maximum over both samples. The distances come from scipy's
  cKDTree on triangle centroids refined exactly with ``trimesh.triangles.closest_point``: every
  triangle whose centroid lies within the best distance so far plus the triangle's own reach
  (largest centroid-to-corner distance) is tested, so no closer triangle is missed — exact
  distances, not an approximation by dense samples;
* on the sphere and the torus, whose signed distance is known: the distance to the exact
  surface, mean over the 20,000 samples, maximum over the samples and every vertex.

Everything is in voxels: each mesher runs in index space (unit spacing, origin 0), so on the
anisotropic volumes a "voxel" is a grid step. Volumes: the built-in sphere, knot and noisy sphere
of bench/compare.py and the torus of sc_runtime::demo (radii 0.6 and 0.25), at --size³ (128), and
the raw + JSON volumes of SC_DATA_DIR at their suggested iso values (bench/python_compare.py reads
them). --quick keeps the sphere, the torus and the first SC_DATA_DIR volume (about 30 s).

    SC_DATA_DIR=../shared/data bench/accuracy.sh [--quick]

(bench/accuracy.sh builds the venv: numpy scipy vtk scikit-image fast-simplification trimesh and
./sc-python.)
"""
import argparse
import importlib.metadata
import inspect
import itertools
import json
import os
import platform
import statistics
import sys
import time
from types import SimpleNamespace

import fast_simplification
import numpy as np
import skimage.measure
import trimesh.triangles
import vtk
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree
from vtk.util import numpy_support

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare import BUILTIN, cells  # noqa: E402
from error_bound import BOUNDS, sample  # noqa: E402
from python_compare import data_volumes  # noqa: E402

import skelclimb  # noqa: E402

SAMPLES = 20_000
MODES = ("steps123", "embedded", "paper")
BOUNDED = "max_error" in inspect.signature(skelclimb.extract).parameters
ALL = os.cpu_count() or 1
TORUS = (0.6, 0.25)  # ring and tube radius in [-1, 1]³, as sc_runtime::demo::torus


def torus(n):
    x, y, z = cells(n, -1.0, 1.0)
    return TORUS[1] - np.hypot(np.hypot(x, y) - TORUS[0], z)


# Signed distance to the exact surface of the analytic volumes, world positions (x, y, z) in
# [-1, 1]³; their samples sit at cell centres, world = -1 + (index + 0.5) · 2 / n.
EXACT = {
    "sphere": lambda p: np.linalg.norm(p, axis=1) - 0.8,
    "torus": lambda p: np.hypot(np.hypot(p[:, 0], p[:, 1]) - TORUS[0], p[:, 2]) - TORUS[1],
}


def volumes(size, data_dir, quick):
    """(label, analytic name or None, array (z, y, x), iso)."""
    made = {"sphere": BUILTIN["sphere-256"], "torus": (torus, 0.0)}
    if not quick:
        made.update(knot=BUILTIN["knot-256"], noise=BUILTIN["noise-256"])
    for name, (make, iso) in made.items():
        yield f"{name}-{size}", name if name in EXACT else None, make(size).astype(np.float32), iso
    for label, vol, iso in itertools.islice(data_volumes(data_dir), 1 if quick else None):
        yield label, None, vol, iso


# ---- meshers: each `prepare(vol, iso)` returns (run, to_mesh); only `run()` is timed --------


def vtk_threads(n):
    vtk.vtkSMPTools.SetBackend("Sequential" if n == 1 else "STDThread")
    vtk.vtkSMPTools.Initialize(n)


def vtk_mesher(cls):
    def prepare(vol, iso, threads):
        image = vtk.vtkImageData()
        nz, ny, nx = vol.shape
        image.SetDimensions(nx, ny, nz)
        image.GetPointData().SetScalars(numpy_support.numpy_to_vtk(vol.ravel(), deep=True))
        f = cls()
        f.SetInputData(image)
        f.SetValue(0, iso)
        f.ComputeNormalsOff()
        f.ComputeGradientsOff()
        f.ComputeScalarsOff()
        vtk_threads(threads)

        def run():
            f.Modified()
            f.Update()
            return f.GetOutput()

        return run, vtk_mesh

    return prepare


def vtk_mesh(out):
    vertices = numpy_support.vtk_to_numpy(out.GetPoints().GetData()).astype(np.float64)
    faces = numpy_support.vtk_to_numpy(out.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    return vertices, faces.astype(np.int64)


def scikit_image(vol, iso, threads):
    return (lambda: skimage.measure.marching_cubes(vol, iso),
            lambda out: (out[0][:, ::-1].astype(np.float64), out[1].astype(np.int64)))


def skelclimb_mesher(mode, bound=None):
    extra = {} if bound is None else {"max_error": bound, "error_units": "voxels"}

    def prepare(vol, iso, threads):
        return (lambda: skelclimb.extract(vol, iso, mode=mode, normals=False, threads=threads,
                                          **extra),
                lambda m: (m.vertices.astype(np.float64), m.faces.astype(np.int64)))

    return prepare


def decimated(fe, target):
    """Flying Edges' mesh `fe` reduced by fast-simplification to about `target` triangles."""
    reduction = 1 - target / len(fe[1])

    def run():
        return fast_simplification.simplify(fe[0], fe[1], target_reduction=reduction)

    return run, lambda out: (np.asarray(out[0], np.float64), np.asarray(out[1], np.int64))


def timed(run, repeat):
    times, out = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        out = run()
        times.append(1000 * (time.perf_counter() - start))
    return times, out


# ---- measures ---------------------------------------------------------------------------------


def topology(faces, n_vertices):
    """Open and overfull edges, edges run the same way by both triangles, non-manifold vertices."""
    start = faces.ravel()
    end = np.roll(faces, -1, axis=1).ravel()  # half-edge 3f + k runs start → end
    key = np.minimum(start, end) * n_vertices + np.maximum(start, end)
    order = np.argsort(key, kind="stable")
    _, first, counts = np.unique(key[order], return_index=True, return_counts=True)
    pairs = order[first[counts == 2][:, None] + np.arange(2)]  # the two half-edges of an edge
    h, g = pairs[:, 0], pairs[:, 1]
    same_way = start[h] == start[g]
    # Corners 3f + k (vertex faces[f, k]) join across each two-triangle edge; a vertex whose
    # corners fall into more than one group has more than one fan.
    nxt = lambda e: e - e % 3 + (e % 3 + 1) % 3  # noqa: E731
    a = np.concatenate([h, nxt(h)])
    b = np.concatenate([np.where(same_way, g, nxt(g)), np.where(same_way, nxt(g), g)])
    graph = coo_matrix((np.ones(len(a)), (a, b)), shape=(len(start), len(start)))
    _, group = connected_components(graph, directed=False)
    fans = len(np.unique(start * len(start) + group)) - len(np.unique(start))
    return {"open_edges": int((counts == 1).sum()), "overfull_edges": int((counts > 2).sum()),
            "same_way_edges": int(same_way.sum()), "nonmanifold_vertices": int(fans)}


def shape(vertices, faces):
    t = vertices[faces]
    e = [t[:, (k + 1) % 3] - t[:, k] for k in range(3)]
    area = 0.5 * np.linalg.norm(np.cross(e[0], -e[2]), axis=1)
    angles = []
    for k in range(3):  # the angle at corner k, between the edges leaving it
        u, v = e[k], -e[(k + 2) % 3]
        norm = np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1)
        cos = np.divide((u * v).sum(1), norm, out=np.ones(len(t)), where=norm > 0)
        angles.append(np.degrees(np.arccos(np.clip(cos, -1, 1))))
    smallest = np.min(angles, axis=0)
    return {"zero_area": int((area < 1e-12).sum()),
            "min_angle_p5": float(np.percentile(smallest, 5)),
            "min_angle_median": float(np.median(smallest)),
            "min_angle_min": float(smallest.min())}


def distance_to(points, vertices, faces, chunk=4096):
    """Exact distance from each point to the triangles `faces` (see the module's docstring)."""
    tri = vertices[faces]
    centre = tri.mean(axis=1)
    reach = np.linalg.norm(tri - centre[:, None], axis=2).max(axis=1)
    k = min(2, len(faces))
    near = cKDTree(centre).query(points, k=k)[1].reshape(len(points), k)
    best = exact(np.repeat(points, k, axis=0), tri[near.ravel()]).reshape(-1, k).min(axis=1)
    # Triangles in classes of similar reach, so a few long ones do not widen every search.
    reach_class = np.floor(np.log2(np.maximum(reach, 0.5))).astype(int)
    for c in np.unique(reach_class):
        members = np.flatnonzero(reach_class == c)
        tree = cKDTree(centre[members])
        for lo in range(0, len(points), chunk):
            p = points[lo:lo + chunk]
            hits = tree.query_ball_point(p, best[lo:lo + chunk] + reach[members].max(),
                                         return_sorted=False)
            lens = np.fromiter(map(len, hits), np.intp, len(p))
            flat = np.fromiter(itertools.chain.from_iterable(hits), np.intp, lens.sum())
            owner = np.repeat(np.arange(len(p)), lens)
            cand = members[flat]
            # Only triangles whose own reach can bring them closer than the best so far.
            keep = (np.linalg.norm(p[owner] - centre[cand], axis=1) - reach[cand]
                    <= best[lo:lo + chunk][owner])
            owner, cand = owner[keep], cand[keep]
            lens = np.bincount(owner, minlength=len(p))
            d = exact(p[owner], tri[cand])
            some = lens > 0  # `owner` is sorted: reduce each point's run of candidates
            starts = np.concatenate([[0], np.cumsum(lens)[:-1]])[some]
            best[lo:lo + chunk][some] = np.minimum(best[lo:lo + chunk][some],
                                                   np.minimum.reduceat(d, starts))
    return best


def exact(points, triangles):
    return np.linalg.norm(trimesh.triangles.closest_point(triangles, points) - points, axis=1)


def samples(mesh, seed=0):
    return sample(SimpleNamespace(vertices=mesh[0], faces=mesh[1]), SAMPLES,
                  np.random.default_rng(seed))


def quality(mesh, fe, fe_points, analytic, size):
    """Every measure of one padded mesh against Flying Edges' padded mesh and its samples."""
    vertices, faces = mesh
    q = {"padded_triangles": len(faces), "padded_vertices": len(vertices)}
    q.update(topology(faces, len(vertices)))
    q.update(shape(vertices, faces))
    points = samples(mesh)
    if mesh is fe:
        q.update(fe_mean=0.0, fe_max=0.0)
    else:
        there = distance_to(points, *fe)
        back = distance_to(fe_points, vertices, faces)
        q.update(fe_mean=float((there.mean() + back.mean()) / 2),
                 fe_max=float(max(there.max(), back.max())),
                 fe_mean_to=float(there.mean()), fe_mean_from=float(back.mean()))
    if analytic:
        h = 2.0 / size
        sd = EXACT[analytic]
        on_samples = np.abs(sd(-1 + (points + 0.5) * h)) / h
        on_vertices = np.abs(sd(-1 + (vertices[np.unique(faces)] + 0.5) * h)) / h
        q.update(exact_mean=float(on_samples.mean()),
                 exact_max=float(max(on_samples.max(), on_vertices.max())))
    return q


# ---- one volume -------------------------------------------------------------------------------


def families():
    """(name, prepare, thread counts); the decimated Flying Edges row is built apart."""
    rows = [("Flying Edges", vtk_mesher(vtk.vtkFlyingEdges3D), (1, ALL)),
            ("vtkMarchingCubes", vtk_mesher(vtk.vtkMarchingCubes), (1,)),
            ("scikit-image", scikit_image, (1,))]
    rows += [(f"ours {m}", skelclimb_mesher(m), (1, ALL)) for m in MODES]
    if BOUNDED:
        rows += [(f"ours ≤ {b:g} voxel", skelclimb_mesher("embedded", b), (1, ALL))
                 for b in BOUNDS]
    return rows


def pad(vol, iso):
    low = vol.min()
    if not low < iso:
        raise SystemExit(f"no sample below iso {iso}: cannot pad with an empty value")
    return np.pad(vol, 1, constant_values=low)


def measure(label, analytic, vol, iso, size, repeat):
    vol = np.ascontiguousarray(vol)
    padded = pad(vol, iso)
    rows, meshes = {}, {}
    for name, prepare, threads in families():
        row = {"mesher": name}
        for t in threads:
            run, to_mesh = prepare(vol, iso, t)
            times, out = timed(run, repeat)
            mesh = to_mesh(out)
            row[f"ms_{t}t"] = statistics.median(times)
            row[f"runs_ms_{t}t"] = times
            if t == 1:
                meshes[name] = mesh
                row.update(triangles=len(mesh[1]), vertices=len(mesh[0]))
            else:
                same = all(np.array_equal(a, b) for a, b in zip(meshes[name], mesh))
                row["same_mesh_all_threads"] = same
        run, to_mesh = prepare(padded, iso, 1)
        v, f = to_mesh(run())
        row["padded"] = (v - 1, f)
        rows[name] = row
    vtk_threads(1)
    # Flying Edges, then fast-simplification down to our embedded count (padded: to the padded).
    fe, ours = rows["Flying Edges"], rows["ours embedded"]
    run = decimated(meshes["Flying Edges"], ours["triangles"])
    times, out = timed(run[0], repeat)
    v, f = run[1](out)
    dec_run, dec_mesh = decimated(fe["padded"], len(ours["padded"][1]))
    qem = {"mesher": "FE + QEM decimation", "decimation_ms": statistics.median(times),
           "runs_ms_decimation": times, "ms_1t": fe["ms_1t"] + statistics.median(times),
           "triangles": len(f), "vertices": len(v), "padded": dec_mesh(dec_run())}
    order = list(rows)
    rows["FE + QEM decimation"] = qem
    order.insert(3, "FE + QEM decimation")
    fe_padded = fe["padded"]
    fe_points = samples(fe_padded)
    result = []
    for name in order:
        row = rows[name]
        row.update(quality(row.pop("padded"), fe_padded, fe_points, analytic, size))
        row["time_vs_fe"] = row["ms_1t"] / fe["ms_1t"]
        if f"ms_{ALL}t" in row:
            row["time_all_vs_fe"] = row[f"ms_{ALL}t"] / fe["ms_1t"]
        row["triangles_vs_fe"] = row["triangles"] / fe["triangles"]
        result.append(row)
    return {"volume": label, "shape_zyx": list(vol.shape), "dtype": str(vol.dtype), "iso": iso,
            "analytic": analytic, "rows": result}


# ---- report -----------------------------------------------------------------------------------


def tick(n):
    return "✓" if n == 0 else f"✗ {n:,}"


def volume_table(v):
    exact_col = v["analytic"] is not None
    head = ["mesher", "triangles (× FE)", "vertices", "ms 1 thread (× FE)",
            f"ms {ALL} threads (× FE 1 t)", "closed", "oriented", "manifold vertices",
            "zero-area", "smallest angle p5 / median °", "to FE mean / max (voxel)"]
    if exact_col:
        head.append("to exact surface mean / max (voxel)")
    lines = [f"#### {v['volume']} (iso {v['iso']:g})", "", "| " + " | ".join(head) + " |",
             "|---" * len(head) + "|"]
    for r in v["rows"]:
        all_t = "–"
        if f"ms_{ALL}t" in r:
            all_t = f"{r[f'ms_{ALL}t']:.1f} ({r['time_all_vs_fe']:.2f}×)"
            if not r["same_mesh_all_threads"]:
                all_t += " (other mesh)"
        time_1t = f"{r['ms_1t']:.1f} ({r['time_vs_fe']:.2f}×"
        if "decimation_ms" in r:
            time_1t += f"; decimation {r['decimation_ms']:.0f}"
        to_fe = f"{r['fe_mean']:.4f} / {r['fe_max']:.3f}"
        cells = [r["mesher"], f"{r['triangles']:,} ({r['triangles_vs_fe']:.3f})",
                 f"{r['vertices']:,}", time_1t + ")", all_t,
                 tick(r["open_edges"] + r["overfull_edges"]), tick(r["same_way_edges"]),
                 tick(r["nonmanifold_vertices"]), f"{r['zero_area']:,}",
                 f"{r['min_angle_p5']:.1f} / {r['min_angle_median']:.1f}",
                 "reference" if r["mesher"] == "Flying Edges" else to_fe]
        if exact_col:
            cells.append(f"{r['exact_mean']:.4f} / {r['exact_max']:.3f}")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def summary_table(vols):
    names = [r["mesher"] for r in vols[0]["rows"]]
    lines = ["| mesher | triangles × FE (median) | time × FE, 1 thread (median) | "
             f"time × FE 1 t, {ALL} threads (median) | closed + oriented + manifold | "
             "zero-area (total) | smallest angle p5 ° (median) | to FE mean (median) | "
             "to FE max (worst) |", "|---" * 9 + "|"]
    for name in names:
        rs = [next(r for r in v["rows"] if r["mesher"] == name) for v in vols]
        med = lambda k: statistics.median(r[k] for r in rs)  # noqa: E731
        clean = sum(r["open_edges"] + r["overfull_edges"] + r["same_way_edges"]
                    + r["nonmanifold_vertices"] == 0 for r in rs)
        all_t = f"{med('time_all_vs_fe'):.2f}" if "time_all_vs_fe" in rs[0] else "–"
        fe = f"{med('fe_mean'):.4f} | {max(r['fe_max'] for r in rs):.3f}"
        if name == "Flying Edges":
            fe = "reference | reference"
        lines.append(f"| {name} | {med('triangles_vs_fe'):.3f} | {med('time_vs_fe'):.2f} | "
                     f"{all_t} | {clean} of {len(rs)} | {sum(r['zero_area'] for r in rs):,} | "
                     f"{med('min_angle_p5'):.1f} | {fe} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true",
                    help="sphere, torus and the first SC_DATA_DIR volume only")
    ap.add_argument("--size", type=int, default=128, help="edge of the built-in volumes")
    ap.add_argument("--repeat", type=int, default=5, help="runs per time (median)")
    ap.add_argument("--out-md", default="target/accuracy.md")
    ap.add_argument("--out-json", default="target/accuracy.json")
    a = ap.parse_args()
    cpu = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                if line.startswith("model name")), platform.processor())
    versions = {p: importlib.metadata.version(p) for p in
                ("skelclimb", "vtk", "scikit-image", "fast-simplification", "trimesh", "scipy",
                 "numpy")}
    head = (f"Machine: {cpu}, {ALL} threads. Times: median of {a.repeat} runs, milliseconds; "
            "ratios to Flying Edges on one thread. Versions: "
            + ", ".join(f"{k} {v}" for k, v in versions.items()) + ".")
    print(head, flush=True)
    if not BOUNDED:
        print("note: this skelclimb has no max_error: the error-bound rows are skipped", flush=True)
    vols = []
    started = time.perf_counter()
    for label, analytic, vol, iso in volumes(a.size, os.environ.get("SC_DATA_DIR"), a.quick):
        t = time.perf_counter()
        vols.append(measure(label, analytic, vol, iso, a.size, a.repeat))
        print("\n" + volume_table(vols[-1]) + f"\n\n({time.perf_counter() - t:.0f} s)", flush=True)
    summary = summary_table(vols)
    print("\n" + summary)
    md = "\n\n".join([head, "### Summary over the volumes", summary, "### Each volume"]
                     + [volume_table(v) for v in vols]) + "\n"
    for path, text in ((a.out_md, md), (a.out_json, json.dumps(
            {"machine": cpu, "threads": ALL, "repeat": a.repeat, "versions": versions,
             "bounded": BOUNDED, "seconds": time.perf_counter() - started, "volumes": vols},
            indent=1))):
        os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
        with open(path + ".tmp", "w") as f:
            f.write(text)
        os.replace(path + ".tmp", path)
    print(f"\n{time.perf_counter() - started:.0f} s; wrote {a.out_md} and {a.out_json}")


if __name__ == "__main__":
    main()
