#!/usr/bin/env bash
# Node tools the test suite runs, pinned, installed into build/node-tools (or $LOD_NODE_TOOLS):
# the Khronos glTF validator (npm gltf-validator) and ajv + ajv-formats, which check exported
# 3D Tiles tilesets against the 3D Tiles 1.1 JSON schemas (Cesium's 3d-tiles-validator is not on
# the npm registry reachable here). Idempotent: when the pinned versions are already
# there this only checks them and exits. Installs Debian's nodejs + npm when either is
# missing (needs root or sudo then).
set -euo pipefail
cd "$(dirname "$0")/.."
PREFIX=${LOD_NODE_TOOLS:-$PWD/build/node-tools}
VALIDATOR_VERSION=2.0.0-dev.3.10
AJV_VERSION=8.20.0
AJV_FORMATS_VERSION=3.0.1
PACKAGES=("gltf-validator@$VALIDATOR_VERSION" "ajv@$AJV_VERSION" "ajv-formats@$AJV_FORMATS_VERSION")

if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "[node-tools] need root or sudo to install nodejs and npm" >&2; exit 1; }
    SUDO=sudo
  fi
  echo "[node-tools] installing nodejs and npm (Debian)"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  missing=()
  command -v node >/dev/null || missing+=(nodejs)
  command -v npm >/dev/null || missing+=(npm)
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# present NAME@VERSION: the package is installed in $PREFIX at exactly that version.
present() {
  local name=${1%@*} version=${1##*@}
  local pkg="$PREFIX/node_modules/$name/package.json"
  [ -f "$pkg" ] && grep -q "\"version\": *\"$version\"" "$pkg"
}

missing_pkgs=()
for p in "${PACKAGES[@]}"; do present "$p" || missing_pkgs+=("$p"); done
if [ ${#missing_pkgs[@]} -eq 0 ]; then
  echo "[node-tools] ${PACKAGES[*]} present in $PREFIX (node $(node --version))"
  exit 0
fi
echo "[node-tools] npm install ${PACKAGES[*]} into $PREFIX"
mkdir -p "$PREFIX"
# All at once: npm --no-save prunes what the same call does not name.
npm install --prefix "$PREFIX" --no-audit --no-fund --no-save --loglevel=error "${PACKAGES[@]}"
for p in "${PACKAGES[@]}"; do
  present "$p" || { echo "[node-tools] $p did not install into $PREFIX" >&2; exit 1; }
done
echo "[node-tools] ${PACKAGES[*]} installed"
