#!/usr/bin/env bash
# Run HERE (the build machine): builds the CUDA configuration and gathers what the GPU machine
# needs into .carry/ (git-ignored): the test and benchmark binaries, the shared libraries they
# use that a bare Ubuntu 24.04 + CUDA machine lacks (Abseil, GMP, MPFR, GEOS, gRPC, protobuf,
# prometheus-cpp and what they pull in), and the data sets.
# Then call the device tool with carry=[".carry-pack"] and the command
#   tar -xJf .carry-pack/carry.tar.xz && bash bench/gpu_run.sh test alpha
# The argument picks the binaries (the device takes at most 64 MiB of carry, and all of them
# compress to about 90 MB): `engine` (default) for the phases test, hard, alpha, bench,
# topology, identity and profile; `service` for smoke, sanitize and service (the server, its test
# and benchmark, alphactl, and alpha_bench).
set -euo pipefail
set_name=${1:-engine}
cd "$(dirname "$0")/.."
# Without GDAL and PROJ: alphactl would carry GDAL and the hundred libraries it pulls in, and PROJ
# its database (the GPU machine reads .bin files only, without a CRS).
scripts/drop-stale-build-dir.sh cuda
cmake --preset cuda -DGALPHA_WITH_GDAL=OFF -DGALPHA_WITH_PROJ=OFF -DGALPHA_WITH_GEMMI=OFF >/dev/null
# An object whose compile was interrupted (two builds at once in this tree, a killed build) can be
# left with no header dependencies recorded, and ninja then never rebuilds it when a header
# changes: the bundle carried a stale engine once. Such objects are rebuilt.
stale=$(ninja -C build/cuda -t deps 2>/dev/null | awk '/: #deps 0,/ && $1 ~ /\.(cu|cpp)\.o:$/ {sub(/:$/, "", $1); print $1}' || true)
for object in $stale; do rm -f "build/cuda/$object"; done
cmake --build --preset cuda -j"$(nproc)"
rm -rf .carry && mkdir -p .carry/bin .carry/lib
bins=()
# By name, wherever the build tree puts them (it mirrors the source folders).
case "$set_name" in
  engine) names="predicates_test predicates_device_test power_test delaunay_test delaunay_cgal_test regular_test regular_cgal_test triangulation_checks_test triangulate_sets_test
                 radius_test weighted_radius_test alpha_family_cgal_test weighted_family_cgal_test alpha_family_test
                 alpha_bruteforce_test alpha_backend_identity_test packed_families_test
                 persistence_gudhi_test persistence_engine_test resident_family_test shape_test delaunay_bench alpha_bench
                 topology_bench resident_bench" ;;
  service) names="alphactl service_bench galpha_server service_test alpha_bench" ;;
  *) echo "usage: $0 [engine|service]" >&2; exit 2 ;;
esac
for name in $names; do
  b=$(find build/cuda -name "$name" -type f -perm -u+x -not -path '*/CMakeFiles/*' | head -n 1)
  if [ -n "$b" ]; then cp "$b" .carry/bin/; bins+=(".carry/bin/$name"); fi
done
for b in "${bins[@]}"; do
  # Everything but the C/C++ runtime, OpenMP and the driver, which the GPU machine has (newer).
  ldd "$b" | awk '/=> \//{print $3}' |
    grep -vE '/(libc|libm|libpthread|libdl|librt|libstdc\+\+|libgcc_s|libgomp|libcuda)\.so|ld-linux' || true
done | sort -u | while read -r lib; do cp -L "$lib" .carry/lib/; done
# Symbols are not needed there and the carried folder must stay under 64 MiB.
strip --strip-unneeded .carry/bin/* .carry/lib/*
du -sh .carry
# The binaries hold the CUDA code of the whole engine (about 13 MB each): compressed, they travel.
rm -rf .carry-pack && mkdir -p .carry-pack
tar -cJf .carry-pack/carry.tar.xz .carry
du -sh .carry-pack
