#!/usr/bin/env bash
# The whole test suite on a fresh Debian 12 machine: packages, a Release build with every
# test and benchmark, ctest; then ThreadSanitizer on the threaded code and
# AddressSanitizer + UBSan on the rest. Tests that need ../shared skip with a message.
# Every stage sets its cache options itself (scripts/configure.sh), refuses an empty run and
# fails unless it ran every test it lists (scripts/ctest-all.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/install-node-tools.sh  # the glTF validator the export tests run
# The real elevation data of configs/terrain.toml (one file from Debian's libdeal.ii-doc);
# without it (no network) the terrain config's tests skip, saying so.
./scripts/fetch-topography.sh build/data || echo "[topography] not fetched: configs/terrain.toml cannot run" >&2
JOBS=$(nproc)

echo "== Release build + ctest =="
./scripts/configure.sh build
cmake --build build -j "$JOBS"
# Each layer's binary must have registered its tests: a build that lost one fails here.
for label in unit integration stress viewer package; do
  n=$(ctest --test-dir build -N -L "^$label\$" | sed -n 's/^Total Tests: *//p')
  echo "[ctest] build: label $label lists ${n:-0} tests"
  [ "${n:-0}" -gt 0 ] || { echo "[ctest] build: no $label tests registered" >&2; exit 1; }
done
./scripts/ctest-all.sh build -j "$JOBS" --timeout 900

echo "== ThreadSanitizer: frame pool, service (simulation + consumers), frame graph, stream pager, bake loops, distributed bakes (ranks as threads), writers taking turns =="
./scripts/configure.sh build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLOD_SANITIZE=thread \
      -DLOD_BUILD_BENCH=OFF -DLOD_BUILD_VIEWER=OFF
cmake --build build-tsan -j "$JOBS" --target test_jobs test_stress test_runtime
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" LOD_SOAK_SECONDS=${LOD_TSAN_SOAK_SECONDS:-15} \
  ./scripts/ctest-all.sh build-tsan -j "$JOBS" --timeout 900 -R '^(FramePool|Service|ServiceObjects|ServiceThreads|FrameGraph|FrameGraphVd|FrameGraphTerrain|FrameGeomorph|StreamPager|HlodStream|Soak|TsanProbe|BakeJobs|BakeJobsCulledLevel|FrameGraphHlod|HlodDistributedBake|HlodModelsDistributedBake|HostTurn)\.'

echo "== AddressSanitizer + UBSan: runtime, preprocess, jobs, integration =="
./scripts/configure.sh build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLOD_SANITIZE=address \
      -DLOD_BUILD_BENCH=OFF -DLOD_BUILD_VIEWER=OFF
cmake --build build-asan -j "$JOBS" --target test_runtime test_preprocess test_jobs test_c_api test_integration
ASAN_OPTIONS="detect_leaks=1" UBSAN_OPTIONS="print_stacktrace=1" \
  ./scripts/ctest-all.sh build-asan -j "$JOBS" --timeout 900 -L 'unit|integration'
# ---- fuzzing (mesh readers, .lod assets, scene configs): each libFuzzer target for a bounded time; a crash, sanitizer
# report, hang or > 64 MB allocation fails the suite (scripts/fuzz.sh SECONDS runs longer).
echo "== libFuzzer + ASan/UBSan: every reader, ${LOD_FUZZ_SECONDS:-20} s per target =="
./scripts/fuzz.sh "${LOD_FUZZ_SECONDS:-20}"
echo "== all tests passed =="
