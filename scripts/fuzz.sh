#!/usr/bin/env bash
# Builds the libFuzzer targets (in the `debug-asan` preset: clang 14, ASan + UBSan, tests/fuzz/) and runs each one
# for SECONDS (default 60), as many at once as there are cores, from a seed corpus copied out of the repository's
# robots, scenarios and test data. Fails on any crash, leak, sanitizer report, timeout or out-of-memory; the input is
# kept under build/fuzz/artifacts/<target>/ and printed with the report. docs/fuzzing.md has the details.
#   Usage: scripts/fuzz.sh [SECONDS]
#   FUZZ_TARGETS="robot_loader formula" runs only those targets; FUZZ_ARGS="..." adds libFuzzer flags;
#   FUZZ_JOBS=N runs N targets at once (default: the number of cores).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
read -r -a targets <<<"${FUZZ_TARGETS:-robot_loader urdf_loader scenario_loader overrides formula}"
jobs="$(nproc 2>/dev/null || echo 2)"
parallel="${FUZZ_JOBS:-$jobs}"
bin_dir=build/debug-asan/bin
out=build/fuzz

# One scripts/fuzz.sh at a time: runs share the corpus, the logs and the targets' scratch directories.
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
cmake --preset debug-asan >/dev/null
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

# fuzz_one TARGET: fuzzes one target in its own corpus, artifacts, log and scratch directory; writes its summary line
# to $out/logs/TARGET.result and, when it fails, its report to $out/logs/TARGET.report.
fuzz_one() {
  local t="$1" bin="$bin_dir/${1}_fuzz" corpus="$out/corpus/$1" artifacts="$out/artifacts/$1"
  local log="$out/logs/$1.log" result="$out/logs/$1.result" report="$out/logs/$1.report"
  local rc=0 run_start runs secs f line first text
  seed_corpus "$t" "$corpus"
  rm -rf "$artifacts" "${out:?}/tmp/$t" "$result" "$report"
  mkdir -p "$artifacts" "$out/tmp/$t"
  echo "==> [fuzz] $t for $seconds s ($(find "$corpus" -type f | wc -l) inputs in $corpus)"
  run_start=$(date +%s)
  # shellcheck disable=SC2086  # FUZZ_ARGS is split on purpose
  TMPDIR="$PWD/$out/tmp/$t" "$bin" -max_total_time="$seconds" -max_len=131072 -timeout=2 -rss_limit_mb=1024 \
    -malloc_limit_mb=1024 -dict="$(dict_of "$t")" -artifact_prefix="$artifacts/" -print_final_stats=1 \
    ${FUZZ_ARGS:-} "$corpus" >"$log" 2>&1 || rc=$?
  runs=$(sed -nE 's/^Done ([0-9]+) runs in ([0-9]+) second.*/\1/p' "$log" | tail -1)
  secs=$(sed -nE 's/^Done ([0-9]+) runs in ([0-9]+) second.*/\2/p' "$log" | tail -1)
  [ -n "$runs" ] || runs=$(sed -nE 's/^stat::number_of_executed_units: *([0-9]+).*/\1/p' "$log" | tail -1)
  [ -n "$secs" ] || secs=$(($(date +%s) - run_start))
  # libFuzzer also keeps inputs that ran for 10 s or more as slow-unit-*: a warning, not a failure (a pause of the
  # machine makes one; a slow input is a failure through -timeout).
  mapfile -t slow < <(find "$artifacts" -type f -name 'slow-unit-*' | sort)
  for f in "${slow[@]}"; do
    echo "fuzz: warning: $t: a slow input (10 s or more once, under the 2 s timeout otherwise) kept at $f"
  done
  mapfile -t found < <(find "$artifacts" -type f ! -name 'slow-unit-*' | sort)
  line="fuzz: $t: ${runs:-0} runs in $secs s, ${#found[@]} crashes"
  if [ "$rc" -ne 0 ] || [ "${#found[@]}" -gt 0 ]; then
    line="$line (FAILED, exit code $rc)"
    {
      echo "fuzz: $t FAILED (exit code $rc); the report (full log: $log):"
      # The sanitizer's or libFuzzer's report, from its first line to its summary (else the end of the log).
      first='==ERROR\|ERROR: libFuzzer\|runtime error:\|ERROR: AddressSanitizer\|ERROR: LeakSanitizer'
      text=$(sed -n "/$first/,/^SUMMARY/p" "$log" | head -n 120)
      if [ -n "$text" ]; then echo "$text"; else tail -n 30 "$log"; fi
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
    } >"$report"
  fi
  echo "$line" >"$result"
  echo "$line"
}

for t in "${targets[@]}"; do
  [ -x "$bin_dir/${t}_fuzz" ] || { echo "fuzz: no target $t ($bin_dir/${t}_fuzz)" >&2; exit 2; }
done
mkdir -p "$out/logs" "$out/tmp"
# Every sanitizer report is fatal (the code is also built with -fno-sanitize-recover=all); leaks are reported at the
# end of each input by libFuzzer's leak check.
export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:symbolize=1:print_summary=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:report_error_type=1:symbolize=1"
export LSAN_OPTIONS="print_suppressions=0"
export ASAN_SYMBOLIZER_PATH=/usr/bin/llvm-symbolizer-14
# The targets run side by side, FUZZ_JOBS at a time (the scratch directories live inside the build tree:
# tests/fuzz/fuzz_util.hpp).
running=0
for t in "${targets[@]}"; do
  if [ "$running" -ge "$parallel" ]; then
    wait -n || true
    running=$((running - 1))
  fi
  fuzz_one "$t" &
  running=$((running + 1))
done
wait || true

failed=()
summary=()
total_runs=0
for t in "${targets[@]}"; do
  result="$out/logs/$t.result"
  if [ ! -f "$result" ]; then
    line="fuzz: $t: did not finish (FAILED)"
  else
    line=$(cat "$result")
  fi
  [ -f "$out/logs/$t.report" ] && cat "$out/logs/$t.report"
  case "$line" in *FAILED*) failed+=("$t") ;; esac
  runs=$(sed -nE 's/^fuzz: [a-z_]+: ([0-9]+) runs.*/\1/p' <<<"$line")
  total_runs=$((total_runs + ${runs:-0}))
  summary+=("$line")
done

echo "==> [fuzz] summary"
printf '%s\n' "${summary[@]}"
echo "fuzz: $total_runs runs in total"
rm -rf "$out/tmp"
if [ "${#failed[@]}" -gt 0 ]; then
  echo "fuzz: FAILED: ${failed[*]}" >&2
  exit 1
fi
