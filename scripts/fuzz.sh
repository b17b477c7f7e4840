#!/usr/bin/env bash
# libFuzzer over every reader: one target per mesh format (PLY, OFF, STL, OBJ, GLB), the .lod asset
# reader (`lod`, with a mutator that keeps the checksum valid), the .hlod reader (`hlod`, the
# same for its head and payload checksums), the distributed bake's subtree cache entry (`hsub`,
# the full, root-only and payload-span readers, checksums kept valid likewise), the HLOD bake's
# cleaned-mesh cache entry (`hmesh`: positions, indices, uvs, submeshes, materials, images; its
# mutator keeps the checksum valid and resizes one section at a time), the scene config
# reader (`scene`) and the height-field readers (`heightmap`: PNG through stb, ESRI ASCII grid
# through GDAL, "x y z" text; the first input byte picks one), and the service itself (`service`:
# byte-derived operation sequences through the C API only, checking every frame's invariants; built by CMake
# with LOD_SANITIZE=fuzzer in $OUT/service-build, since it links the whole library), built with Debian's clang
# (-fsanitize=fuzzer,address,undefined; UB aborts), each
# run for SECONDS (default 600) from the seeds in tests/fuzz/corpus/<target>/ with
# tests/fuzz/<target>.dict. A target without a corpus folder there (hmesh) writes its own seeds
# through the real writer first (its binary run with LOD_FUZZ_WRITE_SEEDS=$OUT/<target>/seeds), so
# they follow the format's version. A crash, sanitizer report, timeout (> 5 s on one input) or single
# allocation over 64 MB fails the run; the input is kept in $OUT/<target>/ (crash-*, timeout-*,
# oom-*) and the script exits non-zero. Every finding must become a regression test
# (tests/unit/preprocess/mesh_reader_hostile_test.cpp, tests/unit/runtime/lod_asset_test.cpp,
# tests/unit/jobs/scene_config_test.cpp, tests/unit/jobs/hlod_mesh_cache_test.cpp).
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]      e.g. scripts/fuzz.sh 20   or  scripts/fuzz.sh 180 ply lod
# Env: LOD_FUZZ_BUILD (default build-fuzz), LOD_FUZZ_JOBS (parallel targets; default nproc),
#      LOD_FUZZ_MAX_LEN (default 4096 bytes; 16384 for lod and hmesh and 32768 for hlod and hsub, whose seeds are larger),
#      LOD_FUZZ_TIMEOUT (seconds per input, default 5; more on a loaded or niced run).
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH=${1:-600}
shift || true
TARGETS=("$@")
[ ${#TARGETS[@]} -gt 0 ] || TARGETS=(ply off stl obj glb lod hlod hsub hmesh scene heightmap service)
OUT=${LOD_FUZZ_BUILD:-build-fuzz}
JOBS=${LOD_FUZZ_JOBS:-$(nproc)}
CXX=${LOD_FUZZ_CXX:-clang++}
command -v "$CXX" >/dev/null || { echo "[fuzz] $CXX not found (apt-get install clang libclang-rt-14-dev)" >&2; exit 1; }
mkdir -p "$OUT/obj"

# ---- build (objects shared by the targets; rebuilt when a source or header is newer) ----
FLAGS=(-std=c++20 -g -O1 -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all
       -I. -Iinclude -I/usr/include/gdal -I/usr/include/stb -D_USE_MATH_DEFINES -DGLM_FORCE_XYZW_ONLY '-DLOD_DEFAULT_DATA_DIR="/nonexistent"')
MESH_SOURCES=(preprocess/mesh_io.cpp preprocess/ply_reader.cpp preprocess/off_reader.cpp preprocess/stl_reader.cpp
              preprocess/obj_reader.cpp preprocess/mtl_reader.cpp runtime/texture_uri.cpp preprocess/gltf_io.cpp
              runtime/file_write.cpp runtime/host_turn.cpp runtime/embedded_image.cpp runtime/regular_file.cpp
              preprocess/plain_ply_file.cpp runtime/bytes_hasher.cpp preprocess/mesh_clean.cpp preprocess/material_runs.cpp
              preprocess/first_of_equal.cpp preprocess/cluster_simplifier.cpp
              preprocess/qem_simplifier.cpp preprocess/position_copies.cpp)  # gltf_io compiles tinygltf in;
# mesh_clean for the clean's checks, material_runs for it, and the simplifiers material_runs calls
LOD_SOURCES=(runtime/lod_asset.cpp runtime/bytes_hasher.cpp runtime/lod_chain.cpp runtime/embedded_image.cpp runtime/vertex_tree.cpp
             runtime/vertex_front.cpp runtime/file_write.cpp runtime/host_turn.cpp runtime/model_table.cpp runtime/view.cpp
             runtime/regular_file.cpp)
HLOD_SOURCES=(runtime/hlod_asset.cpp runtime/hlod_cut_check.cpp runtime/hlod_select.cpp runtime/lod_asset.cpp runtime/bytes_hasher.cpp
              runtime/lod_chain.cpp runtime/embedded_image.cpp runtime/vertex_tree.cpp runtime/file_write.cpp runtime/host_turn.cpp
              runtime/model_table.cpp runtime/view.cpp runtime/world_bounds.cpp runtime/regular_file.cpp)
HMESH_SOURCES=(jobs/hlod_mesh_cache.cpp "${LOD_SOURCES[@]}")
HEIGHTMAP_SOURCES=(preprocess/height_field_io.cpp preprocess/height_field_png.cpp preprocess/height_field_raster.cpp preprocess/ascii_grid_header.cpp
                   runtime/height_field.cpp runtime/regular_file.cpp runtime/bytes_hasher.cpp)  # GDAL itself is Debian's, uninstrumented
SCENE_SOURCES=(jobs/scene_config.cpp runtime/roam.cpp runtime/height_field.cpp runtime/view.cpp runtime/regular_file.cpp runtime/bytes_hasher.cpp)  # [[terrain]] checks grid sizes
# The scene reader links Debian's toml++ library as lodkit does (its header-only mode has debug
# asserts that the shipped, NDEBUG library does not: "[[[a]]" asserts there, is refused here).
SCENE_FLAGS=(-DTOML_HEADER_ONLY=0 -DTOML_SHARED_LIB=1)
newest_header=$(ls -t preprocess/*.h runtime/*.h jobs/scene_config.h jobs/hlod_mesh_cache.h jobs/hlod_subtree_cache.h \
                 include/lodkit/*.hpp | head -1)
declare -A built=()
pids=()
object_of() { echo "$OUT/obj/$(echo "$1" | tr / _ | sed 's/\.cpp$/.o/')"; }
compile() {  # compiles each source once per run, in the background
  for src in "$@"; do
    local o
    o=$(object_of "$src")
    [ -n "${built[$o]:-}" ] && continue
    built[$o]=1
    if [ ! -f "$o" ] || [ "$src" -nt "$o" ] || [ "$newest_header" -nt "$o" ]; then
      local own=()
      [[ " ${SCENE_SOURCES[*]} tests/fuzz/scene_fuzz.cpp " == *" $src "* ]] && own=("${SCENE_FLAGS[@]}")
      "$CXX" "${FLAGS[@]}" "${own[@]}" -fsanitize=fuzzer-no-link -c "$src" -o "$o" & pids+=($!)
    fi
  done
}
sources_of() {
  case $1 in
    lod) echo "${LOD_SOURCES[@]}" ;;
    hlod) echo "${HLOD_SOURCES[@]}" ;;
    hsub) echo "${HLOD_SOURCES[@]} runtime/hlod_subtree_entry.cpp" ;;
    hmesh) echo "${HMESH_SOURCES[@]}" ;;
    scene) echo "${SCENE_SOURCES[@]}" ;;
    heightmap) echo "${HEIGHTMAP_SOURCES[@]}" ;;
    service) ;;  # built by CMake below
    *) echo "${MESH_SOURCES[@]}" ;;
  esac
}
for t in "${TARGETS[@]}"; do
  case $t in ply|off|stl|obj|glb|lod|hlod|hsub|hmesh|scene|heightmap|service) ;; *) echo "[fuzz] unknown target '$t' (ply off stl obj glb lod hlod hsub hmesh scene heightmap service)" >&2; exit 2 ;; esac
  # shellcheck disable=SC2046
  compile $(sources_of "$t")
done
for p in "${pids[@]}"; do wait "$p"; done
for t in "${TARGETS[@]}"; do
  bin="$OUT/fuzz_$t"
  if [ "$t" = service ]; then  # the whole library instrumented: CMake builds it, ccache keeps rebuilds short
    CC_BIN=${LOD_FUZZ_CC:-clang}
    ./scripts/configure.sh "$OUT/service-build" -DCMAKE_CXX_COMPILER="$CXX" -DCMAKE_C_COMPILER="$CC_BIN" \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo -DLOD_SANITIZE=fuzzer -DLOD_BUILD_BENCH=OFF -DLOD_BUILD_VIEWER=OFF \
      -DLOD_BUILD_CLI=OFF -DLOD_BUILD_EXAMPLES=OFF -DLOD_INSTALL=OFF >"$OUT/service-build.log" 2>&1 &&
      cmake --build "$OUT/service-build" -j "$(nproc)" --target fuzz_service >>"$OUT/service-build.log" 2>&1 ||
      { echo "[fuzz] service: build failed; see $OUT/service-build.log" >&2; tail -20 "$OUT/service-build.log" >&2; exit 1; }
    cp "$OUT/service-build/tests/fuzz_service" "$bin"
    continue
  fi
  objs=()
  for src in $(sources_of "$t"); do objs+=("$(object_of "$src")"); done
  case $t in
    lod) main=tests/fuzz/asset_fuzz.cpp; extra=() ;;
    hlod) main=tests/fuzz/hlod_fuzz.cpp; extra=() ;;
    hsub) main=tests/fuzz/hsub_fuzz.cpp; extra=() ;;
    hmesh) main=tests/fuzz/hmesh_fuzz.cpp; extra=() ;;
    scene) main=tests/fuzz/scene_fuzz.cpp; extra=("${SCENE_FLAGS[@]}" -ltomlplusplus) ;;
    heightmap) main=tests/fuzz/height_field_fuzz.cpp; extra=(-lgdal) ;;
    *) main=tests/fuzz/mesh_fuzz.cpp; extra=("-DLOD_FUZZ_EXT=\".$t\"") ;;
  esac
  if [ ! -x "$bin" ] || [ "$main" -nt "$bin" ] || [ -n "$(find "${objs[@]}" -newer "$bin")" ]; then
    libs=(); defs=()
    for e in "${extra[@]}"; do case $e in -l*) libs+=("$e") ;; *) defs+=("$e") ;; esac; done
    "$CXX" "${FLAGS[@]}" -fsanitize=fuzzer "${defs[@]}" "$main" "${objs[@]}" "${libs[@]}" -o "$bin"
  fi
done
echo "[fuzz] built ${TARGETS[*]} in $OUT/; ${SECONDS_EACH} s per target, $JOBS at a time"

# ---- run ---------------------------------------------------------------------------------
run_one() {  # runs in a background subshell; reports by its exit status
  set +e +o pipefail
  local fmt=$1 dir="$OUT/$1"
  local max_len=${LOD_FUZZ_MAX_LEN:-4096}
  [ "$fmt" = lod ] && max_len=${LOD_FUZZ_MAX_LEN:-16384}
  [ "$fmt" = hmesh ] && max_len=${LOD_FUZZ_MAX_LEN:-16384}
  [ "$fmt" = hlod ] && max_len=${LOD_FUZZ_MAX_LEN:-32768}
  [ "$fmt" = hsub ] && max_len=${LOD_FUZZ_MAX_LEN:-32768}
  mkdir -p "$dir/corpus"
  rm -f "$dir"/crash-* "$dir"/timeout-* "$dir"/oom-* "$dir"/leak-*
  local rc=0 seeds="tests/fuzz/corpus/$fmt"
  if [ ! -d "$seeds" ]; then  # seeds made by the target through the real writer, of the current version
    seeds="$dir/seeds"
    rm -rf "$seeds"
    if ! LOD_FUZZ_WRITE_SEEDS="$seeds" "$OUT/fuzz_$fmt" >"$dir/seeds.log" 2>&1; then
      echo "[fuzz] $fmt FAILED: writing its seeds:" >&2
      tail -20 "$dir/seeds.log" >&2
      return 1
    fi
  fi
  # -malloc_limit_mb=64: the figure "every file under 1 KB loads in < 64 MB" (inputs here are
  # up to MAX_LEN bytes, so this is stricter); -timeout=5: a hang is a finding.
  ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=0" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
    "$OUT/fuzz_$fmt" -max_total_time="$SECONDS_EACH" -timeout="${LOD_FUZZ_TIMEOUT:-5}" -malloc_limit_mb=64 -rss_limit_mb=1024 \
      -max_len="$max_len" -dict="tests/fuzz/$fmt.dict" -artifact_prefix="$dir/" -print_final_stats=1 \
      "$dir/corpus" "$seeds" >"$dir/log.txt" 2>&1 || rc=$?
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
for fmt in "${TARGETS[@]}"; do
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
echo "[fuzz] all ${#TARGETS[@]} targets clean"
