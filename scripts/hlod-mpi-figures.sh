#!/usr/bin/env bash
# hlod-mpi-figures.sh MESH [BUILD_DIR]: the distributed bake's figures for one mesh.
#   - lod bake --hlod (the local reference bytes, 1 thread)
#   - lod-bake-mpi at 1, 2 and 4 ranks x 1 thread, each from an empty cache: wall time, per-rank
#     bake CPU seconds (balance = slowest / mean; and of each rank's whole CPU up to the gather, as
#     a rank that loads the mesh for its node bakes less), bytes identical to the local bake
#   - 2 ranks killed at <= 50 % (each dies once it has stored a quarter of the subtrees; the first
#     to die ends the job), then the rerun: its time against the full 2-rank build
#   - per rank, CPU seconds per phase, the process's kernel CPU and peak RSS; critical_cpu_s (the
#     job on idle cores) for the ratios
#   - PAIRS=K (default 0): K more 1-rank / 2-rank runs, alternating (1 2, 2 1, 1 2, ...), each
#     from an empty cache, and the median of their ratios: on a shared VM one pair's ratio moves
#     by +-10 %, and a run right after another one finds the memory that one freed
# Output: one JSON summary per run in $OUT (default /tmp/hlod-mpi-figures), a table on stdout;
# the runs' files and caches (GBs on a 14M-triangle mesh) are removed at the end unless KEEP=1.
set -euo pipefail
export NPS=${NPS:-1 2 4}
mesh=$1
build=${2:-$(cd "$(dirname "$0")/.." && pwd)/build}
out=${OUT:-/tmp/hlod-mpi-figures}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mpi=(mpirun --oversubscribe --mca btl self,vader,tcp --mca btl_tcp_if_include lo --mca oob_tcp_if_include lo)
name=$(basename "${mesh%.*}")
rm -rf "$out" && mkdir -p "$out"
now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.3f", b - a }'; }  # JSON needs the 0 of 0.5
# bake NP RUN OUT CACHE: one lod-bake-mpi job at NP ranks x 1 thread; $out/RUN.{json,err,wall}
bake() {
  local t0 t1
  t0=$(now)
  "${mpi[@]}" -np "$1" "$build/lod-bake-mpi" "$mesh" -o "$3" --cache "$4" --threads 1 --json \
    > "$out/$2.json" 2> "$out/$2.err"
  t1=$(now)
  echo "{\"wall_s\": $(since "$t0" "$t1")}" > "$out/$2.wall"
}

t0=$(now); "$build/lod" bake "$mesh" -o "$out/local" --hlod --threads 1 --quiet; t1=$(now)
echo "local  1 thread : $(since "$t0" "$t1") s"
for np in ${NPS:-1 2 4}; do
  bake $np np$np "$out/np$np" "$out/cache$np"
  cmp -s "$out/local/$name.hlod" "$out/np$np/$name.hlod" && same=identical || same=DIFFERENT
  echo "mpi np=$np x 1 thread: $(cat "$out/np$np.wall") bytes $same"
done

total=$(python3 -c "import json; print(json.load(open('$out/np2.json'))['subtrees'])")
quarter=$((total / 4))
t0=$(now)
LOD_MPI_FAIL_AFTER=$quarter LOD_MPI_FAIL_RANK=-1 "${mpi[@]}" -np 2 "$build/lod-bake-mpi-faults" "$mesh" -o "$out/resume" \
  --cache "$out/cache-resume" --threads 1 --quiet > /dev/null 2> "$out/killed.err" || true
t1=$(now)
kept=$(ls "$out/cache-resume" | grep -c '\.hsub$' || true)
echo "killed run: $(since "$t0" "$t1") s, $kept of $total subtrees kept"
bake 2 rerun "$out/resume" "$out/cache-resume"
cmp -s "$out/local/$name.hlod" "$out/resume/$name.hlod" && same=identical || same=DIFFERENT
echo "rerun: $(cat "$out/rerun.wall") bytes $same"

