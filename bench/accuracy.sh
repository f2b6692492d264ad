#!/usr/bin/env bash
# Builds a venv in target/accuracy-venv (once; the skelclimb wheel is rebuilt every run, ~2 min),
# then runs bench/accuracy.py with the arguments given, e.g.
#   SC_DATA_DIR=../shared/data bench/accuracy.sh [--quick] [--out-md F] [--out-json F]
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/accuracy-venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/pip" install --quiet --upgrade pip
"$venv/bin/pip" install --quiet numpy scipy vtk scikit-image fast-simplification trimesh
"$venv/bin/pip" install --quiet --force-reinstall --no-deps ./sc-python
exec "$venv/bin/python" bench/accuracy.py "$@"
