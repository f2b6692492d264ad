#!/usr/bin/env python3
"""Skeleton Climbing against VTK's vtkFlyingEdges3D, measured in one run on the same volumes.

For each volume (the built-in 256³ volumes, rebuilt here sample for sample, and the SC_DATA_DIR
volumes at each suggested iso value), in turn: our criterion benchmarks of that volume alone
(`SC_BENCH_ONLY=<volume> cargo bench -p sc-runtime --bench extract`), then FlyingEdges on the
same array. That is one round; `--rounds` of them are run, so that both sides of every ratio are
measured within seconds of each other, several times over: this machine's speed drifts by tens
of per cent from minute to minute. Then it prints the README's speed tables: times and ratios
(medians over the rounds, and the headline ratios' range), Step 4's and normals' costs,
two-thread speed-ups, and the whole `skelclimb extract` process against its extraction.

    pip install vtk numpy
    SC_DATA_DIR=/abs/path/to/data python3 bench/compare.py [--rounds 3] [--repeat 9] [--only GROUP ...]

With SC_DATA_DIR set, bench/derive_volumes.py first derives larger u8, i16 and f32 volumes from
it into target/bench-data, and both folders are benchmarked.

Times are milliseconds, medians. FlyingEdges runs with gradients and scalars off, normals off
unless the column says otherwise, on one thread unless the column says otherwise; it is run once
untimed before each timed series, as criterion warms ours up.
"""
import argparse, glob, json, os, platform, re, shutil, statistics, subprocess, sys, tempfile, time
import numpy as np
import vtk
from vtk.util import numpy_support

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DERIVED = os.path.join(ROOT, "target", "bench-data")


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
DTYPES = {"u8": "<u1", "i16": "<i2", "u16": "<u2", "f32": "<f4"}


def data_dirs():
    return [d for d in os.environ.get("SC_DATA_DIR", "").split(os.pathsep) if d]


def raw_volume(name):
    """The raw file, its JSON description and the array (z, y, x) of a named data volume."""
    for d in data_dirs():
        meta_path = os.path.join(d, name, name + ".json")
        if os.path.exists(meta_path):
            meta = json.load(open(meta_path))
            nx, ny, nz = meta["dims"]
            raw = os.path.join(d, name, name + ".raw")
            return raw, meta, np.fromfile(raw, dtype=DTYPES[meta["dtype"]]).reshape(nz, ny, nx)
    raise SystemExit(f"{name}: not found in SC_DATA_DIR")


def volume(group):
    """The array (z, y, x) and iso of a benchmark group name."""
    if group in BUILTIN:
        f, iso = BUILTIN[group]
        return f(256).astype(np.float32), iso
    name, iso = group.rsplit("@", 1)
    return raw_volume(name)[2], float(iso)


def smp_backend():
    """VTK's threaded backend: pip's VTK starts on "Sequential", which runs one thread whatever
    it is told; "STDThread" is built in and parallel."""
    tools = vtk.vtkSMPTools()
    tools.SetBackend("STDThread")
    return tools.GetBackend()


def flying_edges(arr, iso, threads, repeat, normals=False):
    img = vtk.vtkImageData()
    img.SetDimensions(arr.shape[2], arr.shape[1], arr.shape[0])
    img.GetPointData().SetScalars(numpy_support.numpy_to_vtk(np.ascontiguousarray(arr).ravel(), deep=True))
    vtk.vtkSMPTools().Initialize(threads)
    fe = vtk.vtkFlyingEdges3D()
    fe.SetInputData(img)
    fe.SetValue(0, iso)
    fe.SetComputeNormals(normals)
    fe.SetComputeGradients(False)
    fe.SetComputeScalars(False)
    fe.Update()
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


