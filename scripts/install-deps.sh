#!/usr/bin/env bash
# Installs the Debian 12 packages lodkit needs, only those missing. Needs root (or sudo).
set -euo pipefail
PKGS=(build-essential cmake ninja-build ccache pkg-config
      libtbb-dev libopenmesh-dev libglm-dev libembree-dev
      libglfw3-dev libepoxy-dev libimgui-dev libstb-dev
      libtomlplusplus-dev nlohmann-json3-dev libcli11-dev
      libgtest-dev libgmock-dev libbenchmark-dev libmeshoptimizer-dev
      libtinygltf-dev gltfpack
      libgdal-dev  # elevation rasters for [[terrain]]
      libcgal-demo xvfb xauth libgl1-mesa-dri
      openmpi-bin libopenmpi-dev  # lod-bake-mpi and its mpirun tests
      clang libclang-rt-14-dev)  # clang: libFuzzer targets (scripts/fuzz.sh)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "[deps] all ${#PKGS[@]} packages present"
  exit 0
fi
echo "[deps] installing: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "[deps] need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  SUDO=sudo
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
