#!/usr/bin/env bash
# Node tools the test suite runs: the Khronos glTF validator (npm gltf-validator, pinned),
# installed into build/node-tools (or $LOD_NODE_TOOLS). Idempotent: when the pinned version is
# already there this only checks it and exits. Installs Debian's nodejs + npm when either is
# missing (needs root or sudo then).
set -euo pipefail
cd "$(dirname "$0")/.."
PREFIX=${LOD_NODE_TOOLS:-$PWD/build/node-tools}
VALIDATOR_VERSION=2.0.0-dev.3.10
pkg="$PREFIX/node_modules/gltf-validator/package.json"

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

if [ -f "$pkg" ] && grep -q "\"version\": *\"$VALIDATOR_VERSION\"" "$pkg"; then
  echo "[node-tools] gltf-validator $VALIDATOR_VERSION present in $PREFIX (node $(node --version))"
  exit 0
fi
echo "[node-tools] npm install gltf-validator@$VALIDATOR_VERSION into $PREFIX"
mkdir -p "$PREFIX"
npm install --prefix "$PREFIX" --no-audit --no-fund --no-save --loglevel=error "gltf-validator@$VALIDATOR_VERSION"
[ -f "$pkg" ] || { echo "[node-tools] gltf-validator did not install into $PREFIX" >&2; exit 1; }
echo "[node-tools] gltf-validator $VALIDATOR_VERSION installed"
