#!/usr/bin/env bash
# Configures and builds one CMake preset (default: release), every target or only those named after it.
# Usage: scripts/build.sh [preset [target...]]
# REDRES_WERROR=ON (CI's scripts/test.sh sets it) turns every compiler warning of redres's own code into an error.
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
shift || true
jobs="$(nproc 2>/dev/null || echo 2)"
cmake --preset "$preset" -DREDRES_WERROR="${REDRES_WERROR:-OFF}" >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build --preset "$preset" -j "$jobs" "${targets[@]}"
