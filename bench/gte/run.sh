#!/usr/bin/env bash
# The Geometric Tools baseline for adaptive mode (docs/adaptive.md, "Baseline"): builds GTE's
# header-only AdaptiveSkeletonClimbing3 with g++ around asc_bench.cpp, meshes centred
# (2^N+1)^3 crops of real scans at a non-integer iso value, and puts beside it what `skelclimb`
# gives on the same crops in steps123, embedded and adaptive mode (default bound, half a voxel;
# and with --allow-wrong-side, which GTE's method also allows), one thread, no normals, best of 3.
#
#   bench/gte/run.sh GTE [DATA] [SKELCLIMB]
#
# GTE: a Geometric Tools checkout (the folder holding GTE/Mathematics), or its git directory
#      (e.g. what the `fetch` tool leaves), or the env var GTE_DIR.
# DATA: the benchmark volumes, each <name>/<name>.raw + .json [default: ../shared/data].
# SKELCLIMB: the command line tool [default: target/release/skelclimb].
# Env: N (crop is 2^N+1 per axis, default 6), VOLUMES (names), REPEATS (default 3),
#      OUT (work folder, default a fresh temporary one).
#
# Each crop's outer layer of samples is set to the crop's minimum, so every surface is closed
# and "closed" is a fair check for both programs. The iso value is the volume's suggested one
# plus 0.5: GTE refuses an iso equal to a sample, and the data here is integer.
# This script is a benchmark, not part of the project's build or tests.
set -euo pipefail

GTE=${1:-${GTE_DIR:-}}
DATA=${2:-../shared/data}
SKELCLIMB=${3:-target/release/skelclimb}
N=${N:-6}
REPEATS=${REPEATS:-3}
VOLUMES=${VOLUMES:-"brainsmall-mri stent-ct mni152-mri"}
HERE=$(cd "$(dirname "$0")" && pwd)

if [[ -z "$GTE" ]]; then
    echo "usage: $0 GTE [DATA] [SKELCLIMB]  (GTE: a Geometric Tools checkout or git dir, or set GTE_DIR)" >&2
    exit 2
fi
[[ -x "$SKELCLIMB" ]] || { echo "$0: $SKELCLIMB not found; cargo build --release -p sc-cli" >&2; exit 2; }
OUT=${OUT:-$(mktemp -d)}
mkdir -p "$OUT"

# A git directory without a work tree: export GTE/Mathematics from its HEAD.
if [[ ! -f "$GTE/GTE/Mathematics/AdaptiveSkeletonClimbing3.h" ]]; then
    if git --git-dir="$GTE" rev-parse --verify -q HEAD >/dev/null; then
        rm -rf "$OUT/gte" && mkdir -p "$OUT/gte"
        git --git-dir="$GTE" archive HEAD GTE/Mathematics | tar -x -C "$OUT/gte"
        echo "GTE commit: $(git --git-dir="$GTE" rev-parse --short HEAD)" >&2
        GTE="$OUT/gte"
    else
        echo "$0: no GTE/Mathematics/AdaptiveSkeletonClimbing3.h under $GTE" >&2
        exit 2
    fi
fi

g++ -std=c++17 -O3 -DNDEBUG -I "$GTE/GTE" -o "$OUT/asc_bench" "$HERE/asc_bench.cpp"

echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores; $(g++ --version | head -1)"
echo "crops: $(( (1 << N) + 1 ))^3, centred, outer layer set to the crop's minimum; one thread; best of $REPEATS"
echo
echo "| volume | iso | GTE ASC triangles | GTE s | GTE closed / misoriented / bad vertex links | steps123 triangles | steps123 s | embedded triangles | embedded s | adaptive triangles | adaptive s | adaptive, wrong side allowed: triangles | s | adaptive's max distance to steps123 (voxels; both) | ours closed / misoriented (each mode) |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"

