#!/usr/bin/env bash
# Installs every Debian 12 package galpha needs to build, test and benchmark. Used by the README's
# commands and by CI. The CUDA toolkit (nvcc, and the CCCL headers that both backends compile
# against) is expected at /usr/local/cuda; it is not a Debian package.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libabsl-dev            # Status / StatusOr, strings, flags
  libgtest-dev libgmock-dev
  libbenchmark-dev
  libgmp-dev             # exact rational oracle in tests
  nlohmann-json3-dev     # GeoJSON point files
  libcgal-dev libmpfr-dev  # CGAL: test oracle and benchmark competitor
  libgeos-dev            # GEOS C API: validity oracle of the shape tests (geometry validity, union)
  libssl-dev             # SHA-256 of point sets: content-derived handles
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler  # the gRPC service
  prometheus-cpp-dev libcivetweb-dev  # the metrics exporter
  openssl                # the TLS tests make a self-signed certificate
  curl                   # the README's service walk-through scrapes /metrics
  clang libclang-rt-14-dev  # libFuzzer: the fuzz targets run briefly in CI
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if [ ! -f /usr/local/cuda/include/cccl/thrust/version.h ] && [ ! -f /usr/local/cuda/include/thrust/version.h ]; then
  echo "install-deps: the CUDA toolkit (CCCL headers) was not found under /usr/local/cuda;" >&2
  echo "install CUDA 12.8+ or pass -DGALPHA_CCCL_INCLUDE_DIR=... to cmake" >&2
  exit 1
fi
