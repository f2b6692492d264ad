#!/usr/bin/env python3
"""How long `skelclimb extract` takes to write each mesh format, as the command reports it.

    python3 bench/write_formats.py [--bin target/release/skelclimb] [--runs 5] [--old OTHER_BINARY]

For each volume (SC_DATA_DIR, default ../shared/data; the MNI brain at 80 and the stent CT at
281, with normals as the command's default), every format: binary PLY, ASCII PLY, OBJ, STL, GLB.
Prints the median and fastest of `--stats-json`'s `seconds.write` over --runs runs, and the
file's size. With --old, the same for another build, alternating runs, and the ratio of the
fastest writes (new / old).
"""
import argparse, json, os, statistics, subprocess, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VOLUMES = [("mni152-mri", "80"), ("stent-ct", "281")]
FORMATS = [("ply", []), ("ply", ["--ascii"]), ("obj", []), ("stl", []), ("glb", [])]


def write_ms(binary, raw, iso, out, stats, extra):
    subprocess.run([binary, "extract", raw, "--iso", iso, "-o", out, "-q", "--stats-json", stats,
                    *extra], check=True)
    with open(stats) as f:
        return json.load(f)["seconds"]["write"] * 1e3


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "skelclimb"))
    ap.add_argument("--old")
    ap.add_argument("--runs", type=int, default=5)
    a = ap.parse_args()
    data = os.environ.get("SC_DATA_DIR", os.path.join(ROOT, "..", "shared", "data"))
    builds = [a.bin] + ([a.old] if a.old else [])
    with tempfile.TemporaryDirectory() as tmp:
        stats = os.path.join(tmp, "s.json")
        for name, iso in VOLUMES:
            raw = os.path.join(data, name, name + ".raw")
            for ext, extra in FORMATS:
                out = os.path.join(tmp, "mesh." + ext)
                times = {b: [] for b in builds}
                for _ in range(a.runs):
                    for b in builds:
                        times[b].append(write_ms(b, raw, iso, out, stats, extra))
                label = f"{name}@{iso} {ext}{' ascii' if extra else ''}"
                new = times[a.bin]
                line = (f"{label}: {os.path.getsize(out) / 1e6:.1f} MB, write median "
                        f"{statistics.median(new):.1f} ms, fastest {min(new):.1f} ms")
                if a.old:
                    old = times[a.old]
                    line += (f"; old median {statistics.median(old):.1f} ms, fastest "
                             f"{min(old):.1f} ms; fastest new / old {min(new) / min(old):.3f}")
                print(line, flush=True)


if __name__ == "__main__":
    main()
