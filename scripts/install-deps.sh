#!/usr/bin/env bash
# Installs every Debian 12 package galpha needs to build, test and benchmark (--profile=all, the
# default), or only what the server and alphactl need to build (--profile=server: the container
# image's build stage, deploy/build-server.sh). Used by the README's commands, CI and the image. The CUDA toolkit (nvcc, and the CCCL headers that both backends compile
# against) is expected at /usr/local/cuda; it is not a Debian package.
set -euo pipefail

# What the server and alphactl need to build (the container image installs only this: --profile server).
server_packages=(
  build-essential cmake ninja-build pkg-config
  libabsl-dev            # Status / StatusOr, strings, flags
  libgmp-dev             # exact rational fallback of the radius comparisons
  nlohmann-json3-dev     # GeoJSON point files
  libssl-dev             # SHA-256 of point sets: content-derived handles
  libzstd-dev            # zstd-compressed point chunks on the wire (proto/codec)
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler  # the gRPC service
  prometheus-cpp-dev libcivetweb-dev  # the metrics exporter
  libproj-dev proj-data  # coordinate reference systems: geographic input in metres, GeoJSON in WGS84 (GALPHA_WITH_PROJ)
)
# Everything else the tests, benchmarks and CI need (the default profile, "all").
test_packages=(
  libgtest-dev libgmock-dev
  libbenchmark-dev
  libcgal-dev libmpfr-dev  # CGAL: test oracle and benchmark competitor
  libgudhi-dev libeigen3-dev  # GUDHI's exact alpha-complex persistence: the persistence oracle and competitor
  python3-gudhi          # the same oracle for the Python package's persistence tests
  libgeos-dev            # GEOS C API: validity oracle of the shape tests (geometry validity, union)
  gemmi-dev tao-pegtl-dev  # alphactl reads PDB and mmCIF structures (GALPHA_WITH_GEMMI; gemmi's headers need PEGTL,
                         # which Debian's gemmi-dev does not pull in); the server image builds without it
  libgdal-dev            # alphactl reads Shapefile, GeoPackage and FlatGeobuf point layers (GALPHA_WITH_GDAL);
                         # the server image builds without it (deploy/build-server.sh: -DGALPHA_WITH_GDAL=OFF)
  openssl                # the TLS tests make a self-signed certificate
  curl                   # the README's service walk-through scrapes /metrics
  clang libclang-rt-14-dev  # libFuzzer: the fuzz targets run briefly in CI
  clang-format clang-tidy   # scripts/lint.sh: the format check and static analysis, as errors
  ccache                 # scripts/test.sh: the image build reuses the CPU build's objects
  pybind11-dev python3-dev python3-numpy python3-pytest  # galpha._engine (GALPHA_BUILD_PYTHON) and its tests
  python3-grpcio python3-protobuf  # the Python package's network client (stubs: protobuf-compiler-grpc above)
  python3-zstandard      # its compressed point chunks (EncodedPointChunk) and Classify answers (EncodedSimplexChunk)
  python3-shapely python3-geopandas python3-pyproj python3-tqdm  # its geometry answers, CRSs, progress bars
  python3-matplotlib     # python/examples: the plot of a shape over its points
  python3-pip python3-venv python3-setuptools  # the package's pip install (tested by its tests)
)

profile=all
for arg in "$@"; do
  case "$arg" in
    --profile=server) profile=server ;;
    --profile=all) profile=all ;;
    *) echo "usage: install-deps.sh [--profile=all|server]" >&2; exit 2 ;;
  esac
done
packages=("${server_packages[@]}")
[ "$profile" = server ] || packages+=("${test_packages[@]}")

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

# deploy/k8s/validate.sh runs on Node.js and npm: any installed ones do (machines often carry
# NodeSource's, whose nodejs package conflicts with Debian's npm package), else Debian's.
if [ "$profile" = all ] && ! command -v npm >/dev/null; then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends nodejs npm
fi

if [ ! -f /usr/local/cuda/include/cccl/thrust/version.h ] && [ ! -f /usr/local/cuda/include/thrust/version.h ]; then
  echo "install-deps: the CUDA toolkit (CCCL headers) was not found under /usr/local/cuda;" >&2
  echo "install CUDA 12.8+ or pass -DGALPHA_CCCL_INCLUDE_DIR=... to cmake" >&2
  exit 1
fi
