#!/usr/bin/env python3
"""Label-volume meshers measured side by side on one thread: VTK's vtkSurfaceNets3D and
vtkDiscreteFlyingEdges3D, zmesh, serra (PyPI `serra-mesh`) and, when it has `labels`, skelclimb.
What is counted and why is in docs/labels-benchmark.md.

    python3 bench/labels/voronoi.py                          # the synthetic volumes, once
    SC_DATA_DIR=/abs/path/to/data python3 bench/labels/peers.py [--repeat 3] [--only NAME ...]
        [--peers surfacenets flyingedges zmesh serra skelclimb] [--out bench/labels/results]

Volumes: every `$SC_DATA_DIR/labels/<name>/<name>.raw` + `.json` (dims and dtype from the json),
padded here by one voxel of background, and every `.npy` + `.json` that voronoi.py wrote into
`--volumes` (those carry their border already). The 512³ volume is measured once (`--heavy-repeat`),
the others best of `--repeat`.

Each (volume, peer) runs in a child process of its own (a fresh heap, one peer's memory never
counted against another's), with every thread-count knob at one: VTK's SMP backend set to
Sequential (environment and vtkSMPTools), serra's `threads=1`, RAYON_NUM_THREADS, OMP_NUM_THREADS.
The child measures process CPU time beside wall time for each run, and the table shows their
ratio: about 1.0 means one busy thread. Writes `<out>.json` (machine, versions, command, date,
every run) and `<out>.md` (the tables).
"""
import argparse
import datetime
import glob
import inspect
import json
import os
import platform
import shlex
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
VOLUMES_DIR = os.path.join(ROOT, "target", "labelbench")
PEERS = ["surfacenets", "flyingedges", "zmesh", "serra", "skelclimb"]
ONE_THREAD = {
    "VTK_SMP_BACKEND_IN_USE": "Sequential",
    "VTK_SMP_MAX_THREADS": "1",
    "RAYON_NUM_THREADS": "1",
    "OMP_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
}
NP_DTYPES = {"u8": np.uint8, "u16": np.uint16, "u32": np.uint32, "u64": np.uint64,
             "i16": np.int16, "i32": np.int32}


# ---------------------------------------------------------------------------------------------
# Volumes


def find_volumes(data_dir, volumes_dir):
    """(name, description) for each volume: the real atlases, then the synthetic ones."""
    found = []
    if data_dir:
        for js in sorted(glob.glob(os.path.join(data_dir, "labels", "*", "*.json"))):
            name = os.path.splitext(os.path.basename(js))[0]
            raw = os.path.join(os.path.dirname(js), name + ".raw")
            if os.path.exists(raw):
                found.append((name, {"path": raw, "json": js, "pad": 1}))
    for js in sorted(glob.glob(os.path.join(volumes_dir, "*.json"))):
        name = os.path.splitext(os.path.basename(js))[0]
        npy = os.path.join(volumes_dir, name + ".npy")
        if os.path.exists(npy):
            found.append((name, {"path": npy, "json": js, "pad": 0}))
    return found


def load_volume(desc):
    """The volume as a C-ordered (nz, ny, nx) array with a background border, its json, and its
    labels (ascending, background excluded)."""
    with open(desc["json"]) as f:
        meta = json.load(f)
    nx, ny, nz = meta["dims"]
    dtype = np.dtype(NP_DTYPES[meta["dtype"]]).newbyteorder("<")
    if desc["path"].endswith(".raw"):
        vol = np.fromfile(desc["path"], dtype=dtype).reshape(nz, ny, nx)
    else:
        vol = np.load(desc["path"])
    vol = np.ascontiguousarray(vol, dtype=vol.dtype.newbyteorder("="))
    if desc["pad"]:
        vol = np.pad(vol, desc["pad"], constant_values=meta.get("background", 0))
    if "label_values" in meta:
        labels = meta["label_values"]
    else:
        labels = sorted(int(k) for k, v in meta["voxels_per_label"].items() if v > 0)
    return vol, meta, [int(v) for v in labels]


