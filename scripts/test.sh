#!/usr/bin/env bash
# Installs what is missing, builds everything, and runs every test: first in the optimised release build, then in
# the debug build with AddressSanitizer and UndefinedBehaviorSanitizer, then the fuzz targets. This is the command CI
# runs.
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
# Then the libFuzzer targets (docs/fuzzing.md): the `fuzz` preset (clang, ASan + UBSan), each target fuzzed for 60 s
# from the repository's seed corpus; a crash, leak, sanitizer report, timeout or out-of-memory fails the run.
echo "==> [fuzz] build and run"
bash scripts/fuzz.sh 60
