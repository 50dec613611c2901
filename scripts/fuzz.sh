#!/usr/bin/env bash
# Builds the libFuzzer targets (the `fuzz` preset: clang 14, ASan + UBSan, tests/fuzz/) and runs each one for
# SECONDS (default 60) from a seed corpus copied out of the repository's robots, scenarios and test data. Fails on
# any crash, leak, sanitizer report, timeout or out-of-memory; the input is kept under
# build/fuzz/artifacts/<target>/ and printed with the report. docs/fuzzing.md has the details.
#   Usage: scripts/fuzz.sh [SECONDS]
#   FUZZ_TARGETS="robot_loader formula" runs only those targets; FUZZ_ARGS="..." adds libFuzzer flags.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
read -r -a targets <<<"${FUZZ_TARGETS:-robot_loader urdf_loader scenario_loader overrides formula}"
jobs="$(nproc 2>/dev/null || echo 2)"
out=build/fuzz

# One run at a time: runs share the corpus, the logs and the targets' scratch directories.
mkdir -p "$out"
exec 9>"$out/fuzz.lock"
if ! flock -n 9; then
  echo "fuzz: another scripts/fuzz.sh is running on $out" >&2
  exit 2
fi

# clang 14 with libFuzzer's runtime, and llvm-symbolizer for the stack traces.
bash scripts/install_deps.sh clang-14 libclang-rt-14-dev llvm-14

echo "==> [fuzz] build"
build_start=$(date +%s)
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j "$jobs"
echo "fuzz: build took $(($(date +%s) - build_start)) s"

