"""Meshing a Zarr store too big to want in one piece: one process against a Dask cluster.

Writes (once) an N³ uint8 volume of overlapping balls as a Zarr v3 store with C³ chunks, then
meshes it with ``skelclimb.dask.extract``

* on one process with Dask's synchronous scheduler (one core), and
* on a ``distributed.LocalCluster`` of W single-threaded worker processes,

and checks both meshes are identical. Prints wall time, time per core against the single
process, and each process's peak resident memory. Needs the venv of ``bench/python_compare.py``
plus ``dask[array] distributed zarr``.

    python bench/dask_bench.py --size 1024 --chunk 128 --workers 2 --dir /tmp/skelclimb-dask

With ``--shards`` the workers write one shard per chunk instead of returning shares, and the
mesh is joined afterwards with ``skelclimb.merge_shards`` (its time and memory go to stderr).
With ``--null-graph`` the cluster then also runs a graph of the same shape whose tasks do
nothing: what Dask itself costs for that many tasks on this machine.
"""

import argparse
import json
import os
import resource
import subprocess
import sys
import time

import numpy as np


def write_store(path, n, chunk):
    import zarr

    if os.path.exists(os.path.join(path, "zarr.json")):
        z = zarr.open_array(path, mode="r")
        if z.shape == (n, n, n) and z.chunks == (chunk,) * 3:
            return
    rng = np.random.default_rng(1)
    centres = rng.uniform(0.2, 0.8, (6, 3)) * n
    radii = rng.uniform(0.12, 0.22, 6) * n
    z = zarr.create_array(store=path, shape=(n, n, n), chunks=(chunk,) * 3, dtype=np.uint8,
                          overwrite=True)
    y, x = np.mgrid[0:n, 0:n].astype(np.float32)
    for z0 in range(0, n, chunk):
        slab = np.empty((min(chunk, n - z0), n, n), np.uint8)
        for dz in range(slab.shape[0]):
            f = np.zeros((n, n), np.float32)
            for c, r in zip(centres, radii):
                d2 = (x - c[2]) ** 2 + (y - c[1]) ** 2 + (z0 + dz - c[0]) ** 2
                f += np.exp(-d2 / (r * r))
            slab[dz] = np.clip(f * 100, 0, 255).astype(np.uint8)
        z[z0:z0 + slab.shape[0]] = slab
        print(f"  wrote z {z0 + slab.shape[0]}/{n}", file=sys.stderr)


def peak_rss_mib():
    """This process's own peak resident memory. On Linux that is VmHWM: ``ru_maxrss`` also
    counts the parent's resident memory at the fork that started the process (the kernel keeps
    it across ``exec``), which made idle Dask workers look 140–270 MiB large instead of 67."""
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def run_single(path, level):
    """One process, one core: the synchronous scheduler. Run in a child for a clean peak RSS."""
    import dask
    import dask.array as da

    import skelclimb.dask

    arr = da.from_zarr(path)
    t = time.perf_counter()
    with dask.config.set(scheduler="synchronous"):
        mesh = skelclimb.dask.extract(arr, level, normals=False)
    seconds = time.perf_counter() - t
    np.save(path + ".single-faces.npy", mesh.faces)
    np.save(path + ".single-verts.npy", mesh.vertices)
    print(json.dumps({"seconds": seconds, "peak_mib": peak_rss_mib(),
                      "triangles": int(mesh.faces.shape[0])}))


def _nothing(*dependencies):
    return np.zeros(4, np.uint8)


def null_graph_seconds(client, arr, level):
    """The time of ``skelclimb.dask.extract``'s graph for ``arr`` with every task (the array's
    own chunk loads included) replaced by one that returns four bytes: Dask's cost alone."""
    import dask.core

    import skelclimb.dask

    delayed = skelclimb.dask.extract(arr, level, normals=False, compute=False)
    graph = dict(delayed.__dask_graph__())
    null = {k: (_nothing, *dask.core.get_dependencies(graph, k)) for k in graph}
    t = time.perf_counter()
    client.get(null, [delayed.key])
    return time.perf_counter() - t


