#!/usr/bin/env bash
# Run ON THE GPU MACHINE (H100/H200, CUDA 13, no Abseil/CGAL there) from the repository root,
# with .carry/ made by bench/gpu_bundle.sh. Phases, in the order given (default: smoke test bench):
#   smoke   alphactl triangulate on every data set, CUDA then CPU backend, each under a timeout
#   sanitize  compute-sanitizer memcheck, racecheck and synccheck of one small CUDA triangulation,
#           then memcheck of one whole family build (two streams, pinned staging)
#   test    the test binaries (CUDA backend included), each test under GALPHA_TEST_TIMEOUT seconds
#           (default 240), one process per test so that a hang names its test
#   bench   delaunay_bench (CUDA vs CGAL on the same machine); GALPHA_BENCH_ARGS overrides the args of
#           its first run (the benchmark distributions)
#   alpha   alpha_bench: the whole family, CUDA and CPU backends, CGAL Alpha_shape_2 in the same run,
#           the floor sort of the spectrum's pairs, and 100M uniform points on the GPU
#   hard    alpha_bench over every generator (the hard ones: lattices, circles, lines, offsets,
#           ulp-perturbed lattices, centimetre LiDAR) at 100K and 1M with CGAL at 100K, at 10M on
#           the GPU alone, and the CPU backend at 1M on this machine's cores
#   regular the regular (weighted) triangulation: delaunay_bench --weights (CGAL's
#           Regular_triangulation_2 in the same run) at 1M for every kind of weights, the unweighted
#           1M rows beside them, 10M with uniform weights; then compute-sanitizer memcheck of the
#           weighted tests on CUDA (regular_test's small cases)
#   identity the CUDA/CPU identity test alone
#   sets    many sets in one build (issue 20): delaunay_bench --sets (TriangulateSets) and
#           alpha_bench --sets (BuildAlphaFamilies) at 10,000 x 1,000 on every generator and
#           1,000 x 10,000 on three, against one 10M build, one call a set and CGAL a set; then
#           triangulate_sets_test and packed_families_test on the CUDA backend
#   topology topology_bench: Betti curves and persistence diagrams at 1M (GUDHI's exact persistence
#           in the same run at 1M uniform and at 100K on the hard generators) and 10M uniform
#   resident resident_bench: a resident family (rank tables kept on the device) against the family
#           in host memory, at 1M on every generator and at 10M uniform
#   profile Nsight Systems (nsys, when the machine has it) over one 1M-point family build: the
#           kernels and the CUDA API calls (waits) by total time
#   kernels Nsight Compute's kernel times, summed by name, of one 1M-point family build of each
#           input in GALPHA_KERNEL_DISTS (default uniform): where a slow input's stages go
#   service service_test with the CUDA backend, then service_bench (the gRPC service on loopback:
#           transport cost, Classify rate, concurrent builds, query latency; CGAL in the same run)
#   warm_up the server's first two 1M-point builds (alphactl over loopback) in three fresh
#           processes with --warm_up=false and three with --warm_up=true: the running sum of the
#           builds' engine times after each (galpha_build_seconds_sum; the second build's is the
#           difference) and the warm-up's time (galpha_warm_up_seconds)
# Full logs go to $OUT (or /tmp/galpha-gpu), 8 files at most so that all of them come back; a
# short summary goes to standard output.
set -uo pipefail
out="${OUT:-/tmp/galpha-gpu}"
mkdir -p "$out"
export LD_LIBRARY_PATH="$PWD/.carry/lib:${LD_LIBRARY_PATH:-}"
export GALPHA_DATA_DIR="$PWD/data"
phases=("$@")
[ ${#phases[@]} -gt 0 ] || phases=(smoke test bench)
status=0

nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader | tee "$out/machine.txt"
echo "cores: $(nproc)" | tee -a "$out/machine.txt"

# run_step NAME SECONDS CMD...: runs CMD under a timeout, logs to $out/NAME.log, reports the outcome.
run_step() {
  local name=$1 seconds=$2
  shift 2
  local start=$SECONDS
  timeout -k 5 "$seconds" "$@" >>"$out/$name.log" 2>&1
  local rc=$?
  local verdict=ok
  [ $rc -eq 0 ] || verdict="FAILED rc=$rc"
  [ $rc -eq 124 ] && verdict="TIMED OUT after ${seconds}s"
  echo "$name: $* -> $verdict ($((SECONDS - start)) s)"
  [ $rc -eq 0 ] || status=1
  return $rc
}

for phase in "${phases[@]}"; do
  case "$phase" in
    smoke)
      for backend in cuda cpu; do
        for f in data/*.bin; do
          run_step smoke 60 .carry/bin/alphactl triangulate "$f" --backend=$backend
        done
      done
      grep -E '"backend"' "$out/smoke.log" | sed -E 's/"stage_ms".*//' 
      ;;
    sets)
      run_step sets 420 .carry/bin/delaunay_bench --backend=cuda --sets=10000x1000 --repeat=3
      run_step sets 200 .carry/bin/delaunay_bench --backend=cuda --sets=1000x10000 --repeat=3 \
        --dists=uniform,two_lines,circle
      run_step sets 420 .carry/bin/alpha_bench --backend=cuda --sets=10000x1000 --repeat=3
      run_step sets 200 .carry/bin/alpha_bench --backend=cuda --sets=1000x10000 --repeat=3 \
        --dists=uniform,two_lines,circle
      run_step sets 300 .carry/bin/triangulate_sets_test --gtest_filter='*/cuda'
      run_step sets 300 .carry/bin/packed_families_test --gtest_filter='*/cuda'
      grep -E '^\| [a-z_0-9]+ \| [0-9]+x|PASSED|FAILED' "$out/sets.log"
      ;;
    regular)
      run_step regular 300 .carry/bin/delaunay_bench --backend=cuda --sizes=1000000 \
        --dists=uniform,gaussian,clustered --repeat=3
      for w in uniform signed many_hidden one_huge integers; do
        run_step regular 300 .carry/bin/delaunay_bench --backend=cuda --sizes=1000000 \
          --dists=uniform,gaussian,clustered --repeat=3 --weights=$w
      done
      run_step regular 300 .carry/bin/delaunay_bench --backend=cuda --sizes=10000000 --dists=uniform --repeat=2 \
        --weights=uniform
      run_step regular 300 compute-sanitizer --tool memcheck --error-exitcode 9 .carry/bin/regular_test \
        --gtest_filter='Backends/RegularTest.*/cuda'
      grep -E '^\| [a-z_]+ \| [0-9]+ \| cuda|weights |ERROR SUMMARY' "$out/regular.log"
      ;;
    weighted)
      # Weighted families (issue 18) against CGAL's weighted Alpha_shape_2, each beside the same
      # points unweighted (the table's last column); then 10M, every weight kind, and memcheck.
      run_step weighted 420 .carry/bin/alpha_bench --backend=cuda --sizes=1000000 \
        --dists=uniform,gaussian,clustered,grid --repeat=3 --weights=uniform
      for w in zero signed many_hidden one_huge integers; do
        run_step weighted 200 .carry/bin/alpha_bench --backend=cuda --sizes=1000000 --dists=uniform --repeat=3 \
          --cgal-max=0 --weights=$w
      done
      run_step weighted 200 .carry/bin/alpha_bench --backend=cuda --sizes=10000000 --dists=uniform --repeat=2 \
        --cgal-max=0 --weights=uniform
      run_step weighted 300 compute-sanitizer --tool memcheck --error-exitcode 9 .carry/bin/weighted_family_cgal_test \
        --gtest_filter='*KnownShape/cuda:*ManySmall*/cuda'
      grep -E '^\| [a-z_]+ \| [0-9]+ \| (cuda|[0-9.]+ \|)|weights |ERROR SUMMARY|x \(' "$out/weighted.log"
      ;;
    sanitize)
      small=data/ourairports_medium_large.bin
      for tool in memcheck racecheck synccheck; do
        run_step sanitize 240 compute-sanitizer --tool "$tool" --error-exitcode 9 \
          .carry/bin/alphactl triangulate "$small" --backend=cuda
      done
      run_step sanitize 300 compute-sanitizer --tool memcheck --error-exitcode 9 \
        .carry/bin/alphactl bench "$small" --backend=cuda
      grep -E "ERROR SUMMARY|RACECHECK SUMMARY|Invalid|Race" "$out/sanitize.log" | sort | uniq -c | head -n 20
      ;;
    test)
      for t in predicates_test predicates_device_test power_test radius_test weighted_radius_test triangulation_checks_test delaunay_test regular_test regular_cgal_test \
               delaunay_cgal_test shape_test alpha_family_test alpha_bruteforce_test alpha_family_cgal_test weighted_family_cgal_test persistence_gudhi_test persistence_engine_test resident_family_test alpha_backend_identity_test; do
        [ -x ".carry/bin/$t" ] || continue
        # One process per test, so that a hang names its test and the rest still run.
        for name in $(".carry/bin/$t" --gtest_list_tests | awk '/^[^ ]/{suite=$1} /^  /{print suite $1}'); do
          run_step "$t" "${GALPHA_TEST_TIMEOUT:-240}" ".carry/bin/$t" --gtest_filter="$name" >>"$out/steps.txt"
        done
        grep -v -- '-> ok' "$out/steps.txt" | grep -F "$t" || true
        grep -cE '^\[       OK \]' "$out/$t.log" | sed "s/^/$t: tests passed: /"
        grep -E '^\[  FAILED  \]|Failure' "$out/$t.log" | sort -u | head -n 20
      done
      # One file for all test logs: at most 8 files come back from the machine.
      for f in "$out"/*_test.log; do { echo "=== $(basename "$f")"; cat "$f"; } >>"$out/tests.log"; rm -f "$f"; done
      ;;
    profile)
      nsys_bin=$(command -v nsys || ls /usr/local/cuda/bin/nsys /opt/nvidia/nsight-systems/*/bin/nsys 2>/dev/null | head -n 1)
      if [ -z "$nsys_bin" ]; then
        echo "profile: no nsys on this machine"
        continue
      fi
      run_step profile 300 "$nsys_bin" profile --force-overwrite=true -o "$out/family_1m" --stats=false \
        .carry/bin/alpha_bench --backend=cuda --sizes=1000000 --dists=uniform --repeat=3 --cgal-max=0
      run_step profile 120 "$nsys_bin" stats --force-export=true --report cuda_gpu_kern_sum,cuda_api_sum \
        --format csv --output "$out/family_1m" "$out/family_1m.nsys-rep"
      rm -f "$out/family_1m.nsys-rep" "$out/family_1m.sqlite"
      for f in "$out"/family_1m_*.csv; do echo "== $f"; head -n 16 "$f"; done
      ;;
    kernels)
      # Kernel times by name (Nsight Compute, one pass, clocks left alone) of one 1M-point family
      # build per input in GALPHA_KERNEL_DISTS: where a slow input's stages spend their time.
      [ -x .carry/bin/alpha_bench ] || { echo "no alpha_bench in .carry"; status=1; continue; }
      ncu_bin=$(command -v ncu || ls /usr/local/cuda/bin/ncu /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -n 1)
      if [ -z "$ncu_bin" ]; then
        echo "kernels: no ncu on this machine"
        status=1
        continue
      fi
      for dist in ${GALPHA_KERNEL_DISTS:-uniform}; do
        run_step "kernels_$dist" 240 "$ncu_bin" --csv --page raw --print-units base --clock-control none \
          --metrics gpu__time_duration.sum --kernel-name-base demangled \
          .carry/bin/alpha_bench --backend=cuda --sizes=1000000 --dists="$dist" --repeat=1 --cgal-max=0
        echo "== $dist"
        python3 bench/ncu_kernels.py "$out/kernels_$dist.log" 30 | cut -c1-220
        grep -E "^\| $dist \| 1000000 \| (validate|upload)" "$out/kernels_$dist.log" | cut -c1-400
        rm -f "$out/kernels_$dist.log"
      done
      ;;
    hard)
      [ -x .carry/bin/alpha_bench ] || { echo "no alpha_bench in .carry"; status=1; continue; }
      # Sized to fit one 10-minute call; rows print as they finish, so a timeout keeps the rest.
      run_step hard 300 .carry/bin/alpha_bench --backend=cuda --sizes=100000,1000000 --repeat=3 --cgal-max=100000
      run_step hard 130 .carry/bin/alpha_bench --backend=cuda --sizes=10000000 --repeat=1 --cgal-max=0
      run_step hard 150 .carry/bin/alpha_bench --backend=cpu --sizes=1000000 --repeat=1 --cgal-max=0
      grep -E '^\|' "$out/hard.log" | grep -vE 'stages of the best run|^\| [a-z_0-9]+ \| [0-9]+ \| (validate|upload)'
      ;;
    topology)
      [ -x .carry/bin/topology_bench ] || { echo "no topology_bench in .carry"; status=1; continue; }
      run_step topology 330 .carry/bin/topology_bench --backend=cuda --sizes=1000000 --dists=uniform --repeat=3 \
        --gudhi-max=1000000
      run_step topology 200 .carry/bin/topology_bench --backend=cuda --sizes=100000,1000000 \
        --dists=grid,circle,two_lines,ulp_lattice,lidar_cm --repeat=3 --gudhi-max=100000
      run_step topology 90 .carry/bin/topology_bench --backend=cuda --sizes=10000000 --dists=uniform --repeat=2 \
        --gudhi-max=0
      grep -E '^\|' "$out/topology.log" | grep -v -- '---'
      ;;
    resident)
      [ -x .carry/bin/resident_bench ] || { echo "no resident_bench in .carry"; status=1; continue; }
      run_step resident 200 .carry/bin/resident_bench --backend=cuda --sizes=1000000 --repeat=3
      run_step resident 120 .carry/bin/resident_bench --backend=cuda --sizes=10000000 --dists=uniform --repeat=2
      grep -E '^\|' "$out/resident.log" | grep -v -- '---'
      ;;
    identity)
      # The CUDA/CPU identity test alone (every generator and data set): the quick correctness
      # check after an engine change, before the benchmarks.
      run_step identity 300 .carry/bin/alpha_backend_identity_test
      grep -E '^\[  (PASSED|FAILED) |Failure|SKIPPED' "$out/identity.log" | head -n 20
      ;;
    service)
      run_step service 300 env GALPHA_SERVICE_BACKEND=cuda .carry/bin/service_test
      # Again with the families resident on the GPU (the cache's device budget).
      run_step service 300 env GALPHA_SERVICE_BACKEND=cuda GALPHA_SERVICE_DEVICE_CACHE_BYTES=8000000000 \
        .carry/bin/service_test
      grep -E '^\[  (PASSED|FAILED) |Failure' "$out/service.log" | head -n 20
      # shellcheck disable=SC2086
      run_step service 420 .carry/bin/service_bench ${GALPHA_SERVICE_BENCH_ARGS:---backend=cuda --points=1000000 --clients=1,2,4,8 --repeat=3}
      sed -n '/^service_bench:/,$p' "$out/service.log"
      ;;
    warm_up)
      [ -x .carry/bin/galpha_server ] || { echo "no galpha_server in .carry (bench/gpu_bundle.sh service)"; status=1; continue; }
      # Two sets of 1M uniform points in the data files' format (uint64 N, then N x, y doubles),
      # outside $out (only logs come back), removed however the phase ends.
      work=$(mktemp -d)
      trap 'kill "${server:-}" 2> /dev/null; rm -rf "$work"' EXIT
      python3 - "$work" <<'PY'
