#!/usr/bin/env bash
# Coverage-guided fuzzing of every reader with AFL++ through cargo-afl, on stable Rust.
#
#   fuzz/run.sh [SECONDS_PER_TARGET] [TARGET...]    (default: 60 seconds, every target)
#
# CI runs `AFL_OPT_LEVEL=1 fuzz/run.sh 5`: a smoke run that every reader starts, calibrates its
# corpus and survives a few thousand mutations; real campaigns use 600 seconds a target.
#
# Installs cargo-afl if it is missing and builds AFL++ once (cargo afl config --build), builds the
# instrumented target (src/main.rs; again with sc-io's `zarr` feature for the Zarr target), then
# runs one afl-fuzz at a time (one core) on each reader, starting from fuzz/corpus/<target>.
# AFL's findings go to fuzz/out/<target>/default/{crashes,hangs}; the script fails if any target
# has one. A finding becomes a file in fuzz/regressions/<target>/ (replayed by `cargo test -p
# sc-io --test fuzz_corpus`) and a fix in sc-io.
#
# Limits per input: 2 s (a hang beyond that is a finding) and 1 GiB of address space (a reader
# that allocates past what a small file declares aborts, which is a finding too).
set -euo pipefail
cd "$(dirname "$0")"

seconds=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(nifti nifti_gz nrrd metaimage npy npz dicom sidecar ply obj stl zarr shards)
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$PWD/target}

if ! cargo afl --version >/dev/null 2>&1; then
    cargo install cargo-afl --locked
fi
# Builds AFL++ (afl-fuzz and its runtime) from the source cargo-afl ships, once per toolchain.
cargo afl config --build >/dev/null 2>&1 || true
# An explicit --target keeps the instrumentation flags off build scripts and proc macros, which
# then build plainly: a cold build takes 2 minutes instead of 3. AFL_OPT_LEVEL (cargo-afl's,
# default 3) trades execution speed for build time; CI's short run uses 1.
host=$(rustc -vV | awk '$1 == "host:" { print $2 }')
cargo afl build --release --locked --bin read --bin zarr_off --target "$host"
binary=$CARGO_TARGET_DIR/$host/release/read
# sc-io is built here without its `zarr` feature: a Zarr store must be refused, naming it.
"$CARGO_TARGET_DIR/$host/release/zarr_off"
# The Zarr target is the same program built again with sc-io's `zarr` feature (`read_zarr`):
# only sc-io and zarrs's crates are built for it, the rest is shared with the build above.
if [[ " ${targets[*]} " == *" zarr "* ]]; then
    cargo afl build --release --locked --features zarr --bin read_zarr --target "$host"
fi

# Containers and CI machines: no core_pattern or CPU frequency tuning, no pinning, no UI.
export AFL_I_DONT_CARE_ABOUT_MISSING_CRASHES=1 AFL_SKIP_CPUFREQ=1 AFL_NO_AFFINITY=1 AFL_NO_UI=1
export AFL_SKIP_CRASHES=1

failed=0
printf '%-10s %10s %8s %7s %7s\n' target execs paths crashes hangs
for t in "${targets[@]}"; do
    out=out/$t
    rm -rf "$out"
    mkdir -p out
    program=$binary
    if [ "$t" = zarr ]; then program=${binary}_zarr; fi
    SC_FUZZ_TARGET=$t cargo afl fuzz -V "$seconds" -m 1024 -t 2000 -i "corpus/$t" -o "$out" \
        -- "$program" >"out/$t.log" 2>&1 || { echo "afl-fuzz failed on $t:"; tail -20 "out/$t.log"; exit 1; }
    stats=$out/default/fuzzer_stats
    field() { awk -v k="$1" '$1 == k { print $3 }' "$stats"; }
    crashes=$(find "$out/default/crashes" -type f ! -name README.txt | wc -l)
    hangs=$(find "$out/default/hangs" -type f | wc -l)
    printf '%-10s %10s %8s %7s %7s\n' "$t" "$(field execs_done)" "$(field corpus_count)" "$crashes" "$hangs"
    if [ "$crashes" -gt 0 ] || [ "$hangs" -gt 0 ]; then
        failed=1
    fi
done
if [ "$failed" -ne 0 ]; then
    echo "AFL found crashes or hangs: see fuzz/out/<target>/default/{crashes,hangs}"
    exit 1
fi
