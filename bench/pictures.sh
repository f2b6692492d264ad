#!/usr/bin/env bash
# The README's pictures, made with `skelclimb render`: the knot and a real MRI, Steps 1–3 beside
# Steps 1–4 with their edges (as the paper's Fig. 11), the MRI's surface coloured by its
# distance to Steps 1–3, and a piece of the MNI template in adaptive mode beside embedded mode.
# Usage: bench/pictures.sh [DATA_DIR] (default ../shared/data).
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-../shared/data}
cargo build --quiet --release -p sc-cli
sc=./target/release/skelclimb
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
$sc extract --demo knot -q -o "$tmp/knot.ply"
$sc extract --demo knot --mode steps123 -q -o "$tmp/knot13.ply"
$sc render "$tmp/knot.ply" --compare "$tmp/knot13.ply" --wireframe --size 640x480 -o docs/knot-compare.png
brain="$data/brainsmall-mri/brainsmall-mri.raw"
$sc extract "$brain" --iso 20 --pad -q -o "$tmp/brain.ply"
$sc extract "$brain" --iso 20 --pad --mode steps123 -q -o "$tmp/brain13.ply"
# The edges are legible on a small piece of a scan: the T1 MRI crop of the test data.
crop=tests/data/itk-t1-crop-40x40x30.i16.raw
$sc extract "$crop" --iso 20 --pad -q -o "$tmp/crop.ply"
$sc extract "$crop" --iso 20 --pad --mode steps123 -q -o "$tmp/crop13.ply"
$sc render "$tmp/crop.ply" --compare "$tmp/crop13.ply" --wireframe --azimuth 30 --elevation 35 --size 640x560 -o docs/mri-crop-compare.png
$sc render "$tmp/brain.ply" --color-by-error "$tmp/brain13.ply" --view front --smooth --size 640x560 -o docs/brain-error.png
# Adaptive mode beside embedded mode at adaptive mode's default bound (half a voxel), on a
# 60×60×50 piece of the smooth MNI template (x 30..90, y 40..100, z 120..170), where the edges
# are legible.
python3 - "$data/mni152-mri/mni152-mri.raw" "$tmp/mni.raw" <<'PY'
import sys
nx, ny = 197, 233
src = open(sys.argv[1], "rb").read()
with open(sys.argv[2], "wb") as out:
    for z in range(120, 170):
        for y in range(40, 100):
            row = (z * ny + y) * nx
            out.write(src[row + 30:row + 90])
PY
mni=("$tmp/mni.raw" --dims 60,60,50 --dtype u8 --iso 80.5 --pad -q)
$sc extract "${mni[@]}" -o "$tmp/mni.ply"
$sc extract "${mni[@]}" --mode adaptive -o "$tmp/mni-adaptive.ply"
$sc render "$tmp/mni.ply" --compare "$tmp/mni-adaptive.ply" --wireframe --azimuth 30 --elevation 35 --size 640x560 -o docs/mni-adaptive.png
