#!/usr/bin/env bash
# The main job on a fresh Debian 12 machine: packages, Release build, then
# `lod run` on configs/default.toml with a JSON log, CSV and plot in build/report/.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DLOD_BUILD_TESTS=OFF -DLOD_BUILD_BENCH=OFF
cmake --build build --target lod
mkdir -p build/report
./build/lod run --config configs/default.toml --json build/report/run.json --report build/report "$@"
