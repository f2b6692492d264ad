#!/usr/bin/env python3
"""Adaptive mode against Flying Edges and Flying Edges + quadric decimation, in one run.

For each volume, one after another on one thread: `skelclimb extract` in Steps 1–3, embedded and
adaptive modes (best of `--repeat` of the `seconds.extract` its stats JSON reports), VTK's
vtkFlyingEdges3D on the same array (best of `--repeat`), and the Flying Edges mesh decimated to
each adaptive mesh's triangle count by fast_simplification (and, once, by vtkQuadricDecimation).
Then every mesh is measured against the Steps 1–3 mesh and the samples (bench/adaptive/meshstats.py):
symmetric sampled distance, smallest angles, edge sharing, and samples on the wrong side.

    python3 -m venv venv && venv/bin/pip install vtk numpy scipy fast-simplification
    cargo build --release -p sc-cli
    venv/bin/python bench/adaptive/compare.py [--data /path/to/data] [--only knot stent-ct]

Volumes: the built-ins sphere, torus and knot at 64³, rebuilt here sample for sample and written
as .npy (the Steps 1–3 and adaptive triangle counts are checked against `--demo`), and the data
volumes `<data>/<name>/<name>.raw` + `.json` padded with one layer of their smallest value (what
`--pad` does) at their first suggested iso + 0.5. Distances are in grid steps, angles in world
space. Ours runs without normals, Flying Edges without normals, gradients or scalars.
"""
import argparse, datetime, importlib.util, json, os, platform, shlex, subprocess, sys, tempfile, time
import numpy as np
import vtk
from vtk.util import numpy_support

import meshstats as ms

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DTYPES = {"u8": "<u1", "i8": "<i1", "u16": "<u2", "i16": "<i2", "f32": "<f4", "f64": "<f8"}
SCANS = ["brainsmall-mri", "stent-ct", "mni152-mri", "itk-t1-mri"]
DEMOS = ["sphere", "torus", "knot"]