def process_times(group, repeat):
    """The whole `skelclimb extract` (one thread, no normals, binary PLY) against the extraction
    time it reports, medians of `repeat` runs; None for built-in volumes."""
    if "@" not in group:
        return None
    name, iso = group.rsplit("@", 1)
    raw = raw_volume(name)[0]
    exe = os.path.join(ROOT, "target", "release", "skelclimb")
    whole, extract, tris = [], [], 0
    with tempfile.TemporaryDirectory() as tmp:
        out, stats = os.path.join(tmp, "m.ply"), os.path.join(tmp, "s.json")
        for _ in range(repeat):
            t = time.perf_counter()
            subprocess.run([exe, "extract", raw, "--iso", iso, "-o", out, "--threads", "1", "--no-normals",
                            "-q", "--stats-json", stats], check=True)
            whole.append(time.perf_counter() - t)
            j = json.load(open(stats))
            extract.append(j["seconds"]["extract"])
            tris = j["result"]["triangles"]
    return 1000 * sorted(whole)[repeat // 2], 1000 * sorted(extract)[repeat // 2], tris


def groups_of():
    """The benchmark groups: the built-in volumes, and each data volume at each suggested iso
    value, named as the benchmark harness names them (`name@iso`, iso as Rust prints it)."""
    groups = list(BUILTIN)
    for d in data_dirs():
        for name in sorted(os.listdir(d)):
            meta_path = os.path.join(d, name, name + ".json")
            if os.path.exists(meta_path):
                isos = json.load(open(meta_path)).get("iso_suggestions", {}).values()
                groups += [f"{name}@{iso:g}" for iso in isos if isinstance(iso, (int, float))]
    return sorted(groups)


def ours(group):
    """Our criterion medians for one group, measured now: one thread in each mode, all
    threads embedded, one thread embedded with normals."""
    env = dict(os.environ, SC_BENCH_ONLY=group)
    # Earlier results must not stand in for a run that measured nothing.
    shutil.rmtree(os.path.join(ROOT, "target", "criterion", group), ignore_errors=True)
    # Only the benchmarks the table reads (not `embedded-normals-reused`, say).
    wanted = f"^{re.escape(group)}/(steps123|embedded|paper|embedded-normals)/"
    subprocess.run(["cargo", "bench", "--quiet", "-p", "sc-runtime", "--bench", "extract", "--", wanted],
                   cwd=ROOT, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    all_t = os.cpu_count() or 1
    t = {f: criterion_ms(group, f, 1) for f in ("steps123", "embedded", "paper", "embedded-normals")}
    t["embedded-all"] = criterion_ms(group, "embedded", all_t)
    return None if None in t.values() else t


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=3, help="rounds of every volume, ours then FE")
    ap.add_argument("--repeat", type=int, default=9, help="timed Flying Edges runs per series")
    ap.add_argument("--only", nargs="*", help="these groups only (say stent-ct@281)")
    a = ap.parse_args()
    if data_dirs():
        if not os.path.isdir(DERIVED):
            subprocess.run([sys.executable, os.path.join(ROOT, "bench", "derive_volumes.py"), DERIVED], check=True)
        os.environ["SC_DATA_DIR"] = os.pathsep.join(data_dirs() + [DERIVED])
    subprocess.run(["cargo", "bench", "--no-run", "-p", "sc-runtime", "--bench", "extract"], cwd=ROOT, check=True)
    subprocess.run(["cargo", "build", "--quiet", "--release", "-p", "sc-cli"], cwd=ROOT, check=True)
    all_t = os.cpu_count() or 1
    groups = [g for g in groups_of() if not a.only or g in a.only]
    arrays = {}
    backend = smp_backend()
    runs = {g: [] for g in groups}
    for r in range(a.rounds):
        for n, g in enumerate(groups):
            print(f"round {r + 1}/{a.rounds}, {n + 1}/{len(groups)}: {g}", file=sys.stderr, flush=True)
            if g not in arrays:
                arrays[g] = volume(g)
            arr, iso = arrays[g]
            t = ours(g)
            if t is None:
                continue
            t["fe"], t["tris"] = flying_edges(arr, iso, 1, a.repeat)
            t["fe-all"], _ = flying_edges(arr, iso, all_t, a.repeat)
            t["fe-normals"], _ = flying_edges(arr, iso, 1, a.repeat, normals=True)
            runs[g].append(t)
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), platform.processor())
    print(f"\nMachine: {cpu}, {all_t} threads; VTK {vtk.vtkVersion.GetVTKVersion()} (SMP backend {backend}); "
          f"medians of {a.rounds} rounds, the headline ratios' range over the rounds in brackets\n")
    print(f"| volume (FE triangles) | FE | Steps 1–3 | embedded | paper | **embedded / FE** | Step 4 cost | normals: ours / FE's "
          f"| FE, {all_t} threads | embedded, {all_t} threads | speed-up: ours / FE's | **embedded / FE, {all_t} threads** |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    rows = []
    for g in groups:
        rs = runs[g]
        if not rs:
            print(f"| {g} | missing criterion results |")
            continue
        rows.append(g)
        med = lambda f: statistics.median(f(t) for t in rs)
        span = lambda f: f"{min(f(t) for t in rs):.2f}–{max(f(t) for t in rs):.2f}"
        one = lambda t: t["embedded"] / t["fe"]
        two = lambda t: t["embedded-all"] / t["fe-all"]
        print(f"| {g} ({rs[0]['tris']:,}) | {med(lambda t: t['fe']):.1f} | {med(lambda t: t['steps123']):.1f} "
              f"| {med(lambda t: t['embedded']):.1f} | {med(lambda t: t['paper']):.1f} "
              f"| **{med(one):.2f}×** ({span(one)}) | {100 * (med(lambda t: t['embedded'] / t['steps123']) - 1):+.0f}% "
              f"| {100 * (med(lambda t: t['embedded-normals'] / t['embedded']) - 1):+.0f}% / "
              f"{100 * (med(lambda t: t['fe-normals'] / t['fe']) - 1):+.0f}% "
              f"| {med(lambda t: t['fe-all']):.1f} | {med(lambda t: t['embedded-all']):.1f} "
              f"| {med(lambda t: t['embedded'] / t['embedded-all']):.2f}× / {med(lambda t: t['fe'] / t['fe-all']):.2f}× "
              f"| **{med(two):.2f}×** ({span(two)}) |")
    print("\n| volume | triangles (embedded) | whole `skelclimb extract` | its extraction | **ratio** |")
    print("|---|---|---|---|---|")
    for g in rows:
        t = process_times(g, a.repeat)
        if t:
            print(f"| {g} | {t[2]:,} | {t[0]:.1f} | {t[1]:.1f} | **{t[0] / t[1]:.2f}×** |")


if __name__ == "__main__":
    main()
