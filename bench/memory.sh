#!/usr/bin/env bash
# Peak resident memory of `skelclimb extract` on large volumes written here: a 256³ f32 and a
# 512³ u16 sphere (64 MiB and 256 MiB of samples) read whole (the first in adaptive mode too,
# about 10 s), and a 1600 × 1600 × 1000 u8 ball (2.4 GiB) read slice by slice with --stream.
# Needs python3 with numpy, GNU time, and 2.5 GB of free space in $TMPDIR.
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
# 2.4 GiB of u8: a ball of radius 0.6 (in [-1, 1]) centred in a 1600 × 1600 × 1000 box.
nx, nz = 1600, 1000
out = np.memmap(f"{d}/ball.raw", dtype=np.uint8, mode="w+", shape=(nz, nx, nx))
c = (np.arange(nx) + 0.5) * (2.0 / nx) - 1.0
y, x = np.meshgrid(c, c, indexing="ij")
r2 = (x * x + y * y).astype(np.float32)
for z in range(nz):
    cz = (z + 0.5) * (2.0 / nz) - 1.0
    out[z] = np.clip(128 + 200 * (0.6 - np.sqrt(r2 + cz * cz)), 0, 255).astype(np.uint8)
out.flush()
del out
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
# Adaptive mode against embedded mode's figure above (docs/adaptive.md asks at most 1.5×).
/usr/bin/time -f "sphere 256³ f32, adaptive mode, 1 thread: peak RSS %M KiB, %e s" \
  ./target/release/skelclimb extract "$dir/sphere256.raw" --dims 256,256,256 --dtype f32 --iso 0 \
  --mode adaptive --threads 1 -q -o "$dir/out.ply"
/usr/bin/time -f "ball 1600×1600×1000 u8 (--stream): peak RSS %M KiB, input $(( 1600 * 1600 * 1000 / 1024 )) KiB, %e s" \
  ./target/release/skelclimb extract "$dir/ball.raw" --dims 1600,1600,1000 --dtype u8 --iso 128 \
  --stream --no-normals -q -o "$dir/out.ply"