import random, struct, sys
for name, seed in (("a", 1), ("b", 2)):
    r = random.Random(seed)
    with open(f"{sys.argv[1]}/{name}.bin", "wb") as f:
        f.write(struct.pack("<Q", 1000000))
        f.write(struct.pack("<2000000d", *[r.random() for _ in range(2000000)]))
PY
      for run in 1 2 3; do
        for warm in false true; do
          .carry/bin/galpha_server --backend=cuda --listen=127.0.0.1:0 --metrics_listen=127.0.0.1:0 \
            --warm_up=$warm --drain_notice_ms=0 > "$work/server.log" 2>&1 &
          server=$!
          for _ in $(seq 1 300); do grep -q "metrics on port" "$work/server.log" && break; sleep 0.1; done
          port=$(sed -n 's/.*listening on port \([0-9]*\).*/\1/p' "$work/server.log")
          metrics=$(sed -n 's/.*metrics on port \([0-9]*\).*/\1/p' "$work/server.log")
          if [ -z "$port" ] || [ -z "$metrics" ]; then
            echo "warm_up=$warm run=$run: the server did not start" | tee -a "$out/warm_up.log"
            cat "$work/server.log" >> "$out/warm_up.log"; status=1; kill $server; continue
          fi
          for set in a b; do
            if ! timeout 120 .carry/bin/alphactl --server 127.0.0.1:$port summary "$work/$set.bin" --rank 1 \
              > /dev/null 2>> "$out/warm_up.log"; then
              echo "warm_up=$warm run=$run: build $set failed" | tee -a "$out/warm_up.log"; status=1
            fi
            echo "warm_up=$warm run=$run after build $set: $(python3 - "$metrics" <<'PY'
