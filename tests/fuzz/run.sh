#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) and runs each for a short while:
#   tests/fuzz/run.sh [SECONDS_PER_TARGET]   (default 20; CI uses the default)
# Only the sources a target needs are compiled, so the engine (OpenMP, CUDA) is not involved.
# predicates_fuzzer compares the exact predicates with GMP rationals on arbitrary finite doubles.
# simplex_chunk_fuzzer decodes arbitrary compact Classify chunks (what a client reads).
# Corpora start from seeds/ and grow in build/fuzz/corpus (kept between local runs).
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:-20}
out=build/fuzz
mkdir -p "$out/gen" "$out/corpus"
protoc --proto_path=proto --cpp_out="$out/gen" galpha/v1/alpha_shapes.proto
# -ffp-contract=off as in every galpha target: scaled integers decode as offset + scale * X, unfused.
flags=(-std=c++17 -O1 -g -ffp-contract=off -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined -I. -I"$out/gen")
libs=($(pkg-config --libs protobuf absl_statusor absl_strings libcrypto) -lpthread)

# The four targets compile side by side (each clang++ compiles its sources one after another), and
# then run side by side: CI's 2 cores were otherwise half idle in this step.
# The decoder with the CRS functions that refuse (coordinate_system_no_proj.cpp): a header's crs is
# then an error, decided without PROJ's database; the fuzzer aims at the decoder.
clang++ "${flags[@]}" tests/fuzz/build_stream_fuzzer.cpp server/build_stream.cpp server/chunk_codec_pool.cpp server/build_refusal.cpp core/io/point_set_handle.cpp \
  core/io/coordinate_system_no_proj.cpp proto/codec/point_chunk_codec.cpp proto/codec/simplex_chunk_codec.cpp proto/sections/simplex_sections.cpp "$out/gen/galpha/v1/alpha_shapes.pb.cc" -o "$out/build_stream_fuzzer" "${libs[@]}" \
  $(pkg-config --libs libzstd) &
builds=($!)
clang++ "${flags[@]}" tests/fuzz/point_formats_fuzzer.cpp core/io/point_formats.cpp core/io/point_io.cpp core/io/las_reader.cpp \
  -o "$out/point_formats_fuzzer" "${libs[@]}" $(pkg-config --libs absl_str_format) &
builds+=($!)
clang++ "${flags[@]}" tests/fuzz/predicates_fuzzer.cpp core/io/input_validation.cpp core/io/number_text.cpp \
  -o "$out/predicates_fuzzer" "${libs[@]}" $(pkg-config --libs absl_str_format) -lgmpxx -lgmp &
builds+=($!)
clang++ "${flags[@]}" tests/fuzz/simplex_chunk_fuzzer.cpp proto/codec/simplex_chunk_codec.cpp proto/sections/simplex_sections.cpp "$out/gen/galpha/v1/alpha_shapes.pb.cc" \
  -o "$out/simplex_chunk_fuzzer" "${libs[@]}" $(pkg-config --libs libzstd) &
builds+=($!)
for pid in "${builds[@]}"; do wait "$pid"; done

targets=(build_stream_fuzzer point_formats_fuzzer predicates_fuzzer simplex_chunk_fuzzer)
runs=()
for target in "${targets[@]}"; do
  corpus="$out/corpus/$target"
  mkdir -p "$corpus"
  echo "fuzz: $target for ${seconds} s"
  "$out/$target" -artifact_prefix="$out/" -max_total_time="$seconds" -max_len=65536 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    "$corpus" "tests/fuzz/seeds/$target" >"$out/$target.log" 2>&1 &
  runs+=($!)
done
# Every target's verdict and last lines, in order; a crash (or any failure) fails the step.
failed=0
for i in "${!targets[@]}"; do
  rc=0
  wait "${runs[$i]}" || rc=$?
  echo "fuzz: ${targets[$i]} exited $rc"
  tail -n 12 "$out/${targets[$i]}.log"
  [ "$rc" -eq 0 ] || failed=1
done
exit "$failed"