def interface_faces(vol, background):
    """Voxel faces between two different labels, split into (label|label, label|background):
    the peer-independent size of the job. Each such face is one SurfaceNets quad."""
    ll = lb = 0
    for axis in range(3):
        n = vol.shape[axis]
        for s in range(0, n - 1, 32):
            e = min(s + 33, n)
            a = np.take(vol, np.arange(s, e - 1), axis=axis)
            b = np.take(vol, np.arange(s + 1, e), axis=axis)
            diff = a != b
            bg = (a == background) | (b == background)
            ll += int(np.count_nonzero(diff & ~bg))
            lb += int(np.count_nonzero(diff & bg))
    return ll, lb


# ---------------------------------------------------------------------------------------------
# Peers: each returns a runner `run()` (the timed work, returning its output) and `summary(out)`
# (counts and per-label meshes, untimed).


def vtk_image(vol, spacing):
    import vtk
    from vtk.util import numpy_support

    img = vtk.vtkImageData()
    img.SetDimensions(vol.shape[2], vol.shape[1], vol.shape[0])
    img.SetSpacing(*spacing)
    arr = numpy_support.numpy_to_vtk(vol.ravel(), deep=False)
    arr.SetName("labels")
    img.GetPointData().SetScalars(arr)
    return img, arr


def vtk_arrays(poly):
    from vtk.util import numpy_support

    pts = numpy_support.vtk_to_numpy(poly.GetPoints().GetData()) if poly.GetNumberOfPoints() else \
        np.zeros((0, 3), np.float32)
    polys = poly.GetPolys()
    offsets = numpy_support.vtk_to_numpy(polys.GetOffsetsArray())
    conn = numpy_support.vtk_to_numpy(polys.GetConnectivityArray())
    if not np.all(np.diff(offsets) == 3):
        raise RuntimeError("expected triangles only")
    return pts, conn.reshape(-1, 3)


def vtk_one_thread():
    from vtkmodules.vtkCommonCore import vtkSMPTools

    vtkSMPTools.SetBackend("Sequential")
    return {"vtk_smp_backend": vtkSMPTools.GetBackend(),
            "vtk_smp_threads": vtkSMPTools.GetEstimatedNumberOfThreads()}


def labelled_filter(cls, img, labels):
    """A new filter (a new one each run: VTK would not re-execute an unmodified one) on `img`,
    with every label as a contour value: both filters mesh only the labels they are given."""
    f = cls()
    f.SetInputData(img)
    f.SetNumberOfContours(len(labels))
    for i, v in enumerate(labels):
        f.SetValue(i, v)
    return f


def peer_surfacenets(vol, meta, labels, spacing):
    import vtk

    info = vtk_one_thread()
    img, keep = vtk_image(vol, spacing)
    background = meta.get("background", 0)

    def run():
        f = labelled_filter(vtk.vtkSurfaceNets3D, img, labels)
        f.SetBackgroundLabel(background)
        f.SmoothingOff()
        # Each quad split in two by the filter itself (greedy split, its default).
        f.SetOutputMeshTypeToTriangles()
        f.Update()
        return f.GetOutput()

    def summary(poly):
        from vtk.util import numpy_support

        pts, faces = vtk_arrays(poly)
        pairs = numpy_support.vtk_to_numpy(poly.GetCellData().GetArray("BoundaryLabels"))
        pairs = pairs.astype(np.int64)
        inner = pairs[:, 1] != background
        counts = {"triangles": len(faces), "vertices": len(pts),
                  "triangles_label_label": int(inner.sum()),
                  "triangles_label_background": int((~inner).sum())}
        # Per-label meshes: the label's own triangles, with the ones it shares with another
        # label taken from the atlas (each interface is stored once).
        owner = np.concatenate([pairs[:, 0], pairs[inner, 1]])
        face_ids = np.concatenate([np.arange(len(faces)), np.nonzero(inner)[0]])
        return counts, split_by_label(owner, face_ids, faces, pts)

    return run, summary, info, keep


