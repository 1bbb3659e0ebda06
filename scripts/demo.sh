#!/usr/bin/env bash
# The README's first command: installs what is needed, builds the CPU configuration, and
# triangulates a bundled real data set with the embedded engine (no server, no GPU needed).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset cpu >/dev/null
cmake --build --preset cpu --target alphactl -j"$(nproc)"
build/cpu/client/alphactl triangulate "${1:-data/lidar_autzen.bin}"
