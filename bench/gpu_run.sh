#!/usr/bin/env bash
# Run ON THE GPU MACHINE (H100/H200, CUDA 13, no Abseil/CGAL there) from the repository root,
# with .carry/ made by bench/gpu_bundle.sh: runs the tests on the CUDA backend, then the
# benchmark (galpha CUDA vs CGAL on the same machine). Logs go to $OUT when set.
set -uo pipefail
out="${OUT:-/tmp/galpha-gpu}"
mkdir -p "$out"
export LD_LIBRARY_PATH="$PWD/.carry/lib:${LD_LIBRARY_PATH:-}"
export GALPHA_DATA_DIR="$PWD/data"
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader | tee "$out/machine.txt"
nproc | sed 's/^/cores: /' | tee -a "$out/machine.txt"
status=0
for t in predicates_test predicates_device_test delaunay_test; do
  if [ -x ".carry/bin/$t" ]; then
    echo "== $t"
    ".carry/bin/$t" --gtest_brief=1 2>&1 | tee "$out/$t.log" | tail -n 30
    [ "${PIPESTATUS[0]}" -eq 0 ] || status=1
  fi
done
if [ -x .carry/bin/delaunay_bench ]; then
  echo "== delaunay_bench"
  .carry/bin/delaunay_bench ${GALPHA_BENCH_ARGS:---backend=cuda --sizes=100000,1000000,10000000} 2>&1 | tee "$out/bench.md"
fi
exit $status
