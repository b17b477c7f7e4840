#!/usr/bin/env bash
# fetch-topography.sh [OUT_DIR]: fetches the one real elevation file lodkit's terrain tests use,
# examples/step-53/topography.txt.gz from Debian's libdeal.ii-doc (SRTM-derived, East African
# Rift, 380 x 220 samples on a 0.05 degree grid), into OUT_DIR (default build/data/).
# The 258 MB package is downloaded into a temporary folder and only that file is extracted;
# nothing is installed. Also writes the gunzipped text beside it (topography.txt), since
# lod_preprocess reads plain text (see preprocess/height_field_io.h).
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$src/build/data}
mkdir -p "$out"
if [ -s "$out/topography.txt" ]; then
  echo "[topography] present: $out/topography.txt"
  exit 0
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
member=./usr/share/doc/libdeal.ii-doc/examples/step-53/topography.txt.gz
(cd "$tmp" && apt-get download libdeal.ii-doc >/dev/null)
deb=$(ls "$tmp"/libdeal.ii-doc_*.deb)
# The examples folder moved between Debian releases: find the member by name first.
path=$(dpkg-deb --fsys-tarfile "$deb" | tar -t | grep 'step-53/topography.txt.gz$' | head -n1 || true)
[ -n "$path" ] || path=$member
dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$tmp" "$path"
cp "$tmp/$path" "$out/topography.txt.gz"
gzip -dc "$out/topography.txt.gz" > "$out/topography.txt.part"
mv "$out/topography.txt.part" "$out/topography.txt"
echo "[topography] $out/topography.txt ($(wc -l < "$out/topography.txt") lines)"