def peer_flyingedges(vol, meta, labels, spacing):
    import vtk

    info = vtk_one_thread()
    img, keep = vtk_image(vol, spacing)

    def run():
        f = labelled_filter(vtk.vtkDiscreteFlyingEdges3D, img, labels)
        f.ComputeNormalsOff()
        f.ComputeGradientsOff()
        # Scalars on: each output point carries the label it was made for (the per-label split).
        f.ComputeScalarsOn()
        f.Update()
        return f.GetOutput()

    def summary(poly):
        from vtk.util import numpy_support

        pts, faces = vtk_arrays(poly)
        counts = {"triangles": len(faces), "vertices": len(pts)}
        scal = numpy_support.vtk_to_numpy(poly.GetPointData().GetScalars()).astype(np.int64)
        owner = scal[faces[:, 0]] if len(faces) else np.zeros(0, np.int64)
        return counts, split_by_label(owner, np.arange(len(faces)), faces, pts)

    return run, summary, info, keep


def peer_zmesh(vol, meta, labels, spacing):
    import zmesh

    xyz = vol.T  # Fortran-ordered (nx, ny, nz): the same bytes, indexed [x, y, z]

    def run():
        m = zmesh.Mesher(tuple(spacing))
        t0 = time.perf_counter()
        m.mesh(xyz, close=False)
        t1 = time.perf_counter()
        meshes = [(int(i), m.get(i, normals=False, reduction_factor=0)) for i in m.ids()]
        t2 = time.perf_counter()
        return meshes, {"mesh_s": t1 - t0, "get_s": t2 - t1}

    def summary(out):
        return per_label_summary([(i, mm.vertices, mm.faces) for i, mm in out[0]])

    return run, summary, {}, None


def peer_serra(vol, meta, labels, spacing):
    import serra_mesh

    def run():
        m = serra_mesh.Mesher(voxel_resolution=list(spacing)[::-1], axis_order="ZYX", threads=1)
        t0 = time.perf_counter()
        m.mesh(vol, close=False)
        t1 = time.perf_counter()
        meshes = [(int(i), m.get(int(i))) for i in m.ids()]
        t2 = time.perf_counter()
        return meshes, {"mesh_s": t1 - t0, "get_s": t2 - t1, "threads": m.effective_threads}

    def summary(out):
        return per_label_summary([(i, mm.vertices, mm.faces) for i, mm in out[0]])

    return run, summary, {"serra_threads": 1}, None


def skelclimb_labels():
    """skelclimb.labels, or None with the reason it is missing."""
    try:
        import skelclimb
    except ImportError as e:
        return None, f"skelclimb not importable ({e})"
    fn = getattr(skelclimb, "labels", None)
    if fn is None:
        return None, "skelclimb has no `labels` function yet"
    return fn, None


def peer_skelclimb(vol, meta, labels, spacing):
    fn, why = skelclimb_labels()
    if fn is None:
        raise Skip(why)
    kwargs = {"spacing": tuple(spacing), "origin": (0.0, 0.0, 0.0),
              "background": meta.get("background", 0)}
    params = inspect.signature(fn).parameters
    if "threads" in params:
        kwargs["threads"] = 1
    # Like the peers, which return no normals.
    if "normals" in params:
        kwargs["normals"] = False

    def run():
        c0, t0 = time.process_time(), time.perf_counter()
        res = fn(vol, **kwargs)
        t1, c1 = time.perf_counter(), time.process_time()
        # The call builds the atlas alone; the first mesh asked for cuts every label's (a
        # wheel from before that cut them in the call: `lazy` is then false).
        lazy = getattr(res, "_meshes", ()) is None
        meshes = [(int(l), res[l]) for l in res.labels()]
        t2 = time.perf_counter()
        return res, meshes, {"atlas_s": t1 - t0, "atlas_cpu_s": c1 - c0,
                             "per_label_s": t2 - t1, "lazy": lazy}

    def summary(out):
        res, meshes, _ = out
        atlas = res.atlas
        counts, per_label = per_label_summary([(i, m.vertices, m.faces) for i, m in meshes])
        counts = {"atlas_triangles": int(len(atlas.faces)), "atlas_vertices": int(len(atlas.vertices)),
                  "per_label_triangles": counts["triangles"], "per_label_vertices": counts["vertices"]}
        return counts, per_label

    return run, summary, {"threads_argument": "threads" in params}, None


