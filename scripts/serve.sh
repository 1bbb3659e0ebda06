#!/usr/bin/env bash
# Starts the galpha server in the foreground with its defaults (gRPC on :50051, Prometheus metrics
# on :9464, the GPU when there is one), installing and building what it needs first. Flags pass
# through to galpha_server (see docs/operations.md, or galpha_server --helpfull); Ctrl-C or SIGTERM
# drains it.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
preset=cpu
if [ -x /usr/local/cuda/bin/nvcc ] || command -v nvcc >/dev/null; then preset=cuda; fi
scripts/drop-stale-build-dir.sh "$preset"
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" --target galpha_server alphactl -j"$(nproc)"
exec "build/$preset/server/galpha_server" "$@"