def run_cluster(path, level, workers, shards=None, null=False):
    import dask.array as da
    import distributed

    import skelclimb.dask

    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        client.run(lambda: None)  # workers up before the clock starts
        # A worker's memory before any task: Python, NumPy, Dask, zarr and the extension.
        idle = sorted(client.run(peak_rss_mib).values())
        arr = da.from_zarr(path)
        t = time.perf_counter()
        result = skelclimb.dask.extract(arr, level, normals=False, shards=shards)
        seconds = time.perf_counter() - t
        peaks = sorted(client.run(peak_rss_mib).values())
        null_seconds = null_graph_seconds(client, arr, level) if null else None
    if shards is not None:
        # Joined here, on "a machine that can hold the result", after the cluster is gone.
        t = time.perf_counter()
        mesh = skelclimb.merge_shards(result)
        print(f"merge_shards of {result}: {time.perf_counter() - t:.1f} s, peak RSS of this "
              f"process {peak_rss_mib():.0f} MiB", file=sys.stderr)
    else:
        mesh = result
    same = (np.array_equal(mesh.faces, np.load(path + ".single-faces.npy"))
            and np.array_equal(mesh.vertices, np.load(path + ".single-verts.npy")))
    mesh_mib = (mesh.faces.nbytes + mesh.vertices.nbytes) / 2**20
    return seconds, idle, peaks, same, int(mesh.faces.shape[0]), mesh_mib, null_seconds


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--size", type=int, default=1024)
    p.add_argument("--chunk", type=int, default=128)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--level", type=float, default=50)
    p.add_argument("--dir", default="/tmp/skelclimb-dask")
    p.add_argument("--shards", action="store_true",
                   help="workers write shards (in DIR/shards) instead of returning shares")
    p.add_argument("--null-graph", action="store_true",
                   help="also time the same graph with tasks that do nothing")
    p.add_argument("--single", action="store_true", help=argparse.SUPPRESS)
    a = p.parse_args()
    path = os.path.join(a.dir, f"balls{a.size}-c{a.chunk}.zarr")
    if a.single:
        return run_single(path, a.level)
    os.makedirs(a.dir, exist_ok=True)
    write_store(path, a.size, a.chunk)
    single = json.loads(subprocess.run(
        [sys.executable, __file__, "--single", "--size", str(a.size), "--chunk", str(a.chunk),
         "--level", str(a.level), "--dir", a.dir],
        check=True, capture_output=True, text=True).stdout)
    shards = os.path.join(a.dir, "shards") if a.shards else None
    seconds, idle, peaks, same, triangles, mesh_mib, null_seconds = run_cluster(
        path, a.level, a.workers, shards, a.null_graph)
    gib = a.size**3 / 2**30
    print(f"| run | wall time | time × cores / single | peak RSS per process |")
    print(f"|---|---|---|---|")
    print(f"| 1 process (synchronous) | {single['seconds']:.1f} s | 1.00 | "
          f"{single['peak_mib']:.0f} MiB |")
    how = ", shards" if a.shards else ""
    print(f"| LocalCluster, {a.workers} processes{how} | {seconds:.1f} s | "
          f"{seconds * a.workers / single['seconds']:.2f} | "
          f"{', '.join(f'{m:.0f}' for m in peaks)} MiB |")
    if null_seconds is not None:
        print(f"| LocalCluster, the same graph with no-op tasks | {null_seconds:.1f} s | "
              f"{null_seconds * a.workers / single['seconds']:.2f} | – |")
    print(f"\n{a.size}³ uint8 ({gib:.2f} GiB) in {a.chunk}³ chunks, level {a.level:g}: "
          f"{triangles:,} triangles ({mesh_mib:.0f} MiB of vertices and faces); "
          f"meshes identical: {same}; idle workers before the run: "
          f"{', '.join(f'{m:.0f}' for m in idle)} MiB")
    if not same:
        sys.exit("the cluster's mesh differs from the single process's")


if __name__ == "__main__":
    main()