class Skip(Exception):
    pass


# ---------------------------------------------------------------------------------------------
# Per-label meshes, and what is checked on them


def split_by_label(owner, face_ids, faces, pts):
    """(label, points, that label's faces) for each label in `owner` (one entry per face id)."""
    order = np.argsort(owner, kind="stable")
    owner, face_ids = owner[order], face_ids[order]
    cuts = np.flatnonzero(np.diff(owner)) + 1
    out = []
    for ids, lab in zip(np.split(face_ids, cuts), owner[np.r_[0, cuts]] if len(owner) else []):
        out.append((int(lab), pts, faces[ids]))
    return out


def per_label_summary(meshes):
    tri = sum(len(f) for _, _, f in meshes)
    ver = sum(len(v) for _, v, _ in meshes)
    return {"triangles": int(tri), "vertices": int(ver)}, meshes


def weld(pts):
    """An id per distinct position (bit-exact float32), and the count of distinct positions."""
    p = np.ascontiguousarray(pts, dtype=np.float32) + np.float32(0.0)  # -0.0 becomes 0.0
    b = p.view(np.uint32).astype(np.uint64)
    k1, k2 = (b[:, 0] << np.uint64(32)) | b[:, 1], b[:, 2]
    order = np.lexsort((k2, k1))
    new = np.ones(len(p), bool)
    new[1:] = (np.diff(k1[order]) != 0) | (np.diff(k2[order]) != 0)
    ids = np.empty(len(p), np.int64)
    ids[order] = np.cumsum(new) - 1
    return ids, int(new.sum())


def closed(faces, nverts):
    """(every edge in exactly two triangles, every edge in an even number of triangles): the
    first is a closed edge-manifold surface, the second at least leaves no hole."""
    if len(faces) == 0:
        return False, False
    f = faces.astype(np.int64)
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    e.sort(axis=1)
    _, c = np.unique(e[:, 0] * nverts + e[:, 1], return_counts=True)
    return bool(np.all(c == 2)), bool(np.all(c % 2 == 0))


def checks(per_label):
    """Closedness of each label's mesh, as indexed and with coincident vertices welded (and,
    welded, whether it is at least without holes: every edge in an even number), and the
    share of all per-label triangles that have a coincident twin (same three positions) in
    another label's mesh: a conforming mesher gives every label|label triangle a twin."""
    n = len(per_label)
    closed_idx = closed_weld = even_weld = 0
    keys, owners = [], []
    shared_pts = n > 0 and all(p is per_label[0][1] for _, p, _ in per_label)
    if shared_pts:
        gid_all, nw_all = weld(per_label[0][1])
    for lab, pts, faces in per_label:
        faces = np.asarray(faces, dtype=np.int64)
        if shared_pts:
            # Indexed closedness needs the label's vertices only; compact the index space.
            used, local = np.unique(faces, return_inverse=True)
            closed_idx += closed(local.reshape(-1, 3), len(used))[0]
            gid = gid_all[faces]
            two, even = closed(gid, nw_all)
        else:
            closed_idx += closed(faces, len(pts))[0]
            ids, nw = weld(pts)
            two, even = closed(ids[faces], nw)
        closed_weld += two
        even_weld += even
        if not shared_pts:
            keys.append(np.asarray(pts, np.float32)[faces])  # (T, 3, 3) positions
        else:
            keys.append(gid)
        owners.append(np.full(len(faces), lab, np.int64))
    twin = None
    if n:
        if shared_pts:
            tri = np.sort(np.concatenate(keys), axis=1)
        else:
            allpos = np.concatenate(keys).reshape(-1, 3)
            ids, _ = weld(allpos)
            tri = np.sort(ids.reshape(-1, 3), axis=1)
        own = np.concatenate(owners)
        _, inv, cnt = np.unique(tri, axis=0, return_inverse=True, return_counts=True)
        inv = inv.ravel()
        # A twin in another label: the key appears more than once, and not only in this label.
        lo = np.full(cnt.size, np.iinfo(np.int64).max, np.int64)
        hi = np.full(cnt.size, np.iinfo(np.int64).min, np.int64)
        np.minimum.at(lo, inv, own)
        np.maximum.at(hi, inv, own)
        twin = float(np.mean(lo[inv] != hi[inv]))
    return {"labels_meshed": n, "closed_indexed": closed_idx, "closed_welded": closed_weld,
            "no_holes_welded": even_weld,
            "twin_fraction": twin}


