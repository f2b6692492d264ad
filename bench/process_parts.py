#!/usr/bin/env python3
"""Where a whole `skelclimb extract` process's time goes beside the extraction, on a small volume.

Times, from Python's `subprocess` as bench/compare.py starts the CLI: `/bin/true` (starting any
process), `skelclimb --version` (starting ours: the loader and its libraries), and the extraction
of brainsmall at iso 20 (one thread, no normals, binary PLY) written to a new file and over an
existing one; plus the read, extract and write times the process reports (`--stats-json`).
Medians of --runs, the cases alternating.

    cargo build --release -p sc-cli
    SC_DATA_DIR=../shared/data python3 bench/process_parts.py [--runs 25]
"""
import argparse, json, os, statistics, subprocess, sys, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=25)
    a = ap.parse_args()
    data = os.environ.get("SC_DATA_DIR")
    if not data:
        sys.exit("set SC_DATA_DIR to the folder holding brainsmall-mri/brainsmall-mri.raw")
    exe = os.path.join(ROOT, "target", "release", "skelclimb")
    raw = os.path.join(os.path.abspath(data), "brainsmall-mri", "brainsmall-mri.raw")
    with tempfile.TemporaryDirectory() as tmp:
        out, stats = os.path.join(tmp, "m.ply"), os.path.join(tmp, "s.json")
        extract = [exe, "extract", raw, "--iso", "20", "-o", out, "--threads", "1", "--no-normals",
                   "-q", "--stats-json", stats]
        cases = {"/bin/true": ["/bin/true"], "skelclimb --version": [exe, "--version"],
                 "extract, new output": extract, "extract, replacing it": extract}
        times = {k: [] for k in cases}
        inside = {"read": [], "extract": [], "write": []}
        for _ in range(a.runs):
            for name, cmd in cases.items():
                if name == "extract, new output" and os.path.exists(out):
                    os.unlink(out)
                start = time.perf_counter()
                subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
                times[name].append(1e3 * (time.perf_counter() - start))
                if cmd is extract:
                    seconds = json.load(open(stats))["seconds"]
                    for k in inside:
                        inside[k].append(1e3 * seconds[k])
    for name, t in times.items():
        print(f"{name}: {statistics.median(t):.2f} ms")
    for k, t in inside.items():
        print(f"  in the process, {k}: {statistics.median(t):.2f} ms")


if __name__ == "__main__":
    main()
