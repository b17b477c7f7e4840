#!/usr/bin/env bash
# soak.sh [SECONDS]: the soak test (tests/stress/soak_test.cpp) for SECONDS (default 600) on the
# Release build: 100,000 objects moving and churning, a circling camera, two consumers; prints
# resident memory as it goes and fails on growth >= 1 % after warm-up, a torn or lost frame.
# The test suite runs the same test for 20 s (and 15 s under ThreadSanitizer).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/configure.sh build >/dev/null
cmake --build build --target test_stress
LOD_SOAK_SECONDS=${1:-600} build/tests/test_stress --gtest_filter='Soak.*'
