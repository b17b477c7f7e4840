#!/usr/bin/env bash
# The whole test suite on a fresh Debian 12 machine: packages, a Release build with every
# test and benchmark, ctest; then ThreadSanitizer on the threaded code and
# AddressSanitizer + UBSan on the rest. Tests that need ../shared skip with a message.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
JOBS=$(nproc)

echo "== Release build + ctest =="
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$JOBS"
ctest --test-dir build --output-on-failure -j "$JOBS" --timeout 900

echo "== ThreadSanitizer: frame hand-off, service, frame graph =="
cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLOD_SANITIZE=thread \
      -DLOD_BUILD_BENCH=OFF -DLOD_BUILD_VIEWER=OFF
cmake --build build-tsan -j "$JOBS" --target test_jobs
TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" \
  ctest --test-dir build-tsan --output-on-failure -j "$JOBS" --timeout 900 -R '^(FrameHandoff|Service|FrameGraph|FrameGraphVd|FrameGeomorph)\.'

echo "== AddressSanitizer + UBSan: runtime, preprocess, jobs, integration =="
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLOD_SANITIZE=address \
      -DLOD_BUILD_BENCH=OFF -DLOD_BUILD_VIEWER=OFF
cmake --build build-asan -j "$JOBS" --target test_runtime test_preprocess test_jobs test_integration
ASAN_OPTIONS="detect_leaks=1" UBSAN_OPTIONS="print_stacktrace=1" \
  ctest --test-dir build-asan --output-on-failure -j "$JOBS" --timeout 900 -L 'unit|integration'
echo "== all tests passed =="
