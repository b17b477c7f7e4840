#!/usr/bin/env bash
# configure.sh DIR [cmake -D options...]: configures DIR with Ninja, setting every lodkit
# cache option explicitly (the caller's -D options override the defaults below), so that
# a folder configured earlier by the other script, or by an older checkout, gives the same
# build. A cache made by another generator or for another source tree is thrown away.
set -euo pipefail
dir=$1; shift
src=$(cd "$(dirname "$0")/.." && pwd)
cache="$dir/CMakeCache.txt"
if [ -f "$cache" ]; then
  gen=$(sed -n 's/^CMAKE_GENERATOR:INTERNAL=//p' "$cache")
  home=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$cache")
  if [ "$gen" != "Ninja" ] || [ "$home" != "$src" ]; then
    echo "[configure] $dir was configured for '$gen' in '$home': starting it afresh"
    rm -rf "$cache" "$dir/CMakeFiles"
  fi
fi
cmake -S "$src" -B "$dir" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release -DLOD_SANITIZE= \
  -DLOD_BUILD_TESTS=ON -DLOD_BUILD_BENCH=ON -DLOD_BUILD_VIEWER=ON -DLOD_BUILD_CLI=ON -DLOD_BUILD_EXAMPLES=ON -DLOD_INSTALL=ON \
  "$@"
