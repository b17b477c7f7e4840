#!/usr/bin/env bash
# ctest-all.sh DIR [ctest options...]: runs ctest on DIR, refuses an empty run, and fails
# unless it ran every test the selection lists (ctest -N with the same options).
set -euo pipefail
dir=$1; shift
listed=$(ctest --test-dir "$dir" -N "$@" | sed -n 's/^Total Tests: *//p')
listed=${listed:-0}
echo "[ctest] $dir: $listed tests listed"
log=$(mktemp)
trap 'rm -f "$log"' EXIT
set +e
ctest --test-dir "$dir" --no-tests=error --output-on-failure "$@" 2>&1 | tee "$log"
rc=${PIPESTATUS[0]}
set -e
ran=$(sed -n 's/.*tests passed, [0-9]* tests* failed out of \([0-9]*\).*/\1/p' "$log" | tail -n1)
ran=${ran:-0}
echo "[ctest] $dir: ran $ran of $listed tests"
[ "$rc" -eq 0 ] || exit "$rc"
if [ "$listed" -eq 0 ] || [ "$ran" -ne "$listed" ]; then
  echo "[ctest] $dir: ran $ran tests but $listed are listed" >&2
  exit 1
fi
