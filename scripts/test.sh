#!/usr/bin/env bash
# The README's second command, and what CI runs: installs what is needed, builds every target
# (the CUDA backend too when nvcc is present, for one architecture, and the Python package's
# compiled parts: GALPHA_BUILD_PYTHON) and runs the whole test suite, pytest's included.
# Tests that need a GPU skip themselves on machines without one. Then the format check and
# clang-tidy (scripts/lint.sh), the sanitizer builds of the CPU backend (scripts/sanitize.sh), the
# fuzz targets briefly, the Kubernetes manifests' validation and the container image's build steps.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
preset=cpu
if [ -x /usr/local/cuda/bin/nvcc ] || command -v nvcc >/dev/null; then preset=cuda; fi
cmake --preset "$preset" -DGALPHA_BUILD_PYTHON=ON
cmake --build --preset "$preset" -j"$(nproc)"
ctest --preset "$preset"
# Formatting and static analysis, as errors (.clang-format, .clang-tidy).
scripts/lint.sh --build-dir "build/$preset"
# AddressSanitizer + UBSan and ThreadSanitizer on the CPU build (a chosen subset: CI's time budget).
scripts/sanitize.sh
# The fuzz targets, briefly (20 s each): parsers of untrusted input must not crash.
tests/fuzz/run.sh 20
# The API's style (buf lint).
proto/lint.sh
# Deployment: the manifests against their schemas, and the container image's build steps (no
# Docker engine here: deploy/build-server.sh is what the Dockerfile runs).
deploy/k8s/validate.sh
deploy/build-server.sh build/image-root
