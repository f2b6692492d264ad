#!/usr/bin/env bash
# Where the sweep's time goes: instructions per pass (callgrind, inclusive), for one
# single-threaded extraction of a raw volume. Instruction counts, unlike seconds, do not move
# with the machine's load, so they compare variants of the code on a busy machine.
#
#   bench/profile.sh VOLUME.raw NX,NY,NZ DTYPE ISO [MODE] [--normals]
#   bench/profile.sh tests/data/brainsmall-crop-40x40x30.u8.raw 40,40,30 u8 20
#
# Needs valgrind. The passes are the sweep's functions (sc-runtime/src/sweep.rs), kept out of
# line so they show apart. With BRANCHES=1, callgrind also simulates a branch predictor and a
# second column gives each pass's mispredicted conditional branches, which instruction counts do
# not see; with BIN=path, that `time_extract` is profiled instead of one built from this tree
# (another commit's, say).
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 4 ] || { sed -n '2,9p' "$0"; exit 2; }
volume=$1 dims=$2 dtype=$3 iso=$4 mode=${5:-embedded}
shift $(( $# < 5 ? $# : 5 ))
bin=${BIN:-}
if [ -z "$bin" ]; then
    cargo build --quiet --release -p sc-runtime --example time_extract
    bin=target/release/examples/time_extract
fi
sim=()
[ "${BRANCHES:-0}" = 1 ] && sim=(--branch-sim=yes)
out=$(mktemp)
trap 'rm -f "$out"' EXIT
valgrind --tool=callgrind "${sim[@]}" --callgrind-out-file="$out" "$bin" \
    "$volume" "$dims" "$dtype" "$iso" 1 "$mode" "$@" >/dev/null 2>&1
# With the branch simulation the columns are Ir Bc Bcm Bi Bim, each with its share in brackets
# (dropped before splitting, since a share under 10 % has a space in them) and "." for none.
# The list is sorted by inclusive instructions: a function's first line is its own total.
callgrind_annotate --inclusive=yes "$out" 2>/dev/null | awk -v mode="$mode" -v sim="${#sim[@]}" '
    function keep(name,    line, f) {
        if (name in v) return
        line = $0
        gsub(/\( *[0-9.]+%\)/, "", line)
        gsub(",", "", line)
        split(line, f, " ")
        v[name] = f[1]; m[name] = f[3]
    }
    /PROGRAM TOTALS/ { keep("whole program") }
    /sweep::Sweep<T>::layer \[/ { keep("all layers") }
    /sweep::Grid::classify \[/ { keep("classify (Step 1 signs)") }
    /sweep::Grid::compute_cases \[/ { keep("cube cases") }
    /sweep::Sweep<T>::plane_vertices \[/ { keep("x- and y-edge vertices") }
    /sweep::Sweep<T>::z_vertices \[/ { keep("z-edge vertices") }
    /sweep::Sweep<T>::triangles \[/ { keep("triangles (Steps 3-4)") }
    END {
        printf "%-26s %12s", "pass (" mode ")", "instructions"
        if (sim) printf " %12s", "mispredicted"
        printf "\n"
        n = split("classify (Step 1 signs)|cube cases|x- and y-edge vertices|z-edge vertices|triangles (Steps 3-4)|all layers|whole program", order, "|")
        for (i = 1; i <= n; i++) if (order[i] in v) {
            printf "%-26s %12.1f M", order[i], v[order[i]] / 1e6
            if (sim) printf " %10.1f k", m[order[i]] / 1e3
            printf "\n"
        }
    }'