NPS="${NPS:-1 2 4}" python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
def load(n): return json.load(open(f"{out}/{n}.json")), json.load(open(f"{out}/{n}.wall"))["wall_s"]
import os
runs = {int(np): load(f"np{np}") for np in os.environ.get("NPS", "1 2 4").split()}
for np, (j, wall) in runs.items():
    cpu = [w["bake_cpu_s"] for w in j["per_rank"]]
    whole = [w["cpu_until_report_s"] for w in j["per_rank"]]  # load, clean, plan and check too
    print(f"np={np}: wall {wall:.2f} s, job {j['total_s']:.2f} s (load {j['load_s']:.2f}, plan {j['plan_s']:.2f}, "
          f"bake {j['bake_s']:.2f}, assemble {j['assemble_s']:.2f}, write {j['write_s']:.2f}), subtrees {j['subtrees']}, "
          f"bake cpu per rank {[round(c, 2) for c in cpu]}, balance {max(cpu) / (sum(cpu) / len(cpu)):.3f} "
          f"(whole work up to the gather {max(whole) / (sum(whole) / len(whole)):.3f}), "
          f"entries read {j['entry_bytes_read'] / 1e6:.1f} MB, file {j['bytes'] / 1e6:.1f} MB")
    for r, w in enumerate(j["per_rank"]):  # CPU seconds per phase (bvh is part of bake)
        print(f"  rank {r} CPU s: " + ", ".join(f"{k} {v:.2f}" for k, v in w["cpu_s"].items()) +
              f"; process: kernel {w['kernel_cpu_s']:.2f} s, peak RSS {w['peak_rss_mb']:.0f} MB")
    print("  rank 0 serial CPU s: " + ", ".join(f"{k} {v:.2f}" for k, v in j["rank0_cpu_s"].items()))
w1, w2 = runs[1][1], runs[2][1]
c = {np: runs[np][0]["critical_cpu_s"] for np in runs}
print("critical-path CPU s: " + ", ".join(f"{v:.2f} at {np}" for np, v in c.items()))
print(f"speed-up 2 ranks x 1 thread vs 1 x 1: wall {w1 / w2:.2f}x, job {runs[1][0]['total_s'] / runs[2][0]['total_s']:.2f}x, "
      f"critical-path CPU {c[1] / c[2]:.2f}x")
r, rw = load("rerun")
print(f"resume: rerun {rw:.2f} s wall = {rw / w2:.0%} of the full 2-rank build; critical-path CPU "
      f"{r['critical_cpu_s']:.2f} s = {r['critical_cpu_s'] / c[2]:.0%} ({r['cached']} of {r['subtrees']} cached)")
PY

pairs=${PAIRS:-0}
for k in $(seq 1 "$pairs"); do
  order="1 2"
  [ $((k % 2)) = 0 ] && order="2 1"  # ABBA: neither always runs right after the other (freed memory)
  for np in $order; do
    rm -rf "$out/pair"
    bake $np pair$k-np$np "$out/pair/out" "$out/pair/cache"
  done
  rm -rf "$out/pair"
done
[ "$pairs" -gt 0 ] && python3 - "$out" "$pairs" <<'PY'
import json, statistics, sys
out, pairs = sys.argv[1], int(sys.argv[2])
wall, cpu = [], []
for k in range(1, pairs + 1):
    j = {np: json.load(open(f"{out}/pair{k}-np{np}.json")) for np in (1, 2)}
    w = {np: json.load(open(f"{out}/pair{k}-np{np}.wall"))["wall_s"] for np in (1, 2)}
    wall.append(w[1] / w[2]), cpu.append(j[1]["critical_cpu_s"] / j[2]["critical_cpu_s"])
    kernel = {np: max(w["kernel_cpu_s"] for w in j[np]["per_rank"]) for np in (1, 2)}
    print(f"pair {k}: 1 rank {w[1]:.2f} s wall / {j[1]['critical_cpu_s']:.2f} s CPU, 2 ranks {w[2]:.2f} / "
          f"{j[2]['critical_cpu_s']:.2f}: {wall[-1]:.2f}x wall, {cpu[-1]:.2f}x critical CPU; kernel CPU "
          f"{kernel[1]:.2f} s at 1 rank, {kernel[2]:.2f} s on the busiest of 2")
print(f"pairs: median {statistics.median(wall):.2f}x wall ({min(wall):.2f}-{max(wall):.2f}), "
      f"{statistics.median(cpu):.2f}x critical CPU ({min(cpu):.2f}-{max(cpu):.2f})")
PY
[ "${KEEP:-0}" = 1 ] || find "$out" -mindepth 1 -maxdepth 1 -type d -exec rm -rf {} +
true
