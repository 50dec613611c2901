#!/usr/bin/env bash
# Installs what is missing, builds everything, and runs every test: first in the optimised release build, then in
# the debug build with AddressSanitizer and UndefinedBehaviorSanitizer. This is the command CI runs.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
jobs="$(nproc 2>/dev/null || echo 2)"
for preset in release debug-asan; do
  echo "==> [$preset] build"
  bash scripts/build.sh "$preset"
  echo "==> [$preset] test"
  ctest --preset "$preset" -j "$jobs"
done
