#!/usr/bin/env bash
# The main job on a fresh Debian 12 machine: packages, Release build, then
# `lod run` on configs/default.toml with a JSON log, CSV and plot in build/report/.
# Extra arguments go to `lod run` (e.g. --frames 30).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
# The real elevation data of configs/terrain.toml (one file from Debian's libdeal.ii-doc);
# without it (no network) the terrain config's tests skip, saying so.
./scripts/fetch-topography.sh build/data || echo "[topography] not fetched: configs/terrain.toml cannot run" >&2
# The same cache options as the test command (scripts/configure.sh), so either order works
# on one build/ folder; only the lod target is built here.
./scripts/configure.sh build
cmake --build build --target lod
mkdir -p build/report
./build/lod run --config configs/default.toml --json build/report/run.json --report build/report "$@"
