#!/usr/bin/env bash
# The README's first command: installs what is needed, builds the CPU configuration, and computes
# the alpha-shape family of a bundled real data set with the embedded engine (no server, no GPU
# needed). It picks the smallest alpha whose regularized shape is one piece covering every point,
# writes that shape as SVG and GeoJSON under build/, and prints its summary.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/drop-stale-build-dir.sh cpu
cmake --preset cpu >/dev/null
cmake --build --preset cpu --target alphactl -j"$(nproc)"
alphactl=build/cpu/client/alphactl
file="${1:-data/lidar_autzen.bin}"
optimal=$("$alphactl" optimal "$file" --components 1)
rank=$(sed -nE 's/.*"regularized":\{"rank":([0-9]+).*/\1/p' <<<"$optimal")
mode=regularized
if [ -z "$rank" ]; then  # collinear or tiny input: no triangles, use the general sense
  rank=$(sed -nE 's/.*"general":\{"rank":([0-9]+).*/\1/p' <<<"$optimal")
  mode=general
fi
"$alphactl" shape "$file" --rank "$rank" --mode "$mode" --format svg >build/shape.svg
"$alphactl" shape "$file" --rank "$rank" --mode "$mode" --format geojson >build/shape.geojson
"$alphactl" summary "$file" --rank "$rank" --mode "$mode"
echo "demo: wrote build/shape.svg and build/shape.geojson: the $mode alpha shape of $file at rank $rank" >&2
