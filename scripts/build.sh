#!/usr/bin/env bash
# Configures and builds one CMake preset (default: release), every target or only those named after it.
# Usage: scripts/build.sh [preset [target...]]
# REDRES_WERROR=ON (CI's scripts/test.sh sets it) turns every compiler warning of redres's own code into an error;
# REDRES_WERROR=OFF turns that off again (the choice stays in the build directory's cache).
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
shift || true
jobs="$(nproc 2>/dev/null || echo 2)"
werror=()
if [ -n "${REDRES_WERROR:-}" ]; then werror=(-DREDRES_WERROR="$REDRES_WERROR"); fi
cmake --preset "$preset" "${werror[@]}" >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build --preset "$preset" -j "$jobs" "${targets[@]}"