# Seeds: copied (named by content, as libFuzzer names its own inputs) into a scratch corpus under build/fuzz, which
# the fuzzer then extends; the repository is never written to. tests/fuzz/regressions/<target>/ holds the inputs
# of findings that were fixed, so each run checks them again.
add_seed() {  # add_seed DIR FILE...
  local dir="$1" f
  shift
  for f in "$@"; do
    [ -f "$f" ] && cp -f "$f" "$dir/$(sha1sum <"$f" | cut -c1-40)"
  done
  return 0
}
seed_corpus() {  # seed_corpus TARGET DIR
  local target="$1" dir="$2" s
  mkdir -p "$dir"
  shopt -s nullglob
  case "$target" in
    robot_loader)
      add_seed "$dir" robots/*.toml tests/data/*.toml tests/data/robots/*.toml tests/data/robot_corpus/*.toml ;;
    urdf_loader)
      # The shipped URDFs, the test URDFs (hostile ones among them) and any other URDF in the test data.
      add_seed "$dir" robots/urdf/*.urdf tests/data/urdf/*.urdf ;;
    scenario_loader)
      add_seed "$dir" configs/*.toml tests/data/scenario_corpus/*.toml ;;
    overrides)
      add_seed "$dir" tests/fuzz/seeds/overrides/* ;;
    formula)
      # Every quoted string of the robot, scenario and test files: their formulas, and words that are not formulas.
      grep -ohE '"[^"]*"' robots/*.toml configs/*.toml tests/data/*.toml tests/data/*/*.toml | sort -u |
        while IFS= read -r s; do
          s="${s#\"}"
          s="${s%\"}"
          printf '%s' "$s" >"$dir/$(printf '%s' "$s" | sha1sum | cut -c1-40)"
        done ;;
  esac
  add_seed "$dir" tests/fuzz/regressions/"$target"/*
  shopt -u nullglob
}
dict_of() {
  case "$1" in
    robot_loader | scenario_loader) echo tests/fuzz/dictionaries/toml.dict ;;
    urdf_loader) echo tests/fuzz/dictionaries/urdf.dict ;;
    *) echo "tests/fuzz/dictionaries/$1.dict" ;;
  esac
}

# Every sanitizer report is fatal (the code is also built with -fno-sanitize-recover=all); leaks are reported at the
# end of each input by libFuzzer's leak check.
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:symbolize=1:print_summary=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:report_error_type=1:symbolize=1"
export LSAN_OPTIONS="print_suppressions=0"
export ASAN_SYMBOLIZER_PATH=/usr/bin/llvm-symbolizer-14
# The targets' scratch directories (tests/fuzz/fuzz_util.hpp), kept inside the build tree.
export TMPDIR="$PWD/$out/tmp"

failed=()
summary=()
total_runs=0
for t in "${targets[@]}"; do
  bin="$out/bin/${t}_fuzz"
  [ -x "$bin" ] || { echo "fuzz: no target $t ($bin)" >&2; exit 2; }
  corpus="$out/corpus/$t"
  artifacts="$out/artifacts/$t"
  log="$out/logs/$t.log"
  seed_corpus "$t" "$corpus"
  rm -rf "$artifacts" "$TMPDIR"
  mkdir -p "$artifacts" "$TMPDIR" "$(dirname "$log")"
  echo "==> [fuzz] $t for $seconds s ($(find "$corpus" -type f | wc -l) inputs in $corpus)"
  rc=0
  run_start=$(date +%s)
  # shellcheck disable=SC2086  # FUZZ_ARGS is split on purpose
  "$bin" -max_total_time="$seconds" -max_len=131072 -timeout=2 -rss_limit_mb=1024 -malloc_limit_mb=1024 \
    -dict="$(dict_of "$t")" -artifact_prefix="$artifacts/" -print_final_stats=1 ${FUZZ_ARGS:-} "$corpus" \
    >"$log" 2>&1 || rc=$?
  runs=$(sed -nE 's/^Done ([0-9]+) runs in ([0-9]+) second.*/\1/p' "$log" | tail -1)
  secs=$(sed -nE 's/^Done ([0-9]+) runs in ([0-9]+) second.*/\2/p' "$log" | tail -1)
  [ -n "$runs" ] || runs=$(sed -nE 's/^stat::number_of_executed_units: *([0-9]+).*/\1/p' "$log" | tail -1)
  [ -n "$secs" ] || secs=$(($(date +%s) - run_start))
  runs="${runs:-0}"
  total_runs=$((total_runs + runs))
  # libFuzzer also keeps inputs that ran for 10 s or more as slow-unit-*: a warning, not a failure (a pause of the
  # machine makes one; a slow input is a failure through -timeout).
  mapfile -t slow < <(find "$artifacts" -type f -name 'slow-unit-*' | sort)
  for f in "${slow[@]}"; do
    echo "fuzz: warning: $t: a slow input (10 s or more once, under the 2 s timeout otherwise) kept at $f"
  done
  mapfile -t found < <(find "$artifacts" -type f ! -name 'slow-unit-*' | sort)
  line="fuzz: $t: $runs runs in $secs s, ${#found[@]} crashes"
  if [ "$rc" -ne 0 ] || [ "${#found[@]}" -gt 0 ]; then
    failed+=("$t")
    line="$line (FAILED, exit code $rc)"
    echo "fuzz: $t FAILED (exit code $rc); the report (full log: $log):"
    # The sanitizer's or libFuzzer's report, from its first line to its summary (else the end of the log).
    first='==ERROR\|ERROR: libFuzzer\|runtime error:\|ERROR: AddressSanitizer\|ERROR: LeakSanitizer'
    report=$(sed -n "/$first/,/^SUMMARY/p" "$log" | head -n 120)
    if [ -n "$report" ]; then echo "$report"; else tail -n 30 "$log"; fi
    for f in "${found[@]}"; do
      echo "fuzz: input kept at $f ($(stat -c %s "$f") bytes); reproduce with: $bin $f"
      echo "----- begin input -----"
      if LC_ALL=C grep -q '[^[:print:][:space:]]' "$f"; then
        od -A d -c "$f" | head -n 60  # binary: escaped
      else
        head -c 4096 "$f"
        echo
      fi
      echo "----- end input -----"
    done
  fi
  echo "$line"
  summary+=("$line")
done

echo "==> [fuzz] summary"
printf '%s\n' "${summary[@]}"
echo "fuzz: $total_runs runs in total"
rm -rf "$TMPDIR"
if [ "${#failed[@]}" -gt 0 ]; then
  echo "fuzz: FAILED: ${failed[*]}" >&2
  exit 1
fi