# ---------------------------------------------------------------------------------------------
# Child: one (volume, peer)


def child(args):
    volumes = dict(find_volumes(args.data_dir, args.volumes))
    vol, meta, labels = load_volume(volumes[args.child_volume])
    spacing = [float(s) for s in meta.get("spacing", [1, 1, 1])]
    make = globals()["peer_" + args.child_peer]
    result = {"volume": args.child_volume, "peer": args.child_peer}
    try:
        run, summary, info, _keep = make(vol, meta, labels, spacing)
    except Skip as e:
        result["skipped"] = str(e)
        print(json.dumps(result), flush=True)
        return 0
    except ImportError as e:
        result["skipped"] = f"not importable: {e}"
        print(json.dumps(result), flush=True)
        return 0
    result.update(info)
    runs = []
    out = None
    for _ in range(args.child_repeat):
        out = None  # the previous run's output is freed before the next, untimed
        c0, w0 = time.process_time(), time.perf_counter()
        out = run()
        w1, c1 = time.perf_counter(), time.process_time()
        r = {"wall_s": w1 - w0, "cpu_s": c1 - c0}
        if isinstance(out, tuple) and isinstance(out[-1], dict):
            r.update(out[-1])
        runs.append(r)
        print(json.dumps({"progress": r}), file=sys.stderr, flush=True)
    result["runs"] = runs
    best = min(runs, key=lambda r: r["wall_s"])
    result["best_s"] = best["wall_s"]
    result["cpu_over_wall"] = best["cpu_s"] / best["wall_s"]
    counts, per_label = summary(out)
    result.update(counts)
    if not args.no_checks:
        t = time.perf_counter()
        result.update(checks(per_label))
        result["checks_s"] = time.perf_counter() - t
    print(json.dumps(result), flush=True)
    return 0


# ---------------------------------------------------------------------------------------------
# Parent


def versions():
    out = {"python": platform.python_version()}
    for mod, name in [("numpy", "numpy"), ("vtk", "vtk"), ("zmesh", "zmesh"),
                      ("serra_mesh", "serra-mesh"), ("scipy", "scipy"), ("skelclimb", "skelclimb")]:
        try:
            from importlib.metadata import version
            out[name] = version(name)
        except Exception:
            out[name] = None
    return out


def machine():
    info = {"platform": platform.platform(), "nproc": os.cpu_count()}
    try:
        lscpu = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        for line in lscpu.splitlines():
            k, _, v = line.partition(":")
            if k.strip() in ("Model name", "CPU(s)", "Thread(s) per core", "Core(s) per socket",
                             "L2 cache", "L3 cache"):
                info[k.strip()] = v.strip()
    except OSError:
        pass
    try:
        with open("/proc/meminfo") as f:
            info["MemTotal"] = f.readline().split(":")[1].strip()
    except OSError:
        pass
    return info


def run_child(args, name, peer, repeat, timeout):
    cmd = [sys.executable, os.path.abspath(__file__), "--child-volume", name, "--child-peer", peer,
           "--child-repeat", str(repeat), "--volumes", args.volumes]
    if args.data_dir:
        cmd += ["--data-dir", args.data_dir]
    if args.no_checks or (name in args.heavy and not args.check_heavy):
        cmd.append("--no-checks")
    env = dict(os.environ, **ONE_THREAD)
    t = time.perf_counter()
    try:
        p = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"volume": name, "peer": peer,
                "skipped": f"stopped after {timeout:.0f} s (limit for this peer on this volume)"}
    lines = [l for l in p.stdout.splitlines() if l.startswith("{")]
    if p.returncode != 0 or not lines:
        return {"volume": name, "peer": peer, "failed": p.stderr.strip().splitlines()[-5:]}
    res = json.loads(lines[-1])
    res["child_s"] = time.perf_counter() - t
    return res


