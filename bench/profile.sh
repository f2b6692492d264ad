#!/usr/bin/env bash
# Where the sweep's time goes: instructions per pass (callgrind, inclusive), for one
# single-threaded extraction of a raw volume. Instruction counts, unlike seconds, do not move
# with the machine's load, so they compare variants of the code on a busy machine.
#
#   bench/profile.sh VOLUME.raw NX,NY,NZ DTYPE ISO [MODE] [--normals]
#   bench/profile.sh tests/data/brainsmall-crop-40x40x30.u8.raw 40,40,30 u8 20
#
# Needs valgrind. The passes are the sweep's functions (sc-runtime/src/sweep.rs), kept out of
# line so they show apart.
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 4 ] || { sed -n '2,9p' "$0"; exit 2; }
volume=$1 dims=$2 dtype=$3 iso=$4 mode=${5:-embedded}
shift $(( $# < 5 ? $# : 5 ))
cargo build --quiet --release -p sc-runtime --example time_extract
out=$(mktemp)
trap 'rm -f "$out"' EXIT
valgrind --tool=callgrind --callgrind-out-file="$out" target/release/examples/time_extract \
    "$volume" "$dims" "$dtype" "$iso" 1 "$mode" "$@" >/dev/null 2>&1
callgrind_annotate --inclusive=yes "$out" 2>/dev/null | awk -v mode="$mode" '
    /PROGRAM TOTALS/ { gsub(",", "", $1); total = $1 }
    /sweep::Sweep<T>::layer \[/ { gsub(",", "", $1); v["all layers"] = $1 }
    /sweep::Sweep<T>::start \[/ { gsub(",", "", $1); v["start"] = $1 }
    /sweep::Grid::classify \[/ { gsub(",", "", $1); v["classify (Step 1 signs)"] = $1 }
    /sweep::Grid::compute_cases \[/ { gsub(",", "", $1); v["cube cases"] = $1 }
    /sweep::Sweep<T>::plane_vertices \[/ { gsub(",", "", $1); v["x- and y-edge vertices"] = $1 }
    /sweep::Sweep<T>::z_vertices \[/ { gsub(",", "", $1); v["z-edge vertices"] = $1 }
    /sweep::Sweep<T>::triangles \[/ { gsub(",", "", $1); v["triangles (Steps 3-4)"] = $1 }
    END {
        printf "%-26s %12s\n", "pass (" mode ")", "instructions"
        n = split("classify (Step 1 signs)|cube cases|x- and y-edge vertices|z-edge vertices|triangles (Steps 3-4)|all layers", order, "|")
        for (i = 1; i <= n; i++) if (order[i] in v) printf "%-26s %12.1f M\n", order[i], v[order[i]] / 1e6
        printf "%-26s %12.1f M\n", "whole program", total / 1e6
    }'
