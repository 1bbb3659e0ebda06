#!/usr/bin/env bash
# Removes build/PRESET for each preset named whose tree was configured with another generator than
# the presets' (CMakePresets.json: Ninja since 2026-11-27, Unix Makefiles before): CMake refuses to
# reconfigure such a tree, so the scripts that configure a preset call this first.
#   scripts/drop-stale-build-dir.sh PRESET...
set -euo pipefail
cd "$(dirname "$0")/.."
for preset in "$@"; do
  cache="build/$preset/CMakeCache.txt"
  [ -f "$cache" ] || continue
  if ! grep -qx 'CMAKE_GENERATOR:INTERNAL=Ninja' "$cache"; then
    echo "drop-stale-build-dir: build/$preset was configured for $(sed -n 's/^CMAKE_GENERATOR:INTERNAL=//p' "$cache");" \
      "the presets use Ninja now: removing it" >&2
    rm -rf "build/$preset"
  fi
done