def fmt_int(v):
    return "—" if v is None else f"{v:,}"


def table(results, vols):
    rows = ["| volume | voxels | labels | peer | interfaces in count | wall s | CPU s | "
            "triangles | vertices | CPU/wall | labels closed: indexed / welded / welded, no holes | "
            "twin share |",
            "|---|---|---|---|---|---:|---:|---:|---:|---:|---|---:|"]
    for r in results:
        v = vols[r["volume"]]
        head = f"| {r['volume']} | {v['shape']} {v['dtype']} | {v['labels']:,} | {r['peer']} |"
        if "skipped" in r or "failed" in r:
            note = r.get("skipped") or "failed: " + " / ".join(r["failed"])
            rows.append(head + f" — | — | — | — | — | — | {note} | — |")
            continue
        once = {"surfacenets": "once", "skelclimb": "once (atlas)"}.get(r["peer"], "twice")
        tri = r.get("triangles", r.get("atlas_triangles"))
        ver = r.get("vertices", r.get("atlas_vertices"))
        b = min(r["runs"], key=lambda x: x["wall_s"])
        t = f"{r['best_s']:.2f}"
        cpu = f"{min(x['cpu_s'] for x in r['runs']):.2f}"
        if r["peer"] == "skelclimb":
            # The atlas alone, as SurfaceNets; the row below adds the per-label meshes. Runs
            # that cut the meshes in the call have no atlas time of their own.
            t = f"{b['atlas_s']:.2f}" if b.get("lazy") else \
                f"{b['atlas_s']:.2f} (with the per-label meshes)"
            cpu = f"{b['atlas_cpu_s']:.2f}" if "atlas_cpu_s" in b else "—"
        if "mesh_s" in r["runs"][0]:
            t += f" ({b['mesh_s']:.2f} + {b['get_s']:.2f})"
        if "closed_indexed" in r:
            n = r["labels_meshed"]
            closed = f"{r['closed_indexed']} / {r['closed_welded']} / {r['no_holes_welded']} of {n}"
            twin = f"{r['twin_fraction']:.3f}" if r["twin_fraction"] is not None else "—"
        else:
            closed, twin = "not checked", "—"
        rows.append(head + f" {once} | {t} | {cpu} | {fmt_int(tri)} | {fmt_int(ver)} | "
                           f"{r['cpu_over_wall']:.2f} | {closed} | {twin} |")
        if r["peer"] == "skelclimb":
            rows.append(f"| {r['volume']} | | | skelclimb atlas + per-label | twice | "
                        f"{b['wall_s']:.2f} ({b['atlas_s']:.2f} + {b['per_label_s']:.2f}) | "
                        f"{min(x['cpu_s'] for x in r['runs']):.2f} | "
                        f"{fmt_int(r['per_label_triangles'])} | {fmt_int(r['per_label_vertices'])} | "
                        f"| | |")
    return "\n".join(rows)


