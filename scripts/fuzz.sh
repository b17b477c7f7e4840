#!/usr/bin/env bash
# libFuzzer over the mesh readers: one target per format (PLY, OFF, STL, OBJ, GLB), built with
# Debian's clang (-fsanitize=fuzzer,address,undefined; UB aborts), each run for SECONDS
# (default 600) from the seeds in tests/fuzz/corpus/<format>/ with tests/fuzz/<format>.dict.
# A crash, sanitizer report, timeout (> 5 s on one input) or single allocation over 64 MB
# fails the run; the input is kept in $OUT/<format>/ (crash-*, timeout-*, oom-*) and the
# script exits non-zero. Every finding must become a regression test in
# tests/unit/preprocess/mesh_reader_hostile_test.cpp.
#
#   scripts/fuzz.sh [SECONDS] [FORMAT...]      e.g. scripts/fuzz.sh 20   or  scripts/fuzz.sh 180 ply
# Env: LOD_FUZZ_BUILD (default build-fuzz), LOD_FUZZ_JOBS (parallel targets; default nproc),
#      LOD_FUZZ_MAX_LEN (default 4096 bytes).
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH=${1:-600}
shift || true
FORMATS=("$@")
[ ${#FORMATS[@]} -gt 0 ] || FORMATS=(ply off stl obj glb)
OUT=${LOD_FUZZ_BUILD:-build-fuzz}
JOBS=${LOD_FUZZ_JOBS:-$(nproc)}
MAX_LEN=${LOD_FUZZ_MAX_LEN:-4096}
CXX=${LOD_FUZZ_CXX:-clang++}
command -v "$CXX" >/dev/null || { echo "[fuzz] $CXX not found (apt-get install clang libclang-rt-14-dev)" >&2; exit 1; }
mkdir -p "$OUT/obj"

# ---- build (objects shared by the targets; rebuilt when a source or header is newer) ----
FLAGS=(-std=c++20 -g -O1 -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all
       -I. -D_USE_MATH_DEFINES)
SOURCES=(preprocess/mesh_io.cpp preprocess/ply_reader.cpp preprocess/off_reader.cpp preprocess/stl_reader.cpp
         preprocess/obj_reader.cpp preprocess/gltf_io.cpp)  # gltf_io.cpp compiles tinygltf in (instrumented too)
HEADERS=(preprocess/mesh_io.h preprocess/mesh_readers.h preprocess/mesh.h preprocess/gltf_io.h runtime/status.h)
newest_header=$(ls -t "${HEADERS[@]}" | head -1)
objs=()
pids=()
for src in "${SOURCES[@]}"; do
  o="$OUT/obj/$(basename "$src" .cpp).o"
  objs+=("$o")
  if [ ! -f "$o" ] || [ "$src" -nt "$o" ] || [ "$newest_header" -nt "$o" ]; then
    "$CXX" "${FLAGS[@]}" -fsanitize=fuzzer-no-link -c "$src" -o "$o" & pids+=($!)
  fi
done
for p in "${pids[@]}"; do wait "$p"; done
for fmt in "${FORMATS[@]}"; do
  bin="$OUT/fuzz_$fmt"
  if [ ! -x "$bin" ] || [ tests/fuzz/mesh_fuzz.cpp -nt "$bin" ] || [ -n "$(find "${objs[@]}" -newer "$bin")" ]; then
    "$CXX" "${FLAGS[@]}" -fsanitize=fuzzer "-DLOD_FUZZ_EXT=\".$fmt\"" tests/fuzz/mesh_fuzz.cpp "${objs[@]}" -o "$bin"
  fi
done
echo "[fuzz] built ${FORMATS[*]} in $OUT/; ${SECONDS_EACH} s per target, $JOBS at a time"

# ---- run ---------------------------------------------------------------------------------
run_one() {  # runs in a background subshell; reports by its exit status
  set +e +o pipefail
  local fmt=$1 dir="$OUT/$1"
  mkdir -p "$dir/corpus"
  rm -f "$dir"/crash-* "$dir"/timeout-* "$dir"/oom-* "$dir"/leak-*
  local rc=0
  # -malloc_limit_mb=64: the figure "every file under 1 KB loads in < 64 MB" (inputs here are
  # up to MAX_LEN bytes, so this is stricter); -timeout=5: a hang is a finding.
  ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=0" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
    "$OUT/fuzz_$fmt" -max_total_time="$SECONDS_EACH" -timeout=5 -malloc_limit_mb=64 -rss_limit_mb=1024 \
      -max_len="$MAX_LEN" -dict="tests/fuzz/$fmt.dict" -artifact_prefix="$dir/" -print_final_stats=1 \
      "$dir/corpus" "tests/fuzz/corpus/$fmt" >"$dir/log.txt" 2>&1 || rc=$?
  local execs rate cov
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$dir/log.txt" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$dir/log.txt" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$dir/log.txt" | tail -1 | cut -d' ' -f2)
  local found
  found=$(ls "$dir"/crash-* "$dir"/timeout-* "$dir"/oom-* "$dir"/leak-* 2>/dev/null | wc -l)
  echo "[fuzz] $fmt: ${execs:-0} executions (${rate:-0}/s), coverage ${cov:-?} edges, corpus $(ls "$dir/corpus" | wc -l) files, findings $found, exit $rc"
  if [ "$rc" -ne 0 ] || [ "$found" -ne 0 ]; then
    echo "[fuzz] $fmt FAILED; last lines of $dir/log.txt:" >&2
    grep -E "ERROR|SUMMARY|runtime error|Test unit written|timeout|out-of-memory" "$dir/log.txt" | head -20 >&2
    return 1
  fi
}
failed=0
running=0
declare -A pid_of
for fmt in "${FORMATS[@]}"; do
  run_one "$fmt" & pid_of[$fmt]=$!
  running=$((running + 1))
  if [ "$running" -ge "$JOBS" ]; then
    wait -n || failed=1
    running=$((running - 1))
  fi
done
while [ "$running" -gt 0 ]; do
  wait -n || failed=1
  running=$((running - 1))
done
if [ "$failed" -ne 0 ]; then
  echo "[fuzz] FAILED: findings above (inputs kept in $OUT/<format>/)" >&2
  exit 1
fi
echo "[fuzz] all ${#FORMATS[@]} targets clean"
