#!/usr/bin/env bash
# Installs what is missing, builds everything, and runs every test: first in the optimised release build (GCC), then
# in the debug build with AddressSanitizer and UndefinedBehaviorSanitizer (clang, which also builds the libFuzzer
# targets), then the fuzz targets. This is the command CI runs. Each stage prints how long it took, and the last line
# sums them up.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc 2>/dev/null || echo 2)"
times=()
stage() {  # stage NAME COMMAND...: runs the command and records its wall time
  local name="$1" start=$SECONDS
  shift
  echo "==> [$name]"
  "$@"
  times+=("$name $((SECONDS - start)) s")
  echo "==> [$name] took $((SECONDS - start)) s"
}
stage install bash scripts/install_deps.sh clang-14 libclang-rt-14-dev llvm-14
# Every warning of redres's own code is an error here, so that the release and sanitizer builds stay free of them.
export REDRES_WERROR=ON
for preset in release debug-asan; do
  stage "$preset build" bash scripts/build.sh "$preset"
  stage "$preset test" ctest --preset "$preset" -j "$jobs"
done
# Then the libFuzzer targets (docs/fuzzing.md), built by the sanitizer build above: each target fuzzed for 60 s from
# the repository's seed corpus, two at a time on two cores; a crash, leak, sanitizer report, timeout or out-of-memory
# fails the run.
stage fuzz bash scripts/fuzz.sh 60
echo "test.sh: stage times: $(IFS=';'; echo "${times[*]}"); total $SECONDS s"