def faces_table(vols):
    rows = ["| volume | voxel faces label\\|label | voxel faces label\\|background | "
            "2 × their sum (SurfaceNets' triangles) |", "|---|---:|---:|---:|"]
    for name, v in vols.items():
        ll, lb = v["faces"]
        rows.append(f"| {name} | {ll:,} | {lb:,} | {2 * (ll + lb):,} |")
    return "\n".join(rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data-dir", default=os.environ.get("SC_DATA_DIR"),
                    help="folder holding labels/<name>/<name>.raw + .json (default $SC_DATA_DIR)")
    ap.add_argument("--volumes", default=VOLUMES_DIR, help="where voronoi.py wrote its volumes")
    ap.add_argument("--only", nargs="+", metavar="NAME", help="only these volumes")
    ap.add_argument("--peers", nargs="+", choices=PEERS, default=PEERS)
    ap.add_argument("--repeat", type=int, default=3, help="runs per measurement (best is kept)")
    ap.add_argument("--heavy", nargs="*", default=["voronoi-512-u32"],
                    help="volumes run once, with FlyingEdges stopped at --fe-limit")
    ap.add_argument("--heavy-repeat", type=int, default=1)
    ap.add_argument("--check-heavy", action="store_true",
                    help="also check closedness on the heavy volumes (minutes, GBs)")
    ap.add_argument("--fe-limit", type=float, default=120.0,
                    help="seconds one FlyingEdges run may take on a heavy volume")
    ap.add_argument("--no-checks", action="store_true", help="time and count only")
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "labels", "results"),
                    help="write <out>.json and <out>.md")
    ap.add_argument("--from-json", metavar="FILE",
                    help="only rewrite the tables (<out>.md) from a results file this script wrote")
    ap.add_argument("--child-volume", help=argparse.SUPPRESS)
    ap.add_argument("--child-peer", help=argparse.SUPPRESS)
    ap.add_argument("--child-repeat", type=int, default=3, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child_volume:
        return child(args)
    if args.from_json:
        with open(args.from_json) as f:
            report = json.load(f)
        return write_markdown(report, args.out)

    found = find_volumes(args.data_dir, args.volumes)
    if args.only:
        missing = set(args.only) - {n for n, _ in found}
        if missing:
            sys.exit(f"no such volume: {', '.join(sorted(missing))} "
                     f"(looked in {args.data_dir}/labels and {args.volumes})")
        found = [(n, d) for n, d in found if n in args.only]
    if not found:
        sys.exit(f"no volumes: set SC_DATA_DIR, or run bench/labels/voronoi.py (into {args.volumes})")
    started = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    load_at_start = os.getloadavg()
    vols, results = {}, []
    for name, desc in found:
        vol, meta, labels = load_volume(desc)
        vols[name] = {"shape": "×".join(str(s) for s in vol.shape[::-1]), "dtype": meta["dtype"],
                      "labels": len(labels), "padded_here": bool(desc["pad"]),
                      "faces": interface_faces(vol, meta.get("background", 0))}
        del vol
        heavy = name in args.heavy
        for peer in args.peers:
            repeat = args.heavy_repeat if heavy else args.repeat
            timeout = 30 + args.fe_limit * repeat if (heavy and peer == "flyingedges") else 4 * 3600
            r = run_child(args, name, peer, repeat, timeout)
            results.append(r)
            shown = r.get("skipped") or r.get("failed") or \
                f"{r['best_s']:.2f} s, {fmt_int(r.get('triangles', r.get('atlas_triangles')))} triangles, " \
                f"cpu/wall {r['cpu_over_wall']:.2f}"
            print(f"{name} {peer}: {shown}", flush=True)
    report = {
        "command": " ".join(shlex.quote(a) for a in sys.argv),
        "started": started,
        "finished": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "machine": machine(),
        "load_average_at_start": load_at_start,
        "load_average_at_end": os.getloadavg(),
        "repeat": args.repeat,
        "heavy": args.heavy,
        "heavy_repeat": args.heavy_repeat,
        "versions": versions(),
        "one_thread": ONE_THREAD,
        "volumes": vols,
        "results": results,
    }
    with open(args.out + ".json", "w") as f:
        json.dump(report, f, indent=1)
    return write_markdown(report, args.out)


def write_markdown(report, out):
    m = report["machine"]
    kinds = [k for k in ("load_average_at_start", "load_average_at_end") if k in report]
    load = " → ".join("/".join(f"{x:.1f}" for x in report[k]) for k in kinds)
    load += " (1/5/15 min, " + " and ".join(k.split("_")[-1] for k in kinds) + ")"
    md = [f"Measured {report['started']} on {m.get('Model name', '?')} ({m.get('CPU(s)', '?')} CPUs, "
          f"load average {load}), one thread, best of {report.get('repeat', '?')} "
          f"({report.get('heavy_repeat', 1)} run for {', '.join(report.get('heavy', [])) or 'none'}).",
          "Versions: " + ", ".join(f"{k} {v}" for k, v in report["versions"].items()) + ".",
          f"Command: `{report['command']}`", "",
          table(report["results"], report["volumes"]), "", faces_table(report["volumes"]), ""]
    with open(out + ".md", "w") as f:
        f.write("\n".join(md))
    print("\n".join(md))
    return 0


if __name__ == "__main__":
    sys.exit(main())