def builtin_fields():
    """The 256³ benchmark's generators (bench/compare.py), and the torus beside them: the same
    arithmetic as sc_runtime::demo."""
    spec = importlib.util.spec_from_file_location("bench_compare", os.path.join(ROOT, "bench", "compare.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)

    def torus(n):
        x, y, z = mod.cells(n, -1.0, 1.0)
        ring = np.sqrt(x * x + y * y) - 0.6
        return 0.25 - np.sqrt(ring * ring + z * z)

    return {"sphere": (mod.sphere, 0.0), "torus": (torus, 0.0), "knot": (mod.knot, 0.9)}


class Volume:
    """A benchmark volume: the array (z, y, x) that both sides mesh (padded for data volumes),
    ours' input arguments, iso, spacing, and where ours puts grid index 0."""

    def __init__(self, name, arr, iso, args, spacing, padded):
        self.name, self.arr, self.iso, self.args = name, arr, iso, args
        self.spacing = np.asarray(spacing, dtype=np.float64)
        self.padded = padded

    def to_index(self, points):
        """Ours' world positions (index × spacing + origin; --pad moves the origin one step
        back) to indices of `self.arr`."""
        return points / self.spacing + (1.0 if self.padded else 0.0)


def load_volumes(names, data, work):
    fields = builtin_fields()
    out = []
    for name in names:
        if name in fields:
            f, iso = fields[name]
            arr = f(64)
            path = os.path.join(work, name + ".npy")
            np.save(path, arr)
            out.append(Volume(name, arr, iso, [path, "--iso", repr(iso)], [1, 1, 1], False))
            continue
        meta = json.load(open(os.path.join(data, name, name + ".json")))
        raw = os.path.join(data, name, name + ".raw")
        nx, ny, nz = meta["dims"]
        arr = np.fromfile(raw, dtype=DTYPES[meta["dtype"]]).reshape(nz, ny, nx)
        suggested = [v for k, v in meta["iso_suggestions"].items() if isinstance(v, (int, float))]
        iso = float(suggested[0]) + 0.5
        lo = arr.min()
        if not lo < iso:
            raise SystemExit(f"{name}: no sample below iso {iso} to pad with")
        padded = np.pad(arr, 1, constant_values=lo)
        args = [raw, "--dims", f"{nx},{ny},{nz}", "--dtype", meta["dtype"], "--pad", "--iso", repr(iso),
                "--spacing", ",".join(repr(float(s)) for s in meta["spacing"])]
        out.append(Volume(name, padded, iso, args, meta["spacing"], True))
    return out


def read_ply(path):
    r = vtk.vtkPLYReader()
    r.SetFileName(path)
    r.Update()
    return ms.from_polydata(r.GetOutput())


def run_ours(binary, args, mode_args, work, repeat):
    """Best `seconds.extract` of `repeat` one-thread runs, the stats of the last, and its mesh."""
    out, stats = os.path.join(work, "ours.ply"), os.path.join(work, "stats.json")
    cmd = [binary, "-q", "extract", *args, *mode_args, "--threads", "1", "--no-normals", "-o", out,
           "--stats-json", stats]
    best = None
    for _ in range(repeat):
        subprocess.run(cmd, check=True)
        s = json.load(open(stats))
        best = s["seconds"]["extract"] if best is None else min(best, s["seconds"]["extract"])
    return best, s, read_ply(out)


def image(arr):
    img = vtk.vtkImageData()
    img.SetDimensions(arr.shape[2], arr.shape[1], arr.shape[0])
    img.GetPointData().SetScalars(numpy_support.numpy_to_vtk(np.ascontiguousarray(arr).ravel(), deep=True))
    return img


def best_time(fn, repeat):
    best, out = None, None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        dt = time.perf_counter() - t
        best = dt if best is None else min(best, dt)
    return best, out


def flying_edges(arr, iso, repeat):
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(image(arr))
    fe.SetValue(0, iso)
    fe.SetComputeNormals(False)
    fe.SetComputeGradients(False)
    fe.SetComputeScalars(False)
    fe.Update()  # untimed first run, as ours' first run reads the file into the page cache

    def once():
        fe.Modified()
        fe.Update()
        return fe.GetOutput()

    t, pd = best_time(once, repeat)
    out = vtk.vtkPolyData()
    out.DeepCopy(pd)
    return t, out


def fast_decimate(mesh, target, repeat):
    import fast_simplification

    pts, faces = mesh[0], mesh[1].astype(np.int32)
    t, (p, f) = best_time(lambda: fast_simplification.simplify(pts, faces, target_count=target), repeat)
    return t, (np.asarray(p, dtype=np.float64), np.asarray(f, dtype=np.int64))


def vtk_decimate(pd, target, repeat):
    q = vtk.vtkQuadricDecimation()
    q.SetInputData(pd)
    q.SetTargetReduction(1.0 - target / pd.GetNumberOfCells())

    def once():
        q.Modified()
        q.Update()
        return q.GetOutput()

    t, out = best_time(once, repeat)
    return t, ms.from_polydata(out)


def measure(mesh, reference, vol, sides, step, with_distance=True):
    angles = ms.min_angles(mesh[0], mesh[1], vol.spacing)
    m = {
        "triangles": int(len(mesh[1])),
        "min_angle_p5": float(np.percentile(angles, 5)),
        "min_angle_median": float(np.median(angles)),
        "edges": ms.edge_use(mesh[1]),
        "sides": sides.wrong(*mesh),
    }
    e = m["edges"]
    m["closed_manifold"] = e["border"] == 0 and e["nonmanifold"] == 0
    m["oriented"] = e["misoriented"] == 0
    if with_distance:
        m["distance"] = ms.symmetric_distance(mesh, reference, step)
    return m


def check_on_grid(points, name):
    """Steps 1–3 vertices lie on grid edges: two of three index coordinates whole. Proves that
    ours' positions were mapped onto the array's indices."""
    whole = (np.abs(points - np.round(points)) < 1e-3).sum(axis=1)
    if not np.all(whole >= 2):
        raise SystemExit(f"{name}: {int((whole < 2).sum())} Steps 1–3 vertices off the grid edges")


def has_flag(binary, flag):
    return flag in subprocess.run([binary, "extract", "--help"], capture_output=True, text=True).stdout


def machine():
    model = ""
    for line in subprocess.run(["lscpu"], capture_output=True, text=True).stdout.splitlines():
        if line.startswith("Model name"):
            model = line.split(":", 1)[1].strip()
    return {
        "nproc": int(subprocess.run(["nproc"], capture_output=True, text=True).stdout),
        "cpu": model,
        "python": platform.python_version(),
        "vtk": vtk.vtkVersion.GetVTKVersion(),
        "loadavg_at_start": os.getloadavg(),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "skelclimb"))
    ap.add_argument("--data", default=os.environ.get("SC_DATA_DIR", "/work/shared/data"))
    ap.add_argument("--only", nargs="*", default=DEMOS + SCANS)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--max-error", type=float, nargs="*", default=[0.5, 1.0])
    ap.add_argument("--step", type=float, default=0.5,
                    help="distance sampling: lattice spacing on each triangle, in grid steps")
    ap.add_argument("--out", default=HERE)
    ap.add_argument("--from-json", metavar="FILE", help="only rewrite results.md from a results.json")
    a = ap.parse_args()
    if a.from_json:
        with open(os.path.join(a.out, "results.md"), "w") as f:
            f.write(markdown(json.load(open(a.from_json))))
        return

    tools = vtk.vtkSMPTools()
    tools.SetBackend("Sequential")
    tools.Initialize(1)
    assert tools.GetBackend() == "Sequential", tools.GetBackend()
    wrong_flag = has_flag(a.bin, "--allow-wrong-side")
    variants = [(f"adaptive {e:g}", ["--mode", "adaptive", "--max-error", repr(e), "--error-units", "voxels"])
                for e in a.max_error]
    if wrong_flag:
        variants += [(f"adaptive {e:g} wrong-side", v + ["--allow-wrong-side"])
                     for e, (_, v) in zip(a.max_error, list(variants))]
    report = {
        "command": " ".join(shlex.quote(x) for x in [sys.executable, os.path.relpath(__file__, ROOT), *sys.argv[1:]]),
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "machine": machine(),
        "allow_wrong_side_flag": wrong_flag,
        "repeat": a.repeat,
        "distance_step": a.step,
        "volumes": [],
    }
    with tempfile.TemporaryDirectory() as work:
        for vol in load_volumes(a.only, a.data, work):
            print(f"== {vol.name}: {vol.arr.shape[::-1]} iso {vol.iso}", file=sys.stderr, flush=True)
            rows, sides = [], ms.Sides(vol.arr, vol.iso)
            t, s, steps = run_ours(a.bin, vol.args, ["--mode", "steps123"], work, a.repeat)
            steps = (vol.to_index(steps[0]), steps[1])
            check_on_grid(steps[0], vol.name)
            rows.append({"method": "ours steps123", "seconds": t, **measure(steps, steps, vol, sides, a.step, False)})
            meshes = {}
            for label, margs in [("ours embedded", ["--mode", "embedded"])] + [("ours " + l, v) for l, v in variants]:
                t, s, mesh = run_ours(a.bin, vol.args, margs, work, a.repeat)
                mesh = (vol.to_index(mesh[0]), mesh[1])
                meshes[label] = len(mesh[1])
                rows.append({"method": label, "seconds": t, **measure(mesh, steps, vol, sides, a.step)})
                print(f"   {label}: {len(mesh[1])} triangles, {t:.4f} s", file=sys.stderr, flush=True)
            if vol.name in DEMOS:
                for label, margs in [("steps123", ["--mode", "steps123"])] + variants[:1]:
                    demo = [a.bin, "-q", "extract", "--demo", vol.name, "--size", "64", *margs, "--threads", "1",
                            "--no-normals", "-o", os.path.join(work, "demo.ply"),
                            "--stats-json", os.path.join(work, "demo.json")]
                    subprocess.run(demo, check=True)
                    want = json.load(open(os.path.join(work, "demo.json")))["result"]["triangles"]
                    got = next(r["triangles"] for r in rows if r["method"] == "ours " + label)
                    if want != got:
                        raise SystemExit(f"{vol.name}: {label} of the .npy rebuild gives {got} triangles, --demo {want}")
            t_fe, fe_pd = flying_edges(vol.arr, vol.iso, a.repeat)
            fe = ms.from_polydata(fe_pd)
            rows.append({"method": "FE", "seconds": t_fe, **measure(fe, steps, vol, sides, a.step)})
            print(f"   FE: {len(fe[1])} triangles, {t_fe:.4f} s", file=sys.stderr, flush=True)
            for label, _ in variants:
                target = meshes["ours " + label]
                t, dec = fast_decimate(fe, target, a.repeat)
                rows.append({"method": f"FE + fast_simplification to {label}", "seconds": t_fe + t,
                             "seconds_decimation": t, **measure(dec, steps, vol, sides, a.step)})
                print(f"   FE+fs to {label}: {len(dec[1])} triangles, {t:.4f} s", file=sys.stderr, flush=True)
            target = meshes["ours " + variants[0][0]]
            # Half as many: how far decimation goes before its distance reaches adaptive mode's.
            t, dec = fast_decimate(fe, target // 2, a.repeat)
            rows.append({"method": f"FE + fast_simplification to ½ of {variants[0][0]}", "seconds": t_fe + t,
                         "seconds_decimation": t, **measure(dec, steps, vol, sides, a.step)})
            t, dec = vtk_decimate(fe_pd, target, a.repeat)
            rows.append({"method": f"FE + vtkQuadricDecimation to {variants[0][0]}", "seconds": t_fe + t,
                         "seconds_decimation": t, **measure(dec, steps, vol, sides, a.step)})
            report["volumes"].append({"name": vol.name, "dims": list(vol.arr.shape[::-1]), "iso": vol.iso,
                                      "padded": vol.padded, "spacing": vol.spacing.tolist(), "rows": rows})
    report["machine"]["loadavg_at_end"] = os.getloadavg()
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "results.json"), "w") as f:
        json.dump(report, f, indent=1)
    with open(os.path.join(a.out, "results.md"), "w") as f:
        f.write(markdown(report))
    print(markdown(report))


