#!/usr/bin/env bash
# Sanitizer runs of the CPU build, called by scripts/test.sh (and so by CI). The presets are in
# CMakePresets.json:
#   asan  AddressSanitizer + UndefinedBehaviorSanitizer (leaks included) on the exact arithmetic,
#         the point parsers, and the family build and its queries: the code that handles untrusted
#         input and raw indices. UBSan reports halt the test (halt_on_error);
#         scripts/ubsan.supp suppresses one report inside Thrust's own headers. The service's tests
#         are not in this build: they would compile the service library and the gRPC code for it
#         (about 2 of its 6 minutes on CI's 2 cores). The upload decoder runs under ASan + UBSan in
#         the fuzz targets (tests/fuzz, build_stream_fuzzer), the cache and the upload streams
#         under TSan below, and all of them in the Release suite.
#   tsan  ThreadSanitizer on the service's threaded parts (build scheduler, family cache, upload
#         streams, compact answers encoded on the codec pool) and the client's parallel decoding
#         of compact answers. OpenMP runs one thread there (OMP_NUM_THREADS=1 in the preset): Debian's
#         libgomp is not instrumented, and its own threads would only report its internals.
# Only these tests, not the whole suite: both builds and runs must fit in CI's budget on 2 cores.
# Both presets compile at -O1 -g1 (CMAKE_CXX_FLAGS_RELWITHDEBINFO), the level the sanitizers'
# documentation recommends, with line tables for their reports. On the 2-core machine this step
# (both builds and their tests, from scratch) took 1,334 s at -O2 -g and 690 s at -O1 -g1; the
# engine's two Thrust translation units, compiled side by side, 110 s and 53 s. Without the
# service's tests in the ASan build: 534 s (in CI's script, 2026-11-26). GCC's
# -Wmaybe-uninitialized is off in these two builds: at -O1 under the instrumentation it reports
# false positives inside GoogleTest's own matchers. The Release build keeps the warning.
# Usage: scripts/sanitize.sh [asan|tsan]...   (default: both)
set -euo pipefail
cd "$(dirname "$0")/.."

asan_tests=(predicates_test power_test attachment_test radius_test point_formats_test point_set_handle_test
            alpha_family_test alpha_bruteforce_test)
tsan_tests=(build_scheduler_test family_cache_test family_promoter_test build_stream_test encoded_answer_test
            classify_answer_decoder_test classify_parts_merger_test)

run_preset() {
  local preset=$1
  shift
  local tests=("$@")
  scripts/drop-stale-build-dir.sh "$preset"
  cmake --preset "$preset" -DGALPHA_UNITY_TESTS=ON >/dev/null
  cmake --build --preset "$preset" -j"$(nproc)" --target "${tests[@]}"
  local regex
  regex="^($(IFS='|'; echo "${tests[*]}"))\$"
  ctest --preset "$preset" -R "$regex" -j"$(nproc)"
}

presets=("$@")
[ ${#presets[@]} -gt 0 ] || presets=(asan tsan)
for preset in "${presets[@]}"; do
  case "$preset" in
    asan) run_preset asan "${asan_tests[@]}" ;;
    tsan) run_preset tsan "${tsan_tests[@]}" ;;
    *) echo "usage: scripts/sanitize.sh [asan|tsan]..." >&2; exit 2 ;;
  esac
done
