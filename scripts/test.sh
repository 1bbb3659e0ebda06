#!/usr/bin/env bash
# The README's second command, and what CI runs: installs what is needed, builds every target
# (the CUDA backend too when a GPU is present, for one architecture, and the Python package's
# compiled parts: GALPHA_BUILD_PYTHON) and runs the whole test suite, pytest's included.
# Tests that need a GPU skip themselves on machines without one. Then the format check and
# clang-tidy (scripts/lint.sh), the sanitizer builds of the CPU backend (scripts/sanitize.sh), the
# fuzz targets briefly, the Kubernetes manifests' validation and the container image's build steps.
set -euo pipefail
cd "$(dirname "$0")/.."
# Each step's wall time, printed as it ends and summed at the end, so that CI's log shows where
# its time goes (the goal is under 30 minutes on 2 cores).
step_start=$SECONDS
step_times=()
step_done() {
  step_times+=("$(printf '%5d s  %s' $((SECONDS - step_start)) "$1")")
  echo "test.sh: step '$1' took $((SECONDS - step_start)) s"
  step_start=$SECONDS
}
trap 'echo "test.sh: times of the steps that ended:"; printf "  %s\n" "${step_times[@]}"; echo "  $SECONDS s in all"' EXIT
scripts/install-deps.sh
step_done "install dependencies"
# OpenMP threads that spin while they wait for work stall every other process that needs the core:
# with two tests at a time (ctest -j below), alphactl_test took 137 s instead of 28. Waiting
# threads sleep instead; the engine's results do not depend on it.
export OMP_WAIT_POLICY=passive
# Every CMake build below compiles its C and C++ through ccache (not nvcc's CUDA units, nor the
# fuzz targets, which clang++ compiles directly), in a cache inside this tree: the container image's
# build (the last step) then takes the CPU build's objects for the units they share (same flags:
# CMakeLists.txt makes all code position-independent). Depend mode hashes the compiler's own
# dependency list instead of running the preprocessor once more on a miss, which the sanitizer
# builds, all misses, would pay for every unit. CMake reads the launcher from the environment when
# it configures a tree for the first time; an existing tree keeps what it has.
if command -v ccache >/dev/null; then
  export CMAKE_CXX_COMPILER_LAUNCHER=ccache CMAKE_C_COMPILER_LAUNCHER=ccache
  export CCACHE_DIR=${CCACHE_DIR:-$PWD/build/ccache} CCACHE_BASEDIR=$PWD CCACHE_DEPEND=1 CCACHE_MAXSIZE=${CCACHE_MAXSIZE:-5G}
  ccache --zero-stats >/dev/null
fi
# The CUDA configuration only where a GPU can run its tests: without one they skip, and compiling
# the CUDA objects (about 13 minutes of nvcc on 2 cores) would test nothing but the compiler. The
# GPU runs (bench/gpu_bundle.sh, bench/gpu_run.sh) build and test it.
preset=cpu
if command -v nvidia-smi >/dev/null && nvidia-smi -L 2>/dev/null | grep -q '^GPU'; then preset=cuda; fi
# Each test executable as one translation unit (GALPHA_UNITY_TESTS): its files parse GoogleTest,
# gRPC and Thrust once (CMakeLists.txt says what it saves).
scripts/drop-stale-build-dir.sh "$preset"
cmake --preset "$preset" -DGALPHA_BUILD_PYTHON=ON -DGALPHA_UNITY_TESTS=ON
cmake --build --preset "$preset" -j"$(nproc)"
step_done "build ($preset)"
# Two at a time, the longest first (their COST): the pytest suite and the service test spend much
# of their time in one thread or waiting on their servers.
ctest --preset "$preset" -j"$(nproc)"
step_done "ctest ($preset)"
# Formatting and static analysis, as errors (.clang-format, .clang-tidy): clang-tidy on the shipped
# code only (scripts/lint.sh says why; the tests and benchmarks are tidied before they are committed).
scripts/lint.sh --build-dir "build/$preset" --tidy-scope=product
step_done "format and clang-tidy"
# AddressSanitizer + UBSan and ThreadSanitizer on the CPU build (a chosen subset: CI's time budget).
scripts/sanitize.sh
step_done "sanitizer builds and tests"
# The fuzz targets, briefly (20 s each): parsers of untrusted input must not crash.
tests/fuzz/run.sh 20
step_done "fuzz targets"
# The API's style (buf lint).
proto/lint.sh
step_done "buf lint"
# Deployment: the manifests against their schemas, and the container image's build steps (no
# Docker engine here: deploy/build-server.sh is what the Dockerfile runs).
deploy/k8s/validate.sh
step_done "manifests"
# The image's CUDA code only where it can be tested, as for the preset above.
GALPHA_IMAGE_WITH_CUDA=$([ "$preset" = cuda ] && echo AUTO || echo OFF) deploy/build-server.sh build/image-root
step_done "image build steps"
if command -v ccache >/dev/null; then ccache --show-stats | grep -iE 'hits|misses' || true; fi
