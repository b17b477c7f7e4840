#!/usr/bin/env bash
# make-dragon-14m.sh [BUILD_DIR]: BUILD_DIR/bench-data/dragon-14m.ply, the 871k Stanford dragon
# (../shared/data/meshes) subdivided twice (13.9M triangles, 265 MB), the mesh of the distributed bake's
# figures: scripts/hlod-mpi-figures.sh BUILD_DIR/bench-data/dragon-14m.ply BUILD_DIR
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
src=../shared/data/meshes/stanford-dragon.ply
[ -f "$src" ] || { echo "[dragon-14m] $src is absent on this machine" >&2; exit 1; }
mkdir -p "$build/bench-data"
g++ -O2 -std=c++20 scripts/tools/subdivide_ply.cpp -o "$build/bench-data/subdivide-ply"
"$build/bench-data/subdivide-ply" "$src" "$build/bench-data/dragon-14m.ply"