def upper(d):
    return f" / {d['max_upper']:.3f}" if d["max_upper"] > d["max"] + 0.005 else ""


def summary(r):
    """One line per volume: adaptive mode at 0.5 voxel (and with --allow-wrong-side) against
    Flying Edges decimated by fast_simplification to the same triangle count."""
    lines = [
        "| volume | Steps 1–3 △ | adaptive 0.5 △ | its time ms | FE ms | FE + fs ms | max dist ours / FE + fs | wrong side ours / FE + fs | FE + fs non-manifold edges |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for v in r["volumes"]:
        rows = {row["method"]: row for row in v["rows"]}
        fe = rows["FE"]
        for label in ["adaptive 0.5", "adaptive 0.5 wrong-side"]:
            if "ours " + label not in rows:
                continue
            ours, fs = rows["ours " + label], rows[f"FE + fast_simplification to {label}"]
            steps = rows["ours steps123"]["triangles"]
            lines.append(
                f"| {v['name']}{' (wrong side allowed)' if 'wrong' in label else ''} | {steps:,} | "
                f"{ours['triangles']:,} ({steps / ours['triangles']:.2f}×) | {1000 * ours['seconds']:.0f} | "
                f"{1000 * fe['seconds']:.1f} | {1000 * fs['seconds']:.0f} | "
                f"{ours['distance']['max']:.2f} / {fs['distance']['max']:.2f} | "
                f"{ours['sides']['wrong']} / {fs['sides']['wrong']} | {fs['edges']['nonmanifold'] + fs['edges']['border']} |"
            )
    return "\n".join(lines) + "\n"


def markdown(r):
    m = r["machine"]
    lines = [
        f"Run {r['date']} on {m['nproc']} cores ({m['cpu']}), shared with other work (load average "
        f"{m['loadavg_at_start'][1]:.1f} at the start, {m['loadavg_at_end'][1]:.1f} at the end, 5-minute); "
        f"VTK {m['vtk']}, Python {m['python']}.",
        f"Command: `{r['command']}`.",
        f"`--allow-wrong-side` in this build: {'yes' if r['allow_wrong_side_flag'] else 'no'}.",
        f"Times: best of {r['repeat']}, one thread; ours is the `seconds.extract` of its stats JSON, "
        "FE + decimation is FE's best plus the decimation's best.",
        "Distance to the Steps 1–3 mesh, in grid steps, both ways: exact point–triangle distance from "
        f"lattice samples {r['distance_step']:g} grid steps apart on every triangle (mean: the average of "
        "the two ways' means); the maximum is the largest sampled distance, refined where it could be "
        "larger, with a proven upper bound after the slash when that exceeds it by more than 0.005.",
        "Wrong side: samples whose side by the mesh (ray parity) differs from `value >= iso`, "
        "all samples (within 2 samples of the surface in brackets when they differ).",
        "",
        summary(r),
    ]
    for v in r["volumes"]:
        lines.append(f"### {v['name']} ({' × '.join(map(str, v['dims']))}{', padded' if v['padded'] else ''}, iso {v['iso']:g})")
        lines.append("")
        lines.append("| method | triangles | time ms | mean dist | max dist | min angle p5 / median (°) | closed 2-manifold | wrong side |")
        lines.append("|---|---:|---:|---:|---:|---:|---|---:|")
        for row in v["rows"]:
            d = row.get("distance")
            s = row["sides"]
            e = row["edges"]
            closed = "yes" if row["closed_manifold"] else f"no ({e['border']} border, {e['nonmanifold']} non-manifold edges)"
            if row["closed_manifold"] and not row["oriented"]:
                closed += f", {e['misoriented']} misoriented"
            wrong = f"{s['wrong']}" + (f" ({s['wrong_in_band']})" if s["wrong_in_band"] != s["wrong"] else "")
            lines.append(
                f"| {row['method']} | {row['triangles']:,} | {1000 * row['seconds']:.1f} | "
                + (f"{d['mean']:.3f} | {d['max']:.3f}{upper(d)} | " if d else "— | — | ")
                + f"{row['min_angle_p5']:.1f} / {row['min_angle_median']:.1f} | {closed} | {wrong} |"
            )
        lines.append("")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