for name in $VOLUMES; do
    json="$DATA/$name/$name.json"
    raw="$DATA/$name/$name.raw"
    # Crop and metadata: dtype, iso (suggested + 0.5) and the crop file.
    read -r dtype iso < <(python3 - "$json" "$raw" "$OUT/$name.crop.raw" "$N" <<'PY'
import json, struct, sys
meta = json.load(open(sys.argv[1]))
raw, out, n = sys.argv[2], sys.argv[3], int(sys.argv[4])
nx, ny, nz = meta["dims"]
dtype = meta["dtype"]
fmt, width = {"u8": ("B", 1), "i16": ("h", 2), "u16": ("H", 2), "i32": ("i", 4)}[dtype]
iso = next(v for v in meta["iso_suggestions"].values() if isinstance(v, (int, float))) + 0.5
side = (1 << n) + 1
if min(nx, ny, nz) < side:
    sys.exit(f"{raw}: {nx}x{ny}x{nz} is smaller than a {side}^3 crop")
x0, y0, z0 = ((d - side) // 2 for d in (nx, ny, nz))
data = open(raw, "rb").read()
rows = []
for z in range(z0, z0 + side):
    for y in range(y0, y0 + side):
        start = ((z * ny + y) * nx + x0) * width
        rows.append(data[start:start + side * width])
vals = list(struct.unpack("<" + fmt * (side ** 3), b"".join(rows)))
low = min(vals)
for z in range(side):
    for y in range(side):
        for x in range(side):
            if 0 in (x, y, z) or side - 1 in (x, y, z):
                vals[x + side * (y + side * z)] = low
open(out, "wb").write(struct.pack("<" + fmt * len(vals), *vals))
print(dtype, iso)
PY
)
    side=$(( (1 << N) + 1 ))
    gte=$("$OUT/asc_bench" "$OUT/$name.crop.raw" "$dtype" "$N" "$iso" -1 "$REPEATS")
    echo "$gte" > "$OUT/$name.gte.json"
    ours() { # run name, then extract options -> best seconds; the stats file of the last run
        local run=$1 best=""
        shift
        for _ in $(seq "$REPEATS"); do
            "$SKELCLIMB" extract "$OUT/$name.crop.raw" --dims "$side,$side,$side" --dtype "$dtype" \
                --iso "$iso" "$@" --threads 1 --no-normals --check -q \
                -o "$OUT/$name.$run.ply" --stats-json "$OUT/$name.$run.json"
            s=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["seconds"]["extract"])' "$OUT/$name.$run.json")
            best=$(python3 -c 'import sys; a=[float(x) for x in sys.argv[1:] if x]; print(min(a))' "$s" $best)
        done
        echo "$best"
    }
    s123=$(ours steps123 --mode steps123)
    semb=$(ours embedded --mode embedded)
    sada=$(ours adaptive --mode adaptive)
    sadw=$(ours adaptive-allowed --mode adaptive --allow-wrong-side)
    python3 - "$name" "$iso" "$OUT/$name.gte.json" "$OUT/$name".{steps123,embedded,adaptive,adaptive-allowed}.json "$s123" "$semb" "$sada" "$sadw" <<'PY'
import json, sys
name, iso, g, a, b, c, d, sa, sb, sc, sd = sys.argv[1:]
g, a, b, c, d = (json.load(open(p)) for p in (g, a, b, c, d))
def ok(s):
    e = s["edges"]
    closed = e["border_edges"] == 0 and e["non_manifold_edges"] == 0
    return f'{"yes" if closed else "no"} / {e["misoriented_edges"]}'
gte_ok = f'{"yes" if g["closed"] else "no"} / {g["misoriented_edges"]} / {g["bad_vertex_links"]}'
dist = " / ".join(f'{s["distance_to_steps123"]["max"]:.3f}' for s in (c, d))
print(f'| {name} | {iso} | {g["triangles"]:,} | {g["seconds"]:.3f} | {gte_ok} | '
      f'{a["result"]["triangles"]:,} | {float(sa):.3f} | {b["result"]["triangles"]:,} | {float(sb):.3f} | '
      f'{c["result"]["triangles"]:,} | {float(sc):.3f} | {d["result"]["triangles"]:,} | {float(sd):.3f} | '
      f'{dist} | {", ".join(ok(s) for s in (a, b, c, d))} |')
PY
done
echo
echo "raw results (GTE JSON, our --stats-json, meshes) in $OUT"
