#!/usr/bin/env bash
# Formatting and static analysis, as errors; called by scripts/test.sh (and so by CI) after the
# CPU or CUDA build has written compile_commands.json.
#   format  clang-format (.clang-format) on every tracked C++ and CUDA file: any difference fails.
#   tidy    clang-tidy (.clang-tidy, warnings are errors) on the project's C++ translation units
#           in the build's compile_commands.json; the headers they include (.hpp and the engine's
#           .cuh, which the OpenMP backend compiles as C++) are checked through them. CUDA
#           translation units (.cu) are nvcc's alone: clang-tidy does not parse them.
#           --tidy-scope=all (the default) checks every unit: what the shipped code is made of
#           (core, gpu, server, client, python, proto) and the tests and benchmarks.
#           --tidy-scope=product checks the first group only. CI (scripts/test.sh) uses it: on its
#           2 cores the 77 test and benchmark units, each parsing GoogleTest, gRPC or Thrust,
#           took about two thirds of the 16 minutes clang-tidy needed (2026-11-26), and CI's
#           whole budget is 30.
#           Run the whole scope before a change to tests is committed (scripts/lint.sh tidy).
# Usage: scripts/lint.sh [format|tidy]... [--build-dir DIR] [--tidy-scope=all|product]
#        (default: both steps, build/cpu or build/cuda, scope all)
set -euo pipefail
cd "$(dirname "$0")/.."

build_dir=""
steps=()
tidy_scope=all
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build_dir=$2; shift 2 ;;
    format|tidy) steps+=("$1"); shift ;;
    --tidy-scope=all|--tidy-scope=product) tidy_scope=${1#--tidy-scope=}; shift ;;
    *) echo "usage: scripts/lint.sh [format|tidy]... [--build-dir DIR] [--tidy-scope=all|product]" >&2; exit 2 ;;
  esac
done
[ ${#steps[@]} -gt 0 ] || steps=(format tidy)
if [ -z "$build_dir" ]; then
  for candidate in build/cpu build/cuda; do
    if [ -f "$candidate/compile_commands.json" ]; then build_dir=$candidate; break; fi
  done
fi

for step in "${steps[@]}"; do
  case "$step" in
    format)
      mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.cu' '*.cuh')
      clang-format --dry-run --Werror "${files[@]}"
      echo "lint: clang-format: ${#files[@]} files formatted"
      ;;
    tidy)
      if [ -z "$build_dir" ] || [ ! -f "$build_dir/compile_commands.json" ]; then
        echo "lint: no compile_commands.json (build first, or pass --build-dir)" >&2
        exit 2
      fi
      # With GALPHA_UNITY_TESTS on, the test files are not units of their own in the compilation
      # database, so the whole scope would skip them without a word.
      if [ "$tidy_scope" = all ] && grep -q '^GALPHA_UNITY_TESTS:BOOL=ON$' "$build_dir/CMakeCache.txt" 2>/dev/null; then
        echo "lint: $build_dir compiles each test executable as one unit (GALPHA_UNITY_TESTS=ON, as" \
          "scripts/test.sh configures it): reconfigure it with -DGALPHA_UNITY_TESTS=OFF and build, or" \
          "pass --tidy-scope=product" >&2
        exit 2
      fi
      # Our translation units only: not the generated protobuf code under the build folder.
      root=$(pwd)
      dirs="core|gpu|server|client|python|proto"
      [ "$tidy_scope" = all ] && dirs="$dirs|bench|tests"
      run-clang-tidy -p "$build_dir" -quiet -j"$(nproc)" "^${root}/(${dirs})/.*\\.cpp\$" \
        > "$build_dir/clang-tidy.log" 2>&1 || {
        grep -E 'error:|warning:' "$build_dir/clang-tidy.log" | sort -u
        echo "lint: clang-tidy found problems (whole log: $build_dir/clang-tidy.log)" >&2
        exit 1
      }
      echo "lint: clang-tidy ($tidy_scope): clean"
      ;;
  esac
done