import sys, urllib.request
page = urllib.request.urlopen(f"http://127.0.0.1:{sys.argv[1]}/metrics", timeout=10).read().decode()
print(" ".join(l for l in page.splitlines() if l.startswith(("galpha_build_seconds_sum", "galpha_warm_up_seconds"))))
PY
)" | tee -a "$out/warm_up.log"
          done
          kill $server; wait $server 2> /dev/null
        done
      done
      rm -rf "$work"; trap - EXIT
      ;;
    bench)
      [ -x .carry/bin/delaunay_bench ] || { echo "no delaunay_bench in .carry"; status=1; continue; }
      # The benchmark distributions at three sizes, then the degenerate test distributions, whose
      # rows only show that they are not pathologically slow.
      # shellcheck disable=SC2086
      run_step bench 420 .carry/bin/delaunay_bench \
        ${GALPHA_BENCH_ARGS:---backend=cuda --sizes=100000,1000000,10000000 --repeat=3}
      run_step bench 120 .carry/bin/delaunay_bench --backend=cuda --sizes=100000,1000000 --repeat=1 \
        --dists=parallel_lines,two_lines,circle,tiny,huge_offset_1e15
      grep -E '^\|' "$out/bench.log"
      ;;
    alpha)
      [ -x .carry/bin/alpha_bench ] || { echo "no alpha_bench in .carry"; status=1; continue; }
      # The whole family on the GPU against CGAL's Alpha_shape_2 (exact constructions, one thread)
      # at 100K and 1M, then the GPU alone at 10M; then the CPU backend on this machine's cores.
      run_step alpha 300 .carry/bin/alpha_bench --backend=cuda --sizes=100000,1000000 --repeat=3
      run_step alpha 120 .carry/bin/alpha_bench --backend=cuda --sizes=10000000 --repeat=2 --cgal-max=0
      # 100M points: whether they fit on one 80 GB GPU (about 51 GB at the measured 508 B/pt).
      run_step alpha 300 .carry/bin/alpha_bench --backend=cuda --sizes=100000000 --dists=uniform --repeat=1 --cgal-max=0
      run_step alpha 150 .carry/bin/alpha_bench --backend=cpu --sizes=1000000 --repeat=1 --cgal-max=0
      grep -E '^\|' "$out/alpha.log"
      ;;
    *)
      echo "unknown phase '$phase'"
      status=1
      ;;
  esac
done
exit $status
