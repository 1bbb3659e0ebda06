#!/usr/bin/env bash
# The container image's build steps, in one script so that CI runs exactly what the image runs
# (no Docker engine in CI): installs the server's build dependencies with the same script as the
# README and CI (--profile=server), builds galpha_server and alphactl without tests, benchmarks,
# CGAL, GDAL or gemmi (alphactl in the image reads no Shapefiles, GeoPackages or structures) (CUDA for CMAKE_CUDA_ARCHITECTURES, default 90, when nvcc is present), and stages them with
# the shared libraries a CUDA runtime image lacks:
#   deploy/build-server.sh DEST       ->  DEST/bin/{galpha_server,alphactl}, DEST/lib/*.so*
# Then checks that the staged server starts from DEST alone and answers its health check.
# GALPHA_IMAGE_WITH_CUDA (AUTO, ON or OFF; default AUTO, what the Dockerfile uses) is passed to
# GALPHA_WITH_CUDA: CI on a machine without a GPU sets OFF, since compiling the engine's CUDA code
# there would only test nvcc (the GPU runs build it).
set -euo pipefail
cd "$(dirname "$0")/.."
dest=${1:?usage: deploy/build-server.sh DEST}
build=${GALPHA_IMAGE_BUILD_DIR:-build/image}
scripts/install-deps.sh --profile=server
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DGALPHA_BUILD_TESTS=OFF -DGALPHA_BUILD_BENCH=OFF \
  -DGALPHA_WITH_CGAL=OFF -DGALPHA_WITH_GDAL=OFF -DGALPHA_WITH_GEMMI=OFF -DGALPHA_WITH_CUDA="${GALPHA_IMAGE_WITH_CUDA:-AUTO}" -DCMAKE_CUDA_ARCHITECTURES="${CUDA_ARCHITECTURES:-90}" >/dev/null
cmake --build "$build" --target galpha_server alphactl -j"$(nproc)"

rm -rf "$dest" && mkdir -p "$dest/bin" "$dest/lib"
cp "$build/server/galpha_server" "$build/client/alphactl" "$dest/bin/"
# Every library but the C/C++ runtime and the CUDA driver, which the runtime image provides.
for b in "$dest"/bin/*; do
  ldd "$b" | awk '/=> \//{print $3}'
done | sort -u | grep -vE '/(libc|libm|libpthread|libdl|librt|libstdc\+\+|libgcc_s|libcuda)\.so|ld-linux' |
  while read -r lib; do cp -L "$lib" "$dest/lib/"; done
strip --strip-unneeded "$dest"/bin/* "$dest"/lib/*
# PROJ's database (alphactl --crs; the image sets PROJ_DATA to it).
mkdir -p "$dest/share/proj" && cp /usr/share/proj/proj.db "$dest/share/proj/"

# Smoke test of the staged tree: libraries found, server up, health SERVING, SIGTERM exits 0;
# alphactl projects with the staged PROJ database.
export LD_LIBRARY_PATH="$dest/lib" PROJ_DATA="$dest/share/proj"
printf -- '-123.0 44.0\n-122.99 44.0\n-123.0 44.01\n' | "$dest/bin/alphactl" summary - --crs EPSG:4326 --rank 1 --backend=cpu >/dev/null
log=$(mktemp)
"$dest/bin/galpha_server" --listen=127.0.0.1:0 --metrics_listen= --backend=cpu --drain_notice_ms=0 >"$log" 2>&1 &
pid=$!
for _ in $(seq 100); do grep -q "listening on port" "$log" && break; sleep 0.1; done
port=$(sed -n 's/.*listening on port \([0-9]*\).*/\1/p' "$log")
[ -n "$port" ] || { cat "$log"; echo "build-server: the staged server did not start" >&2; kill $pid; exit 1; }
"$dest/bin/galpha_server" --health_check="127.0.0.1:$port"
kill -TERM $pid
wait $pid
rm -f "$log"
echo "build-server: staged $(du -sh "$dest" | cut -f1) in $dest"
