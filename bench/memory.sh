#!/usr/bin/env bash
# Peak resident memory of `skelclimb extract` on large volumes written here: a 256³ f32 and a
# 512³ u16 sphere (64 MiB and 256 MiB of samples). Needs python3 with numpy, and GNU time.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
python3 - "$dir" <<'PY'
import sys, numpy as np
d = sys.argv[1]
for n, dtype, scale in ((256, np.float32, 1.0), (512, np.uint16, 1000.0)):
    c = (np.arange(n) + 0.5) * (2.0 / n) - 1.0
    out = np.memmap(f"{d}/sphere{n}.raw", dtype=dtype, mode="w+", shape=(n, n, n))
    y, x = np.meshgrid(c, c, indexing="ij")
    for z in range(n):
        r = np.sqrt(x * x + y * y + c[z] * c[z])
        out[z] = ((0.8 - r) * scale if dtype == np.float32 else np.clip((1.6 - r) * scale, 0, 65535)).astype(dtype)
    out.flush()
PY
cargo build --quiet --release -p sc-cli
for spec in "256 f32 0 4" "512 u16 800 2"; do
  set -- $spec
  for threads in 1 2; do
    /usr/bin/time -f "sphere $1³ $2, $threads thread(s): peak RSS %M KiB, input $(( $1 * $1 * $1 * $4 / 1024 )) KiB" \
      ./target/release/skelclimb extract "$dir/sphere$1.raw" --dims "$1,$1,$1" --dtype "$2" --iso "$3" \
      --threads "$threads" -q -o "$dir/out.ply"
  done
done
